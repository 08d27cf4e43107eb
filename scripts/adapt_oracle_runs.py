#!/usr/bin/env python3
"""Runs `nesy adapt --vlm oracle --execute` on one scenario per factor x complexity (15) and
prints SR/GC/PD and the time breakdown as a markdown table (crates/nesy-cli/README.md).

usage: scripts/adapt_oracle_runs.py [--nesy PATH] [--work DIR] [--episode N] [--codegen vlm|template]

Each scenario's source demo is recorded with `nesy record` (the scripted expert), then adapted
to the scenario's target scene. Per cell, the first episode is used whose demo the expert
completes and whose final state shows every goal placement (the goal checks latch an object once
it is placed, so an object the expert knocked out again afterwards passes them, but the goal
derived from the demo's final state then lacks it); skipped episodes are listed under the table.
With --keep-gapped-demos such a demo is adapted anyway and the last column names the gaps.
Standard library only.
"""

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

FACTORS = ["affo", "obst", "grip", "vacu", "comb"]
COMPLEXITIES = ["low", "medium", "high"]


def mean_se(values):
    n = len(values)
    if n == 0:
        return float("nan"), float("nan")
    m = sum(values) / n
    if n < 2:
        return m, float("nan")
    var = sum((v - m) ** 2 for v in values) / (n - 1)
    return m, math.sqrt(var) / math.sqrt(n)


def placement_atoms(scene):
    """`(InsideOf object container)` of every placement of a scene's goals."""
    atoms = []
    for goal in scene.get("goals", []):
        if goal["subtask"] == "sweep":
            atoms += [f"(InsideOf {p['object']} {p['container']})" for p in goal["placements"]]
        else:
            container = goal.get("container") or goal.get("drawer")
            atoms += [f"(InsideOf {o} {container})" for o in goal["objects"]]
    return atoms


def demo_goal_gaps(nesy, sid, out):
    """The source goals' placements that the goal derived from the demo's final state lacks:
    a demonstration whose arm knocked a counted object out again (the goal checks keep their
    latch) adapts towards the wrong goal. Empty when the demo shows its goal."""
    world_model = out / "world_model.json"
    if not world_model.exists():
        return ["no world_model.json"]
    shown = subprocess.run(
        [nesy, "scenarios", "show", sid, "--side", "source"], capture_output=True, text=True
    )
    if shown.returncode != 0:
        return ["source scene unavailable"]
    goal = json.loads(world_model.read_text()).get("goal", "")
    return [a for a in placement_atoms(json.loads(shown.stdout)) if a not in goal]


def record(nesy, candidate, cdemo):
    """Records the source demo of `candidate` (once); the last line of the error, or None."""
    # `nesy record` writes the files even when the expert fails; only a run that exited 0
    # leaves the marker.
    if (cdemo / "recorded.ok").exists():
        return None
    rec = subprocess.run(
        [nesy, "record", "--scenario", candidate, "--out", str(cdemo)], capture_output=True, text=True
    )
    if rec.returncode != 0:
        return ((rec.stderr.strip() or rec.stdout.strip()).splitlines() or ["?"])[-1]
    (cdemo / "recorded.ok").write_text(rec.stdout)
    return None


