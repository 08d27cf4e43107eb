# expect: rejected
with open("@MARKER@/open_write", "w") as f:
    f.write("escaped")
