# expect: rejected
T = type("T", (), {"__del__": lambda self: print("finalizer")})
t = T()
