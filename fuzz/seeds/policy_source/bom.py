open_gripper()
move_gripper_to('red_cube')
