# Compiled by nesy's template compiler from 65 verified action(s) for the finger robot.
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

# 1. MoveToAlignGreenCylinder
move_gripper_to("green_cylinder", depth=get_obj_size("green_cylinder")[2] / 2)

# 2. AttachGreenCylinder
close_gripper()

# 3. SuctionCarryOverBottomDrawerGreenCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("green_cylinder")[2] + 0.05]))

# 4. SuctionDropIntoBottomDrawerGreenCylinder
open_gripper()

# 5. MoveToAlignBlueCylinder
move_gripper_to("blue_cylinder", depth=get_obj_size("blue_cylinder")[2] / 2)

# 6. AttachBlueCylinder
close_gripper()

# 7. SuctionCarryOverBottomDrawerBlueCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("blue_cylinder")[2] + 0.05]))

# 8. SuctionDropIntoBottomDrawerBlueCylinder
open_gripper()

# 9. MoveToAlignRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 10. AttachRedCylinder
close_gripper()

# 11. SuctionCarryOverBottomDrawerRedCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0, drawer[1] + 0.035 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("red_cylinder")[2] + 0.05]))

# 12. SuctionDropIntoBottomDrawerRedCylinder
open_gripper()

# 13. SuctionMoveToBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)

# 14. AttachBottomDrawerHandle
grasp_handle("bottom_drawer_handle")

# 15. SuctionCloseBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 16. DetachBottomDrawerHandle
release_handle()

# 17. MoveToAlignApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 18. AttachApple
close_gripper()

# 19. SuctionCarryOverHingeBodyApple
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("apple")[2] / 2 + 0.03]))

# 20. SuctionDropIntoHingeBodyApple
open_gripper()

# 21. MoveToAlignOrange
fb = get_obj_bbox("orange")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("orange")[2] / 2, 0.027)]), angle=clear_angle("orange"))

# 22. AttachOrange
close_gripper()

# 23. SuctionCarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("orange")[2] / 2 + 0.03]))

# 24. SuctionDropIntoHingeBodyOrange
open_gripper()

# 25. MoveToAlignLemon
fb = get_obj_bbox("lemon")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("lemon")[2] / 2, 0.027)]), angle=clear_angle("lemon"))

# 26. AttachLemon
close_gripper()

# 27. SuctionCarryOverHingeBodyLemon
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0.06, body[1][2] + get_obj_size("lemon")[2] / 2 + 0.03]))

# 28. SuctionDropIntoHingeBodyLemon
open_gripper()

# 29. SuctionMoveToHingeHandle
move_gripper_to("hinge_handle", depth=0.0)

# 30. AttachHingeHandle
grasp_handle("hinge_handle")

# 31. SuctionCloseHingeLid
# (one swing with the next action)

# 32. SuctionCloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 33. DetachHingeHandle
release_handle()

# 34. MoveToAlignPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 35. AttachPurpleCube
close_gripper()

# 36. SuctionCarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 37. SuctionReleaseIntoPurpleCubeToyBox
open_gripper()

# 38. MoveToAlignYellowCube
move_gripper_to("yellow_cube", depth=get_obj_size("yellow_cube")[2] / 2)

# 39. AttachYellowCube
close_gripper()

# 40. SuctionCarryIntoYellowCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("yellow_cube")[2] / 2 + 0.01]))

# 41. SuctionReleaseIntoYellowCubeToyBox
open_gripper()

# 42. MoveToAlignGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 43. AttachGreenCube
close_gripper()

# 44. SuctionCarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 45. SuctionReleaseIntoGreenCubeToyBox
open_gripper()

# 46. MoveToAlignBlueCube
move_gripper_to("blue_cube", depth=get_obj_size("blue_cube")[2] / 2)

# 47. AttachBlueCube
close_gripper()

# 48. SuctionCarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("blue_cube")[2] / 2 + 0.01]))

# 49. SuctionReleaseIntoBlueCubeToyBox
open_gripper()

# 50. MoveToAlignRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 51. AttachRedCube
close_gripper()

# 52. SuctionCarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 53. SuctionReleaseIntoRedCubeToyBox
open_gripper()

# 54. MoveToAlignWhiteBishop
move_gripper_to("white_bishop", depth=get_obj_size("white_bishop")[2] / 2)

# 55. AttachWhiteBishop
close_gripper()

# 56. SlideIntoWhiteBishopLeftChessBox
move_gripper_to("white_bishop", depth=get_obj_size("white_bishop")[2] / 1.3)
piece_y = get_obj_pos("white_bishop")[1]
box_y = get_obj_pos("left_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 57. SuctionReleaseIntoWhiteBishopLeftChessBox
open_gripper()

# 58. MoveToAlignBlackKnight
move_gripper_to("black_knight", depth=get_obj_size("black_knight")[2] / 2)

# 59. AttachBlackKnight
close_gripper()

# 60. SlideIntoBlackKnightRightChessBox
move_gripper_to("black_knight", depth=get_obj_size("black_knight")[2] / 1.3)
piece_y = get_obj_pos("black_knight")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 61. SuctionReleaseIntoBlackKnightRightChessBox
open_gripper()

# 62. MoveToAlignBlackBishop
move_gripper_to("black_bishop", depth=get_obj_size("black_bishop")[2] / 2)

# 63. AttachBlackBishop
close_gripper()

# 64. SlideIntoBlackBishopRightChessBox
move_gripper_to("black_bishop", depth=get_obj_size("black_bishop")[2] / 1.3)
piece_y = get_obj_pos("black_bishop")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 65. SuctionReleaseIntoBlackBishopRightChessBox
open_gripper()
