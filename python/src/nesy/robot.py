"""The robot protocol ``nesy-robot/1`` in pure Python: a server base class and a client.

``nesy run --robot ADDRESS`` and ``nesy adapt --execute --robot ADDRESS`` do not drive a robot
themselves. They connect to a *robot server* and send it the policy's robot calls as JSON-RPC
2.0 requests, one JSON object per line, over TCP or a Unix socket (the protocol is described in
``docs/robot-protocol.md`` of the nesy repository). This module gives you both sides:

``RobotServer``
    Subclass it, implement the robot API's methods for your arm (``get_obj_pos``,
    ``move_to_position``, ``close_gripper``, ...) and ``stop``, and call ``serve``. The base class
    does the protocol: ``hello`` and the speed-scale echo, heartbeats answered at once while a
    motion runs, robot calls run one at a time in order on an executor thread, parameter
    checks, error mapping, and the safety duties (the heartbeat watchdog and stop on
    disconnect both call your ``stop``).

``RobotClient``
    A small client for the same protocol: ``hello()``, ``call(method, **params)``, a heartbeat
    thread and ``close()``. Use it to talk to ``nesy robot-server`` (the simulator), to test your
    own server, or to forward calls to another server.

Only the standard library is used.
"""

from __future__ import annotations

import inspect
import itertools
import json
import logging
import math
import os
import queue
import socket
import stat
import threading
import time
from typing import Any, Callable, Dict, Iterable, List, Optional, Tuple, Union

__all__ = [
    "PROTOCOL_VERSION",
    "MAX_MESSAGE_BYTES",
    "PARSE_ERROR",
    "INVALID_REQUEST",
    "METHOD_NOT_FOUND",
    "INVALID_PARAMS",
    "ROBOT_ERROR",
    "SESSION_STOPPED",
    "NO_SESSION",
    "DIRECTIONS",
    "API_METHODS",
    "RobotError",
    "Infeasible",
    "OutOfWorkspace",
    "IkFailed",
    "NoEmptySpace",
    "UnknownObject",
    "WrongEmbodiment",
    "InvalidArgument",
    "Collision",
    "Stopped",
    "TimedOut",
    "RpcError",
    "ProtocolError",
    "RobotServer",
    "RobotClient",
    "parse_address",
    "format_address",
]

log = logging.getLogger("nesy.robot")

#: The protocol's name and version, exchanged in ``hello``.
PROTOCOL_VERSION = "nesy-robot/1"
#: The longest message line either side accepts, in bytes (newline included).
MAX_MESSAGE_BYTES = 1 << 20

#: The line is not JSON.
PARSE_ERROR = -32700
#: Not a JSON-RPC 2.0 request (no ``jsonrpc``, ``id`` or ``method``).
INVALID_REQUEST = -32600
#: No such method (or this robot does not implement it).
METHOD_NOT_FOUND = -32601
#: The params do not fit the method.
INVALID_PARAMS = -32602
#: A robot error: the robot refused or failed the call; ``data`` is the typed error.
ROBOT_ERROR = -32000
#: The session was stopped (watchdog, ``stop``, the robot); nothing more runs.
SESSION_STOPPED = -32001
#: A call before ``hello``.
NO_SESSION = -32002

#: The API's direction names: left (-y), right (+y), front (+x), back (-x), up (+z), down (-z).
DIRECTIONS = ("left", "right", "front", "back", "up", "down")

_EMBODIMENTS = ("finger", "vacuum")

#: The 20 robot API methods: for each, its parameters as ``(name, kind)`` pairs (kind is
#: ``name``, ``direction``, ``number`` or ``vec3``) and the shape of its result (``bool``,
#: ``names``, ``vec3``, ``bbox``, ``xy``, or ``None`` for actions, which answer ``null``).
API_METHODS: Dict[str, Tuple[Tuple[Tuple[str, str], ...], Optional[str]]] = {
    "is_obj_visible": ((("obj_name", "name"),), "bool"),
    "get_obj_names": ((), "names"),
    "get_obj_pos": ((("obj_name", "name"),), "vec3"),
    "get_obj_bbox": ((("obj_name", "name"),), "bbox"),
    "get_obj_size": ((("obj_name", "name"),), "vec3"),
    "gripper_is_open": ((), "bool"),
    "obj_in_gripper": ((("obj_name", "name"),), "bool"),
    "get_empty_floor_xy": ((("obj_name", "name"),), "xy"),
    "move_gripper_to": (
        (("obj_name", "name"), ("pointing_to", "direction"), ("depth", "number")),
        None,
    ),
    "move_to_position": (
        (
            ("pos", "vec3"),
            ("pointing_to", "direction"),
            ("lift_clearance", "number"),
            ("angle", "number"),
        ),
        None,
    ),
    "move_parallel": (
        (("move_dir", "direction"), ("offset", "number"), ("pointing_to", "direction")),
        None,
    ),
    "grasp_handle": ((("handle_name", "name"),), None),
    "release_handle": ((), None),
    "open_gripper": ((), None),
    "close_gripper": ((), None),
    "attach_vacuum_handle": ((("handle_name", "name"),), None),
    "detach_vacuum_handle": ((), None),
    "activate_vacuum": ((), None),
    "deactivate_vacuum": ((), None),
    "gather_with_hook": ((("obj_name", "name"),), None),
}


# --------------------------------------------------------------------------------------
# Robot errors
# --------------------------------------------------------------------------------------


def _point(target: Iterable[float]) -> str:
    x, y, z = (float(v) for v in target)
    return "({:.3f}, {:.3f}, {:.3f})".format(x, y, z)


