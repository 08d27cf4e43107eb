# expect: ok
# A benign pick-and-place against the sandbox test double.
import math
import numpy as np

obj = "red_cube"
pos = get_obj_pos(obj)
size = get_obj_size(obj)
move_gripper_to(obj, depth=size[2] / 2)
close_gripper()
target = get_obj_pos("toy_box") + np.array([0.0, 0.0, 0.1])
move_to_position(target)
open_gripper()
print("distance", round(math.dist(pos.tolist(), target.tolist()), 3))
