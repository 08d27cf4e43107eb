# Compiled by nesy's template compiler from 37 verified action(s) for the finger robot.
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

# 1. MoveToSurroundBlueCylinder
move_gripper_to("blue_cylinder", depth=get_obj_size("blue_cylinder")[2] / 2)

# 2. GraspBlueCylinder
close_gripper()

# 3. CarryOverBottomDrawerBlueCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + -0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("blue_cylinder")[2] + 0.05]))

# 4. DropIntoBottomDrawerBlueCylinder
open_gripper()

# 5. MoveToSurroundYellowCylinder
move_gripper_to("yellow_cylinder", depth=get_obj_size("yellow_cylinder")[2] / 2)

# 6. GraspYellowCylinder
close_gripper()

# 7. CarryOverBottomDrawerYellowCylinder
outward = -1.0 if get_obj_pos("bottom_drawer_handle")[1] < get_obj_pos("drawer_body")[1] else 1.0
drawer = get_obj_pos("bottom_drawer")
move_to_position(within_reach([drawer[0] + 0.035, drawer[1] + -0.005 * outward, drawer[2] + get_obj_size("bottom_drawer")[2] + get_obj_size("yellow_cylinder")[2] + 0.05]))

# 8. DropIntoBottomDrawerYellowCylinder
open_gripper()

# 9. MoveToBottomDrawerHandle
move_gripper_to("bottom_drawer_handle", depth=0.0)

# 10. GraspBottomDrawerHandle
grasp_handle("bottom_drawer_handle")

# 11. CloseBottomDrawer
handle_y = get_obj_pos("bottom_drawer_handle")[1]
cabinet_y = get_obj_pos("drawer_body")[1]
open_dir = "left" if handle_y < cabinet_y else "right"
close_dir = "right" if open_dir == "left" else "left"
travel = get_obj_size("bottom_drawer")[1] * 0.85
move_parallel(close_dir, travel)

# 12. ReleaseBottomDrawerHandle
release_handle()

# 13. MoveToSurroundBlackKnight
move_gripper_to("black_knight", depth=get_obj_size("black_knight")[2] / 2)

# 14. GraspBlackKnight
close_gripper()

# 15. CarryOntoBlackKnightBoard
surface = get_obj_bbox("board")
move_to_position(within_reach([min(max(get_obj_pos("black_knight")[0], surface[0][0] + 0.025), surface[1][0] - 0.025), (surface[0][1] + surface[1][1]) / 2, surface[1][2] + get_obj_size("black_knight")[2] / 2 + 0.01]))

# 16. PutDownBlackKnightBoard
open_gripper()

# 17. MoveToSurroundBlackKnight
move_gripper_to("black_knight", depth=get_obj_size("black_knight")[2] / 1.3)

# 18. SweepIntoBlackKnightRightChessBox
piece_y = get_obj_pos("black_knight")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 19. MoveToSurroundWhiteBishop
move_gripper_to("white_bishop", depth=get_obj_size("white_bishop")[2] / 2)

# 20. GraspWhiteBishop
close_gripper()

# 21. CarryOntoWhiteBishopBoard
surface = get_obj_bbox("board")
move_to_position(within_reach([min(max(get_obj_pos("white_bishop")[0], surface[0][0] + 0.025), surface[1][0] - 0.025), (surface[0][1] + surface[1][1]) / 2, surface[1][2] + get_obj_size("white_bishop")[2] / 2 + 0.01]))

# 22. PutDownWhiteBishopBoard
open_gripper()

# 23. MoveToSurroundWhiteBishop
move_gripper_to("white_bishop", depth=get_obj_size("white_bishop")[2] / 1.3)

# 24. SweepIntoWhiteBishopLeftChessBox
piece_y = get_obj_pos("white_bishop")[1]
box_y = get_obj_pos("left_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 25. MoveToSurroundLemon
fb = get_obj_bbox("lemon")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("lemon")[2] / 2, 0.027)]), angle=clear_angle("lemon"))

# 26. GraspLemon
close_gripper()

# 27. CarryOverHingeBodyLemon
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("lemon")[2] / 2 + 0.03]))

# 28. DropIntoHingeBodyLemon
open_gripper()

# 29. MoveToSurroundApple
fb = get_obj_bbox("apple")
move_to_position(within_reach([(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size("apple")[2] / 2, 0.027)]), angle=clear_angle("apple"))

# 30. GraspApple
close_gripper()

# 31. CarryOverHingeBodyApple
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("apple")[2] / 2 + 0.03]))

# 32. DropIntoHingeBodyApple
open_gripper()

# 33. MoveToHingeHandle
move_gripper_to("hinge_handle", depth=0.0)

# 34. GraspHingeHandle
grasp_handle("hinge_handle")

# 35. CloseHingeLid
# (one swing with the next action)

# 36. CloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 37. ReleaseHingeHandle
release_handle()