class RobotError(Exception):
    """The robot refused or failed a call: answered as error ``-32000`` with a typed ``data``.

    Raise one of the subclasses from a robot method (``Infeasible``, ``Collision``,
    ``Stopped``, ...). The policy sees it as the matching ``robot.*Error`` exception with the
    message as its text, and nesy ends the run (the first robot error ends it).

    Attributes:
        kind: the ``kind`` field of the error's ``data`` (``infeasible``, ``collision``, ...).
        fields: the other fields of ``data``, a dict of JSON values.
    """

    kind = "stopped"

    def __init__(self, kind: str, fields: Optional[Dict[str, Any]] = None, message: Optional[str] = None):
        self.kind = kind
        self.fields = dict(fields or {})
        self._message = message
        super().__init__(kind)

    def _render(self) -> str:
        """The message from the fields, worded like nesy's own errors (subclasses override)."""
        details = ", ".join("{}={}".format(k, v) for k, v in self.fields.items())
        return "{}: {}".format(self.kind, details) if details else self.kind

    @property
    def message(self) -> str:
        """The text the policy sees."""
        return self._message if self._message is not None else self._render()

    def __str__(self) -> str:
        return self.message

    def __repr__(self) -> str:
        return "{}({!r})".format(type(self).__name__, self.data())

    def data(self) -> Dict[str, Any]:
        """The error's ``data`` object: ``{"kind": ..., **fields}``."""
        data = {"kind": self.kind}
        data.update(self.fields)
        return data

    def _fill_call(self, method: str) -> None:
        # A `call` field left as None names the method that raised the error.
        if "call" in self.fields and not self.fields["call"]:
            self.fields["call"] = method

    @classmethod
    def from_data(cls, data: Dict[str, Any], message: Optional[str] = None) -> "RobotError":
        """Rebuilds a robot error from the ``data`` (and ``message``) of an error answer, as the
        matching subclass when the kind is known."""
        data = dict(data or {})
        kind = str(data.pop("kind", "stopped"))
        subclass = _KINDS.get(kind, RobotError)
        error = subclass.__new__(subclass)
        RobotError.__init__(error, kind, data, message)
        return error


class Infeasible(RobotError):
    """``infeasible``: the call cannot be done now (a handle out of reach, something in the way)."""

    def __init__(self, call: Optional[str], target: str, reason: str):
        super().__init__("infeasible", {"call": call, "target": str(target), "reason": reason})

    def _render(self) -> str:
        f = self.fields
        return "{}({}) is infeasible: {}".format(f.get("call"), f.get("target"), f.get("reason"))


class OutOfWorkspace(RobotError):
    """``out_of_workspace``: the target ``[x, y, z]`` lies outside what the robot can reach."""

    def __init__(self, target: Iterable[float]):
        super().__init__("out_of_workspace", {"target": [float(v) for v in target]})

    def _render(self) -> str:
        return "target {} is outside the reachable workspace".format(_point(self.fields["target"]))


class IkFailed(RobotError):
    """``ik_failed``: no joint configuration reaches ``target`` pointing ``pointing_to``."""

    def __init__(self, target: Iterable[float], pointing_to: str):
        super().__init__("ik_failed", {"target": [float(v) for v in target], "pointing_to": pointing_to})

    def _render(self) -> str:
        # nesy's own message names the direction capitalised ("pointing Down").
        direction = str(self.fields.get("pointing_to", "")).capitalize()
        return "no inverse-kinematics solution reaches {} pointing {}".format(
            _point(self.fields["target"]), direction
        )


class NoEmptySpace(RobotError):
    """``no_empty_space``: ``get_empty_floor_xy`` found no free spot for the object."""

    def __init__(self, obj_name: str):
        super().__init__("no_empty_space", {"obj_name": obj_name})

    def _render(self) -> str:
        return "no empty floor position for {}".format(self.fields.get("obj_name"))


class UnknownObject(RobotError):
    """``unknown_object``: no object of that name; ``known`` lists the names the robot knows
    (a list, or an already comma-separated string)."""

    def __init__(self, name: str, known: Union[str, Iterable[str]]):
        if not isinstance(known, str):
            known = ", ".join(str(k) for k in known)
        super().__init__("unknown_object", {"name": name, "known": known})

    def _render(self) -> str:
        return "unknown object {}; known objects: {}".format(
            json.dumps(self.fields.get("name")), self.fields.get("known")
        )


class WrongEmbodiment(RobotError):
    """``wrong_embodiment``: a finger-gripper call on a suction robot or the reverse."""

    def __init__(self, call: Optional[str], embodiment: str, use_instead: str):
        super().__init__(
            "wrong_embodiment", {"call": call, "embodiment": embodiment, "use_instead": use_instead}
        )

    def _render(self) -> str:
        f = self.fields
        return "{}() is not available on the {} robot; use {}() instead".format(
            f.get("call"), f.get("embodiment"), f.get("use_instead")
        )


class InvalidArgument(RobotError):
    """``invalid_argument``: an argument is out of range for this robot."""

    def __init__(self, call: Optional[str], message: str):
        super().__init__("invalid_argument", {"call": call, "message": message})

    def _render(self) -> str:
        return "invalid argument to {}(): {}".format(self.fields.get("call"), self.fields.get("message"))


class Collision(RobotError):
    """``collision``: the motion was stopped by contact; the robot stays where it stopped."""

    def __init__(self, call: Optional[str], moving: str, obstacle: str):
        super().__init__("collision", {"call": call, "moving": moving, "obstacle": obstacle})

    def _render(self) -> str:
        f = self.fields
        return "{}() was stopped by contact: {} ran into {}".format(
            f.get("call"), f.get("moving"), f.get("obstacle")
        )


