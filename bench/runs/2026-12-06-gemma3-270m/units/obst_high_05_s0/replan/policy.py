# Compiled by nesy's template compiler from 68 verified action(s) for the finger robot.
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

# 1. MoveToSurroundWhiteKnight
move_gripper_to("white_knight", depth=get_obj_size("white_knight")[2] / 1.3)

# 2. SweepIntoWhiteKnightLeftChessBox
piece_y = get_obj_pos("white_knight")[1]
box_y = get_obj_pos("left_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 3. MoveToSurroundRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 4. GraspRedCube
close_gripper()

# 5. CarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 6. ReleaseIntoRedCubeToyBox
open_gripper()

# 7. MoveToSurroundGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 8. GraspGreenCube
close_gripper()

# 9. CarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 10. ReleaseIntoGreenCubeToyBox
open_gripper()

# 11. MoveToSurroundBlueCube
move_gripper_to("blue_cube", depth=get_obj_size("blue_cube")[2] / 2)

# 12. GraspBlueCube
close_gripper()

# 13. CarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("blue_cube")[2] / 2 + 0.01]))

# 14. ReleaseIntoBlueCubeToyBox
open_gripper()

# 15. MoveToSurroundYellowCube
move_gripper_to("yellow_cube", depth=get_obj_size("yellow_cube")[2] / 2)

# 16. GraspYellowCube
close_gripper()

# 17. CarryIntoYellowCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("yellow_cube")[2] / 2 + 0.01]))

# 18. ReleaseIntoYellowCubeToyBox
open_gripper()

# 19. MoveToSurroundPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 20. GraspPurpleCube
close_gripper()

# 21. CarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 22. ReleaseIntoPurpleCubeToyBox
open_gripper()

# 23. MoveToSurroundWhiteBishop
move_gripper_to("white_bishop", depth=get_obj_size("white_bishop")[2] / 2)

# 24. GraspWhiteBishop
close_gripper()

# 25. CarryIntoWhiteBishopLeftChessBox
box = get_obj_bbox("left_chess_box")
move_to_position(within_reach([min(max(get_obj_pos("white_bishop")[0], box[0][0] + 0.025), box[1][0] - 0.025), (box[0][1] + box[1][1]) / 2, box[1][2] + get_obj_size("white_bishop")[2] / 2 + 0.01]))

# 26. ReleaseIntoWhiteBishopLeftChessBox
open_gripper()

# 27. MoveToSurroundBlackBishop
move_gripper_to("black_bishop", depth=get_obj_size("black_bishop")[2] / 2)

# 28. GraspBlackBishop
close_gripper()

# 29. CarryIntoBlackBishopRightChessBox
box = get_obj_bbox("right_chess_box")
move_to_position(within_reach([min(max(get_obj_pos("black_bishop")[0], box[0][0] + 0.025), box[1][0] - 0.025), (box[0][1] + box[1][1]) / 2, box[1][2] + get_obj_size("black_bishop")[2] / 2 + 0.01]))

# 30. ReleaseIntoBlackBishopRightChessBox
open_gripper()

# 31. GraspTopDrawerHandle
move_gripper_to("top_drawer_handle", depth=0.0)
grasp_handle("top_drawer_handle")

# 32. CloseTopDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 33. ReleaseTopDrawerHandle
release_handle()

# 34. GraspHingeHandle
move_gripper_to("hinge_handle", depth=0.0)
grasp_handle("hinge_handle")

# 35. OpenHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 90.0, 60.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 36. ReleaseHingeHandle
release_handle()

# 37. MoveToSurroundApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 38. GraspApple
close_gripper()

# 39. CarryOverHingeBodyApple
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("apple")[2] / 2 + 0.03]))

# 40. DropIntoHingeBodyApple
open_gripper()

# 41. MoveToSurroundLemon
fb = get_obj_bbox("lemon")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("lemon")[2] / 2, 0.027)]), angle=clear_angle("lemon"))

# 42. GraspLemon
close_gripper()

# 43. CarryOverHingeBodyLemon
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("lemon")[2] / 2 + 0.03]))

# 44. DropIntoHingeBodyLemon
open_gripper()

# 45. MoveToSurroundOrange
fb = get_obj_bbox("orange")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("orange")[2] / 2, 0.027)]), angle=clear_angle("orange"))

# 46. GraspOrange
close_gripper()

# 47. CarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0.06, body[1][2] + get_obj_size("orange")[2] / 2 + 0.03]))

# 48. DropIntoHingeBodyOrange
open_gripper()

# 49. GraspHingeHandle
move_gripper_to("hinge_handle", depth=0.0)
grasp_handle("hinge_handle")

# 50. CloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 51. GraspBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)
grasp_handle("bottom_drawer_handle")

# 52. OpenBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(open_dir, travel)

# 53. ReleaseBottomDrawerHandle
release_handle()

# 54. MoveToSurroundRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 55. GraspRedCylinder
close_gripper()

# 56. CarryOverBottomDrawerRedCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("red_cylinder")[2] + 0.05]))

# 57. DropIntoBottomDrawerRedCylinder
open_gripper()

# 58. MoveToSurroundPurpleCylinder
move_gripper_to("purple_cylinder", depth=get_obj_size("purple_cylinder")[2] / 2)

# 59. GraspPurpleCylinder
close_gripper()

# 60. CarryOverBottomDrawerPurpleCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("purple_cylinder")[2] + 0.05]))

# 61. DropIntoBottomDrawerPurpleCylinder
open_gripper()

# 62. MoveToSurroundGreenCylinder
move_gripper_to("green_cylinder", depth=get_obj_size("green_cylinder")[2] / 2)

# 63. GraspGreenCylinder
close_gripper()

# 64. CarryOverBottomDrawerGreenCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0, drawer[1] + 0.035 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("green_cylinder")[2] + 0.05]))

# 65. DropIntoBottomDrawerGreenCylinder
open_gripper()

# 66. GraspBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)
grasp_handle("bottom_drawer_handle")

# 67. CloseBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 68. ReleaseBottomDrawerHandle
release_handle()
