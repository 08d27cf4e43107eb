"""``SimulatedArm``: a robot adapter whose robot is nesy's simulator.

This is the shape of "your robot adapter" with the hardware replaced by ``nesy robot-server``
(the built-in simulator served over the same protocol). ``SimulatedArm`` subclasses
``RobotServer`` and implements every robot API method by forwarding it, through
``nesy.robot.RobotClient``, to a ``nesy robot-server --scene SCENE`` process it starts; robot
errors from the simulator come back as the same typed errors. Each session of this server
opens a fresh session (a fresh copy of the scene) on the simulator, and ``stop`` ends it. Every
call is also written to a JSON Lines log.

::

    python3 -m nesy.examples.sim_proxy_robot --scene fixtures/scenes/pick_place_finger.json \\
        --listen 127.0.0.1:0 --log arm-calls.jsonl --once
    nesy run --policy policy.py --scene fixtures/scenes/pick_place_finger.json \\
        --robot tcp://127.0.0.1:PORT

For a real arm, replace the ``_forward`` calls with your controller's (see ``franky_sketch``
and ``ros2_sketch``).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import subprocess
import sys
import threading
from typing import Any, Dict, Optional, Sequence

import nesy
from nesy.examples.calllog import CallLog
from nesy.robot import RobotClient, RobotServer, Stopped

__all__ = ["SimulatedArm", "main"]

log = logging.getLogger("nesy.examples.sim_proxy_robot")


class SimulatedArm(RobotServer):
    """A robot server that forwards every call to nesy's simulator.

    Args:
        scene: the scene file the simulator serves (a fresh copy per session).
        log: the call log's path (``None``: no log; ``"-"``: standard error).
        name: the robot's name in ``hello``'s answer.
        heartbeat_timeout: this server's watchdog limit, in seconds.
        sim_log: where ``nesy robot-server`` writes its own events (default: discarded).
        call_timeout: the longest wait for the simulator's answer to one call, in seconds.
    """

    def __init__(
        self,
        scene: str,
        *,
        log: Optional[str] = None,
        name: Optional[str] = None,
        heartbeat_timeout: float = 1.5,
        sim_log: Optional[str] = None,
        call_timeout: float = 60.0,
    ):
        embodiment = "finger"
        try:
            with open(scene, encoding="utf-8") as handle:
                declared = json.load(handle).get("embodiment")
            if declared in ("finger", "vacuum"):
                embodiment = declared
        except (OSError, ValueError, AttributeError):
            pass  # the simulator will say what is wrong with the scene
        super().__init__(embodiment, name or "simulated arm (nesy robot-server, {})".format(scene), heartbeat_timeout)
        self.scene = scene
        self.sim_log = sim_log
        self.call_timeout = call_timeout
        self.calls = CallLog(log)
        self.sim_address: Optional[str] = None
        self._sim: Optional[subprocess.Popen] = None
        self._client: Optional[RobotClient] = None
        self._lock = threading.Lock()

    # -- the simulator -------------------------------------------------------------------

    def start_simulator(self, timeout: float = 30.0) -> str:
        """Starts ``nesy robot-server`` on a free local port (once) and returns its address."""
        with self._lock:
            if self._sim is not None and self._sim.poll() is None and self.sim_address:
                return self.sim_address
            command = [
                nesy.binary(),
                "robot-server",
                "--scene",
                self.scene,
                "--listen",
                "127.0.0.1:0",
                "--heartbeat-timeout",
                str(self.heartbeat_timeout),
                "--log",
                self.sim_log or os.devnull,
            ]
            self._sim = subprocess.Popen(
                command,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
                encoding="utf-8",
                errors="replace",
            )
            first: list = []
            got = threading.Event()

            def read_stdout(stream) -> None:
                for line in stream:
                    if not got.is_set():
                        first.append(line.strip())
                        got.set()
                    else:
                        log.debug("nesy robot-server: %s", line.rstrip())
                got.set()

            threading.Thread(target=read_stdout, args=(self._sim.stdout,), daemon=True).start()
            if not got.wait(timeout) or not first or " " not in first[0]:
                error = self._sim.stderr.read() if self._sim.poll() is not None else ""
                self._stop_simulator()
                raise RuntimeError("nesy robot-server did not start: {}".format(error.strip() or "no address printed"))
            threading.Thread(target=self._drain_stderr, args=(self._sim.stderr,), daemon=True).start()
            # "listening on tcp://127.0.0.1:PORT"
            self.sim_address = first[0].split()[-1]
            log.info("simulator listening on %s", self.sim_address)
            return self.sim_address

    @staticmethod
    def _drain_stderr(stream) -> None:
        for line in stream:
            log.debug("nesy robot-server: %s", line.rstrip())

    def _stop_simulator(self) -> None:
        sim, self._sim = self._sim, None
        if sim is not None and sim.poll() is None:
            sim.terminate()
            try:
                sim.wait(timeout=5)
            except subprocess.TimeoutExpired:
                sim.kill()
                sim.wait()

    def close(self) -> None:
        """Stops serving, ends the simulator session and stops the simulator process."""
        self.shutdown()
        self._end_client("the adapter closed")
        self._stop_simulator()
        self.calls.close()

    # -- session hooks -------------------------------------------------------------------

    def begin_session(self, hello: Dict[str, Any]) -> None:
        address = self.start_simulator()
        client = RobotClient(address, timeout=self.call_timeout)
        try:
            welcome = client.hello(speed_scale=self.speed_scale or 0.5)
        except Exception:
            client.close(send_stop=False)
            raise
        self._client = client
        self.embodiment = welcome.get("embodiment", self.embodiment)
        self.calls.write("session", hello=hello, simulator=welcome)

    def stop(self, reason: str) -> None:
        # A real adapter halts the arm here. The simulator's session is ended with `stop`.
        self._end_client(reason)
        self.calls.write("stopped", reason=reason)

    def on_answer(self, method, params, result=None, error=None, check=False):
        self.calls.call(method, params, result=result, error=error, check=check)

    def _end_client(self, reason: str) -> None:
        client, self._client = self._client, None
        if client is not None:
            client.close(reason)

    def _forward(self, method: str, **params: Any) -> Any:
        client = self._client
        if client is None:
            raise Stopped(method, "the simulator session has ended")
        return client.call(method, **params)

    # -- the robot API, forwarded ----------------------------------------------------------

    def is_obj_visible(self, obj_name):
        return self._forward("is_obj_visible", obj_name=obj_name)

    def get_obj_names(self):
        return self._forward("get_obj_names")

    def get_obj_pos(self, obj_name):
        return self._forward("get_obj_pos", obj_name=obj_name)

    def get_obj_bbox(self, obj_name):
        return self._forward("get_obj_bbox", obj_name=obj_name)

    def get_obj_size(self, obj_name):
        return self._forward("get_obj_size", obj_name=obj_name)

    def gripper_is_open(self):
        return self._forward("gripper_is_open")

    def obj_in_gripper(self, obj_name):
        return self._forward("obj_in_gripper", obj_name=obj_name)

    def get_empty_floor_xy(self, obj_name):
        return self._forward("get_empty_floor_xy", obj_name=obj_name)

    def move_gripper_to(self, obj_name, pointing_to, depth):
        return self._forward("move_gripper_to", obj_name=obj_name, pointing_to=pointing_to, depth=depth)

    def move_to_position(self, pos, pointing_to, lift_clearance, angle):
        return self._forward(
            "move_to_position", pos=pos, pointing_to=pointing_to, lift_clearance=lift_clearance, angle=angle
        )

    def move_parallel(self, move_dir, offset, pointing_to):
        return self._forward("move_parallel", move_dir=move_dir, offset=offset, pointing_to=pointing_to)

    def grasp_handle(self, handle_name):
        return self._forward("grasp_handle", handle_name=handle_name)

    def release_handle(self):
        return self._forward("release_handle")

    def open_gripper(self):
        return self._forward("open_gripper")

    def close_gripper(self):
        return self._forward("close_gripper")

    def attach_vacuum_handle(self, handle_name):
        return self._forward("attach_vacuum_handle", handle_name=handle_name)

    def detach_vacuum_handle(self):
        return self._forward("detach_vacuum_handle")

    def activate_vacuum(self):
        return self._forward("activate_vacuum")

    def deactivate_vacuum(self):
        return self._forward("deactivate_vacuum")

    def gather_with_hook(self, obj_name):
        return self._forward("gather_with_hook", obj_name=obj_name)

    def get_tool_pos(self):
        return self._forward("get_tool_pos")

    def finish(self):
        return self._forward("finish")


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python3 -m nesy.examples.sim_proxy_robot",
        description="Serve a robot adapter whose robot is nesy's simulator (nesy robot-server).",
    )
    parser.add_argument("--scene", required=True, help="the scene the simulator serves")
    parser.add_argument("--listen", default="127.0.0.1:0", help="HOST:PORT (port 0 takes a free one) or unix:PATH")
    parser.add_argument("--log", default=None, help="write each call as a JSON line here ('-' for standard error)")
    parser.add_argument("--sim-log", default=None, help="where nesy robot-server writes its events")
    parser.add_argument("--heartbeat-timeout", type=float, default=1.5, metavar="SECS")
    parser.add_argument("--once", action="store_true", help="serve one session, then exit")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, stream=sys.stderr, format="%(name)s: %(message)s")
    arm = SimulatedArm(args.scene, log=args.log, sim_log=args.sim_log, heartbeat_timeout=args.heartbeat_timeout)
    try:
        arm.start_simulator()
        arm.serve(args.listen, once=args.once)
    except KeyboardInterrupt:
        pass
    finally:
        arm.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