class Stopped(RobotError):
    """``stopped``: the robot stopped the motion on its own account (protective or emergency
    stop, an operator, its controller)."""

    def __init__(self, call: Optional[str], reason: str):
        super().__init__("stopped", {"call": call, "reason": reason})

    def _render(self) -> str:
        return "{}() was stopped by the robot: {}".format(self.fields.get("call"), self.fields.get("reason"))


class TimedOut(RobotError):
    """``timed_out``: the motion did not complete within the robot's own time limit."""

    def __init__(self, call: Optional[str], seconds: float):
        super().__init__("timed_out", {"call": call, "seconds": float(seconds)})

    def _render(self) -> str:
        return "{}() did not complete on the robot within {:.1f} s".format(
            self.fields.get("call"), float(self.fields.get("seconds", 0.0))
        )


_KINDS = {
    "infeasible": Infeasible,
    "out_of_workspace": OutOfWorkspace,
    "ik_failed": IkFailed,
    "no_empty_space": NoEmptySpace,
    "unknown_object": UnknownObject,
    "wrong_embodiment": WrongEmbodiment,
    "invalid_argument": InvalidArgument,
    "collision": Collision,
    "stopped": Stopped,
    "timed_out": TimedOut,
}


class RpcError(Exception):
    """An error answer that is not a robot error (``-32601``, ``-32602``, ``-32001``, ...), as a
    ``RobotClient`` receives it."""

    def __init__(self, code: int, message: str, data: Any = None):
        self.code = code
        self.message = message
        self.data = data
        super().__init__("error {}: {}".format(code, message))


class ProtocolError(Exception):
    """An answer that does not follow the protocol (a ``RobotClient`` fault)."""


# --------------------------------------------------------------------------------------
# Addresses
# --------------------------------------------------------------------------------------


def parse_address(address: str) -> Tuple[str, Any]:
    """Reads a robot address: ``HOST:PORT`` or ``tcp://HOST:PORT`` gives ``("tcp", (host, port))``,
    ``unix:PATH`` (or ``unix://PATH``) gives ``("unix", path)``. Raises ``ValueError`` otherwise."""
    text = str(address)
    if text.startswith("unix:"):
        path = text[len("unix:"):]
        if path.startswith("//"):
            path = path[2:]
        if not path:
            raise ValueError("robot address {!r}: expected a socket path after `unix:`".format(text))
        return "unix", path
    hostport = text[len("tcp://"):] if text.startswith("tcp://") else text
    host, sep, port = hostport.rpartition(":")
    if not sep:
        raise ValueError("robot address {!r}: expected HOST:PORT, tcp://HOST:PORT or unix:PATH".format(text))
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    if not host or not port.isdigit() or int(port) > 65535:
        raise ValueError("robot address {!r}: expected HOST:PORT with a port number from 0 to 65535".format(text))
    return "tcp", (host, int(port))


def format_address(kind: str, where: Any) -> str:
    """The address as nesy prints it: ``tcp://HOST:PORT`` or ``unix:PATH``."""
    if kind == "unix":
        return "unix:{}".format(where)
    host, port = where[0], where[1]
    if ":" in host:
        host = "[{}]".format(host)
    return "tcp://{}:{}".format(host, port)


def _connect(address: str, timeout: float) -> socket.socket:
    kind, where = parse_address(address)
    if kind == "unix":
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(timeout)
        try:
            sock.connect(where)
        except OSError:
            sock.close()
            raise
    else:
        sock = socket.create_connection(where, timeout=timeout)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    sock.settimeout(None)
    return sock


def _shutdown(sock: socket.socket) -> None:
    try:
        sock.shutdown(socket.SHUT_RDWR)
    except OSError:
        pass


# --------------------------------------------------------------------------------------
# Parameter and result shapes
# --------------------------------------------------------------------------------------


class _BadParams(Exception):
    pass


class _BadResult(Exception):
    pass


def _short(value: Any, limit: int = 200) -> str:
    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= limit else text[:limit] + "\u2026"


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _param(kind: str, name: str, value: Any) -> Any:
    if kind == "name":
        if not isinstance(value, str):
            raise _BadParams("`{}` must be a string, not {}".format(name, _short(value)))
        return value
    if kind == "direction":
        if value not in DIRECTIONS:
            raise _BadParams(
                "`{}` must be one of {}, not {}".format(name, ", ".join(DIRECTIONS), _short(value))
            )
        return value
    if kind == "number":
        if not _is_number(value):
            raise _BadParams("`{}` must be a finite number, not {}".format(name, _short(value)))
        return float(value)
    if kind == "vec3":
        if not (isinstance(value, list) and len(value) == 3 and all(_is_number(v) for v in value)):
            raise _BadParams("`{}` must be [x, y, z] (three finite numbers), not {}".format(name, _short(value)))
        return [float(v) for v in value]
    raise AssertionError(kind)


def _api_kwargs(method: str, params: Any) -> Dict[str, Any]:
    """The keyword arguments of an API call, checked against the method's parameter table.
    Parameters the table does not name are passed through (binding then refuses them)."""
    if params is None:
        params = {}
    if not isinstance(params, dict):
        raise _BadParams("params must be an object of named parameters")
    spec = API_METHODS[method][0]
    kwargs = {}
    for name, kind in spec:
        if name not in params:
            raise _BadParams("missing parameter `{}`".format(name))
        kwargs[name] = _param(kind, name, params[name])
    for name, value in params.items():
        if name not in kwargs:
            kwargs[name] = value
    return kwargs


def _plain(value: Any) -> Any:
    """Tuples become lists, numpy-style arrays and scalars their Python values."""
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
        value = value.tolist()
    if isinstance(value, tuple):
        value = list(value)
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def _numbers(value: Any, n: int) -> Optional[List[float]]:
    if isinstance(value, list) and len(value) == n and all(_is_number(v) for v in value):
        return [float(v) for v in value]
    return None


