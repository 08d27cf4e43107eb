"""UNTESTED SKETCH: a robot adapter for a Franka arm (FR3 or Panda) through franky.

This file has never been run against a robot; it shows where each robot API call goes on a
Franka arm with the ``franky`` library (``pip install franky-control`` or ``franky-panda``,
depending on your robot and libfranka) and what an adapter must take care of. Check every franky
call against the version you install; calibrate the frames and orientations on your set-up
before the arm moves, at a low speed scale, with the user stop in hand.

Importing this module needs only the standard library; ``franky`` is imported when a session
starts.

How the API maps onto the arm:

==========================  =============================================================
robot API call              on the Franka arm
==========================  =============================================================
get_obj_names, get_obj_pos, your perception (a detector or markers), in nesy's world frame;
get_obj_bbox, get_obj_size  the arm does not see
is_obj_visible              the detector currently reports the object
gripper_is_open             ``Gripper.width`` above a threshold
obj_in_gripper              ``Gripper.is_grasped`` and the object is the one last grasped
get_empty_floor_xy          perception: a free spot on the table
move_gripper_to             a Cartesian motion to the object's top (``depth`` below it),
                            approached from ``pointing_to``
move_to_position            lift by ``lift_clearance``, move above ``pos``, descend
move_parallel               a relative Cartesian motion of ``offset`` along ``move_dir``
open_gripper                ``Gripper.open``
close_gripper               ``Gripper.grasp`` with a width tolerance
grasp_handle                close on the handle the tool is at
release_handle              open
vacuum calls                ``WrongEmbodiment`` (the Franka hand has fingers)
gather_with_hook            not supported here: ``Infeasible``
get_tool_pos                the end effector's translation, in nesy's world frame
stop(reason)                a stop motion, preempting the running one
==========================  =============================================================

Frames: nesy's positions are metres in *its* world frame (the table top at z = 0.5 in the
simulator; directions left = -y, right = +y, front = +x, back = -x). Give the adapter the
transform from that frame to the robot's base frame (here a plain offset, ``WORLD_IN_BASE``),
and pass ``--workspace`` to ``nesy run``/``nesy adapt`` in the same world frame.
"""

from __future__ import annotations

import math
import threading
from typing import Any, Dict, List, Optional, Sequence, Tuple

from nesy.robot import (
    Collision,
    Infeasible,
    InvalidArgument,
    OutOfWorkspace,
    RobotServer,
    Stopped,
    UnknownObject,
    WrongEmbodiment,
)

__all__ = ["FrankyArm", "Perception"]

#: Where nesy's world origin lies in the robot's base frame (metres): calibrate this.
WORLD_IN_BASE = (-0.3, 0.0, -0.5)
#: The hand's quaternion (x, y, z, w) when pointing down in the base frame: calibrate this.
DOWN = (1.0, 0.0, 0.0, 0.0)
#: Gripper speed (m/s) and grasp force (N).
GRIPPER_SPEED = 0.05
GRASP_FORCE = 20.0


class Perception:
    """What the adapter needs from your perception, in nesy's world frame. Replace with yours."""

    def boxes(self) -> Dict[str, Tuple[List[float], List[float]]]:
        """Every object seen now: ``{name: ([xmin, ymin, zmin], [xmax, ymax, zmax])}``."""
        raise NotImplementedError

    def empty_floor_xy(self, obj_name: str) -> Optional[List[float]]:
        """A free table spot ``[x, y]`` big enough for ``obj_name``, or ``None``."""
        raise NotImplementedError


def _to_base(p: Sequence[float]) -> List[float]:
    return [p[i] + WORLD_IN_BASE[i] for i in range(3)]


def _to_world(p: Sequence[float]) -> List[float]:
    return [p[i] - WORLD_IN_BASE[i] for i in range(3)]


