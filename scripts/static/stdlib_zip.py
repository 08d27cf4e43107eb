"""Builds the zip of standard-library modules that a static nesy binary carries inside it.

A static binary has no standard library on disk: nesy-policy's interpreter.rs serves this zip
from a memfd and puts it on sys.path, so every pure-Python module the embedded runtime will
ever import has to be in it. The set is worked out from the runtime itself instead of being
written down by hand:

* The runtime's Python sources: every .py file in crates/nesy-policy/src/python/ (today the
  static checker and the numpy subset) and, from the Rust files of crates/nesy-policy/src
  that use pyo3, any .py file they pull in with include_str!/include_bytes! and the imports
  in any string literal that parses as Python and imports something (by statement, or by
  `__import__`/`import_module` with a constant name). Such inline Python is reported on
  stderr: it is better moved into a .py file. The module names the Rust code imports
  directly (`py.import("math")` and the like) are roots as well.
* A probe: a fresh interpreter started with -I -S runs each runtime source as a module, then
  imports the names the Rust side imports. What sys.modules holds before the first line of
  the probe is what the interpreter loads at start-up; what it holds afterwards is what the
  runtime needs at import time.
* A static pass with modulefinder over the same sources. In the runtime's own files every
  import counts, including imports inside functions that the probe never calls. In standard
  library modules only the code that runs when the module is imported is followed: function
  bodies and `if __name__ == "__main__":` blocks are left out, because following them drags
  in most of the library (ast's command-line main alone would add argparse, and heapq's
  self-test doctest, unittest and pdb). Imports that the runtime triggers lazily, deep inside
  a library function it calls, are covered by check_stdlib_zip.py, which runs the runtime
  against the zip alone.
* Every submodule of the encodings package, since the interpreter picks a codec at start-up
  from the locale and may need any of them. Their own imports are not followed (idna's
  stringprep, for one): only the locale's codec is needed, and a policy cannot import.

The union is kept to the standard library (files under the directory of os.py, not
site-packages). Modules built into or frozen into libpython are not needed; C extension
modules that live outside libpython cannot be loaded by a static binary and are reported on
stderr. Each remaining module is compiled by this interpreter to an unchecked hash-based .pyc
(there is no source file to validate it against) and written, sorted and with a fixed
timestamp, into an uncompressed (STORED) zip: zipimport would need zlib to read deflated
entries. Run it with the CPython minor version the binary links (Debian's python3.11).

usage: python3.11 -I -S stdlib_zip.py OUT.zip    write the zip
       python3.11 -I -S stdlib_zip.py --list     print the module names, one per line
"""
import argparse
import ast
import dis
import importlib.util
import inspect
import marshal
import modulefinder
import os
import re
import subprocess
import sys
import tempfile
import zipfile

# The runtime's Python files and the Rust code that drives the interpreter, relative to the
# repository root.
RUNTIME_PYTHON_DIR = os.path.join("crates", "nesy-policy", "src", "python")
RUNTIME_RUST_DIR = os.path.join("crates", "nesy-policy", "src")


def repository_root():
    """The checkout this script belongs to (it lives in scripts/static/)."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    if not os.path.isdir(os.path.join(root, RUNTIME_PYTHON_DIR)):
        raise SystemExit(f"{__file__}: expected {RUNTIME_PYTHON_DIR} under {root}")
    return root


# ---------------------------------------------------------------------------------------------
# Collecting the runtime's Python from the repository

_RAW_STRING = re.compile(r'(?:b|c)?r(#*)"')
_CHAR_LITERAL = re.compile(r"""b?'(?:\\(?:x[0-9a-fA-F]{2}|u\{[0-9a-fA-F_]+\}|.)|[^\\'\n])'""")
_ESCAPE = re.compile(r'\\(?:\n\s*|x([0-9a-fA-F]{2})|u\{([0-9a-fA-F_]+)\}|(.))', re.S)
_SIMPLE_ESCAPES = {"n": "\n", "r": "\r", "t": "\t", "\\": "\\", "0": "\0", "'": "'", '"': '"'}


