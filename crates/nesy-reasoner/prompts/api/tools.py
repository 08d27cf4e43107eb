# Tool use, offered when the scene holds a magnetic hook. Screws and other fine-grained
# objects are many small pieces: no gripper can take them one by one, so move_gripper_to and
# get_empty_floor_xy refuse them. The hook's magnet pulls every piece within 5 cm of it;
# pieces it has gathered cling to it and travel with the hook, and are put down with it.

def gather_with_hook(obj_name):
    """With a magnetic hook held (grasped, or under the suction tip), sweep the hook's magnet
    low over every piece of `obj_name` and lift it again, so that the pieces gather on the
    magnet. Refused when no magnetic hook is held or when `obj_name` is not made of small
    pieces.

    Args:
        obj_name (str): the fine-grained object, e.g. "black_screws".
    """
