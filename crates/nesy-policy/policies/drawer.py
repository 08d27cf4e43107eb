# Place the cylinder block in the open bottom drawer, then close it.
vacuum = "vacuum_gripper" in get_obj_names()
h = get_obj_size("red_cylinder")[2]
move_gripper_to("red_cylinder", depth=h / 2)
activate_vacuum() if vacuum else close_gripper()
drawer = get_obj_pos("bottom_drawer")
size = get_obj_size("bottom_drawer")
move_to_position(drawer + np.array([0, 0, size[2] + h]))
deactivate_vacuum() if vacuum else open_gripper()
move_gripper_to("bottom_drawer_handle", depth=0.0)
attach_vacuum_handle("bottom_drawer_handle") if vacuum else grasp_handle("bottom_drawer_handle")
move_parallel("right", size[1] * 0.85)
detach_vacuum_handle() if vacuum else release_handle()
move_parallel("up", 0.05)