def _result(shape: Optional[str], value: Any, method: str) -> Any:
    """The JSON result of a method's return value, in the shape the protocol gives it."""
    if shape is None:
        return None
    value = _plain(value)
    expected = {
        "bool": "true or false",
        "names": "a list of names",
        "vec3": "[x, y, z]",
        "xy": "[x, y]",
        "bbox": "[[xmin, ymin, zmin], [xmax, ymax, zmax]]",
    }[shape]
    converted: Any = None
    if shape == "bool":
        converted = value if isinstance(value, bool) else None
    elif shape == "names":
        if isinstance(value, list) and all(isinstance(v, str) for v in value):
            converted = value
    elif shape == "vec3":
        converted = _numbers(value, 3)
    elif shape == "xy":
        converted = _numbers(value, 2)
    elif shape == "bbox":
        if isinstance(value, list) and len(value) == 2:
            lo, hi = _numbers(value[0], 3), _numbers(value[1], 3)
            converted = [lo, hi] if lo is not None and hi is not None else None
    if converted is None:
        raise _BadResult("{} returned {}, which is not {}".format(method, _short(value), expected))
    return converted


# --------------------------------------------------------------------------------------
# The server
# --------------------------------------------------------------------------------------


class RobotServer:
    """The server side of the robot protocol, for one robot. Subclass it.

    Implement the robot API as methods with the API's names and parameter names (the table in
    ``docs/robot-protocol.md``); each is called with keyword arguments, one call at a time, in
    the order nesy sends them, on the session's executor thread::

        class MyArm(RobotServer):
            def get_obj_names(self):                      # -> ["red_cube", ...]
            def get_obj_pos(self, obj_name):              # -> [x, y, z]
            def move_to_position(self, pos, pointing_to, lift_clearance, angle):  # -> None
            def close_gripper(self):                      # -> None
            def stop(self, reason):                       # halt the arm now
            ...

    Perception methods return plain values (tuples and numpy arrays are converted to lists);
    actions return when the motion has ended. Raise a ``RobotError`` subclass (``Infeasible``,
    ``Collision``, ``Stopped``, ...) when the robot refuses or fails a call; any other exception
    is logged and answered as a ``stopped`` robot error carrying the exception's text. An API
    method you do not implement answers ``-32601``; parameters that do not fit the method (a
    missing one, a wrong type, one your method does not accept) answer ``-32602``.

    Besides the 20 API methods you may override:

    ``get_tool_pos()``
        The tool tip's ``[x, y, z]``, or ``None`` (the default) if the robot cannot tell; with
        ``None`` nesy refuses relative moves (``move_parallel``).
    ``finish()``
        The end-of-run report: ``None`` (the default) or ``{"subtasks": ..., "final_state": ...}``.
    ``stop(reason)``
        Halt the robot. **This is where a real adapter stops the arm.** It is called exactly
        once per session when the session ends: on ``stop`` from nesy, when the heartbeat
        watchdog fires (no message for ``heartbeat_timeout`` seconds), when the connection
        closes or fails, and on ``shutdown()``. It runs on the reader or watchdog thread, so it
        can be called *while a motion is running* on the executor thread: make it safe for
        that (halt the controller; let the running call return or raise ``Stopped``).
    ``begin_session(hello)``
        Called once per session on ``hello`` (with its params), before the answer is built:
        connect to the robot, reset state, set ``self.embodiment``. ``self.speed_scale`` is set
        by then; every motion must keep to it.
    ``on_answer(method, params, result=None, error=None, check=False)``
        Called after each robot call (API calls, ``get_tool_pos`` and ``finish``), just before
        its answer is sent: ``result`` is the JSON result, ``error`` the JSON-RPC error object;
        ``check`` is true for a query nesy made for its own workspace check (request id
        ``check-N``, e.g. a ``get_obj_pos`` before ``move_gripper_to``) rather than for the
        policy. A place to log.

    Args:
        embodiment: ``"finger"`` (parallel gripper) or ``"vacuum"`` (suction tool), reported in
            ``hello``'s answer.
        name: the robot's name in ``hello``'s answer.
        heartbeat_timeout: seconds of silence from the client after which the robot is stopped
            and the session closed (announced in ``hello``'s answer).
    """

    def __init__(self, embodiment: str = "finger", name: str = "python robot", heartbeat_timeout: float = 1.5):
        if embodiment not in _EMBODIMENTS:
            raise ValueError("embodiment must be 'finger' or 'vacuum', not {!r}".format(embodiment))
        if not (heartbeat_timeout > 0):
            raise ValueError("heartbeat_timeout must be positive")
        self.embodiment = embodiment
        self.name = name
        self.heartbeat_timeout = float(heartbeat_timeout)
        #: The speed scale of the current session's ``hello`` (in (0, 1]); ``None`` before.
        self.speed_scale: Optional[float] = None
        #: The bound address (``tcp://HOST:PORT`` or ``unix:PATH``) once ``serve`` listens.
        self.address: Optional[str] = None
        self._closing = threading.Event()
        self._session: Optional[_Session] = None
        self._session_lock = threading.Lock()

    # -- hooks for subclasses ---------------------------------------------------------

    def get_tool_pos(self) -> Optional[Iterable[float]]:
        """The tool tip's position ``[x, y, z]``, or ``None`` if the robot cannot tell."""
        return None

    def finish(self) -> Optional[Dict[str, Any]]:
        """The end-of-run report: ``None``, or ``{"subtasks": [...] or None, "final_state":
        [...] or None}`` for a robot with goal checks."""
        return None

    def stop(self, reason: str) -> None:
        """Halts the robot. Called once per session when it ends (see the class docstring),
        possibly while a motion is still running on another thread. The default does nothing."""

    def begin_session(self, hello: Dict[str, Any]) -> None:
        """Called on a session's ``hello`` with its params, before the answer is built."""

    def on_answer(
        self,
        method: str,
        params: Dict[str, Any],
        result: Any = None,
        error: Optional[Dict[str, Any]] = None,
        check: bool = False,
    ) -> None:
        """Called after each robot call with its JSON result or error object, before the answer
        is sent; ``check`` marks nesy's own workspace-check queries. The default does nothing."""

    # -- serving -----------------------------------------------------------------------

    def serve(
        self,
        address: str = "127.0.0.1:0",
        *,
        once: bool = False,
        ready: Optional[Callable[[str], None]] = None,
        announce: bool = True,
    ) -> None:
        """Listens at ``address`` and serves one session at a time until ``shutdown()`` (or, with
        ``once``, until the first session ends).

        Args:
            address: ``HOST:PORT`` or ``tcp://HOST:PORT`` (port 0 takes a free one) or
                ``unix:PATH`` (the path must not exist; it is removed when serving ends).
            once: serve one session, then return.
            ready: called with the bound address (``tcp://127.0.0.1:40123``) once listening.
            announce: print ``listening on ADDRESS`` to standard output (flushed) once listening.
        """
        kind, where = parse_address(address)
        self._closing.clear()
        listener = self._listen(kind, where)
        try:
            bound = format_address(kind, listener.getsockname() if kind == "tcp" else where)
            self.address = bound
            if announce:
                print("listening on {}".format(bound), flush=True)
            log.info("listening on %s", bound)
            if ready is not None:
                ready(bound)
            listener.settimeout(0.2)
            while not self._closing.is_set():
                try:
                    conn, _ = listener.accept()
                except socket.timeout:
                    continue
                except OSError:
                    if self._closing.is_set():
                        break
                    raise
                conn.settimeout(None)
                if kind == "tcp":
                    conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                session = _Session(self, conn)
                with self._session_lock:
                    self._session = session
                try:
                    session.run()
                finally:
                    with self._session_lock:
                        self._session = None
                if once:
                    break
        finally:
            listener.close()
            if kind == "unix":
                try:
                    os.unlink(where)
                except OSError:
                    pass

    def serve_in_background(self, address: str = "127.0.0.1:0", *, once: bool = False, timeout: float = 10.0) -> str:
        """Starts ``serve`` on a daemon thread and returns the bound address once it listens.
        Stop it with ``shutdown()``. Raises what binding raised if it failed."""
        bound: List[str] = []
        failed: List[BaseException] = []
        listening = threading.Event()

        def run() -> None:
            try:
                self.serve(address, once=once, ready=lambda a: (bound.append(a), listening.set()), announce=False)
            except BaseException as error:  # reported to the caller if it happens while binding
                failed.append(error)
                listening.set()
                if bound:
                    log.exception("the robot server failed")

        self._thread = threading.Thread(target=run, name="nesy-robot-server", daemon=True)
        self._thread.start()
        if not listening.wait(timeout):
            raise TimeoutError("the robot server did not start listening within {} s".format(timeout))
        if not bound:
            raise failed[0]
        return bound[0]

    def shutdown(self, reason: str = "the robot server shut down") -> None:
        """Stops serving: ends the current session (the robot is stopped with ``reason``) and
        makes ``serve`` return. Safe to call from any thread."""
        self._closing.set()
        with self._session_lock:
            session = self._session
        if session is not None:
            session.end(reason)
        thread = getattr(self, "_thread", None)
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=10)

    def _listen(self, kind: str, where: Any) -> socket.socket:
        if kind == "unix":
            if os.path.exists(where):
                # A socket file left by a server that is gone (nothing answers on it) is
                # replaced; one a live server holds, or any other file, is not.
                probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
                try:
                    probe.connect(where)
                    live = True
                except OSError:
                    live = False
                finally:
                    probe.close()
                if live or not stat.S_ISSOCK(os.stat(where).st_mode):
                    raise FileExistsError("{} is in use; stop the server holding it or choose another socket path".format(where))
                os.remove(where)
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.bind(where)
                sock.listen(1)
            except OSError:
                sock.close()
                raise
            return sock
        host, port = where
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
        family = infos[0][0] if infos else socket.AF_INET
        return socket.create_server((host, port), family=family, backlog=1)


