# World frame, in metres: the robot stands at the origin facing +x. The direction names are
# "front" = +x (away from the robot), "back" = -x, "left" = -y, "right" = +y, "up" = +z.
# The table top is at z = 0.5. Positions are numpy arrays.

def is_obj_visible(obj_name):
    """Tell whether an object of this name is in the scene.

    Args:
        obj_name (str): the object's name.
    Returns:
        bool: True if the scene has the object.
    """

def get_obj_names():
    """List the names of every object in the scene.

    Returns:
        list[str]: "floor" first, then the objects in scene order, and last the robot's own
        end effector, "gripper".
    """

def get_obj_pos(obj_name):
    """Centre of an object's axis-aligned bounding box.

    Args:
        obj_name (str): the object's name.
    Returns:
        np.ndarray: (x, y, z). For "floor" z is the table height, 0.5.
    """

def get_obj_bbox(obj_name):
    """The object's axis-aligned bounding box in the world frame.

    Args:
        obj_name (str): the object's name.
    Returns:
        np.ndarray: [[x_min, y_min, z_min], [x_max, y_max, z_max]].
    """

def get_obj_size(obj_name):
    """Extents of the object's bounding box (the max corner minus the min corner).

    Args:
        obj_name (str): the object's name.
    Returns:
        np.ndarray: (size_x, size_y, size_z); size_z is the object's height.
    """

def gripper_is_open():
    """Tell whether the gripper's fingers are open.

    Returns:
        bool: True if the fingers are open.
    """

def obj_in_gripper(obj_name):
    """Tell whether the object is in the grasp region, between the finger pads.

    Args:
        obj_name (str): the object's name.
    Returns:
        bool: True if the object is in the grasp region.
    """

def get_empty_floor_xy(obj_name):
    """Find a free spot on the table in front of the robot where the object can be put down
    without touching anything else. The object's current spot is returned if it is free.

    Args:
        obj_name (str): the object to be put down (its footprint decides the room needed).
    Returns:
        np.ndarray: (x, y) of the free spot. Raises an error if there is no room.
    """
