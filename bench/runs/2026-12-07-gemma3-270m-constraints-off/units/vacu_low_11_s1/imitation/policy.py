# Compiled by nesy's template compiler from 16 verified action(s) for the finger robot.
import math

def within_reach(p):
    # Targets stay inside the reachable table area, next to where they were computed.
    return [min(max(p[0], 0.115), 0.725), min(max(p[1], -0.595), 0.605), p[2]]

# 1. MoveToAlignBlackRook
move_gripper_to("black_rook", depth=get_obj_size("black_rook")[2] / 2)

# 2. AttachBlackRook
close_gripper()

# 3. SlideIntoBlackRookRightChessBox
move_gripper_to("black_rook", depth=get_obj_size("black_rook")[2] / 1.3)
piece_y = get_obj_pos("black_rook")[1]
box_y = get_obj_pos("right_chess_box")[1]
move_parallel("left" if piece_y > box_y else "right", abs(piece_y - box_y) + 0.02)

# 4. SuctionReleaseIntoBlackRookRightChessBox
open_gripper()

# 5. MoveToAlignRedCube
move_gripper_to("red_cube", depth=get_obj_size("red_cube")[2] / 2)

# 6. AttachRedCube
close_gripper()

# 7. SuctionCarryIntoRedCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + -0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("red_cube")[2] / 2 + 0.01]))

# 8. SuctionReleaseIntoRedCubeToyBox
open_gripper()

# 9. MoveToAlignPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 10. AttachPurpleCube
close_gripper()

# 11. SuctionCarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 12. SuctionReleaseIntoPurpleCubeToyBox
open_gripper()

# 13. MoveToAlignGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 14. AttachGreenCube
close_gripper()

# 15. SuctionCarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 16. SuctionReleaseIntoGreenCubeToyBox
open_gripper()
