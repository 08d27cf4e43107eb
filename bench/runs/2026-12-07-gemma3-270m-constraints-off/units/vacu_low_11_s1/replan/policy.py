# Compiled by nesy's template compiler from 14 verified action(s) for the finger robot.
import math

def within_reach(p):
    # Targets stay inside the reachable table area, next to where they were computed.
    return [min(max(p[0], 0.115), 0.725), min(max(p[1], -0.595), 0.605), p[2]]

# 1. MoveToSurroundBlackRook
move_gripper_to("black_rook", depth=get_obj_size("black_rook")[2] / 1.3)

# 2. SweepIntoBlackRookRightChessBox
piece_y = get_obj_pos("black_rook")[1]
box_y = get_obj_pos("right_chess_box")[1]
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

# 7. MoveToSurroundPurpleCube
move_gripper_to("purple_cube", depth=get_obj_size("purple_cube")[2] / 2)

# 8. GraspPurpleCube
close_gripper()

# 9. CarryIntoPurpleCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("purple_cube")[2] / 2 + 0.01]))

# 10. ReleaseIntoPurpleCubeToyBox
open_gripper()

# 11. MoveToSurroundGreenCube
move_gripper_to("green_cube", depth=get_obj_size("green_cube")[2] / 2)

# 12. GraspGreenCube
close_gripper()

# 13. CarryIntoGreenCubeToyBox
box = get_obj_bbox("toy_box")
move_to_position(within_reach([(box[0][0] + box[1][0]) / 2 + 0.042, (box[0][1] + box[1][1]) / 2 + -0.022, box[1][2] + get_obj_size("green_cube")[2] / 2 + 0.01]))

# 14. ReleaseIntoGreenCubeToyBox
open_gripper()
