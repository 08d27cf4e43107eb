# expect: rejected
__import__("os").system("touch @MARKER@/dunder_import")
