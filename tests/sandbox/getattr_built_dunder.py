# expect: rejected
name = "__cl" + "ass__"
base = getattr(getattr((), name), "__ba" + "se__")
print(getattr(base, "__subcl" + "asses__")())