def _unescape(body):
    def one(m):
        if m.group(1):
            return chr(int(m.group(1), 16))
        if m.group(2):
            return chr(int(m.group(2).replace("_", ""), 16))
        if m.group(3) is not None:
            return _SIMPLE_ESCAPES.get(m.group(3), m.group(0))
        return ""  # a backslash at the end of a line continues the string
    return _ESCAPE.sub(one, body)


def _placeholder(body):
    # What a literal leaves in the code text: module-name-like strings stay, so that
    # `py.import("math")` can be found; anything else becomes "" (keeping its line breaks).
    if re.fullmatch(r"[A-Za-z_][\w.]*", body):
        return f'"{body}"'
    return '""' + "\n" * body.count("\n")


def rust_tokens(text):
    """Splits Rust source into its string literals and the code without comments.

    Returns (literals, code): literals is a list of (line, value); code is the text with
    comments blanked and only name-like literals left, so regular expressions over it see
    code and the module names it passes.
    Good enough for nesy's own files: it knows line and nested block comments, char
    literals and lifetimes, plain, byte, C and raw strings."""
    literals = []
    code = []
    i, n = 0, len(text)
    while i < n:
        identifier_before = i > 0 and (text[i - 1].isalnum() or text[i - 1] == "_")
        if text.startswith("//", i):
            end = text.find("\n", i)
            i = n if end < 0 else end
            continue
        if text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    if text[i] == "\n":
                        code.append("\n")
                    i += 1
            continue
        raw = None if identifier_before else _RAW_STRING.match(text, i)
        if raw:
            close = '"' + raw.group(1)
            end = text.find(close, raw.end())
            end = n if end < 0 else end
            literals.append((text.count("\n", 0, i) + 1, text[raw.end():end]))
            code.append(_placeholder(text[raw.end():end]))
            i = end + len(close)
            continue
        prefixed = text[i] in "bc" and text.startswith('"', i + 1) and not identifier_before
        if text[i] == '"' or prefixed:
            start = i + (2 if prefixed else 1)
            j = start
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            literals.append((text.count("\n", 0, i) + 1, _unescape(text[start:j])))
            code.append(_placeholder(text[start:j]))
            i = j + 1
            continue
        if text[i] == "'":
            char = _CHAR_LITERAL.match(text, i)
            if char:
                code.append("' '")
                i = char.end()
                continue
        code.append(text[i])
        i += 1
    return literals, "".join(code)


_RUST_IMPORT = re.compile(
    r'(?:\bimport(?:_bound)?\s*\(\s*(?:[A-Za-z_]\w*\s*,\s*)?|PyImport_ImportModule\s*\(\s*)'
    r'c?"([A-Za-z_][\w.]*)"')
_INCLUDE = re.compile(r'include_(?:str|bytes)!\s*\(\s*"([^"]+\.py)"\s*\)')


def _python_imports(source):
    """The import statements of `source` (anywhere in it) as top-level code, or None when
    `source` is not Python or imports nothing."""
    if "import" not in source:
        return None
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        try:
            tree = ast.parse(inspect.cleandoc(source))
        except (SyntaxError, ValueError):
            return None
    imports = [node for node in ast.walk(tree) if isinstance(node, (ast.Import, ast.ImportFrom))]
    dynamic = [node for node in ast.walk(tree)
               if isinstance(node, ast.Call)
               and getattr(node.func, "id", getattr(node.func, "attr", None)) in ("__import__", "import_module")]
    if not imports and not dynamic:
        return None
    lines = []
    for node in imports:
        if isinstance(node, ast.ImportFrom) and node.level:
            continue
        lines.append(ast.unparse(node))
    for node in dynamic:
        if node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str):
            lines.append(f"import {node.args[0].value}")
    return "\n".join(lines) + "\n"


