# The vacuum suction tool. Its tool point is the suction tip. On the vacuum robot:
# - get_obj_names() lists "vacuum_gripper" last instead of "gripper";
# - gripper_is_open() is True while suction is off;
# - obj_in_gripper(obj_name) tells whether the object is right under the tip;
# - the motion functions work as above, except that move_gripper_to ignores `depth`: the tip
#   stops on the object's top surface (just past a handle's surface);
# - suction holds an object by its top, so a held object hangs its full height below the tip.

def attach_vacuum_handle(handle_name):
    """Vacuum counterpart of grasp_handle: attach the suction tip to a handle within 0.1 m
    of it. While attached, moving the tool opens or closes its lid or drawer.

    Args:
        handle_name (str): "hinge_handle", "top_drawer_handle" or "bottom_drawer_handle".
    """

def detach_vacuum_handle():
    """Vacuum counterpart of release_handle: switch the suction off and let go of the
    handle."""

def activate_vacuum():
    """Vacuum counterpart of close_gripper: switch the suction on and pick up the loose
    object right under the tip, if there is one."""

def deactivate_vacuum():
    """Vacuum counterpart of open_gripper: switch the suction off, releasing a held
    object."""
