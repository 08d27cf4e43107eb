"""nesy from Python: a thin wrapper over the ``nesy`` executable, and the robot protocol.

The wheel installs the ``nesy`` binary next to the Python interpreter's scripts; the functions
here run it and hand back what it writes, as plain dicts:

- ``adapt(demo, target, ...)``: demonstration to verified policy (``nesy adapt``), optionally
  executed in simulation and on a robot.
- ``run(policy, ...)``: one policy in the sandbox on a scene (``nesy run``), or on a robot.
- ``verify(domain, problem, plan)``: a PDDL plan checked against its domain and problem.
- ``bench.run(run_dir, ...)`` and ``bench.records(run_dir)``: benchmark runs and their records.
- ``version()`` and ``binary()``.

``nesy.robot`` holds ``RobotServer``, the base class for connecting your own robot (see its
docstring and ``docs/robot-protocol.md``), and ``RobotClient``.

Only the standard library is used.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sysconfig
import tempfile
import time
from pathlib import Path
from typing import Any, Dict, Iterable, List, Optional, Sequence, Union

__version__ = "0.1.0"

__all__ = [
    "NesyError",
    "binary",
    "version",
    "adapt",
    "run",
    "verify",
    "bench",
    "robot",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]


class NesyError(RuntimeError):
    """The ``nesy`` command could not do what was asked (bad input, a missing file, a robot
    that could not be reached: exit code 2), or the executable could not be found or gave no
    result.

    Attributes:
        command: the command line that ran (a list), or ``None``.
        exit_code: its exit code, or ``None``.
        stdout: what it printed on standard output.
        stderr: what it printed on standard error (the ``error: ...`` line is here).
    """

    def __init__(
        self,
        message: str,
        *,
        command: Optional[List[str]] = None,
        exit_code: Optional[int] = None,
        stdout: str = "",
        stderr: str = "",
    ):
        self.command = command
        self.exit_code = exit_code
        self.stdout = stdout
        self.stderr = stderr
        detail = stderr.strip()
        super().__init__("{}{}".format(message, "\n" + detail if detail else ""))


def binary() -> str:
    """The path of the ``nesy`` executable.

    In this order: ``$NESY_BINARY`` if set; the ``nesy`` installed beside this Python's scripts
    (``sysconfig.get_path("scripts")``, where the wheel puts it; then the user scheme's scripts
    directory); the first ``nesy`` on ``PATH``. Raises ``NesyError`` if there is none.
    """
    exe = "nesy.exe" if os.name == "nt" else "nesy"
    configured = os.environ.get("NESY_BINARY")
    if configured:
        if os.path.isfile(configured) and os.access(configured, os.X_OK):
            return configured
        raise NesyError("NESY_BINARY={} is not an executable file".format(configured))
    directories = [sysconfig.get_path("scripts")]
    try:
        directories.append(sysconfig.get_path("scripts", "{}_user".format(os.name)))
    except KeyError:
        pass
    for directory in directories:
        if directory:
            candidate = os.path.join(directory, exe)
            if os.path.isfile(candidate) and os.access(candidate, os.X_OK):
                return candidate
    found = shutil.which("nesy")
    if found:
        return found
    raise NesyError(
        "the nesy executable was not found: install the nesy wheel (pip install nesy-*.whl), "
        "put nesy on PATH, or set NESY_BINARY to its path"
    )


def _command(args: Iterable[Any]) -> List[str]:
    return [binary()] + [os.fspath(a) if isinstance(a, os.PathLike) else str(a) for a in args]


def _invoke(args: Iterable[Any], *, cwd: Optional[PathLike] = None) -> subprocess.CompletedProcess:
    command = _command(args)
    return subprocess.run(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        stdin=subprocess.DEVNULL,
        text=True,
        encoding="utf-8",
        errors="replace",
        cwd=None if cwd is None else os.fspath(cwd),
    )


def _fail(what: str, done: subprocess.CompletedProcess) -> NesyError:
    return NesyError(
        "{} failed with exit code {}".format(what, done.returncode),
        command=list(done.args),
        exit_code=done.returncode,
        stdout=done.stdout,
        stderr=done.stderr,
    )


def _first_json(text: str) -> Optional[Dict[str, Any]]:
    """The first complete JSON object in ``text`` that starts a line (the binary may print
    plain lines before or after it)."""
    decoder = json.JSONDecoder()
    for match in re.finditer(r"(?m)^[ \t]*\{", text):
        try:
            value, _ = decoder.raw_decode(text, match.end() - 1)
        except ValueError:
            continue
        if isinstance(value, dict):
            return value
    return None


def _fresh_json(path: Path, since: float) -> Optional[Dict[str, Any]]:
    """The JSON file at ``path`` if it was written by the command that started at ``since``."""
    try:
        if path.stat().st_mtime < since - 1.0:
            return None
        with open(path, encoding="utf-8") as handle:
            return json.load(handle)
    except (OSError, ValueError):
        return None


def version() -> str:
    """The version of the ``nesy`` executable, e.g. ``"0.1.0"``."""
    done = _invoke(["--version"])
    if done.returncode != 0:
        raise _fail("nesy --version", done)
    text = done.stdout.strip()
    return text.split()[-1] if text else text


def adapt(
    demo: PathLike,
    target: Optional[PathLike] = None,
    *,
    vlm: Optional[str] = None,
    out: Optional[PathLike] = None,
    execute: bool = False,
    robot: Optional[str] = None,
    skip_dry_run: bool = False,
    extra_args: Sequence[Any] = (),
) -> Dict[str, Any]:
    """Adapts a demonstration to a target scene and synthesizes a verified code policy
    (``nesy adapt ... --json``).

    Args:
        demo: the demonstration: ``demo.mcap``, a folder holding it, or a folder with
            ``manifest.json``.
        target: the target scene (``scene.json``) or camera target folder; ``None`` uses the
            target recorded in the demo.
        vlm: who answers: ``"oracle"``, ``"replay:CASSETTE"`` or the URL of an
            OpenAI-compatible server; ``None`` uses the configured model (``NESY_VLM_*``).
        out: the output directory (default ``runs/adapt/<demo name>`` under the current
            directory).
        execute: run the policy in the sandbox on the target scene and score it.
        robot: also run it on the robot served at this address (``HOST:PORT``,
            ``tcp://HOST:PORT`` or ``unix:PATH``) after the dry run in simulation succeeded.
            Implies ``execute``.
        skip_dry_run: with ``robot``, reach the robot without the dry run.
        extra_args: more ``nesy adapt`` arguments, e.g. ``["--codegen", "template"]``.

    Returns:
        The run summary as the binary prints it (also ``summary.json`` in the output
        directory): ``demo_path``, ``target_path``, ``out_dir``, ``instruction``, ``setting``
        (embodiments, factor, complexity, budget, ...), ``states``, ``target_state`` (atoms such
        as ``"(Closed top_drawer)"``), ``status`` (``"succeeded"`` or another status),
        ``codegen_error``, ``timing`` (seconds per stage), ``usage`` (model calls, tokens, cost)
        and ``prompts`` (template hashes). Added by this function:

        - ``exit_code``: 0 when the procedure was adapted, compiled and (when executed, on the
          robot too) succeeded; 1 otherwise; 2 only when a model call of code generation failed.
        - ``execution``: with ``execute``, the simulated execution (``execution.json``:
          ``scene_path``, ``result`` with ``outcome`` (``{"kind": "ok"}`` or a failure),
          ``trace`` (every API call with its arguments and result), ``stdout``, ``subtasks``,
          ``final_state``; and ``metrics``), or ``None`` if there was none.
        - ``robot_run``: with ``robot``, the robot run's record (``robot/robot-run.json``: see
          ``run``), or ``None`` if the robot was not contacted.
        - ``policy_file``: the path of the synthesized ``policy.py``, or ``None``.

        When the model side ended the run before it had a summary (no usable reply, a refused
        request, an unreachable server: exit code 1 with no JSON), the dict is instead
        ``{"status": "stopped", "exit_code": 1, "output": <stdout>, "stderr": <stderr>,
        "failure": <failure.json or None>}``.

    Raises:
        NesyError: exit code 2 with no summary (bad input, such as a missing demo, or any
            other error, such as a robot that could not be reached), or no result at all.
    """
    execute = execute or robot is not None
    args: List[Any] = ["adapt", "--demo", demo]
    if target is not None:
        args += ["--target", target]
    if vlm is not None:
        args += ["--vlm", vlm]
    if out is not None:
        args += ["--out", out]
    if execute:
        args.append("--execute")
    if robot is not None:
        args += ["--robot", robot]
    if skip_dry_run:
        args.append("--skip-dry-run")
    args.append("--json")
    args += list(extra_args)
    started = time.time()
    done = _invoke(args)
    summary = _first_json(done.stdout)
    if summary is None:
        if done.returncode == 1:
            failure = _fresh_json(Path(out) / "failure.json", started) if out is not None else None
            return {
                "status": "stopped",
                "exit_code": 1,
                "output": done.stdout,
                "stderr": done.stderr,
                "failure": failure,
            }
        raise _fail("nesy adapt", done)
    summary["exit_code"] = done.returncode
    out_dir = Path(summary.get("out_dir") or (out if out is not None else "."))
    summary["execution"] = _fresh_json(out_dir / "execution.json", started) if execute else None
    summary["robot_run"] = _fresh_json(out_dir / "robot" / "robot-run.json", started) if robot is not None else None
    policy = out_dir / "policy.py"
    try:
        summary["policy_file"] = str(policy) if policy.stat().st_mtime >= started - 1.0 else None
    except OSError:
        summary["policy_file"] = None
    return summary


def run(
    policy: PathLike,
    *,
    scene: Optional[PathLike] = None,
    robot: Optional[str] = None,
    skip_dry_run: bool = False,
    robot_run_dir: Optional[PathLike] = None,
    extra_args: Sequence[Any] = (),
) -> Dict[str, Any]:
    """Runs a code policy in nesy's sandbox (``nesy run``): on a simulated scene, or on a robot.

    Args:
        policy: the policy's Python source file.
        scene: the scene (``scene.json``); needed without ``robot``, and with ``robot`` it is
            the scene of the dry run in simulation.
        robot: run the policy on the robot served at this address (``HOST:PORT``,
            ``tcp://HOST:PORT`` or ``unix:PATH``).
        skip_dry_run: with ``robot``, go without the dry run (needed when there is no scene).
        robot_run_dir: where the robot run's record goes (default: a new temporary directory).
        extra_args: more ``nesy run`` arguments, e.g. ``["--speed-scale", "0.3"]``.

    Returns:
        Without ``robot``: the execution result the binary prints with ``--json``:
        ``outcome`` (``{"kind": "ok"}``, or a failure kind with details), ``trace`` (one entry
        per API call: ``index``, ``call``, its arguments, ``result`` as ``{"Ok": {"type", "value"}}``
        or ``{"Err": {...}}``, ``sim_time``), ``stdout`` and ``stderr`` (``{"text",
        "truncated_bytes"}``), ``wall_time_s``, ``subtasks`` (goal checks: ``subtask``,
        ``status``, ``label``, ``achieved``), ``final_state`` (atoms) and ``worker``; plus
        ``exit_code`` (0 ok, 1 the policy failed, 2 it was rejected before running).

        With ``robot``: the run record ``robot-run.json``: ``policy``, ``robot`` (``address``
        and the ``welcome`` that ``hello`` answered), ``workspace``, ``speed_scale``,
        ``confirm``, ``dry_run`` (``{"skipped": true}`` or the scene, outcome and goal checks),
        ``calls_sent`` and ``result`` (the execution result as above; its ``trace`` holds the
        calls answered by the robot); plus ``exit_code`` (0 when the policy ran to its end on
        the robot), ``contacted`` (``True``), ``run_dir`` and ``calls_log`` (the
        ``robot-calls.jsonl`` event log). When the robot was not contacted (the dry run
        failed), the dict is ``{"contacted": False, "reason": ..., "dry_run": {...},
        "exit_code": ..., "run_dir": ...}``.

    Raises:
        NesyError: exit code 2 with no result (bad input, a robot that could not be reached).
    """
    args: List[Any] = ["run", "--policy", policy]
    if scene is not None:
        args += ["--scene", scene]
    if robot is None:
        args.append("--json")
        args += list(extra_args)
        done = _invoke(args)
        result = _first_json(done.stdout)
        if result is None:
            raise _fail("nesy run", done)
        result["exit_code"] = done.returncode
        return result
    run_dir = Path(robot_run_dir) if robot_run_dir is not None else Path(tempfile.mkdtemp(prefix="nesy-robot-run-"))
    args += ["--robot", robot, "--robot-run-dir", run_dir, "--json"]
    if skip_dry_run:
        args.append("--skip-dry-run")
    args += list(extra_args)
    done = _invoke(args)
    # With --json the binary prints the run record, or {"contacted": false, ...} when the dry
    # run kept the robot out.
    record = _first_json(done.stdout)
    if record is None:
        raise _fail("nesy run --robot", done)
    record["exit_code"] = done.returncode
    record["run_dir"] = str(run_dir)
    if record.get("contacted"):
        record["calls_log"] = str(run_dir / "robot-calls.jsonl")
    return record


def verify(domain: PathLike, problem: PathLike, plan: Union[PathLike, Sequence[str]]) -> Dict[str, Any]:
    """Checks a plan against a PDDL domain and problem, like VAL (``nesy verify``).

    Args:
        domain: the PDDL domain file.
        problem: the PDDL problem file.
        plan: the plan file (one ``(action args...)`` per line, ``;`` comments), or the plan's
            actions as a list of strings such as ``["(pick ball1 rooma left)", ...]``.

    Returns:
        The verdict ``nesy verify --json`` prints: ``valid`` (bool), ``steps``, ``executed``,
        ``failure`` (``None`` or ``{"step", "action", "plan_line", "unmet", "error"}``),
        ``goal_satisfied`` (bool, or ``None`` when execution stopped early), ``unmet_goal`` and
        ``report`` (every step with its added and removed atoms, the final state and the goal
        check); plus ``text``, the human-readable verdict, and ``exit_code`` (0 valid, 1 invalid).

    Raises:
        NesyError: a file could not be read or parsed (exit code 2).
    """
    cleanup = None
    if not isinstance(plan, (str, bytes, os.PathLike)):
        handle = tempfile.NamedTemporaryFile("w", suffix=".plan", delete=False, encoding="utf-8")
        with handle:
            handle.write("\n".join(str(step) for step in plan) + "\n")
        plan = cleanup = handle.name
    try:
        base = ["verify", "--domain", domain, "--problem", problem, "--plan", plan]
        done = _invoke(base + ["--json"])
        verdict = _first_json(done.stdout)
        if verdict is None or done.returncode not in (0, 1):
            raise _fail("nesy verify", done)
        text = _invoke(base)
        verdict["text"] = text.stdout.strip()
        verdict["exit_code"] = done.returncode
        verdict["valid"] = bool(verdict.get("valid"))
        return verdict
    finally:
        if cleanup is not None:
            try:
                os.unlink(cleanup)
            except OSError:
                pass


from . import bench, robot  # noqa: E402  (submodules that use the helpers above)
