# Actions of the two-finger gripper. The tool point is the centre of the finger pads.

def move_gripper_to(obj_name, pointing_to="down", depth=0.01):
    """Move the tool to an object: pointing down, the centre of the finger pads ends `depth`
    metres below the object's top surface, with the fingers turned to fit the object (across
    the bar for handles). The tool first rises, travels above the object and then descends.
    Does not open or close the fingers. Refused if another object is stacked on the object,
    if a handle is covered (the bottom drawer's handle under an open top drawer) or if the
    object is out of reach.

    Args:
        obj_name (str): the object or handle to move to.
        pointing_to (str): approach direction, "down" (default), "left" or "right".
        depth (float): how far past the object's near face the pads go, in metres. Use about
            half the object's height to grasp it, and 0 for handles.
    """

def move_to_position(pos, pointing_to="down", lift_clearance=0.12, angle=0.0):
    """Move the tool point to a position. The tool first rises by `lift_clearance` along its
    current approach direction, travels to `lift_clearance` above the target and descends
    onto it. A held object or a grasped handle moves with the tool.

    Args:
        pos (list or np.ndarray): target (x, y, z) of the tool point in metres.
        pointing_to (str): "down" (default), "left", "right", "front" or "back".
        lift_clearance (float): rise and descent height in metres (>= 0); use 0 when the tool
            must move straight to the target, e.g. while turning a lid by its handle.
        angle (float): rotation of the tool about its approach axis, in radians.
    """

def move_parallel(move_dir, offset, pointing_to="down"):
    """Move the tool in a straight line, keeping its orientation. Loose objects in the way
    are pushed along (this is how pieces are swept); a grasped handle drags its drawer or
    lid.

    Args:
        move_dir (str): "left" (-y), "right" (+y), "front" (+x), "back" (-x) or "up" (+z).
        offset (float): distance in metres, > 0.
        pointing_to (str): the tool's current pointing direction, "down" by default.
    """

def grasp_handle(handle_name):
    """Close the fingers on a handle within 0.1 m of the tool point. While the handle is
    held, moving the tool opens or closes its lid or drawer. Refused while an object is held,
    when the handle is covered, or when something rests on the lid.

    Args:
        handle_name (str): "hinge_handle", "top_drawer_handle" or "bottom_drawer_handle".
    """

def release_handle():
    """Let go of the grasped handle and open the fingers. The lid or drawer stays where it
    is."""

def open_gripper():
    """Open the fingers; a held object is released and falls onto what is below it."""

def close_gripper():
    """Close the fingers and grasp the loose object between the pads, if there is one."""
