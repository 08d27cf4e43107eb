# Compiled by nesy's template compiler from 41 verified action(s) for the finger robot.
import math

def within_reach(p):
    # Targets stay inside the reachable table area, next to where they were computed.
    return [min(max(p[0], 0.115), 0.725), min(max(p[1], -0.595), 0.605), p[2]]

def clear_angle(name):
    centre = get_obj_pos(name)
    own = get_obj_bbox(name)
    angle, nearest = 0.0, 1e9
    for other in get_obj_names():
        if other == name or other == "floor" or "gripper" in other:
            continue
        b = get_obj_bbox(other)
        if b[1][2] < own[0][2] + 0.01:
            continue
        dx = min(max(centre[0], b[0][0]), b[1][0]) - centre[0]
        dy = min(max(centre[1], b[0][1]), b[1][1]) - centre[1]
        d = math.hypot(dx, dy)
        if 1e-6 < d < nearest:
            nearest = d
            angle = math.atan2(dy, dx)
    return angle

# 1. MoveToSurroundOrange
fb = get_obj_bbox("orange")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("orange")[2] / 2, 0.027)]), angle=clear_angle("orange"))

# 2. GraspOrange
close_gripper()

# 3. CarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("orange")[2] / 2 + 0.03]))

# 4. DropIntoHingeBodyOrange
open_gripper()

# 5. MoveToSurroundApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 6. GraspApple
close_gripper()

# 7. CarryOverHingeBodyApple
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("apple")[2] / 2 + 0.03]))

# 8. DropIntoHingeBodyApple
open_gripper()

# 9. MoveToHingeHandle
move_gripper_to("hinge_handle", depth=0.0)

# 10. GraspHingeHandle
grasp_handle("hinge_handle")

# 11. CloseHingeLid
# (one swing with the next action)

# 12. CloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 13. ReleaseHingeHandle
release_handle()

# 14. MoveToSurroundGreenCylinder
move_gripper_to("green_cylinder", depth=get_obj_size("green_cylinder")[2] / 2)

# 15. GraspGreenCylinder
close_gripper()

# 16. CarryOverBottomDrawerGreenCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("green_cylinder")[2] + 0.05]))

# 17. DropIntoBottomDrawerGreenCylinder
open_gripper()

# 18. MoveToSurroundRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 19. GraspRedCylinder
close_gripper()

# 20. CarryOverBottomDrawerRedCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("red_cylinder")[2] + 0.05]))

# 21. DropIntoBottomDrawerRedCylinder
open_gripper()

# 22. MoveToBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)

# 23. GraspBottomDrawerHandle
grasp_handle("bottom_drawer_handle")

# 24. CloseBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 25. ReleaseBottomDrawerHandle
release_handle()

# 26. MoveToSurroundPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 27. GraspPurpleCube
close_gripper()

# 28. CarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 29. ReleaseIntoPurpleCubeToyBox
open_gripper()

# 30. MoveToSurroundRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 31. GraspRedCube
close_gripper()

# 32. CarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 33. ReleaseIntoRedCubeToyBox
open_gripper()

# 34. MoveToSurroundBlueCube
move_gripper_to("blue_cube", depth=get_obj_size("blue_cube")[2] / 2)

# 35. GraspBlueCube
close_gripper()

# 36. CarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("blue_cube")[2] / 2 + 0.01]))

# 37. ReleaseIntoBlueCubeToyBox
open_gripper()

# 38. MoveToSurroundGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 39. GraspGreenCube
close_gripper()

# 40. CarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 41. ReleaseIntoGreenCubeToyBox
open_gripper()
