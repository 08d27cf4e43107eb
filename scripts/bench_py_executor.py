#!/usr/bin/env python3
"""A straightforward Python set-based symbolic executor, timed on nesy-core's workloads.

This is the kind of executor the NeSyCR authors wrote (states are Python sets of atom
tuples; preconditions are checked literal by literal, `forall` is expanded over the object
universe at evaluation time; deletes are applied before adds). It runs the same inputs as
nesy-core's criterion benches (exported by `cargo run -p nesy-core --example
export_workload`), checks that it reaches the same results, and prints its timings next to
criterion's and the ratio.

Usage:
    cargo run --release -p nesy-core --example export_workload -- /tmp/workload.json
    cargo bench -p nesy-core --bench core
    python3 scripts/bench_py_executor.py /tmp/workload.json --criterion "$CARGO_TARGET_DIR/criterion"
"""

import argparse
import json
import os
import time
import timeit


def tokenize(text):
    return text.replace("(", " ( ").replace(")", " ) ").split()


def parse_sexpr(text):
    tokens = tokenize(text)
    pos = 0

    def walk():
        nonlocal pos
        tok = tokens[pos]
        pos += 1
        if tok != "(":
            return tok
        items = []
        while tokens[pos] != ")":
            items.append(walk())
        pos += 1
        return items

    return walk()


def typed_vars(items):
    names, out, i = [], [], 0
    while i < len(items):
        if items[i] == "-":
            out += [(n, items[i + 1]) for n in names]
            names, i = [], i + 2
        else:
            names.append(items[i][1:])
            i += 1
    return out + [(n, "thing") for n in names]


def holds(f, state, env, objects):
    head = f[0]
    if head == "not":
        return not holds(f[1], state, env, objects)
    if head == "and":
        return all(holds(x, state, env, objects) for x in f[1:])
    if head == "or":
        return any(holds(x, state, env, objects) for x in f[1:])
    if head == "imply":
        return (not holds(f[1], state, env, objects)) or holds(f[2], state, env, objects)
    if head in ("forall", "exists"):
        names = [n for n, _ in typed_vars(f[1])]
        results = (holds(f[2], state, {**env, **dict(zip(names, combo))}, objects) for combo in product(objects, len(names)))
        return all(results) if head == "forall" else any(results)
    if head == "=":
        return resolve(f[1], env) == resolve(f[2], env)
    return (head,) + tuple(resolve(a, env) for a in f[1:]) in state


def product(objects, n):
    if n == 0:
        yield ()
        return
    for o in objects:
        for rest in product(objects, n - 1):
            yield (o,) + rest


def resolve(term, env):
    return env[term[1:]] if term.startswith("?") else term


def effects(e, state, env, objects, adds, dels):
    head = e[0]
    if head == "and":
        for x in e[1:]:
            effects(x, state, env, objects, adds, dels)
    elif head == "not":
        dels.add((e[1][0],) + tuple(resolve(a, env) for a in e[1][1:]))
    elif head == "forall":
        names = [n for n, _ in typed_vars(e[1])]
        for combo in product(objects, len(names)):
            effects(e[2], state, {**env, **dict(zip(names, combo))}, objects, adds, dels)
    elif head == "when":
        if holds(e[1], state, env, objects):
            effects(e[2], state, env, objects, adds, dels)
    else:
        adds.add((head,) + tuple(resolve(a, env) for a in e[1:]))


class Operator:
    def __init__(self, data):
        self.name = data["name"]
        self.pre = [parse_sexpr(p) for p in data["pre"]]
        self.eff = [parse_sexpr(e) for e in data["eff"]]


def apply(state, op, objects):
    """Returns (next_state, None) or (None, unmet preconditions)."""
    unmet = [p for p in op.pre if not holds(p, state, {}, objects)]
    if unmet:
        return None, unmet
    adds, dels = set(), set()
    for e in op.eff:
        effects(e, state, {}, objects, adds, dels)
    return (state - dels) | adds, None


def verify(init, ops, goal, objects):
    state = init
    for i, op in enumerate(ops):
        nxt, unmet = apply(state, op, objects)
        if unmet:
            return i, state, False
        state = nxt
    return None, state, holds(goal, state, {}, objects)


def atom_tuple(text):
    return tuple(parse_sexpr(text))


def criterion_ns(root, name):
    path = os.path.join(root, name.replace("/", "_"), "new", "estimates.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        estimates = json.load(f)
    # What criterion prints as "time": the slope estimate when it has one, else the mean.
    return (estimates.get("slope") or estimates["mean"])["point_estimate"]


def best_ns(stmt, number, timer):
    return min(timeit.repeat(stmt, number=number, repeat=5, timer=timer)) / number * 1e9


def fmt(ns):
    return f"{ns / 1000:.2f} µs" if ns < 1e6 else f"{ns / 1e6:.2f} ms"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("workload")
    ap.add_argument("--criterion", help="criterion output folder (…/target/criterion) for the ratio")
    ap.add_argument("--cpu", action="store_true",
                    help="time with process CPU time (time.process_time) instead of wall clock, to compare "
                         "with `cargo run --release -p nesy-core --example cpu_time` on a shared machine")
    args = ap.parse_args()
    with open(args.workload) as f:
        w = json.load(f)
    state = frozenset(atom_tuple(a) for a in w["state_200"])
    op20 = Operator(w["operator_20"])
    procedure = [Operator(o) for o in w["procedure_116"]]
    goal = parse_sexpr(w["goal_116"])
    objects = sorted({a for atom in state for a in atom[1:]} | {"box"})

    nxt, unmet = apply(state, op20, objects)
    assert unmet is None and len(nxt) == 200, (unmet, len(nxt) if nxt else None)
    failure, final, goal_ok = verify(state, procedure, goal, objects)
    assert failure is None and goal_ok, (failure, goal_ok)

    timer = time.process_time if args.cpu else time.perf_counter
    rows = [
        ("apply 20-literal operator, 200-atom state", "apply_20_literals_200_atoms/compiled",
         best_ns(lambda: apply(state, op20, objects), 20000, timer)),
        ("verify 116-step procedure", "verify_116_steps/compiled",
         best_ns(lambda: verify(state, procedure, goal, objects), 50, timer)),
    ]
    print("timing:", "process CPU time" if args.cpu else "wall clock (best of 5)")
    print(f"{'workload':<44} {'python':>12} {'nesy-core':>12} {'ratio':>8}")
    for label, bench, py in rows:
        rust = criterion_ns(args.criterion, bench) if args.criterion else None
        ratio = f"{py / rust:,.0f}×" if rust else "n/a"
        print(f"{label:<44} {fmt(py):>12} {fmt(rust) if rust else 'n/a':>12} {ratio:>8}")


if __name__ == "__main__":
    main()
