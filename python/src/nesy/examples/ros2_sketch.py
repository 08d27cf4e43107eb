"""UNTESTED SKETCH: a robot adapter for a ROS 2 robot, through action clients.

This file has never been run; it shows how the robot API can map onto a ROS 2 stack (MoveIt 2
for arm motions, a ``control_msgs/action/GripperCommand`` gripper controller, TF for object
poses) and where the protocol's duties go. Adapt the action names, frames and messages to your
robot; test at a low speed scale with the emergency stop in hand.

Importing this module needs only the standard library; ``rclpy`` and the message packages are
imported when a session starts.

How the API maps onto ROS 2:

==========================  =============================================================
robot API call              on the ROS 2 robot
==========================  =============================================================
get_obj_names               the object frames your perception publishes on TF (a list
                            from a parameter or a detection topic)
get_obj_pos                 ``tf2_ros.Buffer.lookup_transform(world, obj, now)``
get_obj_bbox, get_obj_size  the object's centre from TF and its size from your object
                            database (or a detection message with boxes)
is_obj_visible              the transform is recent (``can_transform`` within a timeout)
gripper_is_open,            the gripper's joint state, and which object was grasped
obj_in_gripper
move_gripper_to,            a ``moveit_msgs/action/MoveGroup`` goal with a pose target
move_to_position,           (position plus the orientation of ``pointing_to``),
move_parallel               ``max_velocity_scaling_factor`` = hello's speed scale
open_gripper, close_gripper ``control_msgs/action/GripperCommand`` (position, max effort)
grasp_handle,               close / open on the handle
release_handle
vacuum calls                your suction I/O service, or ``WrongEmbodiment``
get_tool_pos                TF: world -> the tool frame
stop(reason)                cancel the active goal and halt the controller
==========================  =============================================================

The robot server runs its own threads; rclpy spins in a ``MultiThreadedExecutor`` on another
thread, and each API method waits on a future with a timeout.
"""

from __future__ import annotations

import threading
from typing import Any, Dict, List, Optional

from nesy.robot import Infeasible, RobotServer, Stopped, TimedOut, UnknownObject, WrongEmbodiment

__all__ = ["Ros2Arm"]

#: Names to adapt to your robot.
WORLD_FRAME = "world"
TOOL_FRAME = "tool0"
MOVE_GROUP_ACTION = "/move_action"
PLANNING_GROUP = "arm"
GRIPPER_ACTION = "/gripper_controller/gripper_cmd"
GRIPPER_OPEN, GRIPPER_CLOSED, GRIPPER_EFFORT = 0.04, 0.0, 40.0
MOTION_TIMEOUT_S = 30.0

#: The tool's quaternion (x, y, z, w) for each approach direction in WORLD_FRAME: calibrate.
ORIENTATIONS = {"down": (1.0, 0.0, 0.0, 0.0)}


