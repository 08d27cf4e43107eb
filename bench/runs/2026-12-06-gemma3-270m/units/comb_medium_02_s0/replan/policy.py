# Compiled by nesy's template compiler from 43 verified action(s) for the finger robot.
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

# 1. MoveToSurroundRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 2. GraspRedCylinder
close_gripper()

# 3. CarryOverBottomDrawerRedCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("red_cylinder")[2] + 0.05]))

# 4. DropIntoBottomDrawerRedCylinder
open_gripper()

# 5. MoveToSurroundPurpleCylinder
move_gripper_to("purple_cylinder", depth=get_obj_size("purple_cylinder")[2] / 2)

# 6. GraspPurpleCylinder
close_gripper()

# 7. CarryOverBottomDrawerPurpleCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("purple_cylinder")[2] + 0.05]))

# 8. DropIntoBottomDrawerPurpleCylinder
open_gripper()

# 9. MoveToSurroundApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 10. GraspApple
close_gripper()

# 11. PutDownAppleFloor
spot = get_empty_floor_xy("apple")
move_to_position(within_reach([spot[0], spot[1], 0.5 + get_obj_size("apple")[2] / 2 + 0.01]))
open_gripper()

# 12. MoveToSurroundBlueCube
move_gripper_to("blue_cube", depth=get_obj_size("blue_cube")[2] / 2)

# 13. GraspBlueCube
close_gripper()

# 14. CarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("blue_cube")[2] / 2 + 0.01]))

# 15. ReleaseIntoBlueCubeToyBox
open_gripper()

# 16. MoveToSurroundGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 17. GraspGreenCube
close_gripper()

# 18. CarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 19. ReleaseIntoGreenCubeToyBox
open_gripper()

# 20. MoveToSurroundRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 21. GraspRedCube
close_gripper()

# 22. CarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 23. ReleaseIntoRedCubeToyBox
open_gripper()

# 24. MoveToSurroundPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 25. GraspPurpleCube
close_gripper()

# 26. CarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 27. ReleaseIntoPurpleCubeToyBox
open_gripper()

# 28. GraspBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)
grasp_handle("bottom_drawer_handle")

# 29. CloseBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 30. ReleaseBottomDrawerHandle
release_handle()

# 31. GraspHingeHandle
move_gripper_to("hinge_handle", depth=0.0)
grasp_handle("hinge_handle")

# 32. OpenHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 90.0, 60.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 33. ReleaseHingeHandle
release_handle()

# 34. MoveToSurroundOrange
fb = get_obj_bbox("orange")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("orange")[2] / 2, 0.027)]), angle=clear_angle("orange"))

# 35. GraspOrange
close_gripper()

# 36. CarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("orange")[2] / 2 + 0.03]))

# 37. DropIntoHingeBodyOrange
open_gripper()

# 38. MoveToSurroundApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 39. GraspApple
close_gripper()

# 40. CarryOverHingeBodyApple
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("apple")[2] / 2 + 0.03]))

# 41. DropIntoHingeBodyApple
open_gripper()

# 42. GraspHingeHandle
move_gripper_to("hinge_handle", depth=0.0)
grasp_handle("hinge_handle")

# 43. CloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)
