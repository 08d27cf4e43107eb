#!/usr/bin/env python3
"""Per-method figures of a recorded benchmark run, from its records and cassettes.

    scripts/run-figures.py RUN [--replay REPLAY_RUN] [--scenarios ID,ID,...]

RUN is a folder `nesy bench run --record-cassettes` wrote (manifest.json, results/*.jsonl,
cassettes/<scenario>/<method>.json). Prints one Markdown table row per method:

- units and how they ended (status counts);
- SR as successes over units with a 95 % Wilson interval, GC mean over all units, and PD mean
  over the successful units only (as the paper's Table 1 does);
- model calls per unit, and the re-asks among them: replies the parser could not read, and
  replies it read that the symbolic verifier rejected (its correction starts "The symbolic
  verifier rejected" or "This patch was rejected"), with their share of all calls;
- replies that ran to their output-token cap (`finish_reason` "length");
- prompt and completion tokens per unit (the server's `usage`);
- server seconds per unit: the prompt and generation time llama.cpp reports with each reply
  (`timings`). With several calls in flight on a server of several slots, each call counts
  its own time, so the sum exceeds the wall clock; it never counts a call's time queued;
- with `--replay`, nesy's own seconds per unit: the `total_s` of the same unit in a run folder
  that an offline replay of the cassettes wrote (`scripts/rescore-run.py RUN --out DIR`
  writes DIR/run), so that no model time is in it;
- with `--scenarios`, only those scenarios' units, so that two runs can be set side by side
  over the scenarios they share.

A last line sums the run. Standard library only. Exit 0, or 2 on bad input.
"""

import argparse
import collections
import math
import sys
from pathlib import Path

from run_files import cassette_of, fail_input, interactions, is_verifier_rejection, last_records, reask

def wilson(successes, n, z=1.96):
    """The 95 % Wilson score interval of a proportion, in percent."""
    if n == 0:
        return (0.0, 100.0)
    p = successes / n
    denominator = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denominator
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denominator
    return (100 * max(0.0, centre - half), 100 * min(1.0, centre + half))


def cassette_counts(path):
    """Calls, re-asks by kind, capped replies, tokens and server milliseconds of a cassette."""
    counts = collections.Counter()
    for interaction in interactions(path):
        counts["calls"] += 1
        pair = reask(interaction)
        if pair is not None:
            counts["rejected" if is_verifier_rejection(pair[1]) else "unread"] += 1
        body = interaction.get("response", {}).get("body")
        if not isinstance(body, dict):
            continue
        choices = body.get("choices") or [{}]
        if choices[0].get("finish_reason") == "length":
            counts["capped"] += 1
        usage = body.get("usage") or {}
        counts["prompt_tokens"] += usage.get("prompt_tokens", 0)
        counts["completion_tokens"] += usage.get("completion_tokens", 0)
        timings = body.get("timings") or {}
        counts["server_ms"] += timings.get("prompt_ms", 0) + timings.get("predicted_ms", 0)
    return counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("--replay", type=Path, help="the run folder an offline replay wrote")
    parser.add_argument("--scenarios", help="count only these scenarios (comma-separated ids)")
    args = parser.parse_args()

    records = last_records(args.run)
    if args.scenarios:
        wanted = {name.strip() for name in args.scenarios.split(",") if name.strip()}
        unknown = sorted(wanted - {scenario for scenario, _, _ in records})
        if unknown:
            fail_input(f"--scenarios: {', '.join(unknown)}: no finished unit of the run {args.run}")
        records = {key: record for key, record in records.items() if key[0] in wanted}
    replayed = last_records(args.replay) if args.replay else {}
    # Only the cassettes of finished units count (a unit in flight has one too).
    counts = {}
    for scenario, variant, _ in records:
        path = cassette_of(args.run, scenario, variant)
        if (scenario, variant) not in counts and path.is_file():
            counts[(scenario, variant)] = cassette_counts(path)

    by_variant = collections.defaultdict(list)
    for key, record in records.items():
        by_variant[record["variant"]].append((key, record))

    print(
        "| method | units | statuses | SR [95 % Wilson] | GC mean | PD mean (successes) "
        "| calls / unit | re-asks: unread / rejected (share of calls) | replies at the cap "
        "| prompt / completion tokens per unit | server s / unit | nesy s / unit (replay) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    total = collections.Counter()
    for variant in sorted(by_variant):
        rows = by_variant[variant]
        n = len(rows)
        statuses = collections.Counter(record["status"] for _, record in rows)
        successes = int(sum(record["scores"]["sr"] for _, record in rows))
        low, high = wilson(successes, n)
        gc = sum(record["scores"]["gc"] for _, record in rows) / n
        pds = [record["scores"]["pd"] for _, record in rows if record["status"] == "succeeded"]
        pd = f"{sum(pds) / len(pds):.2f}" if pds else "–"
        summed = collections.Counter()
        for (scenario, _, _), _ in rows:
            summed.update(counts.get((scenario, variant), {}))
        total.update(summed)
        calls = summed["calls"]
        reasks = summed["unread"] + summed["rejected"]
        share = f"{100 * reasks / calls:.0f} %" if calls else "–"
        capped = f"{summed['capped']} / {calls}" if calls else "–"
        own = [replayed[key]["effort"]["total_s"] for key, _ in rows if key in replayed]
        own_s = f"{sum(own) / len(own):.2f}" if own else "–"
        ended = ", ".join(f"{status} {count}" for status, count in statuses.most_common())
        print(
            f"| {variant} | {n} | {ended} | {successes} / {n} [{low:.1f}, {high:.1f}] | {gc:.2f} "
            f"| {pd} | {calls / n:.1f} | {summed['unread']} / {summed['rejected']} ({share}) "
            f"| {capped} | {summed['prompt_tokens'] / n:,.0f} / {summed['completion_tokens'] / n:,.0f} "
            f"| {summed['server_ms'] / 1000 / n:,.0f} | {own_s} |"
        )
    own_total = sum(r["effort"]["total_s"] for key, r in replayed.items() if key in records)
    print(
        f"\n{len(records)} units, {total['calls']:,} calls, "
        f"{total['prompt_tokens']:,} prompt and {total['completion_tokens']:,} completion tokens, "
        f"{total['server_ms'] / 3.6e6:.1f} server hours"
        + (f"; nesy's own time in the replay {own_total:.1f} s" if replayed else "")
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
