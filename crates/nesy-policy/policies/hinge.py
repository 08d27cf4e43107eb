# Open the hinge box, put the apple in, close the lid.
vacuum = "vacuum_gripper" in get_obj_names()


def take_handle():
    move_gripper_to("hinge_handle", depth=0.0)
    if vacuum:
        attach_vacuum_handle("hinge_handle")
    else:
        grasp_handle("hinge_handle")


def let_go_handle():
    if vacuum:
        detach_vacuum_handle()
    else:
        release_handle()


take_handle()
lid = get_obj_pos("hinge_lid")
r = get_obj_size("hinge_lid")[0]
move_to_position([lid[0] + 0.5 * r, lid[1], lid[2] + r], lift_clearance=0.0)
let_go_handle()

h = get_obj_size("apple")[2]
move_gripper_to("apple", depth=h / 2)
activate_vacuum() if vacuum else close_gripper()
body = get_obj_pos("hinge_body")
top = get_obj_bbox("hinge_body")[1][2]
hang = h if vacuum else h / 2  # suction holds the fruit by its top
move_to_position([body[0], body[1], top + hang + 0.03])
deactivate_vacuum() if vacuum else open_gripper()

take_handle()
size = get_obj_size("hinge_body")
move_to_position([body[0] - 0.5 * size[0], body[1], body[2] + 0.5 * size[2]], lift_clearance=0.0)
let_go_handle()