def collect_runtime(root):
    """The runtime's Python as seen from the repository.

    Returns a dict with
      files:    paths of the runtime's .py files,
      snippets: (label, import statements) for Python found in Rust string literals,
      imports:  (module, label) for modules the Rust code imports by name."""
    python_dir = os.path.join(root, RUNTIME_PYTHON_DIR)
    files = sorted(os.path.join(python_dir, f) for f in os.listdir(python_dir) if f.endswith(".py"))
    snippets = []
    imports = []
    for directory, _dirs, names in sorted(os.walk(os.path.join(root, RUNTIME_RUST_DIR))):
        for name in sorted(names):
            if not name.endswith(".rs"):
                continue
            path = os.path.join(directory, name)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            if "pyo3" not in text:
                continue  # does not talk to the interpreter
            where = os.path.relpath(path, root)
            literals, code = rust_tokens(text)
            for line, value in literals:
                found = _python_imports(value)
                if found:
                    snippets.append((f"{where}:{line} (inline Python)", found))
            for m in _RUST_IMPORT.finditer(code):
                imports.append((m.group(1), f"{where}:{code.count(chr(10), 0, m.start()) + 1}"))
            for included in _INCLUDE.findall(text):
                included = os.path.normpath(os.path.join(directory, included))
                if included not in files:
                    files.append(included)
    return {"files": files, "snippets": snippets, "imports": imports}


# ---------------------------------------------------------------------------------------------
# The probe, run in a fresh isolated interpreter

# Runs first in the child: nothing may be imported before the start-up snapshot and the run of
# the runtime's sources (marshal is built in). The analysis proper is this file's
# `_analyse`, loaded afterwards.
PROBE = r"""
import sys
startup = sorted(sys.modules)
import marshal
request = marshal.loads(sys.stdin.buffer.read())
problems = []
for label, source in request["run"]:
    namespace = {"__name__": "nesy_runtime_probe", "__builtins__": __builtins__}
    try:
        exec(compile(source, label, "exec", dont_inherit=True), namespace)
    except Exception as err:
        problems.append(f"running {label} failed: {type(err).__name__}: {err}")
for name, _where in request["imports"]:
    try:
        __import__(name)
    except ImportError:
        pass  # the robot module is nesy's own, built into the binary
loaded = sorted(sys.modules)
namespace = {"__name__": "nesy_stdlib_zip", "__file__": request["self"]}
with open(request["self"], encoding="utf-8") as f:
    exec(compile(f.read(), request["self"], "exec"), namespace)
namespace["_analyse"](request, startup, loaded, problems)
"""


def _main_guard_lines(path):
    """Line numbers inside the module-level `if __name__ == "__main__":` blocks of a file."""
    try:
        with open(path, "rb") as f:
            tree = ast.parse(f.read())
    except (OSError, SyntaxError, ValueError):
        return frozenset()
    lines = set()
    for node in tree.body:
        test = node.test if isinstance(node, ast.If) else None
        if not (isinstance(test, ast.Compare) and len(test.ops) == 1 and isinstance(test.ops[0], ast.Eq)):
            continue
        sides = [test.left, *test.comparators]
        if (any(isinstance(s, ast.Name) and s.id == "__name__" for s in sides)
                and any(isinstance(s, ast.Constant) and s.value == "__main__" for s in sides)):
            lines.update(range(node.body[0].lineno, node.end_lineno + 1))
    return frozenset(lines)


