#!/usr/bin/env python3
"""Checks the rules ARCHITECTURE.md states about the crate graph, so that they cannot drift.

Each rule is a sentence of ARCHITECTURE.md ("Rules the graph keeps") made checkable:

- dependency rules, read from `cargo tree -e normal` (what a crate links when built as a
  dependency; dev-dependencies do not count);
- source rules, read from the crate's `src/` with comments removed (no I/O in nesy-core,
  no runtime built in the libraries);
- module rules: no two files of the listed crates import each other, directly or in a
  circle (`scripts/module_cycles.py`);
- API rules: no item of a library crate is public under two paths, its own or another
  crate's (`scripts/public_paths.py`).

Exit status 1 with one line per broken rule, naming the crate, the rule and what breaks it.

    scripts/check_architecture.py
"""
import functools
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# The workspace's own crates.
NESY = {
    "nesy-core", "nesy-input", "nesy-import", "nesy-sim", "nesy-policy", "nesy-vlm", "nesy-reasoner",
    "nesy-oracle", "nesy-pipeline", "nesy-bench", "nesy-baselines", "nesy-cli", "nesy-testkit", "nesy-view",
    "nesy-robot",
}
# What a crate that talks to models only must not link: the simulator, the sandbox,
# physics and CPython.
HEAVY = {"nesy-sim", "nesy-policy", "rapier3d", "pyo3"}

# crate -> (the nesy crates it may link, external crates it must not link, why)
DEPENDENCY_RULES = {
    "nesy-input": ({"nesy-input"}, set(), "nesy-input has no nesy dependency"),
    "nesy-core": ({"nesy-core"}, {"tokio", "reqwest", "rapier3d", "pyo3", "nesy-input"},
                  "nesy-core is pure: no I/O, no async runtime, no physics, no Python"),
    "nesy-vlm": ({"nesy-vlm", "nesy-input"}, HEAVY,
                 "the model client depends on no nesy crate but nesy-input"),
    "nesy-reasoner": ({"nesy-reasoner", "nesy-vlm", "nesy-input", "nesy-core"}, HEAVY,
                      "the reasoner links neither the simulator nor the Python sandbox"),
    "nesy-baselines": ({"nesy-baselines", "nesy-reasoner", "nesy-vlm", "nesy-input", "nesy-core"}, HEAVY,
                       "the baselines are call flows over the client and the reasoner's prompt pieces"),
    "nesy-sim": ({"nesy-sim", "nesy-core", "nesy-input"}, {"pyo3", "tokio", "reqwest"},
                 "the simulator links no model client, no async runtime and no Python"),
    "nesy-policy": ({"nesy-policy", "nesy-sim", "nesy-core", "nesy-input"}, {"tokio", "reqwest"},
                    "the sandbox knows nothing of models"),
    "nesy-import": ({"nesy-import", "nesy-sim", "nesy-core", "nesy-input"}, {"pyo3", "tokio", "reqwest"},
                    "importing reads pictures and writes a demo folder: no model, no runtime, no Python"),
    "nesy-oracle": ({"nesy-oracle", "nesy-reasoner", "nesy-vlm", "nesy-sim", "nesy-core", "nesy-input"},
                    {"pyo3"}, "the offline responder does not run programs"),
    "nesy-robot": ({"nesy-robot", "nesy-policy", "nesy-sim", "nesy-core", "nesy-input"}, {"tokio", "reqwest"},
                   "the robot bridge knows nothing of models and owns no async runtime: plain sockets and threads"),
    "nesy-view": ({"nesy-view"}, {"rapier3d", "pyo3", "reqwest"},
                  "pages and the read-only server know no nesy type: they are given text and pictures"),
}
# Only this crate may depend on pyo3 directly.
PYO3_OWNER = "nesy-policy"
# A crate no library or binary links: it is a dev-dependency only.
DEV_ONLY = "nesy-testkit"

