# expect: timeout
while True:
    get_obj_names()