def adapt(args, sid, demo, out):
    """Runs `nesy adapt` on one recorded demo; the table row."""
    run = subprocess.run(
        [args.nesy, "adapt", "--demo", str(demo), "--target", str(demo / "target.json"),
         "--vlm", "oracle", "--codegen", args.codegen, "--execute", "--json", "--out", str(out)],
        capture_output=True, text=True,
    )
    try:
        summary = json.loads(run.stdout)
    except json.JSONDecodeError:
        return {"id": sid, "error": (run.stderr.strip().splitlines() or ["?"])[-1]}
    row = {"id": sid, "status": summary["status"], "timing": summary["timing"]}
    execution = out / "execution.json"
    metrics = None
    if execution.exists():
        metrics = json.loads(execution.read_text()).get("metrics")
    row["sr"] = metrics["sr"] if metrics else 0.0
    row["gc"] = metrics["gc"] if metrics else 0.0
    row["pd"] = metrics["pd"] if metrics and metrics["pd"] is not None else 1.0
    row["subtasks"] = ", ".join(
        f"{s['subtask']} {s['status']}" for s in (metrics or {}).get("subtasks", [])
    )
    adaptation = json.loads((out / "adaptation.json").read_text())
    row["proposals"] = len(adaptation["proposals"])
    row["violations"] = len(adaptation["violations"])
    row["demo_gaps"] = demo_goal_gaps(args.nesy, sid, out)
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--nesy", default="target/release/nesy")
    ap.add_argument("--work", default="runs/oracle15")
    ap.add_argument("--episode", type=int, default=0)
    ap.add_argument("--codegen", default="vlm")
    ap.add_argument("--tries", type=int, default=5, help="episodes to try per cell")
    ap.add_argument(
        "--keep-gapped-demos", action="store_true",
        help="adapt a demo whose final state lacks a goal placement instead of trying the next episode",
    )
    args = ap.parse_args()
    work = Path(args.work)
    rows, all_skipped = [], []
    for factor in FACTORS:
        for complexity in COMPLEXITIES:
            # The first episode from --episode on whose source demo the scripted expert
            # completes and whose final state shows the goal (a failed demonstration is no
            # demonstration; the goal checks latch, so an object knocked out again after it
            # counted passes them); skipped ones are listed.
            row, skipped = None, []
            for episode in range(args.episode, args.episode + args.tries):
                candidate = f"{factor}_{complexity}_{episode:02d}_s0"
                cdemo = work / candidate / "demo"
                error = record(args.nesy, candidate, cdemo)
                if error is not None:
                    skipped.append(f"{candidate}: {error}")
                    continue
                row = adapt(args, candidate, cdemo, work / candidate / "adapt")
                if row.get("demo_gaps") and not args.keep_gapped_demos:
                    skipped.append(
                        f"{candidate}: the demo's final state lacks {' '.join(row['demo_gaps'])} "
                        f"(adapted anyway: {row['status']}, SR {row['sr']:.0f})"
                    )
                    row = None
                    continue
                break
            for s in skipped:
                print(f"skipped {s}", file=sys.stderr)
            all_skipped += skipped
            if row is None:
                rows.append({"id": f"{factor}_{complexity}", "error": "no usable demonstration"})
                continue
            rows.append(row)
            if "error" not in row:
                print(f"{row['id']}: {row['status']} SR {row['sr']:.0f} GC {row['gc']:.2f}", file=sys.stderr)
                for gap in row.get("demo_gaps", []):
                    print(f"  the demo's final state lacks {gap}", file=sys.stderr)

    print("| scenario | status | subtasks | violations | proposals | SR | GC | PD | VLM s | symbolic ms (world model + adaptation) | sim s | demo goal gaps |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if "error" in r:
            print(f"| {r['id']} | error: {r['error']} | | | | 0 | 0 | 1 | | | | |")
            continue
        t = r["timing"]
        gaps = " ".join(r["demo_gaps"]) or "none"
        print(
            f"| {r['id']} | {r['status']} | {r['subtasks']} | {r['violations']} | {r['proposals']} | "
            f"{r['sr']:.0f} | {r['gc']:.2f} | {r['pd']:.2f} | {t['vlm_s']:.3f} | {t['symbolic_s'] * 1e3:.2f} ({t['symbolic_world_model_s'] * 1e3:.2f} + {t['symbolic_adaptation_s'] * 1e3:.2f}) | {t['sim_s']:.2f} | {gaps} |"
        )
    srs = [r.get("sr", 0.0) for r in rows]
    gcs = [r.get("gc", 0.0) for r in rows]
    pds = [r.get("pd", 1.0) for r in rows]
    sym = [r["timing"]["symbolic_s"] * 1e3 for r in rows if "timing" in r]
    ada = [r["timing"]["symbolic_adaptation_s"] * 1e3 for r in rows if "timing" in r]
    (sr, sr_se), (gc, gc_se), (pd, pd_se) = mean_se(srs), mean_se(gcs), mean_se(pds)
    print()
    print(f"SR {sr * 100:.1f} ± {sr_se * 100:.1f}, GC {gc * 100:.1f} ± {gc_se * 100:.1f}, "
          f"PD {pd * 100:.1f} ± {pd_se * 100:.1f} over {len(rows)} scenarios; "
          f"symbolic time per run: mean {sum(sym) / max(len(sym), 1):.2f} ms, max {max(sym or [0]):.2f} ms; "
          f"of it in the adaptation loop: mean {sum(ada) / max(len(ada), 1):.2f} ms, max {max(ada or [0]):.2f} ms")
    if all_skipped:
        print()
        print("Episodes skipped (no usable demonstration):")
        for s in all_skipped:
            print(f"- {s}")


if __name__ == "__main__":
    main()
