#!/usr/bin/env python3
"""Lists import cycles between the source files of a crate.

A file imports another when it names a path into it: `use crate::a::b`, `crate::a::b::f()`,
`super::x` or a child module's `self::`-free path. Paths are resolved to the file that
defines the deepest module they name. Any strongly connected group of two or more files is
a cycle. Exit status 1 when there is one.

    scripts/module_cycles.py crates/nesy-sim/src
"""
import re
import sys
from pathlib import Path


def module_of(root: Path, path: Path) -> tuple:
    rel = path.relative_to(root).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return tuple(parts)


def main(src: str) -> int:
    root = Path(src)
    files = {module_of(root, p): p for p in root.rglob("*.rs")}
    edges = {m: set() for m in files}
    for mod, path in files.items():
        text = path.read_text()
        # Drop comments so doc examples and prose do not count.
        text = re.sub(r"//[^\n]*", "", text)
        is_dir_module = path.name in ("mod.rs", "lib.rs")
        parent = mod if is_dir_module else mod[:-1]
        refs = [tuple(m.split("::")) for m in re.findall(r"\bcrate((?:::\w+)+)", text)]
        refs = [r[1:] for r in refs]
        for m in re.findall(r"\bsuper((?:::\w+)+)", text):
            refs.append(parent[:-1] + tuple(m.split("::")[1:]) if is_dir_module else parent + tuple(m.split("::")[1:]))
        for r in refs:
            # The deepest module prefix that is a file.
            for k in range(len(r), 0, -1):
                if r[:k] in files:
                    target = r[:k]
                    break
            else:
                continue
            # A file naming its own descendants or ancestors' items is not an edge to itself.
            if target != mod:
                edges[mod].add(target)
    # Tarjan's strongly connected components.
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            sccs.append(comp)

    sys.setrecursionlimit(10000)
    for v in sorted(files):
        if v not in index:
            visit(v)
    cycles = [c for c in sccs if len(c) > 1]
    for c in cycles:
        print("cycle:", " <-> ".join(str(files[m].relative_to(root)) for m in sorted(c)))
    if not cycles:
        print(f"no import cycles among {len(files)} files under {src}")
    return 1 if cycles else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "crates/nesy-sim/src"))
