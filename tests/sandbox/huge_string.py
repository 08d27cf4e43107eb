# expect: memory
s = "x" * (4 * 10 ** 9)
