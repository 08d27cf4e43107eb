#!/usr/bin/env python3
"""Writes how far a published benchmark run has got into its README.

    scripts/run-status.py RUN [--check]

Reads RUN/manifest.json (how many units the run has) and RUN/results/*.jsonl (the units
finished so far), and rewrites two parts of RUN/README.md: the status line (the line that
starts with `**Status:`) and the table under `## The units finished so far` (up to the next
blank line after it). It also updates the run's row in bench/runs/README.md (the cell that
says `in progress: N of M units`). With --check it changes nothing and exits 1 when a file is
out of date. Standard library only.
"""

import argparse
import json
import re
import sys
from pathlib import Path

TABLE_HEADING = "## The units finished so far"


def records(run: Path):
    rows = []
    for shard in sorted((run / "results").glob("*.jsonl")):
        for number, line in enumerate(shard.read_text(encoding="utf-8").splitlines(), 1):
            if line.strip():
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError as err:
                    sys.exit(f"{shard}:{number}: not a JSON record ({err})")
    return rows


def status_line(done: int, total: int, scenarios_done: int, scenarios_begun: int) -> str:
    if done == total:
        return f"**Status: finished, {total} of {total} units.**"
    return (
        f"**Status: in progress, {done} of {total} units finished** "
        f"({scenarios_done} scenario(s) complete, {scenarios_begun} begun)."
    )


def table(rows) -> list:
    lines = [
        "| scenario | method | status | calls | wall s | first line of the error |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        effort = r.get("effort") or {}
        error = (r.get("error") or "").splitlines()
        first = error[0].replace("|", "\\|") if error else ""
        lines.append(
            f"| {r['scenario']} | {r['variant']} | {r['status']} | {effort.get('calls', 0)} "
            f"| {effort.get('total_s', 0):.0f} | {first} |"
        )
    return lines


def rewrite_readme(text: str, status: str, rows) -> str:
    lines = text.splitlines()
    out, i = [], 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("**Status:"):
            out.append(status)
            i += 1
            continue
        if line.strip() == TABLE_HEADING:
            out.append(line)
            i += 1
            # Keep the prose between the heading and the table.
            while i < len(lines) and not lines[i].startswith("|"):
                out.append(lines[i])
                i += 1
            while i < len(lines) and lines[i].startswith("|"):
                i += 1
            out.extend(table(rows))
            continue
        out.append(line)
        i += 1
    return "\n".join(out) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args()
    run = args.run
    manifest = json.loads((run / "manifest.json").read_text(encoding="utf-8"))
    total = len(manifest["units"])
    rows = records(run)
    per_scenario = {}
    for unit in manifest["units"]:
        per_scenario.setdefault(unit["scenario"], 0)
        per_scenario[unit["scenario"]] += 1
    finished = {}
    for r in rows:
        finished[r["scenario"]] = finished.get(r["scenario"], 0) + 1
    complete = sum(1 for s, n in finished.items() if n >= per_scenario.get(s, n))
    begun = len(finished) - complete
    status = status_line(len(rows), total, complete, begun)

    readme = run / "README.md"
    old = readme.read_text(encoding="utf-8")
    new = rewrite_readme(old, status, rows)
    index = run.parent / "README.md"
    old_index = index.read_text(encoding="utf-8") if index.exists() else ""
    cell = "finished" if len(rows) == total else f"in progress: {len(rows)} of {total} units"
    new_index = re.sub(
        r"(\[" + re.escape(run.name) + r"\]\([^)]*\)[^\n]*\| )(in progress: \d+ of \d+ units|finished)( \|)",
        lambda m: m.group(1) + cell + m.group(3),
        old_index,
    )
    stale = [p for p, a, b in ((readme, old, new), (index, old_index, new_index)) if a != b]
    if args.check:
        for path in stale:
            print(f"run-status: {path} is out of date", file=sys.stderr)
        return 1 if stale else 0
    readme.write_text(new, encoding="utf-8")
    if old_index:
        index.write_text(new_index, encoding="utf-8")
    print(f"run-status: {run}: {len(rows)} of {total} units; {status}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
