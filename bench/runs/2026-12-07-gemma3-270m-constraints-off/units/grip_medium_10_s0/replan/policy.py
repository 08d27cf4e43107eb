# Compiled by nesy's template compiler from 35 verified action(s) for the vacuum robot.
import math

def within_reach(p):
    # Targets stay inside the reachable table area, next to where they were computed.
    return [min(max(p[0], 0.115), 0.725), min(max(p[1], -0.595), 0.605), p[2]]

# 1. MoveToAlignBlackBishop
move_gripper_to("black_bishop")

# 2. AttachBlackBishop
activate_vacuum()

# 3. SuctionCarryIntoBlackBishopRightChessBox
box = get_obj_bbox("right_chess_box")
move_to_position(within_reach([min(max(get_obj_pos("black_bishop")[0], box[0][0] + 0.025), box[1][0] - 0.025), (box[0][1] + box[1][1]) / 2, box[1][2] + get_obj_size("black_bishop")[2] + 0.01]))

# 4. SuctionReleaseIntoBlackBishopRightChessBox
deactivate_vacuum()

# 5. MoveToAlignWhiteRook
move_gripper_to("white_rook")

# 6. AttachWhiteRook
activate_vacuum()

# 7. SuctionCarryIntoWhiteRookLeftChessBox
box = get_obj_bbox("left_chess_box")
move_to_position(within_reach([min(max(get_obj_pos("white_rook")[0], box[0][0] + 0.025), box[1][0] - 0.025), (box[0][1] + box[1][1]) / 2, box[1][2] + get_obj_size("white_rook")[2] + 0.01]))

# 8. SuctionReleaseIntoWhiteRookLeftChessBox
deactivate_vacuum()

# 9. MoveToAlignYellowCube
move_gripper_to("yellow_cube")

# 10. AttachYellowCube
activate_vacuum()

# 11. SuctionCarryIntoYellowCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("yellow_cube")[2] + 0.01]))

# 12. SuctionReleaseIntoYellowCubeToyBox
deactivate_vacuum()

# 13. MoveToAlignPurpleCube
move_gripper_to("purple_cube")

# 14. AttachPurpleCube
activate_vacuum()

# 15. SuctionCarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("purple_cube")[2] + 0.01]))

# 16. SuctionReleaseIntoPurpleCubeToyBox
deactivate_vacuum()

# 17. MoveToAlignRedCube
move_gripper_to("red_cube")

# 18. AttachRedCube
activate_vacuum()

# 19. SuctionCarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("red_cube")[2] + 0.01]))

# 20. SuctionReleaseIntoRedCubeToyBox
deactivate_vacuum()

# 21. MoveToAlignBlueCube
move_gripper_to("blue_cube")

# 22. AttachBlueCube
activate_vacuum()

# 23. SuctionCarryIntoBlueCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + 0.022, box[1][2] + get_obj_size("blue_cube")[2] + 0.01]))

# 24. SuctionReleaseIntoBlueCubeToyBox
deactivate_vacuum()

# 25. MoveToAlignOrange
move_gripper_to("orange")

# 26. AttachOrange
activate_vacuum()

# 27. SuctionCarryOverHingeBodyOrange
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + -0.06, body[1][2] + get_obj_size("orange")[2] + 0.03]))

# 28. SuctionDropIntoHingeBodyOrange
deactivate_vacuum()

# 29. MoveToAlignLemon
move_gripper_to("lemon")

# 30. AttachLemon
activate_vacuum()

# 31. SuctionCarryOverHingeBodyLemon
body = get_obj_bbox("hinge_body")
move_to_position(within_reach([(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + 0, body[1][2] + get_obj_size("lemon")[2] + 0.03]))

# 32. SuctionDropIntoHingeBodyLemon
deactivate_vacuum()

# 33. AttachHingeHandle
move_gripper_to("hinge_handle")
attach_vacuum_handle("hinge_handle")

# 34. SuctionCloseHingeLid
body = get_obj_bbox("hinge_body")
lid = get_obj_bbox("hinge_lid")
lid_y = (lid[0][1] + lid[1][1]) / 2
reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])
for degrees in [135.0, 180.0]:
    a = math.radians(degrees)
    x = min(body[1][0] + reach * math.cos(a), 0.725)
    move_to_position(within_reach([x, lid_y, body[1][2] + reach * math.sin(a)]), lift_clearance=0.0, angle=math.pi / 2)

# 35. DetachHingeHandle
detach_vacuum_handle()
