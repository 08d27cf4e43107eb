# expect: timeout
x = 7 ** (10 ** 9)
