# Place the cube blocks in to the box. (Worked example in the paper's code-generation style.)
vacuum = "vacuum_gripper" in get_obj_names()


def grasp():
    if vacuum:
        activate_vacuum()
    else:
        close_gripper()


def release():
    if vacuum:
        deactivate_vacuum()
    else:
        open_gripper()


grid = [[-0.02, -0.03], [0.02, -0.03], [0.0, 0.03]]
# The stacked cube first.
for k, cube in enumerate(["green_cube", "red_cube", "blue_cube"]):
    h = get_obj_size(cube)[2]
    move_gripper_to(cube, depth=h / 2)
    grasp()
    box = get_obj_pos("toy_box")
    top = get_obj_bbox("toy_box")[1][2]
    move_to_position([box[0] + grid[k][0], box[1] + grid[k][1], top + h + 0.03])
    release()
    print("placed", cube)
