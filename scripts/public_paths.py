#!/usr/bin/env python3
"""Lists the items of a library crate that are public under more than one path.

Reads the crate's `src/` as text: `pub mod` declarations make module paths public, items
declared `pub` (struct, enum, trait, fn, const, static, type, union, macro-free) are public
where every enclosing module is, and `pub use` adds a further path for what it names. A
re-export of another crate's item counts as a second path to that item. Items under
`#[cfg(test)]` and `#[doc(hidden)]` modules are left out.

    scripts/public_paths.py crates/nesy-core   # one line per item with two or more paths

Exit status 1 when an item has two or more public paths.
"""
import re
import sys
from pathlib import Path


def strip(text):
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'r#*"(?:.|\n)*?"#*', '""', text)
    text = re.sub(r'"(?:\\.|[^"\\])*"', '""', text)
    return text.split("#[cfg(test)]")[0]


def module_file(src, mod_path):
    base = src.joinpath(*mod_path) if mod_path else src
    if not mod_path:
        return src / "lib.rs"
    for cand in (base.with_suffix(".rs"), base / "mod.rs"):
        if cand.exists():
            return cand
    return None


def split_top(inner):
    parts, depth, cur = [], 0, ""
    for ch in inner:
        depth += ch == "{"
        depth -= ch == "}"
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    parts.append(cur)
    return [p.strip() for p in parts if p.strip()]


def expand(prefix, tree):
    """`a::{b, c::{d as e}}` -> [[a, b], [a, c, d, ("as", e)]]."""
    tree = tree.strip()
    m = re.match(r"^((?:\w+::)*)\{(.*)\}$", tree, re.S)
    if m:
        head = [x for x in m.group(1).split("::") if x]
        out = []
        for part in split_top(m.group(2)):
            out += expand(prefix + head, part)
        return out
    name, _, alias = tree.partition(" as ")
    path = prefix + [x for x in name.strip().split("::") if x]
    return [path + [("as", alias.strip())]] if alias else [path]


def main(crate_dir):
    src = Path(crate_dir) / "src"
    crate = Path(crate_dir).name.replace("-", "_")
    defs = {}      # canonical (mod_path tuple, name) -> list of public paths
    uses = []      # (mod_path, public?, target path list, alias)
    modules = {(): True}  # mod_path -> fully public?

    def walk(mod_path, public):
        f = module_file(src, list(mod_path))
        if f is None:
            return
        text = strip(f.read_text())
        for m in re.finditer(r"^\s*(pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;", text, re.M):
            is_pub = bool(m.group(1)) and "(" not in (m.group(1) or "")
            child = mod_path + (m.group(2),)
            modules[child] = public and is_pub
            walk(child, public and is_pub)
        for m in re.finditer(r"^pub\s+(?:async\s+|const\s+|unsafe\s+)*(struct|enum|trait|fn|const|static|type|union)\s+(\w+)", text, re.M):
            defs.setdefault((mod_path, m.group(2)), [])
            if public:
                defs[(mod_path, m.group(2))].append("::".join((crate,) + mod_path + (m.group(2),)))
        for m in re.finditer(r"^pub\s+use\s+([^;]+);", text, re.M):
            for target in expand([], re.sub(r"\s+", " ", m.group(1))):
                alias = None
                if target and isinstance(target[-1], tuple):
                    alias = target[-1][1]
                    target = target[:-1]
                uses.append((mod_path, public, target, alias))

    walk((), True)

    def resolve(mod_path, target):
        if not target:
            return None
        head, rest = target[0], target[1:]
        if head == "crate":
            base = ()
        elif head == "self":
            base = mod_path
        elif head == "super":
            base = mod_path[:-1]
            while rest and rest[0] == "super":
                base, rest = base[:-1], rest[1:]
        elif mod_path + (head,) in modules:
            base, rest = mod_path + (head,), rest
        elif head.startswith("nesy_") or head in ("std", "core"):
            return ("foreign", "::".join(target))
        else:
            base, rest = (), target
        path = base
        for i, part in enumerate(rest):
            if path + (part,) in modules and i < len(rest) - 1:
                path = path + (part,)
            else:
                return (path, part) if i == len(rest) - 1 else None
        return None

    changed = True
    seen = set()
    while changed:
        changed = False
        for mod_path, public, target, alias in uses:
            if not public or target and target[-1] == "*":
                continue
            r = resolve(mod_path, target)
            if r is None:
                continue
            name = alias or target[-1]
            path = "::".join((crate,) + mod_path + (name,))
            if r[0] == "foreign":
                key = ("foreign", r[1])
            else:
                key = r
                if key not in defs:
                    # a re-exported re-export: follow one hop
                    continue
            if (key, path) in seen:
                continue
            seen.add((key, path))
            defs.setdefault(key, []).append(path)
            changed = True
    bad = 0
    for key, paths in sorted(defs.items(), key=lambda kv: str(kv[0])):
        if key[0] == "foreign":
            paths = [key[1] + " (foreign)"] + paths
        if len(paths) > 1:
            bad += 1
            print(" = ".join(paths))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
