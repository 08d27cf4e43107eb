"""``LoggingRobot``: a stand-in robot that moves nothing and logs every call it receives.

Use it to see what nesy sends before a real arm is connected::

    python3 -m nesy.examples.logging_robot --listen 127.0.0.1:0 --log calls.jsonl --once
    nesy run --policy policy.py --robot tcp://127.0.0.1:PORT --skip-dry-run

What it answers is bookkeeping, not perception: objects and their boxes come from a small
fixed table (the cube-and-box scene of ``fixtures/scenes/pick_place_finger.json``) or from
``--scene scene.json`` (each object's name and position, with a box size looked up from its
kind; unknown kinds get a 5 cm cube). It keeps a naive record of the tool position, the
gripper state and which object it "holds" (the object named by the last ``move_gripper_to``,
once the gripper closes); a held object's recorded position follows the tool. Nothing checks
collisions, reach or physics, and handles (``grasp_handle``) are accepted by any name.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import sys
from typing import Any, Dict, List, Optional, Sequence, Tuple

from nesy.robot import InvalidArgument, RobotServer, UnknownObject, WrongEmbodiment
from nesy.examples.calllog import CallLog

__all__ = ["LoggingRobot", "DEFAULT_OBJECTS", "load_scene_objects", "main"]

Vec3 = List[float]

#: Box extents (x, y, z) in metres of a few of the simulator's object kinds, at yaw 0.
KIND_SIZES: Dict[str, Tuple[float, float, float]] = {
    "cube": (0.03, 0.03, 0.03),
    "cylinder": (0.03, 0.03, 0.03),
    "toy_box": (0.139, 0.0985, 0.045),
    "drawer_cabinet": (0.154, 0.148, 0.194),
}
_UNKNOWN_SIZE = (0.05, 0.05, 0.05)

#: The fixed table used without a scene: name -> (centre [x, y, z], size [dx, dy, dz]).
DEFAULT_OBJECTS: Dict[str, Tuple[Vec3, Vec3]] = {
    "toy_box": ([0.55, 0.10, 0.5225], [0.0985, 0.139, 0.045]),
    "red_cube": ([0.60, -0.10, 0.515], [0.0375, 0.0375, 0.03]),
    "blue_cube": ([0.52, -0.14, 0.515], [0.0407, 0.0407, 0.03]),
    "green_cube": ([0.52, -0.14, 0.545], [0.0407, 0.0407, 0.03]),
}

#: Where the tool starts (the simulator's home pose, roughly).
HOME: Vec3 = [0.307, 0.0, 1.071]
_TABLE = ([0.5, 0.0, 0.5], [1.0, 2.0, 0.5])
_TOOL_SIZE = [0.07, 0.2, 0.168]
_UNITS = {
    "left": (0.0, -1.0, 0.0),
    "right": (0.0, 1.0, 0.0),
    "front": (1.0, 0.0, 0.0),
    "back": (-1.0, 0.0, 0.0),
    "up": (0.0, 0.0, 1.0),
    "down": (0.0, 0.0, -1.0),
}
# Finger-only and vacuum-only calls, with the call to use on the other tool.
_FINGER_ONLY = {
    "grasp_handle": "attach_vacuum_handle",
    "release_handle": "detach_vacuum_handle",
    "open_gripper": "deactivate_vacuum",
    "close_gripper": "activate_vacuum",
}
_VACUUM_ONLY = {value: key for key, value in _FINGER_ONLY.items()}


def load_scene_objects(path: str) -> Tuple[Dict[str, Tuple[Vec3, Vec3]], Optional[str]]:
    """Reads a scene file's objects as ``{name: (centre, size)}`` and its embodiment.

    A scene object's ``pose.position`` is the bottom centre of its box; the size comes from
    ``KIND_SIZES`` (rotated by ``pose.yaw``), 5 cm cubes for kinds not in the table.
    """
    with open(path, encoding="utf-8") as handle:
        scene = json.load(handle)
    objects: Dict[str, Tuple[Vec3, Vec3]] = {}
    for item in scene.get("objects", []):
        name = item.get("name")
        pose = item.get("pose") or {}
        position = pose.get("position")
        if not isinstance(name, str) or not (isinstance(position, list) and len(position) == 3):
            continue
        ex, ey, ez = KIND_SIZES.get(str(item.get("kind")), _UNKNOWN_SIZE)
        yaw = float(pose.get("yaw", 0.0) or 0.0)
        c, s = abs(math.cos(yaw)), abs(math.sin(yaw))
        size = [c * ex + s * ey, s * ex + c * ey, ez]
        x, y, z = (float(v) for v in position)
        objects[name] = ([x, y, z + ez / 2.0], size)
    embodiment = scene.get("embodiment")
    return objects, embodiment if embodiment in ("finger", "vacuum") else None


class LoggingRobot(RobotServer):
    """A robot server that moves nothing: it answers from its object table, keeps a naive
    record of tool and gripper, and writes every call it answers to ``log`` (JSON Lines, see
    ``nesy.examples.calllog.CallLog``).

    Args:
        log: the call log's path (``None``: no log; ``"-"``: standard error).
        scene: a scene file to take the objects (and the embodiment) from.
        embodiment: ``"finger"`` or ``"vacuum"``; default the scene's, else ``"finger"``.
        name: the robot's name in ``hello``'s answer.
        heartbeat_timeout: the watchdog's limit, in seconds.
    """

    def __init__(
        self,
        log: Optional[str] = None,
        *,
        scene: Optional[str] = None,
        embodiment: Optional[str] = None,
        name: str = "logging robot (moves nothing)",
        heartbeat_timeout: float = 1.5,
    ):
        scene_embodiment = None
        if scene is not None:
            objects, scene_embodiment = load_scene_objects(scene)
        else:
            objects = DEFAULT_OBJECTS
        super().__init__(embodiment or scene_embodiment or "finger", name, heartbeat_timeout)
        self.calls = CallLog(log)
        self._initial = {k: (list(c), list(s)) for k, (c, s) in objects.items()}
        self._reset()

    def _reset(self) -> None:
        self.objects = {k: (list(c), list(s)) for k, (c, s) in self._initial.items()}
        self.tool: Vec3 = list(HOME)
        self.is_open = True
        self.held: Optional[str] = None
        self.held_offset: Vec3 = [0.0, 0.0, 0.0]
        self.handle: Optional[str] = None
        self.last_target: Optional[str] = None

    # -- session hooks ---------------------------------------------------------------------

    def begin_session(self, hello: Dict[str, Any]) -> None:
        self._reset()
        self.calls.write("session", hello=hello)

    def on_answer(self, method, params, result=None, error=None, check=False):
        self.calls.call(method, params, result=result, error=error, check=check)

    def stop(self, reason: str) -> None:
        self.calls.write("stopped", reason=reason)

    # -- the world as recorded -------------------------------------------------------------

    def _tool_name(self) -> str:
        return "vacuum_gripper" if self.embodiment == "vacuum" else "gripper"

    def _names(self) -> List[str]:
        return ["floor"] + list(self.objects) + [self._tool_name()]

    def _box(self, name: str) -> Tuple[Vec3, Vec3]:
        if name in self.objects:
            return self.objects[name]
        if name == "floor":
            return _TABLE
        if name == self._tool_name():
            return list(self.tool), list(_TOOL_SIZE)
        raise UnknownObject(name, self._names())

    def _needs(self, call: str) -> None:
        if self.embodiment == "vacuum" and call in _FINGER_ONLY:
            raise WrongEmbodiment(call, "vacuum", _FINGER_ONLY[call])
        if self.embodiment == "finger" and call in _VACUUM_ONLY:
            raise WrongEmbodiment(call, "finger", _VACUUM_ONLY[call])

    def _move_tool(self, target: Sequence[float]) -> None:
        self.tool = [float(v) for v in target]
        if self.held is not None and self.held in self.objects:
            _, size = self.objects[self.held]
            centre = [self.tool[i] + self.held_offset[i] for i in range(3)]
            self.objects[self.held] = (centre, size)

    def _grip(self) -> None:
        self.is_open = False
        if self.last_target in self.objects:
            self.held = self.last_target
            centre, _ = self.objects[self.held]
            self.held_offset = [centre[i] - self.tool[i] for i in range(3)]

    def _release(self) -> None:
        self.is_open = True
        self.held = None

    # -- perception ------------------------------------------------------------------------

    def is_obj_visible(self, obj_name):
        return obj_name in self._names()

    def get_obj_names(self):
        return self._names()

    def get_obj_pos(self, obj_name):
        return self._box(obj_name)[0]

    def get_obj_bbox(self, obj_name):
        centre, size = self._box(obj_name)
        return [[centre[i] - size[i] / 2.0 for i in range(3)], [centre[i] + size[i] / 2.0 for i in range(3)]]

    def get_obj_size(self, obj_name):
        return self._box(obj_name)[1]

    def gripper_is_open(self):
        return self.is_open

    def obj_in_gripper(self, obj_name):
        self._box(obj_name)
        return self.held == obj_name

    def get_empty_floor_xy(self, obj_name):
        self._box(obj_name)
        others = [c for name, (c, _) in self.objects.items() if name != obj_name]
        best, best_gap = [0.45, -0.3], -1.0
        for i in range(7):
            for j in range(15):
                x, y = 0.35 + 0.05 * i, -0.35 + 0.05 * j
                gap = min((math.hypot(x - c[0], y - c[1]) for c in others), default=1.0)
                if gap > best_gap:
                    best, best_gap = [x, y], gap
        return best

    def get_tool_pos(self):
        return self.tool

    # -- actions ---------------------------------------------------------------------------

    def move_gripper_to(self, obj_name, pointing_to, depth):
        centre, size = self._box(obj_name)
        if pointing_to == "down":
            target = [centre[0], centre[1], centre[2] + size[2] / 2.0 - depth]
        else:
            target = list(centre)
        self.last_target = obj_name
        self._move_tool(target)

    def move_to_position(self, pos, pointing_to, lift_clearance, angle):
        self._move_tool(pos)

    def move_parallel(self, move_dir, offset, pointing_to):
        if offset <= 0:
            raise InvalidArgument("move_parallel", "offset must be positive, got {}".format(offset))
        unit = _UNITS[move_dir]
        self._move_tool([self.tool[i] + unit[i] * offset for i in range(3)])

    def grasp_handle(self, handle_name):
        self._needs("grasp_handle")
        self.handle = handle_name
        self.is_open = False

    def release_handle(self):
        self._needs("release_handle")
        self.handle = None
        self.is_open = True

    def open_gripper(self):
        self._needs("open_gripper")
        self._release()

    def close_gripper(self):
        self._needs("close_gripper")
        self._grip()

    def attach_vacuum_handle(self, handle_name):
        self._needs("attach_vacuum_handle")
        self.handle = handle_name
        self.is_open = False

    def detach_vacuum_handle(self):
        self._needs("detach_vacuum_handle")
        self.handle = None
        self.is_open = True

    def activate_vacuum(self):
        self._needs("activate_vacuum")
        self._grip()

    def deactivate_vacuum(self):
        self._needs("deactivate_vacuum")
        self._release()

    def gather_with_hook(self, obj_name):
        self._box(obj_name)


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python3 -m nesy.examples.logging_robot",
        description="Serve a stand-in robot that moves nothing and logs every call nesy sends it.",
    )
    parser.add_argument("--listen", default="127.0.0.1:0", help="HOST:PORT (port 0 takes a free one) or unix:PATH")
    parser.add_argument("--log", default=None, help="write each call as a JSON line here ('-' for standard error)")
    parser.add_argument("--scene", default=None, help="take the objects from this scene.json")
    parser.add_argument("--embodiment", choices=("finger", "vacuum"), default=None)
    parser.add_argument("--heartbeat-timeout", type=float, default=1.5, metavar="SECS")
    parser.add_argument("--once", action="store_true", help="serve one session, then exit")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, stream=sys.stderr, format="%(name)s: %(message)s")
    robot = LoggingRobot(args.log, scene=args.scene, embodiment=args.embodiment, heartbeat_timeout=args.heartbeat_timeout)
    try:
        robot.serve(args.listen, once=args.once)
    except KeyboardInterrupt:
        pass
    finally:
        robot.calls.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
