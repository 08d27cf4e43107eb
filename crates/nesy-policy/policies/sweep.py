# Sweep the chess pieces into their corresponding boxes.
vacuum = "vacuum_gripper" in get_obj_names()
for piece, target in [("white_rook", "left_chess_box"), ("black_bishop", "right_chess_box")]:
    h = get_obj_size(piece)[2]
    move_gripper_to(piece, depth=h / 1.3)
    if vacuum:
        activate_vacuum()
    piece_y = get_obj_pos(piece)[1]
    box_y = get_obj_pos(target)[1]
    direction = "left" if piece_y > box_y else "right"
    move_parallel(direction, abs(piece_y - box_y) + 0.02)
    if vacuum:
        deactivate_vacuum()
    move_parallel("up", 0.08)
