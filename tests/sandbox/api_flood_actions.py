# expect: timeout
while True:
    try:
        move_parallel("up", 0.01)
    except Exception:
        pass
