#!/usr/bin/env python3
"""Explains the execution failures of a noisy `nesy bench run` against a noise-free one.

Both runs must cover the same scenarios with one variant each. Every unit of the noisy run
that ended `execution_failed` is paired with the noise-free unit of the same scenario, and
the two are compared:

- the preconditions the noise-free world model has and the verified noisy one lacks (a
  literal left out of an induced operator is consistent with a demonstration in which it
  always held, so the demonstration check cannot refuse it);
- the adapted procedures: steps the noise-free procedure has and the noisy one lacks (on
  an Obstruction target, the repair), or the same steps in another order.

Each failure is put in one class. Exit status 1, with the file named, on bad usage or
unreadable input.

    scripts/trace_execution_failures.py runs/obst-full-noise runs/obst-clean
"""
import collections
import json
import re
import sys
from pathlib import Path

# Preconditions that say a target obstruction is absent: a container is open, nothing is
# stacked on an object, an object stands on the board (the sweep's start).
OBSTRUCTION = re.compile(
    r"^\(Open |^\(forall \(\?y - thing\) \(not \(OnTopOf \?y |^\(OnTopOf \w+ board\)"
)


def records(run: Path) -> list:
    out = []
    for shard in sorted((run / "results").glob("*.jsonl")):
        for number, line in enumerate(shard.read_text().splitlines(), 1):
            if not line.strip():
                continue
            try:
                out.append(json.loads(line))
            except json.JSONDecodeError as e:
                sys.exit(f"{shard}:{number}: not a unit record ({e})")
    if not out:
        sys.exit(f"{run}/results: no unit records")
    return out


def adaptation(run: Path, record: dict) -> dict:
    path = run / record["artifacts"] / "adaptation.json"
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"{path}: {e}")


def dropped_preconditions(noisy: dict, clean: dict) -> list:
    have = {o["name"]: o for o in noisy["world_model"]["procedure"]}
    return [
        (name, literal)
        for name, op in {o["name"]: o for o in clean["world_model"]["procedure"]}.items()
        if name in have
        for literal in op["pre"]
        if literal not in have[name]["pre"]
    ]


def steps(a: dict) -> list:
    return [s["name"] for s in a["outcome"].get("procedure", [])]


def classify(noisy: dict, clean: dict, clean_status: str) -> tuple:
    dropped = dropped_preconditions(noisy, clean)
    ours, theirs = steps(noisy), steps(clean)
    missing = collections.Counter(theirs) - collections.Counter(ours)
    if clean_status != "succeeded":
        kind = "fails without noise too"
    elif missing:
        obstruction = any(OBSTRUCTION.match(lit) for _, lit in dropped)
        kind = "steps of the noise-free procedure missing" + (
            ", an obstruction precondition dropped" if obstruction else ""
        )
    elif ours != theirs:
        kind = "same steps in another order"
    else:
        kind = "same procedure"
    return kind, dropped, sorted(missing.elements())


def main() -> None:
    if len(sys.argv) != 3:
        sys.exit("usage: scripts/trace_execution_failures.py NOISY_RUN CLEAN_RUN")
    noisy_run, clean_run = Path(sys.argv[1]), Path(sys.argv[2])
    clean = {r["scenario"]: r for r in records(clean_run)}
    failed = [r for r in records(noisy_run) if r["status"] == "execution_failed"]
    classes = collections.Counter()
    with_dropped = 0
    for r in failed:
        c = clean.get(r["scenario"])
        if c is None:
            sys.exit(f"{clean_run}: no unit for {r['scenario']}")
        kind, dropped, missing = classify(adaptation(noisy_run, r), adaptation(clean_run, c), c["status"])
        classes[kind] += 1
        with_dropped += bool(dropped)
        first = ", ".join(f"{n} {lit}" for n, lit in dropped[:2])
        print(f"{r['scenario']} r{r['repeat']}: {kind}; missing {missing or '-'}; dropped {first or '-'}")
    print(f"\n{len(failed)} execution failures, {with_dropped} with a dropped precondition")
    for kind, n in classes.most_common():
        print(f"{n:4}  {kind}")


if __name__ == "__main__":
    main()
