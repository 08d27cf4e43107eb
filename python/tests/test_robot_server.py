"""Tests of nesy.robot's server and client (standard library only, no nesy binary needed).

    PYTHONPATH=python/src python3 -m unittest discover -s python/tests
"""

from __future__ import annotations

import json
import os
import socket
import tempfile
import threading
import time
import unittest

from nesy.examples.logging_robot import LoggingRobot
from nesy.robot import (
    INVALID_PARAMS,
    INVALID_REQUEST,
    METHOD_NOT_FOUND,
    NO_SESSION,
    PARSE_ERROR,
    PROTOCOL_VERSION,
    ROBOT_ERROR,
    Collision,
    Infeasible,
    RobotClient,
    RobotError,
    RobotServer,
    RpcError,
    UnknownObject,
    parse_address,
)


class RawConnection:
    """A line-level connection, for requests the client would not send."""

    def __init__(self, address: str):
        _, where = parse_address(address)
        self.sock = socket.create_connection(where, timeout=5)
        self.stream = self.sock.makefile("rb")
        self.next_id = 1

    def send_line(self, line: bytes) -> dict:
        self.sock.sendall(line + b"\n")
        return json.loads(self.stream.readline())

    def request(self, method: str, params=None) -> dict:
        rid = self.next_id
        self.next_id += 1
        message = {"jsonrpc": "2.0", "id": rid, "method": method}
        if params is not None:
            message["params"] = params
        answer = self.send_line(json.dumps(message).encode())
        assert answer["id"] == rid, answer
        return answer

    def hello(self, speed_scale: float = 0.5) -> dict:
        return self.request(
            "hello",
            {"protocol": PROTOCOL_VERSION, "client": "test", "heartbeat_period_s": 0.5, "speed_scale": speed_scale},
        )

    def close(self) -> None:
        self.stream.close()
        self.sock.close()