class _ImportTimeFinder(modulefinder.ModuleFinder):
    """modulefinder that follows everything in the scripts it is given (they are named
    __main__) but, in the modules they import, only code that runs at import time."""

    def __init__(self, path, scripts):
        super().__init__(path=path)
        self._scripts = frozenset(scripts)
        self._guards = {}

    def scan_code(self, co, m):
        if m.__name__ != "__main__" and co.co_flags & inspect.CO_OPTIMIZED:
            return  # a function body (or a comprehension) of a library module
        super().scan_code(co, m)

    def scan_opcodes(self, co):
        # The same events as modulefinder's own scan_opcodes, from the public dis API so it
        # does not depend on one version's bytecode details, minus __main__ blocks.
        skip = frozenset()
        if co.co_filename not in self._scripts:
            if co.co_filename not in self._guards:
                self._guards[co.co_filename] = _main_guard_lines(co.co_filename)
            skip = self._guards[co.co_filename]
        instructions = [i for i in dis.get_instructions(co) if i.opname not in ("EXTENDED_ARG", "CACHE")]
        for k, ins in enumerate(instructions):
            if ins.positions and ins.positions.lineno in skip:
                continue
            if ins.opname in ("STORE_NAME", "STORE_GLOBAL"):
                yield "store", (ins.argval,)
            elif (ins.opname == "IMPORT_NAME" and k >= 2
                  and instructions[k - 1].opcode in dis.hasconst and instructions[k - 2].opcode in dis.hasconst):
                level, fromlist = instructions[k - 2].argval, instructions[k - 1].argval
                if level == 0:
                    yield "absolute_import", (fromlist, ins.argval)
                else:
                    yield "relative_import", (level, fromlist, ins.argval)


def _classify(name, stdlib):
    """(kind, origin) of a module name in this interpreter: builtin, frozen, source (a .py
    file of the standard library), native (a C extension file of the standard library),
    outside (not part of the standard library) or missing."""
    import _imp
    if name in sys.builtin_module_names:
        return "builtin", ""
    if _imp.is_frozen(name):
        return "frozen", ""
    try:
        spec = importlib.util.find_spec(name)
    except Exception:
        return "missing", ""
    if spec is None:
        return "missing", ""
    origin = spec.origin or ""
    if origin in ("built-in", "frozen"):
        return ("builtin" if origin == "built-in" else "frozen"), ""
    if not os.path.isfile(origin):
        return "missing", ""  # namespace packages and the like
    relative = os.path.relpath(origin, stdlib)
    if relative.startswith(os.pardir) or relative.split(os.sep)[0] in ("site-packages", "dist-packages"):
        return "outside", origin
    return ("source" if origin.endswith(".py") else "native"), origin


def _analyse(request, startup, loaded, problems):
    """The second half of the probe: static analysis and classification; writes a
    marshalled dict to request["out"]."""
    stdlib = os.path.dirname(os.__file__)
    path = [p for p in sys.path
            if (p == stdlib or p.startswith(stdlib + os.sep))
            and not {"site-packages", "dist-packages"} & set(p.split(os.sep))]
    finder = _ImportTimeFinder(path, request["scripts"])
    for script in request["scripts"]:
        finder.run_script(script)
    for name, _where in request["imports"]:
        try:
            finder.import_hook(name)
        except ImportError:
            pass
    static = sorted(n for n in finder.modules if n != "__main__")
    import encodings
    import pkgutil
    codecs = sorted("encodings." + m.name for m in pkgutil.iter_modules(encodings.__path__))
    why = {}
    for reason, names in (("start-up", startup), ("encodings", ["encodings", *codecs]),
                          ("run", loaded), ("static", static)):
        for name in names:
            if name != "__main__":
                why.setdefault(name, reason)
    kinds = {}
    for name in sorted(why):
        kind, origin = _classify(name, stdlib)
        kinds[name] = (kind, origin)
    result = {
        "python": sys.version.split()[0],
        "startup": startup,
        "why": why,
        "kinds": kinds,
        "problems": problems,
    }
    with open(request["out"], "wb") as f:
        f.write(marshal.dumps(result))


