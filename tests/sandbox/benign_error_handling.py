# expect: ok
try:
    move_gripper_to("no_such_object")
except robot.UnknownObjectError as err:
    print("recovered:", err)
try:
    activate_vacuum()
except robot.WrongEmbodimentError:
    close_gripper()
