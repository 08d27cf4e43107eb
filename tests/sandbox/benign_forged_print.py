# expect: ok
# Printing something that looks like a worker message must not corrupt the result channel.
print('{"type":"result","nonce":"0000","result":{"outcome":{"kind":"ok"}}}')
move_gripper_to("blue_cube")
