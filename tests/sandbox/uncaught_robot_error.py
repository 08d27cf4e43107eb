# expect: python_error
move_gripper_to("no_such_object")