class _Session:
    """One connection: the reader (this thread), the executor and the watchdog."""

    def __init__(self, server: RobotServer, conn: socket.socket):
        self.server = server
        self.conn = conn
        self.rfile = conn.makefile("rb")
        self.write_lock = threading.Lock()
        self.jobs: "queue.Queue[Optional[Tuple[Any, str, Dict[str, Any], Optional[str]]]]" = queue.Queue()
        self.greeted = False
        self.stopped = threading.Event()
        self.over = threading.Event()
        self.last_heard = time.monotonic()
        self.halt_lock = threading.Lock()
        self.halted: Optional[str] = None

    # -- lifetime ----------------------------------------------------------------------

    def run(self) -> None:
        log.info("client connected")
        executor = threading.Thread(target=self._execute, name="nesy-robot-executor", daemon=True)
        watchdog = threading.Thread(target=self._watch, name="nesy-robot-watchdog", daemon=True)
        executor.start()
        watchdog.start()
        reason = None
        try:
            reason = self._read()
        finally:
            self.halt(reason or "the connection closed")
            self.over.set()
            self.jobs.put(None)
            _shutdown(self.conn)
            # The executor finishes the call in hand, if any; queued calls are dropped.
            executor.join()
            watchdog.join()
            try:
                self.rfile.close()
            finally:
                self.conn.close()
            log.info("session ended: %s", self.halted)

    def halt(self, reason: str) -> None:
        """Stops the robot once: no further calls run, and the server's ``stop`` is called."""
        with self.halt_lock:
            if self.halted is not None:
                return
            self.halted = reason
        self.stopped.set()
        log.info("stopping the robot: %s", reason)
        try:
            self.server.stop(reason)
        except Exception:
            log.exception("stop(%r) raised", reason)

    def end(self, reason: str) -> None:
        """Ends the session from another thread."""
        self.halt(reason)
        _shutdown(self.conn)

    def _watch(self) -> None:
        timeout = self.server.heartbeat_timeout
        while not self.over.wait(0.02):
            silent = time.monotonic() - self.last_heard
            if silent >= timeout:
                self.halt("watchdog: no message from the client for {:.2f} s".format(silent))
                _shutdown(self.conn)
                return

    # -- reading -----------------------------------------------------------------------

    def _read(self) -> Optional[str]:
        """Reads requests until the session ends; returns why, or None if the connection closed."""
        while True:
            try:
                line = self.rfile.readline(MAX_MESSAGE_BYTES + 1)
            except (OSError, ValueError) as error:
                return "the connection failed: {}".format(error)
            if not line:
                return None
            if len(line) > MAX_MESSAGE_BYTES:
                self._reply(None, error=_error(INVALID_REQUEST, "message too long"))
                return "the client sent a message longer than {} bytes".format(MAX_MESSAGE_BYTES)
            self.last_heard = time.monotonic()
            if not line.strip():
                continue
            ended = self._handle(line)
            if ended is not None:
                return ended

    def _handle(self, line: bytes) -> Optional[str]:
        try:
            message = json.loads(line.decode("utf-8"))
        except (UnicodeDecodeError, ValueError) as error:
            self._reply(None, error=_error(PARSE_ERROR, "not JSON: {}".format(error)))
            return None
        if not isinstance(message, dict):
            self._reply(None, error=_error(INVALID_REQUEST, "expected a JSON-RPC request object"))
            return None
        rid = message.get("id")
        if message.get("jsonrpc") != "2.0":
            self._reply(rid, error=_error(INVALID_REQUEST, 'expected "jsonrpc": "2.0"'))
            return None
        if not ((isinstance(rid, int) and not isinstance(rid, bool) and rid >= 0) or isinstance(rid, str)):
            self._reply(rid, error=_error(INVALID_REQUEST, 'expected an "id" (a number or a string)'))
            return None
        method = message.get("method")
        if not isinstance(method, str):
            self._reply(rid, error=_error(INVALID_REQUEST, 'expected a "method" string'))
            return None
        params = message.get("params")
        if method != "heartbeat":
            log.debug("request %s %s %s", rid, method, _short(params))
        return self._dispatch(rid, method, params)

    def _dispatch(self, rid: Any, method: str, params: Any) -> Optional[str]:
        if method == "heartbeat":
            self._reply(rid, result={})
            return None
        if method == "hello":
            return self._hello(rid, params)
        if method == "stop":
            reason = params.get("reason") if isinstance(params, dict) else None
            self.halt("the client sent stop: {}".format(reason) if reason else "the client sent stop")
            self._reply(rid, result={})
            return self.halted or "the client sent stop"
        if not self.greeted:
            self._reply(rid, error=_error(NO_SESSION, "say hello first"))
            return None
        if self.stopped.is_set():
            self._reply(rid, error=_error(SESSION_STOPPED, "the robot was stopped"))
            return None
        if method in ("get_tool_pos", "finish"):
            self.jobs.put((rid, method, {}, None))
            return None
        if method not in API_METHODS:
            self._reply(rid, error=_error(METHOD_NOT_FOUND, "no method {}".format(json.dumps(method))))
            return None
        function = getattr(self.server, method, None)
        if not callable(function):
            self._reply(rid, error=_error(METHOD_NOT_FOUND, "this robot does not implement {}".format(method)))
            return None
        try:
            kwargs = _api_kwargs(method, params)
            inspect.signature(function).bind(**kwargs)
        except (_BadParams, TypeError) as error:
            self._reply(rid, error=_error(INVALID_PARAMS, "{}: {}".format(method, error)))
            return None
        self.jobs.put((rid, method, kwargs, API_METHODS[method][1]))
        return None

    def _hello(self, rid: Any, params: Any) -> Optional[str]:
        if params is None:
            params = {}
        if not isinstance(params, dict):
            self._reply(rid, error=_error(INVALID_PARAMS, "hello: params must be an object"))
            return None
        protocol = params.get("protocol")
        if protocol != PROTOCOL_VERSION:
            self._reply(
                rid,
                error=_error(INVALID_PARAMS, "this server speaks {}, not {}".format(PROTOCOL_VERSION, _short(protocol))),
            )
            return None
        speed = params.get("speed_scale")
        if not (_is_number(speed) and 0.0 < speed <= 1.0):
            self._reply(rid, error=_error(INVALID_PARAMS, "speed_scale must be in (0, 1], not {}".format(_short(speed))))
            return None
        self.server.speed_scale = float(speed)
        if not self.greeted:
            try:
                self.server.begin_session(dict(params))
            except Exception as error:
                log.exception("begin_session failed")
                self._reply(rid, error=_error(SESSION_STOPPED, "the robot is not available: {}".format(error)))
                return "the robot could not start the session: {}".format(error)
            self.greeted = True
        self._reply(
            rid,
            result={
                "protocol": PROTOCOL_VERSION,
                "robot": self.server.name,
                "embodiment": self.server.embodiment,
                "heartbeat_timeout_s": self.server.heartbeat_timeout,
                "speed_scale": float(speed),
            },
        )
        return None

    # -- executing ---------------------------------------------------------------------

    def _execute(self) -> None:
        while True:
            job = self.jobs.get()
            if job is None:
                return
            if self.stopped.is_set():
                continue
            rid, method, kwargs, shape = job
            result: Any = None
            error: Optional[Dict[str, Any]] = None
            try:
                value = getattr(self.server, method)(**kwargs)
                if method == "get_tool_pos":
                    result = None if value is None else _result("vec3", value, method)
                elif method == "finish":
                    result = self._finish_report(value)
                else:
                    result = _result(shape, value, method)
                try:
                    json.dumps(result, allow_nan=False)
                except (TypeError, ValueError) as failure:
                    raise _BadResult("{} returned a value that is not JSON: {}".format(method, failure))
            except RobotError as failure:
                failure._fill_call(method)
                error = _error(ROBOT_ERROR, failure.message, failure.data())
            except _BadResult as failure:
                log.error("%s", failure)
                stopped = Stopped(method, "the robot adapter answered wrongly: {}".format(failure))
                error = _error(ROBOT_ERROR, stopped.message, stopped.data())
            except Exception as failure:
                log.exception("%s raised", method)
                stopped = Stopped(method, str(failure) or type(failure).__name__)
                error = _error(ROBOT_ERROR, stopped.message, stopped.data())
            try:
                check = isinstance(rid, str) and rid.startswith("check-")
                self.server.on_answer(method, kwargs, result=result, error=error, check=check)
            except Exception:
                log.exception("on_answer raised")
            if error is not None:
                self._reply(rid, error=error)
            else:
                self._reply(rid, result=result)

    @staticmethod
    def _finish_report(value: Any) -> Dict[str, Any]:
        if value is None:
            return {"subtasks": None, "final_state": None}
        if not isinstance(value, dict):
            raise _BadResult("finish returned {}, which is not null or an object".format(_short(value)))
        report = {"subtasks": None, "final_state": None}
        report.update(value)
        return report

    # -- writing -----------------------------------------------------------------------

    def _reply(self, rid: Any, *, result: Any = None, error: Optional[Dict[str, Any]] = None) -> None:
        message: Dict[str, Any] = {"jsonrpc": "2.0", "id": rid}
        if error is not None:
            message["error"] = error
        else:
            message["result"] = result
        try:
            text = json.dumps(message, allow_nan=False, separators=(",", ":"))
        except (TypeError, ValueError) as failure:
            log.error("the answer to %s could not be encoded: %s", rid, failure)
            stopped = Stopped("answer", "the answer could not be encoded as JSON: {}".format(failure))
            text = json.dumps(
                {"jsonrpc": "2.0", "id": rid, "error": _error(ROBOT_ERROR, stopped.message, stopped.data())}
            )
        data = (text + "\n").encode("utf-8")
        with self.write_lock:
            try:
                self.conn.sendall(data)
            except OSError:
                pass


