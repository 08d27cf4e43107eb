# expect: timeout
x = 0
while True:
    x = x + 1
    x = x - 1