def derive(root=None, python=None):
    """Works out the modules the runtime needs. Returns the probe's result dict plus the
    collected runtime (key "runtime"): see `_analyse` for the fields."""
    root = root or repository_root()
    runtime = collect_runtime(root)
    with tempfile.TemporaryDirectory(prefix="nesy-stdlib-") as tmp:
        run = []
        for path in runtime["files"]:
            with open(path, encoding="utf-8") as f:
                run.append((path, f.read()))
        scripts = list(runtime["files"])
        for k, (label, text) in enumerate(runtime["snippets"]):
            run.append((label, text))
            snippet = os.path.join(tmp, f"snippet{k}.py")
            with open(snippet, "w", encoding="utf-8") as f:
                f.write(text)
            scripts.append(snippet)
        out = os.path.join(tmp, "result.marshal")
        request = {"run": run, "scripts": scripts, "imports": runtime["imports"],
                   "out": out, "self": os.path.abspath(__file__)}
        probe = subprocess.run([python or sys.executable, "-I", "-S", "-c", PROBE],
                               input=marshal.dumps(request), capture_output=True)
        if probe.returncode != 0:
            raise SystemExit("the module probe failed:\n" + probe.stderr.decode(errors="replace"))
        with open(out, "rb") as f:
            result = marshal.load(f)
    result["runtime"] = runtime
    return result


def zip_modules(result):
    """name -> source file of the modules that go into the zip."""
    return {name: origin for name, (kind, origin) in result["kinds"].items() if kind == "source"}


def report_problems(result, out=sys.stderr, static_builtins=None):
    """Prints what the derivation could not settle: runtime sources that failed to run,
    inline Python in Rust files, and C extensions a static binary cannot load (those not
    built into this interpreter, or not in `static_builtins` when that names the C modules
    of the libpython the binary links)."""
    for problem in result["problems"]:
        print(f"warning: {problem}", file=out)
    for label, _text in result["runtime"]["snippets"]:
        print(f"note: Python with imports in a Rust string at {label}; it is analysed, but a "
              f".py file under {RUNTIME_PYTHON_DIR} would be clearer", file=out)
    for name, (kind, origin) in sorted(result["kinds"].items()):
        if kind == "native" and name not in (static_builtins or ()):
            print(f"warning: {name} ({result['why'][name]}) is a C extension outside libpython "
                  f"({origin}); a static binary cannot load it", file=out)


def pyc_bytes(source, code):
    # Unchecked hash-based pyc (flags = 0b01): there is no source file to validate against.
    flags = (1).to_bytes(4, "little")
    return importlib.util.MAGIC_NUMBER + flags + importlib.util.source_hash(source) + marshal.dumps(code)


def write_zip(out, modules):
    """Compiles `modules` (name -> source file) and writes them as a STORED zip to `out`.
    Returns (number of modules, bytes of bytecode)."""
    stdlib = os.path.dirname(os.__file__)
    entries = []
    for origin in modules.values():
        relative = os.path.relpath(origin, stdlib)
        with open(origin, "rb") as f:
            source = f.read()
        code = compile(source, relative, "exec", dont_inherit=True)
        entries.append((relative[:-3] + ".pyc", pyc_bytes(source, code)))
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_STORED) as z:
        for arcname, data in sorted(entries):
            info = zipfile.ZipInfo(arcname, date_time=(2020, 1, 1, 0, 0, 0))
            z.writestr(info, data, compress_type=zipfile.ZIP_STORED)
    return len(entries), sum(len(d) for _, d in entries)


def main(argv=None):
    parser = argparse.ArgumentParser(
        description="Build the standard-library zip embedded in static nesy binaries.")
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("out", nargs="?", help="the zip to write")
    what.add_argument("--list", action="store_true", help="print the module names instead")
    args = parser.parse_args(argv)
    result = derive()
    report_problems(result)
    modules = zip_modules(result)
    if args.list:
        print("\n".join(sorted(modules)))
        return
    count, total = write_zip(args.out, modules)
    print(f"{args.out}: {count} modules, {total / 1e6:.2f} MB of bytecode", file=sys.stderr)


if __name__ == "__main__":
    main()
