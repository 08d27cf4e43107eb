# Compiled by nesy's template compiler from 25 verified action(s) for the finger robot.
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

# 3. MoveToSurroundBlackBishop
move_gripper_to("black_bishop", depth=get_obj_size("black_bishop")[2] / 1.3)

# 4. SweepIntoBlackBishopRightChessBox
piece_y = get_obj_pos("black_bishop")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 5. MoveToSurroundLemon
fb = get_obj_bbox("lemon")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("lemon")[2] / 2, 0.027)]), angle=clear_angle("lemon"))

# 6. GraspLemon
close_gripper()

# 7. CarryOverHingeBodyLemon
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("lemon")[2] / 2 + 0.03]))

# 8. DropIntoHingeBodyLemon
open_gripper()

# 9. MoveToSurroundOrange
fb = get_obj_bbox("orange")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("orange")[2] / 2, 0.027)]), angle=clear_angle("orange"))

# 10. GraspOrange
close_gripper()

# 11. CarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("orange")[2] / 2 + 0.03]))

# 12. DropIntoHingeBodyOrange
open_gripper()

# 13. GraspHingeHandle
move_gripper_to("hinge_handle", depth=0.0)
grasp_handle("hinge_handle")

# 14. CloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 15. MoveToSurroundRedCylinder
move_gripper_to("red_cylinder", depth=get_obj_size("red_cylinder")[2] / 2)

# 16. GraspRedCylinder
close_gripper()

# 17. CarryOverBottomDrawerRedCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("red_cylinder")[2] + 0.05]))

# 18. DropIntoBottomDrawerRedCylinder
open_gripper()

# 19. MoveToSurroundYellowCylinder
move_gripper_to("yellow_cylinder", depth=get_obj_size("yellow_cylinder")[2] / 2)

# 20. GraspYellowCylinder
close_gripper()

# 21. CarryOverBottomDrawerYellowCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("yellow_cylinder")[2] + 0.05]))

# 22. DropIntoBottomDrawerYellowCylinder
open_gripper()

# 23. GraspBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)
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
