#!/usr/bin/env python3
"""Lists the longest functions of the workspace's library and binary sources.

Reads `crates/*/src/**/*.rs` as text: a function runs from its `fn` line to the brace that
closes its body (strings, characters and comments are skipped when braces are counted);
`#[cfg(test)]` modules are left out.

    scripts/long_functions.py [--top N] [--over LINES]

Test functions in files of their own (a `tests.rs` module) are counted too; read them out.
"""
import argparse
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def code_only(text):
    """The text with comments, strings and char literals blanked (same length and lines)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'r(#*)"', text[i:])
            end = '"' + m.group(1)
            j = text.find(end, i + len(m.group(0)))
            j = n if j < 0 else j + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(re.sub(r"[^\n]", " ", text[i:j + 1]))
            i = j + 1
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:i + 4]):
            m = re.match(r"'(\\.|[^\\'])'", text[i:i + 4])
            out.append(" " * len(m.group(0)))
            i += len(m.group(0))
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    text = code_only(path.read_text())
    cut = text.find("#[cfg(test)]")
    if cut >= 0:
        text = text[:cut]
    for m in re.finditer(r"\bfn\s+(\w+)", text):
        body = text.find("{", m.end())
        semi = text.find(";", m.end())
        if body < 0 or (0 <= semi < body):
            continue
        depth, j = 0, body
        while j < len(text):
            depth += text[j] == "{"
            depth -= text[j] == "}"
            if depth == 0:
                break
            j += 1
        start = text.count("\n", 0, m.start()) + 1
        end = text.count("\n", 0, j) + 1
        yield m.group(1), start, end - start + 1


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--top", type=int, default=10)
    parser.add_argument("--over", type=int, default=None)
    args = parser.parse_args()
    rows = []
    for path in sorted((ROOT / "crates").glob("*/src/**/*.rs")):
        for name, line, length in functions(path):
            rows.append((length, f"{path.relative_to(ROOT)}:{line}", name))
    rows.sort(reverse=True)
    if args.over is not None:
        rows = [r for r in rows if r[0] > args.over]
    else:
        rows = rows[: args.top]
    for length, where, name in rows:
        print(f"{length:5d}  {name}  {where}")


if __name__ == "__main__":
    main()