# Crates whose files import each other in no circle.
ACYCLIC = ["nesy-sim", "nesy-input", "nesy-import", "nesy-reasoner", "nesy-oracle", "nesy-pipeline", "nesy-baselines", "nesy-bench",
           "nesy-cli", "nesy-testkit", "nesy-view", "nesy-robot"]

# Source rules: crate -> [(pattern, why)].
SOURCE_RULES = {
    "nesy-core": [
        (r"\bstd::(fs|net|process)\b|\bFile::|\bstdin\(\)|\bprintln!|\beprintln!",
         "nesy-core does no I/O"),
    ],
    "nesy-pipeline": [
        (r"Builder::new_multi_thread|Builder::new_current_thread|Runtime::new\(",
         "nesy-pipeline owns no async runtime; the CLI builds it"),
    ],
    "nesy-bench": [
        (r"Builder::new_multi_thread|Builder::new_current_thread|Runtime::new\(",
         "nesy-bench owns no async runtime; the CLI builds it"),
    ],
}


def cargo(*args):
    out = subprocess.run(["cargo", *args], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"cargo {' '.join(args)} failed:\n{out.stderr}")
    return out.stdout


@functools.lru_cache(maxsize=None)
def linked(crate):
    """Every package `crate` links in a normal build (itself included); asked of cargo once per
    crate, since several rules read the same crate's graph."""
    text = cargo("tree", "-p", crate, "-e", "normal", "--prefix", "none", "--format", "{p}")
    names = set()
    for line in text.splitlines():
        line = line.strip()
        if line:
            names.add(line.split()[0])
    return names


def direct_normal(crate):
    text = cargo("tree", "-p", crate, "-e", "normal", "--depth", "1", "--prefix", "none", "--format", "{p}")
    return {line.split()[0] for line in text.splitlines()[1:] if line.strip()}


def strip_comments(text):
    return re.sub(r"//[^\n]*", "", text)


def main():
    problems = []
    for crate, (allowed, banned, why) in DEPENDENCY_RULES.items():
        deps = linked(crate)
        for name in sorted((deps & NESY - allowed) | (deps & banned)):
            problems.append(f"{crate} links {name}: {why} (ARCHITECTURE.md)")
    for crate in sorted(NESY - {PYO3_OWNER}):
        if "pyo3" in direct_normal(crate):
            problems.append(f"{crate} depends on pyo3 directly: {PYO3_OWNER} is the only crate that embeds CPython")
    for crate in sorted(NESY - {DEV_ONLY}):
        if DEV_ONLY in linked(crate):
            problems.append(f"{crate} links {DEV_ONLY}: test support is a dev-dependency only")
    for crate, rules in SOURCE_RULES.items():
        for path in sorted((ROOT / "crates" / crate / "src").rglob("*.rs")):
            text = strip_comments(path.read_text())
            # Unit tests may do what the library does not.
            text = text.split("#[cfg(test)]")[0]
            for pattern, why in rules:
                for m in re.finditer(pattern, text):
                    line = text[: m.start()].count("\n") + 1
                    problems.append(f"{path.relative_to(ROOT)}:{line}: `{m.group(0)}`: {why}")
    for crate in ACYCLIC:
        out = subprocess.run([sys.executable, str(ROOT / "scripts/module_cycles.py"), str(ROOT / "crates" / crate / "src")],
                             capture_output=True, text=True)
        if out.returncode != 0:
            for line in out.stdout.splitlines():
                problems.append(f"{crate}: files import each other in a circle: {line}")
    for crate in sorted(NESY - {"nesy-cli"}):
        out = subprocess.run([sys.executable, str(ROOT / "scripts/public_paths.py"), str(ROOT / "crates" / crate)],
                             capture_output=True, text=True)
        for line in out.stdout.splitlines():
            problems.append(f"{crate}: public under two paths: {line}")
    for p in problems:
        print(p)
    checked = len(DEPENDENCY_RULES) + len(SOURCE_RULES) + len(ACYCLIC) + len(NESY - {"nesy-cli"}) + 2
    print(f"architecture: {checked} rules checked, {len(problems)} broken")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