def _error(code: int, message: str, data: Any = None) -> Dict[str, Any]:
    error: Dict[str, Any] = {"code": code, "message": message}
    if data is not None:
        error["data"] = data
    return error


# --------------------------------------------------------------------------------------
# The client
# --------------------------------------------------------------------------------------


class RobotClient:
    """A client of the robot protocol: connect, ``hello()``, ``call(...)``, ``close()``.

    ::

        with RobotClient("tcp://127.0.0.1:40123") as robot:
            robot.hello(speed_scale=0.5)
            names = robot.call("get_obj_names")
            robot.call("move_gripper_to", obj_name="red_cube", pointing_to="down", depth=0.015)

    ``call`` returns the result (JSON values: lists, floats, booleans, ``None``), raises the
    ``RobotError`` subclass of a robot error (``Infeasible``, ...), ``RpcError`` for any other
    error answer, ``TimeoutError`` when no answer comes within ``timeout`` seconds and
    ``ConnectionError`` when the connection is closed. After ``hello`` a heartbeat thread sends
    ``heartbeat`` every ``heartbeat_period`` seconds until ``close()`` or ``stop_heartbeat()``.

    Args:
        address: ``HOST:PORT``, ``tcp://HOST:PORT`` or ``unix:PATH``.
        timeout: the longest wait for one answer, in seconds.
        connect_timeout: the longest wait to connect, in seconds.
        heartbeat_period: seconds between heartbeats (``None`` or 0: no heartbeat thread).
    """

    def __init__(
        self,
        address: str,
        *,
        timeout: float = 60.0,
        connect_timeout: float = 5.0,
        heartbeat_period: Optional[float] = 0.5,
    ):
        self.address = str(address)
        self.timeout = float(timeout)
        self.heartbeat_period = heartbeat_period
        #: ``hello``'s answer, once said.
        self.welcome: Optional[Dict[str, Any]] = None
        self._sock = _connect(self.address, connect_timeout)
        self._write_lock = threading.Lock()
        self._lock = threading.Lock()
        self._ids = itertools.count(1)
        self._pending: Dict[int, List[Any]] = {}
        self._closed: Optional[str] = None
        self._beat_stop = threading.Event()
        self._beat: Optional[threading.Thread] = None
        self._reader = threading.Thread(target=self._read, name="nesy-robot-client-reader", daemon=True)
        self._reader.start()

    def __enter__(self) -> "RobotClient":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def hello(self, speed_scale: float = 0.5, *, client: Optional[str] = None) -> Dict[str, Any]:
        """Says ``hello`` and starts the heartbeat; returns the server's answer (``protocol``,
        ``robot``, ``embodiment``, ``heartbeat_timeout_s``, ``speed_scale``). Raises
        ``RpcError`` if the server refuses and ``ProtocolError`` if it speaks another protocol
        or does not echo the speed scale."""
        if client is None:
            from . import __version__

            client = "nesy-python {}".format(__version__)
        params = {
            "protocol": PROTOCOL_VERSION,
            "client": client,
            "heartbeat_period_s": float(self.heartbeat_period or 0.0),
            "speed_scale": float(speed_scale),
        }
        welcome = self._result(self.request("hello", params, timeout=max(5.0, min(self.timeout, 30.0))))
        if not isinstance(welcome, dict) or welcome.get("protocol") != PROTOCOL_VERSION:
            raise ProtocolError("the server does not speak {}: {}".format(PROTOCOL_VERSION, _short(welcome)))
        echoed = welcome.get("speed_scale")
        if not _is_number(echoed) or abs(echoed - speed_scale) > 1e-9:
            raise ProtocolError(
                "the robot answered speed scale {} to the {} asked for".format(_short(echoed), speed_scale)
            )
        self.welcome = welcome
        if self.heartbeat_period and self._beat is None:
            self._beat = threading.Thread(target=self._heartbeat, name="nesy-robot-client-heartbeat", daemon=True)
            self._beat.start()
        return welcome

    def call(self, method: str, **params: Any) -> Any:
        """Sends one call and returns its result, or raises its error (see the class docstring)."""
        return self._result(self.request(method, params))

    def request(self, method: str, params: Optional[Dict[str, Any]] = None, *, timeout: Optional[float] = None) -> Dict[str, Any]:
        """Sends one request and returns the raw response object (with ``result`` or ``error``)."""
        with self._lock:
            if self._closed is not None:
                raise ConnectionError("{}: the connection to {} is closed: {}".format(method, self.address, self._closed))
            rid = next(self._ids)
            slot: List[Any] = [threading.Event(), None]
            self._pending[rid] = slot
        try:
            self._send({"jsonrpc": "2.0", "id": rid, "method": method, "params": params if params is not None else {}})
            if not slot[0].wait(self.timeout if timeout is None else timeout):
                raise TimeoutError(
                    "{}: no answer from {} within {:.1f} s".format(
                        method, self.address, self.timeout if timeout is None else timeout
                    )
                )
        finally:
            with self._lock:
                self._pending.pop(rid, None)
        response = slot[1]
        if response is None:
            raise ConnectionError("{}: the connection to {} closed: {}".format(method, self.address, self._closed))
        return response

    def stop_heartbeat(self) -> None:
        """Stops sending heartbeats (the server's watchdog will then stop the robot)."""
        self._beat_stop.set()
        if self._beat is not None and self._beat is not threading.current_thread():
            self._beat.join()

    def close(self, reason: str = "the client closed the session", *, send_stop: bool = True) -> None:
        """Ends the session: sends ``stop`` with ``reason`` (unless ``send_stop`` is false or the
        connection is already closed), stops the heartbeat and closes the connection."""
        if send_stop and self._closed is None:
            try:
                self.request("stop", {"reason": reason}, timeout=2.0)
            except (ConnectionError, TimeoutError, OSError):
                pass
        self.stop_heartbeat()
        _shutdown(self._sock)
        if self._reader is not threading.current_thread():
            self._reader.join(timeout=5)
        self._sock.close()

    @property
    def closed(self) -> Optional[str]:
        """Why the connection closed, or ``None`` while it is open."""
        return self._closed

    # -- internals ---------------------------------------------------------------------

    @staticmethod
    def _result(response: Dict[str, Any]) -> Any:
        if "error" in response:
            error = response["error"]
            if not isinstance(error, dict):
                raise ProtocolError("an error answer without an error object: {}".format(_short(response)))
            code = error.get("code")
            message = str(error.get("message", ""))
            data = error.get("data")
            if code == ROBOT_ERROR and isinstance(data, dict) and "kind" in data:
                raise RobotError.from_data(data, message)
            raise RpcError(code if isinstance(code, int) else 0, message, data)
        if "result" not in response:
            raise ProtocolError("an answer with neither result nor error: {}".format(_short(response)))
        return response["result"]

    def _send(self, message: Dict[str, Any]) -> None:
        data = (json.dumps(message, separators=(",", ":")) + "\n").encode("utf-8")
        with self._write_lock:
            try:
                self._sock.sendall(data)
            except OSError as error:
                raise ConnectionError("sending to {}: {}".format(self.address, error)) from error

    def _heartbeat(self) -> None:
        period = float(self.heartbeat_period or 0.5)
        while not self._beat_stop.is_set() and self._closed is None:
            with self._lock:
                rid = next(self._ids)
            try:
                # Its answer matches no waiting request and is dropped by the reader.
                self._send({"jsonrpc": "2.0", "id": rid, "method": "heartbeat", "params": {}})
            except ConnectionError:
                return
            self._beat_stop.wait(period)

    def _read(self) -> None:
        reason = "the server closed the connection"
        try:
            with self._sock.makefile("rb") as stream:
                while True:
                    line = stream.readline(MAX_MESSAGE_BYTES + 1)
                    if not line:
                        break
                    if len(line) > MAX_MESSAGE_BYTES:
                        reason = "an answer longer than {} bytes".format(MAX_MESSAGE_BYTES)
                        break
                    if not line.strip():
                        continue
                    try:
                        response = json.loads(line.decode("utf-8"))
                    except (UnicodeDecodeError, ValueError):
                        log.warning("unreadable answer from %s: %r", self.address, line[:200])
                        continue
                    rid = response.get("id") if isinstance(response, dict) else None
                    with self._lock:
                        slot = self._pending.get(rid) if isinstance(rid, int) else None
                    if slot is not None:
                        slot[1] = response
                        slot[0].set()
        except (OSError, ValueError) as error:
            reason = "the connection failed: {}".format(error)
        with self._lock:
            self._closed = reason
            waiting = list(self._pending.values())
        for slot in waiting:
            slot[0].set()
