#!/usr/bin/env python3
"""What a model got wrong in a recorded benchmark run, most often first.

    scripts/model-errors.py RUN_DIR [--examples N]

Reads the run's cassettes and results (a folder `nesy bench run --record-cassettes` wrote)
and prints two tables:

- the corrections nesy sent back to the model (a re-ask's last message: the parser's or the
  verifier's reason), grouped by call purpose and the reason's first line, with the number of
  re-asks and `--examples` examples of the reply that was corrected;
- how the units ended: status and the first line of their error, grouped, with counts.

Exit 0, or 2 on bad input.
"""

import argparse
import collections
import json
import re
import sys
from pathlib import Path

from run_files import fail_input, interactions, is_verifier_rejection, reask


def reason_line(correction):
    """The line of a correction that names what was wrong, without the attempt count."""
    lines = [line for line in correction.splitlines() if line.strip()]
    if not lines:
        return "(empty)"
    first = re.sub(r"\s*\((attempt|proposal) \d+\)", "", lines[0]).rstrip(":")
    # "The symbolic verifier rejected this answer:" and "This patch was rejected:" head the
    # verifier's reasons; the reason itself is on the next line, without the step it names.
    if is_verifier_rejection(first) and len(lines) > 1:
        return re.sub(r"step \d+ \(\S+\)", "step N (action)", lines[1]).rstrip(":")
    return first


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("--examples", type=int, default=1)
    args = parser.parse_args()
    cassettes = sorted((args.run / "cassettes").glob("*/*.json"))
    if not cassettes:
        fail_input(f"{args.run / 'cassettes'}: no cassettes (<scenario>/<method>.json)")

    reasks = collections.Counter()
    examples = collections.defaultdict(list)
    for path in cassettes:
        for interaction in interactions(path):
            pair = reask(interaction)
            if pair is None:
                continue
            reply, correction = pair
            key = (interaction.get("purpose", "?"), reason_line(correction))
            reasks[key] += 1
            if len(examples[key]) < args.examples:
                examples[key].append(reply)

    print("## Re-asks: what nesy sent back, by call purpose\n")
    print("| purpose | reason | re-asks |")
    print("|---|---|---|")
    for (purpose, reason), count in reasks.most_common():
        print(f"| {purpose} | {reason.replace('|', '/')} | {count} |")
    for (purpose, reason), _ in reasks.most_common():
        for reply in examples[(purpose, reason)]:
            short = reply if len(reply) <= 600 else reply[:600] + " …"
            print(f"\n`{purpose}`, {reason}:\n\n```\n{short}\n```")

    outcomes = collections.Counter()
    for path in sorted((args.run / "results").glob("*.jsonl")):
        for line in path.read_text().splitlines():
            if not line.strip():
                continue
            try:
                record = json.loads(line)
            except json.JSONDecodeError as error:
                fail_input(f"{path}: {error}")
            error = (record.get("error") or "").splitlines()
            first = error[0] if error else ""
            outcomes[(record.get("method", "?"), record.get("status", "?"), first[:160])] += 1
    print("\n## How the units ended\n")
    print("| method | status | first line of the error | units |")
    print("|---|---|---|---|")
    for (method, status, first), count in sorted(outcomes.items()):
        print(f"| {method} | {status} | {first.replace('|', '/')} | {count} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
