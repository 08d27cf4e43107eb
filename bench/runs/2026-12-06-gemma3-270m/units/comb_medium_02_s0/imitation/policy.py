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

# 1. SuctionMoveToTopDrawerHandle
move_gripper_to("top_drawer_handle", depth=0.0)

# 2. AttachTopDrawerHandle
grasp_handle("top_drawer_handle")

# 3. SuctionCloseTopDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 4. DetachTopDrawerHandle
release_handle()

# 5. MoveToAlignRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 6. AttachRedCylinder
close_gripper()

# 7. SuctionCarryOntoRedCylinderFloor
spot = get_empty_floor_xy("red_cylinder")
move_to_position(within_reach([spot[0], spot[1], 0.5 + get_obj_size("red_cylinder")[2] / 2 + 0.01]))

# 8. SuctionPutDownRedCylinderFloor
open_gripper()

# 9. MoveToAlignPurpleCylinder
move_gripper_to("purple_cylinder", depth=get_obj_size("purple_cylinder")[2] / 2)

# 10. AttachPurpleCylinder
close_gripper()

# 11. SuctionCarryOntoPurpleCylinderFloor
spot = get_empty_floor_xy("purple_cylinder")
move_to_position(within_reach([spot[0], spot[1], 0.5 + get_obj_size("purple_cylinder")[2] / 2 + 0.01]))

# 12. SuctionPutDownPurpleCylinderFloor
open_gripper()

# 13. SuctionMoveToBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)

# 14. AttachBottomDrawerHandle
grasp_handle("bottom_drawer_handle")

# 15. SuctionOpenBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(open_dir, travel)

# 16. DetachBottomDrawerHandle
release_handle()

# 17. SuctionRetreat
move_parallel("up", 0.05)

# 18. MoveToAlignRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 19. AttachRedCylinder
close_gripper()

# 20. SuctionCarryOverBottomDrawerRedCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("red_cylinder")[2] + 0.05]))

# 21. SuctionDropIntoBottomDrawerRedCylinder
open_gripper()

# 22. MoveToAlignPurpleCylinder
move_gripper_to("purple_cylinder", depth=get_obj_size("purple_cylinder")[2] / 2)

# 23. AttachPurpleCylinder
close_gripper()

# 24. SuctionCarryOverBottomDrawerPurpleCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("purple_cylinder")[2] + 0.05]))

# 25. SuctionDropIntoBottomDrawerPurpleCylinder
open_gripper()

# 26. SuctionMoveToBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)

# 27. AttachBottomDrawerHandle
grasp_handle("bottom_drawer_handle")

# 28. SuctionCloseBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 29. DetachBottomDrawerHandle
release_handle()

# 30. SuctionMoveToHingeHandle
move_gripper_to("hinge_handle", depth=0.0)

# 31. AttachHingeHandle
grasp_handle("hinge_handle")

# 32. SuctionCloseHingeLid
# (one swing with the next action)

# 33. SuctionOpenHingeLid
# (one swing with the next action)

# 34. SuctionOpenHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 90.0, 60.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 35. DetachHingeHandle
release_handle()

# 36. MoveToAlignOrange
fb = get_obj_bbox("orange")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("orange")[2] / 2, 0.027)]), angle=clear_angle("orange"))

# 37. AttachOrange
close_gripper()

# 38. SuctionCarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("orange")[2] / 2 + 0.03]))

# 39. SuctionDropIntoHingeBodyOrange
open_gripper()

# 40. MoveToAlignApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 41. AttachApple
close_gripper()

# 42. SuctionCarryOverHingeBodyApple
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("apple")[2] / 2 + 0.03]))

# 43. SuctionDropIntoHingeBodyApple
open_gripper()

# 44. SuctionMoveToHingeHandle
move_gripper_to("hinge_handle", depth=0.0)

# 45. AttachHingeHandle
grasp_handle("hinge_handle")

# 46. SuctionCloseHingeLid
# (one swing with the next action)

# 47. SuctionCloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 48. DetachHingeHandle
release_handle()

# 49. MoveToAlignBlueCube
move_gripper_to("blue_cube", depth=get_obj_size("blue_cube")[2] / 2)

# 50. AttachBlueCube
close_gripper()

# 51. SuctionCarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("blue_cube")[2] / 2 + 0.01]))

# 52. SuctionReleaseIntoBlueCubeToyBox
open_gripper()

# 53. MoveToAlignRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 54. AttachRedCube
close_gripper()

# 55. SuctionCarryOntoRedCubeFloor
spot = get_empty_floor_xy("red_cube")
move_to_position(within_reach([spot[0], spot[1], 0.5 + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 56. SuctionPutDownRedCubeFloor
open_gripper()

# 57. MoveToAlignGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 58. AttachGreenCube
close_gripper()

# 59. SuctionCarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 60. SuctionReleaseIntoGreenCubeToyBox
open_gripper()

# 61. MoveToAlignRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 62. AttachRedCube
close_gripper()

# 63. SuctionCarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 64. SuctionReleaseIntoRedCubeToyBox
open_gripper()

# 65. MoveToAlignPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 66. AttachPurpleCube
close_gripper()

# 67. SuctionCarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 68. SuctionReleaseIntoPurpleCubeToyBox
open_gripper()
