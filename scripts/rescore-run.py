#!/usr/bin/env python3
"""Re-scores a recorded benchmark run offline and checks that it comes out the same.

    scripts/rescore-run.py RUN_DIR [--nesy BIN] [--scenarios N] [--out DIR]

RUN_DIR is a run folder that `nesy bench run --record-cassettes` wrote (manifest.json,
results/*.jsonl, cassettes/): a published one under bench/runs/, or one in progress. The
script replays the run's cassettes with the given build (`--vlm replay:RUN_DIR/cassettes`)
over the units the run's results list, in the run's observation setting, repeats and seed,
and compares every unit's record with the recorded one: status, error, scores, calls by
purpose, images, tokens and cost (timings and the configuration hash, which names the
responder, are left out). `--scenarios N` replays only the first N scenarios in id order (the
slice CI runs). When the run is finished (its tables/ exist) and every scenario is replayed,
the tables that hold no timings (table1, status, stages, domain_gap) must be byte-identical
too.

A build later than the one the manifest names may compile a unit's procedure into another
program (the code templates change; a model's code comes from the cassette and does not).
A unit that ends differently AND whose program (`policy.py` in its artifacts folder) differs
from the recorded one is listed as compiled anew, not as a difference: the replies and the
procedure were the same, the program was not. A unit that ends differently from the same
program, or without one, is a difference. When some unit was compiled anew, the tables are
compared but a mismatch is reported as expected of that build; byte-identical tables are
the check for the build the manifest names.

Identical requests sent concurrently (Demo2Code and Critic-V describe keyframes at once, and
keyframes that look alike get the same prompt) replay by their send order, which cassettes
keep from the build that added it; a cassette recorded before then may hand their replies to
each other's callers. A unit whose only difference is its error text, and whose cassette
holds such identical requests without a send order, is listed as replied in another order,
not as a difference: same status, scores, calls and tokens, another of its own replies quoted.

Exit 0 when everything matches, 1 with the differences otherwise, 2 on bad input.
"""

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from run_files import cassette_of, fail_input, has_unordered_twins, interactions, last_records

# Fields of a unit's record that a replay must reproduce exactly.
EFFORT_FIELDS = ("calls", "images", "calls_by_purpose", "tokens", "cost_usd")
RECORD_FIELDS = ("status", "error", "scores", "method", "factor", "complexity", "seed")
# The report's tables without timings.
TIMELESS_TABLES = ("table1.csv", "status.csv", "stages.csv", "domain_gap.csv")


def comparable(record):
    kept = {field: record.get(field) for field in RECORD_FIELDS}
    effort = record.get("effort") or {}
    kept["effort"] = {field: effort.get(field) for field in EFFORT_FIELDS}
    return kept


def program_of(run, record):
    """The program a unit ran (`policy.py` in its artifacts folder), or None."""
    artifacts = record.get("artifacts")
    if not artifacts:
        return None
    path = run / artifacts / "policy.py"
    return path.read_bytes() if path.is_file() else None


def program_changed(run, recorded, replay_run, replayed):
    """True when both ran a program and the replay's is not the recorded one."""
    want, got = program_of(run, recorded), program_of(replay_run, replayed)
    return want is not None and got is not None and want != got


def replies_swapped(run, key, fields):
    """Whether a unit differs in its error text only, with a cassette that kept no send order
    for its identical requests (see the module documentation)."""
    scenario, variant, _ = key
    cassette = cassette_of(run, scenario, variant)
    return fields == ["error"] and cassette.is_file() and has_unordered_twins(interactions(cassette))


def knows_option(nesy, option):
    """Whether this build's `nesy bench run` has the option (older builds lack newer ones)."""
    try:
        shown = subprocess.run([nesy, "bench", "run", "--help"], capture_output=True, text=True)
    except OSError as error:
        fail_input(f"{nesy}: cannot run it ({error})")
    return option in shown.stdout


