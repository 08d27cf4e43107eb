#!/usr/bin/env python3
"""Adapt the quick-start demo, then execute the adapted policy on a Python robot adapter.

1. ``nesy.adapt`` turns the demonstration ``fixtures/demos/adapt-realstyle`` into a verified
   policy for the target scene, with the recorded model answers of
   ``fixtures/cassettes/adapt-realstyle.json`` (no model needed), and runs it in simulation.
2. ``SimulatedArm`` (``nesy.examples.sim_proxy_robot``) is started on a free local port: a
   Python robot server, written like a real adapter, whose "robot" is nesy's simulator.
3. ``nesy.adapt(..., execute=True, robot=ADDRESS)`` runs the pipeline again and sends the
   adapted policy to that server after its dry run in simulation succeeded.

Exits 0 when the policy reached its goal in simulation and ran to its end on the robot.

    NESY_BINARY=target/debug/nesy python3 python/examples/adapt_and_execute.py
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve()
REPO = HERE.parents[2]

try:
    import nesy
except ImportError:  # running from a checkout without the package installed
    sys.path.insert(0, str(REPO / "python" / "src"))
    import nesy

from nesy.examples.sim_proxy_robot import SimulatedArm


def count_lines(path: Path, event: str) -> int:
    try:
        with open(path, encoding="utf-8") as handle:
            return sum(1 for line in handle if line.strip() and json.loads(line).get("event") == event)
    except OSError:
        return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repo", type=Path, default=REPO, help="the nesy repository root (fixtures are found under it)")
    parser.add_argument("--out", type=Path, default=None, help="where the runs go (default: a new temporary directory)")
    parser.add_argument("--nesy", default=None, help="the nesy executable (default: $NESY_BINARY, the installed one, or PATH)")
    args = parser.parse_args()
    if args.nesy:
        os.environ["NESY_BINARY"] = args.nesy
    root = args.repo.resolve()
    demo = root / "fixtures" / "demos" / "adapt-realstyle"
    target = demo / "target.json"
    vlm = "replay:{}".format(root / "fixtures" / "cassettes" / "adapt-realstyle.json")
    out = (args.out or Path(tempfile.mkdtemp(prefix="nesy-adapt-example-"))).resolve()
    print("nesy {} ({})".format(nesy.version(), nesy.binary()))

    # 1. Adapt and execute in simulation.
    sim = nesy.adapt(demo, target, vlm=vlm, out=out / "sim", execute=True)
    execution = sim.get("execution") or {}
    result = execution.get("result") or {}
    print("adaptation: {} (exit code {})".format(sim.get("status"), sim["exit_code"]))
    print("  instruction  {}".format(sim.get("instruction")))
    setting = sim.get("setting", {})
    print("  setting      {} / {}, {} -> {}".format(
        setting.get("factor"), setting.get("complexity"),
        setting.get("source_embodiment"), setting.get("target_embodiment")))
    print("  model calls  {}".format(sim.get("usage", {}).get("total", {}).get("calls")))
    print("  policy       {}".format(sim.get("policy_file")))
    print("  simulation   {} ({} API calls)".format((result.get("outcome") or {}).get("kind"), len(result.get("trace") or [])))
    for check in result.get("subtasks") or []:
        print("    goal {}: {}".format(check.get("subtask"), check.get("status")))
    if sim["exit_code"] != 0:
        print("the adaptation did not succeed; see {}".format(sim.get("out_dir")), file=sys.stderr)
        return 1

    # 2. The Python robot adapter, on the simulator, in a background thread.
    arm_log = out / "arm-calls.jsonl"
    arm = SimulatedArm(str(target), log=str(arm_log))
    try:
        address = arm.serve_in_background("127.0.0.1:0", once=True)
        print("robot adapter listening on {}".format(address))

        # 3. Adapt again and execute on the robot (after the dry run in simulation).
        real = nesy.adapt(demo, target, vlm=vlm, out=out / "robot", execute=True, robot=address)
    finally:
        arm.close()
    record = real.get("robot_run") or {}
    robot_result = record.get("result") or {}
    outcome = (robot_result.get("outcome") or {}).get("kind")
    print("on the robot: {} (exit code {})".format(outcome, real["exit_code"]))
    print("  robot        {}".format((record.get("robot") or {}).get("welcome", {}).get("robot")))
    print("  dry run      {}".format((record.get("dry_run") or {}).get("outcome", "skipped")))
    print("  calls sent   {} (the adapter answered {} requests: these, nesy's workspace-check"
          " queries and finish)".format(record.get("calls_sent"), count_lines(arm_log, "call")))
    for check in robot_result.get("subtasks") or []:
        print("    goal {}: {}".format(check.get("subtask"), check.get("status")))
    print("  record       {}".format(Path(real.get("out_dir", out / "robot")) / "robot"))
    print("  adapter log  {}".format(arm_log))
    if real["exit_code"] != 0 or outcome != "ok":
        print("the run on the robot did not succeed", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