class Ros2Arm(RobotServer):
    """UNTESTED SKETCH of an adapter for a ROS 2 arm with MoveIt 2 and a gripper action.

    Args:
        objects: the objects perception publishes on TF, with their box sizes
            ``{name: [dx, dy, dz]}`` (nesy needs sizes; TF gives only poses).
    """

    def __init__(self, objects: Dict[str, List[float]], *, name: str = "ros2 arm", heartbeat_timeout: float = 1.5):
        super().__init__("finger", name, heartbeat_timeout)
        self.sizes = dict(objects)
        self.node: Any = None
        self.grasped: Optional[str] = None
        self.last_target: Optional[str] = None
        self._goal: Any = None  # the active goal handle, for stop()
        self._goal_lock = threading.Lock()

    # -- session -------------------------------------------------------------------------

    def begin_session(self, hello: Dict[str, Any]) -> None:
        if self.node is not None:
            return
        import rclpy
        from rclpy.action import ActionClient
        from rclpy.executors import MultiThreadedExecutor
        from tf2_ros import Buffer, TransformListener
        from control_msgs.action import GripperCommand
        from moveit_msgs.action import MoveGroup

        if not rclpy.ok():
            rclpy.init()
        self.node = rclpy.create_node("nesy_robot_adapter")
        self.tf = Buffer()
        self.tf_listener = TransformListener(self.tf, self.node)
        self.move_group = ActionClient(self.node, MoveGroup, MOVE_GROUP_ACTION)
        self.gripper = ActionClient(self.node, GripperCommand, GRIPPER_ACTION)
        self.executor = MultiThreadedExecutor()
        self.executor.add_node(self.node)
        threading.Thread(target=self.executor.spin, daemon=True).start()
        if not self.move_group.wait_for_server(timeout_sec=5.0) or not self.gripper.wait_for_server(timeout_sec=5.0):
            raise RuntimeError("the MoveGroup or gripper action server is not running")

    def stop(self, reason: str) -> None:
        # Called on another thread, possibly while a goal runs: cancel it. A real set-up also
        # halts the controller (e.g. switch to a hold-position controller).
        with self._goal_lock:
            goal = self._goal
        if goal is not None:
            goal.cancel_goal_async()
        if self.node is not None:
            self.node.get_logger().warn("nesy stopped the robot: {}".format(reason))

    # -- helpers -------------------------------------------------------------------------

    def _wait(self, future: Any, call: str, timeout: float = MOTION_TIMEOUT_S) -> Any:
        done = threading.Event()
        future.add_done_callback(lambda _: done.set())
        if not done.wait(timeout):
            raise TimedOut(call, timeout)
        return future.result()

    def _run_goal(self, client: Any, goal: Any, call: str) -> Any:
        handle = self._wait(client.send_goal_async(goal), call, 5.0)
        if not handle.accepted:
            raise Infeasible(call, "goal", "the action server rejected the goal")
        with self._goal_lock:
            self._goal = handle
        try:
            outcome = self._wait(handle.get_result_async(), call)
        finally:
            with self._goal_lock:
                self._goal = None
        from action_msgs.msg import GoalStatus

        if outcome.status == GoalStatus.STATUS_CANCELED:
            raise Stopped(call, "the goal was cancelled")
        if outcome.status != GoalStatus.STATUS_SUCCEEDED:
            raise Infeasible(call, "goal", "the action ended with status {}".format(outcome.status))
        return outcome.result

    def _centre(self, name: str) -> List[float]:
        if name not in self.sizes:
            raise UnknownObject(name, sorted(self.sizes))
        from rclpy.time import Time

        try:
            t = self.tf.lookup_transform(WORLD_FRAME, name, Time()).transform.translation
        except Exception as error:  # tf2 LookupException, ExtrapolationException, ...
            raise Infeasible("get_obj_pos", name, "no pose on TF: {}".format(error))
        return [t.x, t.y, t.z]

    def _pose_goal(self, position: List[float], pointing_to: str) -> Any:
        """A MoveGroup goal reaching ``position`` with the tool pointing ``pointing_to``."""
        from geometry_msgs.msg import PoseStamped
        from moveit_msgs.action import MoveGroup
        from moveit_msgs.msg import Constraints, OrientationConstraint, PositionConstraint
        from shape_msgs.msg import SolidPrimitive

        if pointing_to not in ORIENTATIONS:
            raise Infeasible(None, pointing_to, "no calibrated orientation for this approach")
        target = PoseStamped()
        target.header.frame_id = WORLD_FRAME
        target.pose.position.x, target.pose.position.y, target.pose.position.z = position
        q = ORIENTATIONS[pointing_to]
        target.pose.orientation.x, target.pose.orientation.y, target.pose.orientation.z, target.pose.orientation.w = q
        region = SolidPrimitive(type=SolidPrimitive.SPHERE, dimensions=[0.005])
        place = PositionConstraint(header=target.header, link_name=TOOL_FRAME, weight=1.0)
        place.constraint_region.primitives.append(region)
        place.constraint_region.primitive_poses.append(target.pose)
        turn = OrientationConstraint(header=target.header, link_name=TOOL_FRAME, orientation=target.pose.orientation,
                                     absolute_x_axis_tolerance=0.05, absolute_y_axis_tolerance=0.05,
                                     absolute_z_axis_tolerance=0.05, weight=1.0)
        goal = MoveGroup.Goal()
        goal.request.group_name = PLANNING_GROUP
        goal.request.max_velocity_scaling_factor = float(self.speed_scale or 0.1)
        goal.request.max_acceleration_scaling_factor = float(self.speed_scale or 0.1)
        goal.request.goal_constraints.append(Constraints(position_constraints=[place], orientation_constraints=[turn]))
        goal.planning_options.plan_only = False
        return goal

    def _move(self, call: str, position: List[float], pointing_to: str) -> None:
        self._run_goal(self.move_group, self._pose_goal(position, pointing_to), call)

    def _grip(self, call: str, position: float) -> Any:
        from control_msgs.action import GripperCommand

        goal = GripperCommand.Goal()
        goal.command.position = position
        goal.command.max_effort = GRIPPER_EFFORT
        return self._run_goal(self.gripper, goal, call)

    # -- perception ----------------------------------------------------------------------

    def get_obj_names(self):
        return ["floor"] + sorted(self.sizes) + ["gripper"]

    def is_obj_visible(self, obj_name):
        from rclpy.time import Time

        return obj_name in self.sizes and self.tf.can_transform(WORLD_FRAME, obj_name, Time())

    def get_obj_pos(self, obj_name):
        return self._centre(obj_name)

    def get_obj_size(self, obj_name):
        self._centre(obj_name)
        return self.sizes[obj_name]

    def get_obj_bbox(self, obj_name):
        c, s = self._centre(obj_name), self.sizes[obj_name]
        return [[c[i] - s[i] / 2.0 for i in range(3)], [c[i] + s[i] / 2.0 for i in range(3)]]

    def gripper_is_open(self):
        return self.grasped is None  # or read the finger joint from /joint_states

    def obj_in_gripper(self, obj_name):
        self._centre(obj_name)
        return self.grasped == obj_name

    def get_empty_floor_xy(self, obj_name):
        raise Infeasible("get_empty_floor_xy", obj_name, "this sketch has no free-space search")

    def get_tool_pos(self):
        from rclpy.time import Time

        t = self.tf.lookup_transform(WORLD_FRAME, TOOL_FRAME, Time()).transform.translation
        return [t.x, t.y, t.z]

    # -- motions -------------------------------------------------------------------------

    def move_gripper_to(self, obj_name, pointing_to, depth):
        c, s = self._centre(obj_name), self.sizes[obj_name]
        self.last_target = obj_name
        self._move("move_gripper_to", [c[0], c[1], c[2] + s[2] / 2.0 - depth], pointing_to)

    def move_to_position(self, pos, pointing_to, lift_clearance, angle):
        here = self.get_tool_pos()
        up = max(here[2], pos[2]) + lift_clearance
        self._move("move_to_position", [here[0], here[1], up], pointing_to)
        self._move("move_to_position", [pos[0], pos[1], up], pointing_to)
        self._move("move_to_position", list(pos), pointing_to)

    def move_parallel(self, move_dir, offset, pointing_to):
        unit = {"left": (0, -1, 0), "right": (0, 1, 0), "front": (1, 0, 0), "back": (-1, 0, 0), "up": (0, 0, 1), "down": (0, 0, -1)}[move_dir]
        here = self.get_tool_pos()
        self._move("move_parallel", [here[i] + unit[i] * offset for i in range(3)], pointing_to)

    # -- the gripper ---------------------------------------------------------------------

    def open_gripper(self):
        self._grip("open_gripper", GRIPPER_OPEN)
        self.grasped = None

    def close_gripper(self):
        result = self._grip("close_gripper", GRIPPER_CLOSED)
        # GripperCommand reports `stalled` when the fingers stopped on an object.
        self.grasped = self.last_target if getattr(result, "stalled", False) else None

    def grasp_handle(self, handle_name):
        self.last_target = handle_name
        self.close_gripper()

    def release_handle(self):
        self.open_gripper()

    def attach_vacuum_handle(self, handle_name):
        raise WrongEmbodiment("attach_vacuum_handle", "finger", "grasp_handle")

    def detach_vacuum_handle(self):
        raise WrongEmbodiment("detach_vacuum_handle", "finger", "release_handle")

    def activate_vacuum(self):
        raise WrongEmbodiment("activate_vacuum", "finger", "close_gripper")

    def deactivate_vacuum(self):
        raise WrongEmbodiment("deactivate_vacuum", "finger", "open_gripper")

    def gather_with_hook(self, obj_name):
        raise Infeasible("gather_with_hook", obj_name, "this robot has no hook tool")


def main() -> None:  # pragma: no cover - a sketch
    raise SystemExit(
        "ros2_sketch is an untested sketch: adapt the names to your robot, then serve "
        "Ros2Arm({'red_cube': [0.03, 0.03, 0.03], ...}).serve('0.0.0.0:7000')"
    )


if __name__ == "__main__":
    main()