class RecordingRobot(RobotServer):
    """A robot with a few methods, some failing, that records its stops."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.stops = []
        self.stopped = threading.Event()
        self.motion_started = threading.Event()

    def stop(self, reason):
        self.stops.append((time.monotonic(), reason))
        self.stopped.set()

    def get_obj_names(self):
        return ("red_cube", "toy_box")

    def get_obj_pos(self, obj_name):
        if obj_name != "red_cube":
            raise UnknownObject(obj_name, ["red_cube", "toy_box"])
        return (0.4, -0.1, 0.515)

    def grasp_handle(self, handle_name):
        raise Infeasible("grasp_handle", handle_name, "the handle is out of reach")

    def move_parallel(self, move_dir, offset, pointing_to):
        raise Collision(None, "top_drawer", "drawer_body")

    def close_gripper(self):
        raise RuntimeError("the gripper controller is offline")

    def move_to_position(self, pos, pointing_to, lift_clearance, angle):
        # A slow motion: heartbeats must still be answered meanwhile.
        self.motion_started.set()
        time.sleep(0.6)

    def get_tool_pos(self):
        return [0.45, 0.02, 0.71]


class ServerTestCase(unittest.TestCase):
    def start(self, server: RobotServer) -> str:
        address = server.serve_in_background("127.0.0.1:0")
        self.addCleanup(server.shutdown)
        return address


class RoundTrip(ServerTestCase):
    def test_logging_robot_round_trip(self):
        with tempfile.TemporaryDirectory() as tmp:
            log_path = os.path.join(tmp, "calls.jsonl")
            robot = LoggingRobot(log_path)
            address = self.start(robot)
            with RobotClient(address, timeout=5) as client:
                welcome = client.hello(speed_scale=0.25)
                self.assertEqual(welcome["protocol"], PROTOCOL_VERSION)
                self.assertEqual(welcome["embodiment"], "finger")
                self.assertEqual(welcome["speed_scale"], 0.25)
                self.assertEqual(welcome["heartbeat_timeout_s"], 1.5)
                names = client.call("get_obj_names")
                self.assertIn("red_cube", names)
                self.assertIn("gripper", names)
                pos = client.call("get_obj_pos", obj_name="red_cube")
                self.assertEqual(len(pos), 3)
                bbox = client.call("get_obj_bbox", obj_name="toy_box")
                self.assertEqual([len(bbox[0]), len(bbox[1])], [3, 3])
                self.assertEqual(len(client.call("get_empty_floor_xy", obj_name="red_cube")), 2)
                self.assertTrue(client.call("gripper_is_open"))
                self.assertIsNone(client.call("move_gripper_to", obj_name="red_cube", pointing_to="down", depth=0.015))
                self.assertIsNone(client.call("close_gripper"))
                self.assertFalse(client.call("gripper_is_open"))
                self.assertTrue(client.call("obj_in_gripper", obj_name="red_cube"))
                client.call("move_to_position", pos=[0.55, 0.1, 0.6], pointing_to="down", lift_clearance=0.12, angle=0.0)
                self.assertEqual(client.request("get_tool_pos")["result"], [0.55, 0.1, 0.6])
                moved = client.call("get_obj_pos", obj_name="red_cube")
                self.assertAlmostEqual(moved[0], 0.55)
                with self.assertRaises(UnknownObject) as raised:
                    client.call("get_obj_pos", obj_name="unicorn")
                self.assertEqual(raised.exception.fields["name"], "unicorn")
                self.assertIn('unknown object "unicorn"', str(raised.exception))
                with self.assertRaises(RobotError) as raised:
                    client.call("activate_vacuum")
                self.assertEqual(raised.exception.kind, "wrong_embodiment")
                self.assertEqual(
                    str(raised.exception),
                    "activate_vacuum() is not available on the finger robot; use close_gripper() instead",
                )
                self.assertEqual(client.call("finish"), {"subtasks": None, "final_state": None})
                client.close("done")
            robot.shutdown()
            robot.calls.close()
            with open(log_path, encoding="utf-8") as handle:
                events = [json.loads(line) for line in handle]
            calls = [e for e in events if e["event"] == "call"]
            self.assertEqual(events[0]["event"], "session")
            self.assertEqual(calls[0]["method"], "get_obj_names")
            self.assertEqual(
                [c["method"] for c in calls][:8],
                [
                    "get_obj_names",
                    "get_obj_pos",
                    "get_obj_bbox",
                    "get_empty_floor_xy",
                    "gripper_is_open",
                    "move_gripper_to",
                    "close_gripper",
                    "gripper_is_open",
                ],
            )
            self.assertEqual(calls[5]["params"], {"obj_name": "red_cube", "pointing_to": "down", "depth": 0.015})
            self.assertEqual(events[-1], {"t": events[-1]["t"], "event": "stopped", "reason": "the client sent stop: done"})

    def test_heartbeats_are_answered_while_a_motion_runs(self):
        robot = RecordingRobot(heartbeat_timeout=0.4)
        address = self.start(robot)
        with RobotClient(address, timeout=5, heartbeat_period=0.1) as client:
            client.hello()
            # The motion takes longer than the watchdog's limit; the heartbeats keep it alive.
            client.call("move_to_position", pos=[0.5, 0.0, 0.7], pointing_to="down", lift_clearance=0.1, angle=0.0)
            self.assertEqual(client.call("get_tool_pos"), [0.45, 0.02, 0.71])
            self.assertEqual(robot.stops, [])


class ErrorMapping(ServerTestCase):
    def setUp(self):
        self.robot = RecordingRobot()
        self.conn = RawConnection(self.start(self.robot))
        self.addCleanup(self.conn.close)

    def test_call_before_hello(self):
        answer = self.conn.request("get_obj_names", {})
        self.assertEqual(answer["error"]["code"], NO_SESSION)
        # Heartbeats are answered before hello too.
        self.assertEqual(self.conn.request("heartbeat", {})["result"], {})

    def test_hello_checks(self):
        answer = self.conn.request("hello", {"protocol": "nesy-robot/9", "speed_scale": 0.5})
        self.assertEqual(answer["error"]["code"], INVALID_PARAMS)
        answer = self.conn.hello(speed_scale=1.5)
        self.assertEqual(answer["error"]["code"], INVALID_PARAMS)
        answer = self.conn.hello(speed_scale=0.3)
        self.assertEqual(answer["result"]["speed_scale"], 0.3)
        self.assertEqual(self.robot.speed_scale, 0.3)

    def test_robot_errors(self):
        self.conn.hello()
        answer = self.conn.request("grasp_handle", {"handle_name": "hinge_handle"})
        error = answer["error"]
        self.assertEqual(error["code"], ROBOT_ERROR)
        self.assertEqual(
            error["data"],
            {"kind": "infeasible", "call": "grasp_handle", "target": "hinge_handle", "reason": "the handle is out of reach"},
        )
        self.assertEqual(error["message"], "grasp_handle(hinge_handle) is infeasible: the handle is out of reach")
        # A `call` left as None names the method.
        answer = self.conn.request("move_parallel", {"move_dir": "left", "offset": 0.1, "pointing_to": "down"})
        self.assertEqual(answer["error"]["data"]["kind"], "collision")
        self.assertEqual(answer["error"]["data"]["call"], "move_parallel")
        self.assertEqual(answer["error"]["message"], "move_parallel() was stopped by contact: top_drawer ran into drawer_body")
        # Any other exception: a `stopped` robot error with its text, and logged.
        with self.assertLogs("nesy.robot", level="ERROR") as logged:
            answer = self.conn.request("close_gripper", {})
        self.assertIn("close_gripper raised", logged.output[0])
        self.assertEqual(answer["error"]["code"], ROBOT_ERROR)
        self.assertEqual(
            answer["error"]["data"],
            {"kind": "stopped", "call": "close_gripper", "reason": "the gripper controller is offline"},
        )
        # Results are converted to the protocol's shapes.
        self.assertEqual(self.conn.request("get_obj_names", {})["result"], ["red_cube", "toy_box"])
        self.assertEqual(self.conn.request("get_obj_pos", {"obj_name": "red_cube"})["result"], [0.4, -0.1, 0.515])

    def test_unknown_and_unimplemented_methods(self):
        self.conn.hello()
        answer = self.conn.request("fly", {})
        self.assertEqual(answer["error"]["code"], METHOD_NOT_FOUND)
        # An API method this robot does not implement.
        answer = self.conn.request("gather_with_hook", {"obj_name": "red_cube"})
        self.assertEqual(answer["error"]["code"], METHOD_NOT_FOUND)

    def test_bad_params(self):
        self.conn.hello()
        for params in (
            {"obj_name": 7},
            {},
            {"obj_name": "red_cube", "colour": "red"},
            [1, 2],
        ):
            answer = self.conn.request("get_obj_pos", params)
            self.assertEqual(answer["error"]["code"], INVALID_PARAMS, params)
        answer = self.conn.request("move_to_position", {"pos": [0.4, 0.1], "pointing_to": "down", "lift_clearance": 0.1, "angle": 0.0})
        self.assertEqual(answer["error"]["code"], INVALID_PARAMS)
        answer = self.conn.request("move_to_position", {"pos": [0.4, 0.1, 0.6], "pointing_to": "sideways", "lift_clearance": 0.1, "angle": 0.0})
        self.assertEqual(answer["error"]["code"], INVALID_PARAMS)
        self.assertIn("pointing_to", answer["error"]["message"])

    def test_not_json_and_not_requests(self):
        answer = self.conn.send_line(b"{not json")
        self.assertEqual(answer["error"]["code"], PARSE_ERROR)
        self.assertIsNone(answer["id"])
        answer = self.conn.send_line(b'{"id": 3, "method": "hello"}')
        self.assertEqual(answer["error"]["code"], INVALID_REQUEST)
        answer = self.conn.send_line(b'{"jsonrpc": "2.0", "id": 4}')
        self.assertEqual(answer["error"]["code"], INVALID_REQUEST)

    def test_client_maps_errors(self):
        with RobotClient(self.robot.address, timeout=5) as client:
            client.hello()
            with self.assertRaises(Infeasible):
                client.call("grasp_handle", handle_name="hinge_handle")
            with self.assertRaises(RpcError) as raised:
                client.call("fly")
            self.assertEqual(raised.exception.code, METHOD_NOT_FOUND)


class Watchdog(ServerTestCase):
    def test_silence_after_hello_stops_the_robot(self):
        robot = RecordingRobot(heartbeat_timeout=0.5)
        address = self.start(robot)
        client = RobotClient(address, timeout=5, heartbeat_period=0.1)
        self.addCleanup(client.close, send_stop=False)
        client.hello()
        time.sleep(0.8)  # heartbeats keep the session alive past the timeout
        self.assertEqual(robot.stops, [])
        client.stop_heartbeat()
        silent_since = time.monotonic()
        self.assertTrue(robot.stopped.wait(2.0), "stop() was not called")
        waited = robot.stops[0][0] - silent_since
        self.assertLess(waited, 0.5 + 0.25)
        self.assertIn("watchdog", robot.stops[0][1])
        # The session is closed: further calls fail.
        deadline = time.monotonic() + 2
        while client.closed is None and time.monotonic() < deadline:
            time.sleep(0.01)
        self.assertIsNotNone(client.closed)
        with self.assertRaises(ConnectionError):
            client.call("get_obj_names")
        self.assertEqual(len(robot.stops), 1)

    def test_watchdog_stops_a_running_motion(self):
        robot = RecordingRobot(heartbeat_timeout=0.3)
        address = self.start(robot)
        conn = RawConnection(address)
        self.addCleanup(conn.close)
        conn.hello()
        # Send a slow motion and then nothing at all.
        conn.sock.sendall(
            b'{"jsonrpc":"2.0","id":9,"method":"move_to_position","params":'
            b'{"pos":[0.5,0,0.7],"pointing_to":"down","lift_clearance":0.1,"angle":0}}\n'
        )
        self.assertTrue(robot.motion_started.wait(2))
        self.assertTrue(robot.stopped.wait(2))
        # stop() came while the motion was still running.
        self.assertIn("watchdog", robot.stops[0][1])

    def test_disconnect_stops_the_robot(self):
        robot = RecordingRobot()
        address = self.start(robot)
        conn = RawConnection(address)
        conn.hello()
        conn.close()
        self.assertTrue(robot.stopped.wait(2))
        self.assertEqual(robot.stops[0][1], "the connection closed")

    def test_stop_request(self):
        robot = RecordingRobot()
        address = self.start(robot)
        conn = RawConnection(address)
        self.addCleanup(conn.close)
        conn.hello()
        answer = conn.request("stop", {"reason": "the run ended: ok"})
        self.assertEqual(answer["result"], {})
        self.assertEqual(robot.stops[0][1], "the client sent stop: the run ended: ok")
        self.assertEqual(conn.stream.readline(), b"")  # the session is closed


class UnixSocket(unittest.TestCase):
    def test_unix_address(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "robot.sock")
            robot = LoggingRobot(None)
            address = robot.serve_in_background("unix:" + path)
            self.assertEqual(address, "unix:" + path)
            try:
                with RobotClient(address, timeout=5) as client:
                    client.hello()
                    self.assertIn("toy_box", client.call("get_obj_names"))
            finally:
                robot.shutdown()
            self.assertFalse(os.path.exists(path))


if __name__ == "__main__":
    unittest.main()
