# expect: timeout
n = 0
while True:
    try:
        while True: pass
    except BaseException:
        n += 1
