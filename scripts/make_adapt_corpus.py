#!/usr/bin/env python3
"""Builds the adaptation-loop replay corpus (tests/adapt_corpus/) from `nesy adapt` run directories.

usage: scripts/make_adapt_corpus.py RUN_DIR... [--out tests/adapt_corpus]

RUN_DIR is a scenario directory holding `demo/demo.mcap` (as `nesy record --out RUN_DIR/demo`
writes it) and `adapt/{summary.json,world_model.json,adaptation.json,target_scene.json}` (as
`nesy adapt --out RUN_DIR/adapt` writes them; summary.json may also sit in RUN_DIR itself). Each corpus file holds what nesy-core's `adapt::run` received
(demonstrated states, target state, objects, instruction, tier, budget) and every reply the
reasoner gave, in call order, so a scripted reasoner can replay the run without the model.
Standard library only.
"""

import argparse
import json
import sys
from pathlib import Path


def demo_objects(mcap: Path):
    """Scene object names of the demo (the first embedded scene's `objects`), without the robot's."""
    data = mcap.read_bytes()
    key = b'"objects":[{"name":'
    at = data.find(key)
    if at < 0:
        raise SystemExit(f"{mcap}: no embedded scene with an objects list")
    text = data[at + len(b'"objects":'):at + 200_000].decode("utf-8", errors="replace")
    objects, _ = json.JSONDecoder().raw_decode(text)
    return [o["name"] for o in objects if "gripper" not in o["name"]]


def build(run: Path):
    adapt = run / "adapt"
    summary_path = adapt / "summary.json" if (adapt / "summary.json").exists() else run / "summary.json"
    summary = json.loads(summary_path.read_text())
    world_model = json.loads((adapt / "world_model.json").read_text())
    adaptation = json.loads((adapt / "adaptation.json").read_text())
    scene = json.loads((adapt / "target_scene.json").read_text())
    outcome = adaptation["outcome"]
    final = outcome["procedure"] if outcome["outcome"] == "adapted" else outcome["best"]
    return {
        "scenario": run.name,
        "instruction": summary["instruction"],
        "tier": world_model["tier"],
        "budget": summary["setting"]["budget"],
        "demo_objects": demo_objects(run / "demo" / "demo.mcap"),
        "target_objects": [o["name"] for o in scene["objects"] if "gripper" not in o["name"]],
        "demo_states": world_model["states"],
        "target_state": summary["target_state"],
        "induction_replies": [i["reply"] for i in adaptation["inductions"]],
        "patch_replies": [p["reply"] for p in adaptation["proposals"]],
        "expected": {
            "outcome": outcome["outcome"],
            "iterations": outcome["iterations"],
            "procedure": [op["name"] for op in final],
        },
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, default=Path("tests/adapt_corpus"))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for run in args.runs:
        entry = build(run)
        path = args.out / f"{run.name}.json"
        path.write_text(json.dumps(entry, indent=1, ensure_ascii=False) + "\n")
        print(f"{path}: {len(entry['induction_replies'])} inductions, "
              f"{len(entry['patch_replies'])} proposals, {entry['expected']['outcome']}", file=sys.stderr)


if __name__ == "__main__":
    main()
