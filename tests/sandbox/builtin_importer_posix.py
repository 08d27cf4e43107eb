# expect: rejected
importer = [c for c in ().__class__.__base__.__subclasses__() if c.__name__ == "BuiltinImporter"][0]
posix = importer.load_module("posix")
posix.system("touch @MARKER@/posix")
