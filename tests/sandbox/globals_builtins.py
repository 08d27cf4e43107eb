# expect: rejected
b = globals()["__builtins__"]
b["open"]("@MARKER@/globals", "w")