class FrankyArm(RobotServer):
    """UNTESTED SKETCH of an adapter for a Franka arm with its two-finger hand."""

    def __init__(self, fci_host: str, perception: Perception, *, name: str = "franka", heartbeat_timeout: float = 1.5):
        super().__init__("finger", name, heartbeat_timeout)
        self.fci_host = fci_host
        self.perception = perception
        self.franky: Any = None
        self.robot: Any = None
        self.gripper: Any = None
        self.grasped: Optional[str] = None
        self.last_target: Optional[str] = None
        self._halted = threading.Event()

    # -- session -------------------------------------------------------------------------

    def begin_session(self, hello: Dict[str, Any]) -> None:
        import franky  # only on the robot PC

        self.franky = franky
        if self.robot is None:
            self.robot = franky.Robot(self.fci_host)
            self.gripper = franky.Gripper(self.fci_host)
        self.robot.recover_from_errors()
        # Every motion keeps to hello's speed scale (nesy checks the echo).
        self.robot.relative_dynamics_factor = float(self.speed_scale or 0.1)
        self._halted.clear()

    def stop(self, reason: str) -> None:
        # Runs on the reader or watchdog thread, possibly while a motion runs: preempt it.
        self._halted.set()
        if self.robot is not None:
            try:
                self.robot.move(self.franky.CartesianPoseStopMotion(), asynchronous=True)
            except Exception:
                pass  # the arm may already be in a reflex; it is not moving then

    # -- helpers -------------------------------------------------------------------------

    def _box(self, name: str) -> Tuple[List[float], List[float]]:
        boxes = self.perception.boxes()
        if name not in boxes:
            raise UnknownObject(name, sorted(boxes))
        return boxes[name]

    def _orientation(self, pointing_to: str, angle: float) -> Tuple[float, ...]:
        if pointing_to != "down":
            # Side approaches need their own calibrated orientations.
            raise InvalidArgument(None, "this sketch only approaches pointing down, not {}".format(pointing_to))
        # Rotate the downward hand by `angle` about the vertical: calibrate the sign.
        x, y, z, w = DOWN
        c, s = math.cos(angle / 2.0), math.sin(angle / 2.0)
        return (c * x - s * y, c * y + s * x, c * z + s * w, c * w - s * z)

    def _move(self, call: str, world_target: Sequence[float], pointing_to: str = "down", angle: float = 0.0) -> None:
        if self._halted.is_set():
            raise Stopped(call, "the session was stopped")
        franky = self.franky
        target = franky.Affine(_to_base(world_target), list(self._orientation(pointing_to, angle)))
        motion = franky.CartesianMotion(target, franky.ReferenceType.Absolute)
        try:
            self.robot.move(motion, asynchronous=True)
            self.robot.join_motion()
        except franky.ControlException as error:  # a reflex: contact, joint limits, ...
            self.robot.recover_from_errors()
            text = str(error)
            if "reflex" in text.lower() or "collision" in text.lower():
                raise Collision(call, "the hand", "an obstacle ({})".format(text))
            raise Stopped(call, text)
        if self._halted.is_set():
            raise Stopped(call, "stopped during the motion")

    # -- perception ------------------------------------------------------------------------

    def get_obj_names(self):
        return ["floor"] + sorted(self.perception.boxes()) + ["gripper"]

    def is_obj_visible(self, obj_name):
        return obj_name in self.perception.boxes()

    def get_obj_bbox(self, obj_name):
        lo, hi = self._box(obj_name)
        return [lo, hi]

    def get_obj_pos(self, obj_name):
        lo, hi = self._box(obj_name)
        return [(lo[i] + hi[i]) / 2.0 for i in range(3)]

    def get_obj_size(self, obj_name):
        lo, hi = self._box(obj_name)
        return [hi[i] - lo[i] for i in range(3)]

    def gripper_is_open(self):
        return self.gripper.width > 0.07

    def obj_in_gripper(self, obj_name):
        self._box(obj_name)
        return bool(self.gripper.is_grasped) and self.grasped == obj_name

    def get_empty_floor_xy(self, obj_name):
        spot = self.perception.empty_floor_xy(obj_name)
        if spot is None:
            raise Infeasible("get_empty_floor_xy", obj_name, "no free spot seen on the table")
        return spot

    def get_tool_pos(self):
        pose = self.robot.current_cartesian_state.pose.end_effector_pose
        return _to_world(list(pose.translation))

    # -- motions ---------------------------------------------------------------------------

    def move_gripper_to(self, obj_name, pointing_to, depth):
        lo, hi = self._box(obj_name)
        top = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, hi[2] - depth]
        self.last_target = obj_name
        self._move("move_gripper_to", [top[0], top[1], top[2] + 0.08], pointing_to)  # pre-grasp above
        self._move("move_gripper_to", top, pointing_to)

    def move_to_position(self, pos, pointing_to, lift_clearance, angle):
        here = self.get_tool_pos()
        if pos[2] < 0.5:  # below the table top of nesy's frame
            raise OutOfWorkspace(pos)
        up = max(here[2], pos[2]) + lift_clearance
        self._move("move_to_position", [here[0], here[1], up], pointing_to, angle)
        self._move("move_to_position", [pos[0], pos[1], up], pointing_to, angle)
        self._move("move_to_position", pos, pointing_to, angle)

    def move_parallel(self, move_dir, offset, pointing_to):
        if offset <= 0:
            raise InvalidArgument("move_parallel", "offset must be positive, got {}".format(offset))
        unit = {"left": (0, -1, 0), "right": (0, 1, 0), "front": (1, 0, 0), "back": (-1, 0, 0), "up": (0, 0, 1), "down": (0, 0, -1)}[move_dir]
        here = self.get_tool_pos()
        self._move("move_parallel", [here[i] + unit[i] * offset for i in range(3)], pointing_to)

    # -- the hand --------------------------------------------------------------------------

    def open_gripper(self):
        self.gripper.open(GRIPPER_SPEED)
        self.grasped = None

    def close_gripper(self):
        # Grasp anything between fully closed and open, with a wide tolerance.
        self.gripper.grasp(0.0, GRIPPER_SPEED, GRASP_FORCE, epsilon_outer=0.08)
        self.grasped = self.last_target if self.gripper.is_grasped else None

    def grasp_handle(self, handle_name):
        self.last_target = handle_name
        self.close_gripper()
        if not self.gripper.is_grasped:
            raise Infeasible("grasp_handle", handle_name, "the fingers closed on nothing")

    def release_handle(self):
        self.open_gripper()

    # -- what the Franka hand cannot do ----------------------------------------------------

    def _vacuum_only(self, call: str, use_instead: str):
        raise WrongEmbodiment(call, "finger", use_instead)

    def attach_vacuum_handle(self, handle_name):
        self._vacuum_only("attach_vacuum_handle", "grasp_handle")

    def detach_vacuum_handle(self):
        self._vacuum_only("detach_vacuum_handle", "release_handle")

    def activate_vacuum(self):
        self._vacuum_only("activate_vacuum", "close_gripper")

    def deactivate_vacuum(self):
        self._vacuum_only("deactivate_vacuum", "open_gripper")

    def gather_with_hook(self, obj_name):
        raise Infeasible("gather_with_hook", obj_name, "this arm has no hook tool")


def main() -> None:  # pragma: no cover - a sketch
    """``python3 -m nesy.examples.franky_sketch`` would serve the arm; wire in your perception first."""
    raise SystemExit(
        "franky_sketch is an untested sketch: copy it, plug in your perception and calibration, "
        "and serve FrankyArm(fci_host, perception).serve('0.0.0.0:7000')"
    )


if __name__ == "__main__":
    main()
