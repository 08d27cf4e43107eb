# expect: rejected
try:
    1 / 0
except Exception as err:
    frame = err.__traceback__.tb_frame
    frame.f_globals["x"] = 1
