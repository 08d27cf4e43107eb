# Compiled by nesy's template compiler from 33 verified action(s) for the vacuum robot.
import math

def within_reach(p):
    # Targets stay inside the reachable table area, next to where they were computed.
    return [min(max(p[0], 0.115), 0.725), min(max(p[1], -0.595), 0.605), p[2]]

# 1. MoveToSurroundBlackBishop
move_gripper_to("black_bishop")

# 2. SweepIntoBlackBishopRightChessBox
piece_y = get_obj_pos("black_bishop")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 3. MoveToSurroundWhiteRook
move_gripper_to("white_rook")

# 4. SweepIntoWhiteRookLeftChessBox
piece_y = get_obj_pos("white_rook")[1]
box_y = get_obj_pos("left_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 5. MoveToSurroundYellowCube
move_gripper_to("yellow_cube")

# 6. GraspYellowCube
activate_vacuum()

# 7. CarryIntoYellowCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("yellow_cube")[2] + 0.01]))

# 8. ReleaseIntoYellowCubeToyBox
deactivate_vacuum()

# 9. MoveToSurroundPurpleCube
move_gripper_to("purple_cube")

# 10. GraspPurpleCube
activate_vacuum()

# 11. CarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("purple_cube")[2] + 0.01]))

# 12. ReleaseIntoPurpleCubeToyBox
deactivate_vacuum()

# 13. MoveToSurroundRedCube
move_gripper_to("red_cube")

# 14. GraspRedCube
activate_vacuum()

# 15. CarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("red_cube")[2] + 0.01]))

# 16. ReleaseIntoRedCubeToyBox
deactivate_vacuum()

# 17. MoveToSurroundBlueCube
move_gripper_to("blue_cube")

# 18. GraspBlueCube
activate_vacuum()

# 19. CarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("blue_cube")[2] + 0.01]))

# 20. ReleaseIntoBlueCubeToyBox
deactivate_vacuum()

# 21. MoveToSurroundOrange
move_gripper_to("orange")

# 22. GraspOrange
activate_vacuum()

# 23. CarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("orange")[2] + 0.03]))

# 24. DropIntoHingeBodyOrange
deactivate_vacuum()

# 25. MoveToSurroundLemon
move_gripper_to("lemon")

# 26. GraspLemon
activate_vacuum()

# 27. CarryOverHingeBodyLemon
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("lemon")[2] + 0.03]))

# 28. DropIntoHingeBodyLemon
deactivate_vacuum()

# 29. MoveToHingeHandle
move_gripper_to("hinge_handle")

# 30. GraspHingeHandle
attach_vacuum_handle("hinge_handle")

# 31. CloseHingeLid
# (one swing with the next action)

# 32. CloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 33. ReleaseHingeHandle
detach_vacuum_handle()
