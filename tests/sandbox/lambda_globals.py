# expect: rejected
g = (lambda: 0).__globals__
print(g)
