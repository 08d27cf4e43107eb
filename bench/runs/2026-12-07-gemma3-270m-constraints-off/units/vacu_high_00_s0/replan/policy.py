# Compiled by nesy's template compiler from 55 verified action(s) for the finger robot.
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

# 1. MoveToSurroundWhiteBishop
move_gripper_to("white_bishop", depth=get_obj_size("white_bishop")[2] / 1.3)

# 2. SweepIntoWhiteBishopLeftChessBox
piece_y = get_obj_pos("white_bishop")[1]
box_y = get_obj_pos("left_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 3. MoveToSurroundBlackKnight
move_gripper_to("black_knight", depth=get_obj_size("black_knight")[2] / 1.3)

# 4. SweepIntoBlackKnightRightChessBox
piece_y = get_obj_pos("black_knight")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 5. MoveToSurroundBlackBishop
move_gripper_to("black_bishop", depth=get_obj_size("black_bishop")[2] / 1.3)

# 6. SweepIntoBlackBishopRightChessBox
piece_y = get_obj_pos("black_bishop")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 7. MoveToSurroundGreenCylinder
move_gripper_to("green_cylinder", depth=get_obj_size("green_cylinder")[2] / 2)

# 8. GraspGreenCylinder
close_gripper()

# 9. CarryOverBottomDrawerGreenCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("green_cylinder")[2] + 0.05]))

# 10. DropIntoBottomDrawerGreenCylinder
open_gripper()

# 11. MoveToSurroundBlueCylinder
move_gripper_to("blue_cylinder", depth=get_obj_size("blue_cylinder")[2] / 2)

# 12. GraspBlueCylinder
close_gripper()

# 13. CarryOverBottomDrawerBlueCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("blue_cylinder")[2] + 0.05]))

# 14. DropIntoBottomDrawerBlueCylinder
open_gripper()

# 15. MoveToSurroundRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 16. GraspRedCylinder
close_gripper()

# 17. CarryOverBottomDrawerRedCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0, drawer[1] + 0.035 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("red_cylinder")[2] + 0.05]))

# 18. DropIntoBottomDrawerRedCylinder
open_gripper()

# 19. MoveToSurroundApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 20. GraspApple
close_gripper()

# 21. CarryOverHingeBodyApple
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("apple")[2] / 2 + 0.03]))

# 22. DropIntoHingeBodyApple
open_gripper()

# 23. MoveToSurroundOrange
fb = get_obj_bbox("orange")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("orange")[2] / 2, 0.027)]), angle=clear_angle("orange"))

# 24. GraspOrange
close_gripper()

# 25. CarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("orange")[2] / 2 + 0.03]))

# 26. DropIntoHingeBodyOrange
open_gripper()

# 27. MoveToSurroundLemon
fb = get_obj_bbox("lemon")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("lemon")[2] / 2, 0.027)]), angle=clear_angle("lemon"))

# 28. GraspLemon
close_gripper()

# 29. CarryOverHingeBodyLemon
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0.06, body[1][2] + get_obj_size("lemon")[2] / 2 + 0.03]))

# 30. DropIntoHingeBodyLemon
open_gripper()

# 31. GraspHingeHandle
move_gripper_to("hinge_handle", depth=0.0)
grasp_handle("hinge_handle")

# 32. CloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 33. MoveToSurroundPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 34. GraspPurpleCube
close_gripper()

# 35. CarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 36. ReleaseIntoPurpleCubeToyBox
open_gripper()

# 37. MoveToSurroundYellowCube
move_gripper_to("yellow_cube", depth=get_obj_size("yellow_cube")[2] / 2)

# 38. GraspYellowCube
close_gripper()

# 39. CarryIntoYellowCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("yellow_cube")[2] / 2 + 0.01]))

# 40. ReleaseIntoYellowCubeToyBox
open_gripper()

# 41. MoveToSurroundGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 42. GraspGreenCube
close_gripper()

# 43. CarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 44. ReleaseIntoGreenCubeToyBox
open_gripper()

# 45. MoveToSurroundBlueCube
move_gripper_to("blue_cube", depth=get_obj_size("blue_cube")[2] / 2)

# 46. GraspBlueCube
close_gripper()

# 47. CarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("blue_cube")[2] / 2 + 0.01]))

# 48. ReleaseIntoBlueCubeToyBox
open_gripper()

# 49. MoveToSurroundRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 50. GraspRedCube
close_gripper()

# 51. CarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 52. ReleaseIntoRedCubeToyBox
open_gripper()

# 53. GraspBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)
grasp_handle("bottom_drawer_handle")

# 54. CloseBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 55. ReleaseBottomDrawerHandle
release_handle()