def build_of(manifest):
    """The recording build's commit as the manifest names it."""
    provenance = manifest.get("provenance") or {}
    commit = provenance.get("git_commit") or provenance.get("commit") or "?"
    return f"commit {commit[:12]}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path, help="the recorded run folder")
    parser.add_argument("--nesy", default="nesy", help="the nesy binary to re-score with")
    parser.add_argument("--scenarios", type=int, help="replay only the first N scenarios")
    parser.add_argument("--out", type=Path, help="keep the replayed run here (default: a temporary folder)")
    args = parser.parse_args()

    run = args.run
    try:
        manifest = json.loads((run / "manifest.json").read_text())
    except (OSError, json.JSONDecodeError) as error:
        fail_input(f"{run / 'manifest.json'}: {error}")
    if not (run / "cassettes").is_dir():
        fail_input(f"{run / 'cassettes'}: missing; the run was not recorded with --record-cassettes")
    recorded = last_records(run)
    scenarios = sorted({scenario for scenario, _, _ in recorded})
    every_scenario = args.scenarios is None or args.scenarios >= len(scenarios)
    if not every_scenario:
        scenarios = scenarios[: args.scenarios]
    # In the manifest's order: the tables list methods in the order the run was given them.
    present = {variant for scenario, variant, _ in recorded if scenario in scenarios}
    declared = [entry.get("id") for entry in manifest.get("variants", [])]
    variants = [v for v in declared if v in present] + sorted(present - set(declared))
    settings = manifest.get("settings", {})

    out = args.out or Path(tempfile.mkdtemp(prefix="nesy-rescore-"))
    if out.exists() and any(out.iterdir()):
        fail_input(f"{out}: exists and is not empty")
    command = [
        args.nesy, "bench", "run", str(out / "run"),
        "--methods", ",".join(variants),
        "--scenarios", ",".join(scenarios),
        "--observation", settings.get("observation", "images"),
    ]
    # A manifest without the setting is a run made before the protective stop existed; a
    # build from before then has no option for it (and no stop).
    if knows_option(args.nesy, "--protective-stop"):
        command += ["--protective-stop", "on" if settings.get("protective_stop", False) else "off"]
    command += [
        "--repeats", str(manifest.get("repeats", 1)),
        "--seed", str(manifest.get("run_seed", 0)),
        "--vlm", f"replay:{(run / 'cassettes').resolve()}",
        "--demos", str(out / "demos"),
        "--jobs", "2",
        "--no-report",
    ]
    print("+ " + " ".join(command), flush=True)
    finished = subprocess.run(command, stdout=subprocess.DEVNULL)
    if finished.returncode not in (0, 1):
        print(f"rescore-run: the replay exited with {finished.returncode}", file=sys.stderr)
        return 1
    replayed = last_records(out / "run")

    differences = []
    compiled_anew = []
    reordered = []
    compared = 0
    for key in sorted(k for k in recorded if k[0] in scenarios):
        if key not in replayed:
            differences.append(f"{'/'.join(map(str, key))}: not replayed")
            continue
        compared += 1
        want, got = comparable(recorded[key]), comparable(replayed[key])
        if want != got:
            fields = sorted(f for f in want if want[f] != got[f])
            line = (
                f"{'/'.join(map(str, key))}: {', '.join(fields)} differ\n"
                f"    recorded: {json.dumps({f: want[f] for f in fields})[:600]}\n"
                f"    replayed: {json.dumps({f: got[f] for f in fields})[:600]}"
            )
            if program_changed(run, recorded[key], out / "run", replayed[key]):
                compiled_anew.append(line)
            elif replies_swapped(run, key, fields):
                reordered.append(line)
            else:
                differences.append(line)
    tables_checked = []
    table_mismatches = []
    if every_scenario and (run / "tables").is_dir():
        report = [args.nesy, "bench", "report", str(out / "run")]
        print("+ " + " ".join(report), flush=True)
        subprocess.run(report, stdout=subprocess.DEVNULL)
        for table in TIMELESS_TABLES:
            want, got = run / "tables" / table, out / "run" / "tables" / table
            if want.exists():
                tables_checked.append(table)
                if not got.exists() or want.read_bytes() != got.read_bytes():
                    table_mismatches.append(f"tables/{table}: not byte-identical")
    # Tables follow their units: with a unit compiled anew they cannot be byte-identical.
    if not compiled_anew:
        differences += table_mismatches

    print(
        f"rescore-run: {compared} unit(s) of {len(scenarios)} scenario(s) replayed"
        + (f"; tables compared: {', '.join(tables_checked)}" if tables_checked else "")
    )
    if args.out is None:
        shutil.rmtree(out, ignore_errors=True)
    if compiled_anew:
        print(
            f"rescore-run: {len(compiled_anew)} unit(s) "
            f"compiled to another program by this build than the recording one ({build_of(manifest)}) "
            "and end differently from it; re-score with that build to reproduce them:"
        )
        for line in compiled_anew + table_mismatches:
            print("  " + line)
    if reordered:
        print(
            f"rescore-run: {len(reordered)} unit(s) end with the same status, scores, calls and "
            "tokens but quote another of their replies: their cassettes hold identical concurrent "
            "requests recorded without a send order, whose replies replay in another order:"
        )
        for line in reordered:
            print("  " + line)
    if differences:
        print("rescore-run: the replay differs from the recorded run:", file=sys.stderr)
        for line in differences:
            print("  " + line, file=sys.stderr)
        return 1
    print("rescore-run: every " + ("other " if compiled_anew or reordered else "") + "unit ends as recorded")
    return 0


if __name__ == "__main__":
    sys.exit(main())
