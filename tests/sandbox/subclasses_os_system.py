# expect: rejected
# ().__class__.__base__.__subclasses__() -> os._wrap_close -> os.system
for cls in ().__class__.__base__.__subclasses__():
    if cls.__name__ == "_wrap_close":
        cls.__init__.__globals__["system"]("touch @MARKER@/subclasses")
