"""Checks that the stdlib zip of a static nesy binary holds everything the policy runtime uses.

stdlib_zip.py works the module set out from the runtime's sources, mostly statically. This
script tests the result the way the static binary will use it, in a few seconds and without
building anything with cargo:

1. It builds the zip into a temporary directory with stdlib_zip.py's derivation, compiled by
   the interpreter running this script (any CPython 3.11 to 3.13).
2. It starts a fresh isolated interpreter (-I -S) on this same file in child mode. After
   start-up the child makes the zip the only entry of sys.path (with zipimport as the only
   path hook) and forgets every module that came from a file, so nothing the start-up or
   the harness loaded can stand in for a module the zip lacks. C extension modules are
   offered only if the libpython that build-static.sh links has them built in (read from
   Debian's config.c for libpython3.11-pic.a); a plain interpreter keeps many of those as
   shared libraries, which a static binary cannot load.
3. The child then does what nesy's interpreter.rs does when it prepares the runtime, and
   more: re-imports what start-up loaded, imports the modules the Rust code imports, runs
   checker.py and numpy_shim.py as modules the way the Rust side runs them (the numpy subset
   under the curated builtins and the restricted import), hands the checker the globals
   and API parameters the Rust side would, runs the checker on a clean policy and on
   policies that set off each kind of finding (a misspelt name makes it go through
   difflib's "did you mean"), and calls most of the numpy subset. Other .py files in the
   runtime's folder are at least run as modules.
4. Finally every module the child has loaded must be built in, frozen, a permitted C
   extension or a file inside the zip.

Exit status 0 when all of that worked; 1 with a message naming the missing module and the
runtime file and line that needed it (or whatever else went wrong).

usage: python3 scripts/static/check_stdlib_zip.py
"""
import sys

# Child mode: what the interpreter loaded at start-up, before this file imported anything.
# Only os (frozen into libpython) is imported at the top; each mode imports what it needs, so
# the child loads little beyond start-up before it switches to the zip.
_STARTUP = sorted(sys.modules)

import os  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))

# The configuration of the libpython build-static.sh links; its module table lists the C
# modules built into it.
STATIC_LIBPYTHON_CONFIG = "/usr/lib/python3.11/config-3.11-x86_64-linux-gnu/config.c"

# The Rust sources the child mirrors (paths relative to the repository root).
BUILTINS_RS = "crates/nesy-policy/src/python/builtins.rs"
INTERPRETER_RS = "crates/nesy-policy/src/python/interpreter.rs"
ROBOT_MODULE_RS = "crates/nesy-policy/src/python/robot_module.rs"

# A few robot API signatures as interpreter.rs hands them to the checker (API_PARAMETERS):
# (parameter, required) pairs and the rendered signature. Enough to drive the checker's
# argument checks; the full list lives in robot_module::SIGNATURES.
API_PARAMETERS = {
    "get_obj_pos": ([("obj_name", True)], "get_obj_pos(obj_name)"),
    "move_gripper_to": (
        [("obj_name", True), ("pointing_to", False), ("depth", False)],
        "move_gripper_to(obj_name, pointing_to='down', depth=0.01)",
    ),
    "close_gripper": ([], "close_gripper()"),
}

# Policies for the checker: (what, source, substrings each expected among the findings).
# An empty list means the policy must pass without findings.
CLEAN_POLICY = '''\
import math
import numpy as np
from math import *
from robot import get_obj_pos


def lifted(name, height=0.1):
    pos = np.array(get_obj_pos(name))
    return pos + np.array([0.0, 0.0, height])


names = get_obj_names()
for name in names:
    if is_obj_visible(name):
        target = lifted(name)
        move_gripper_to(name, pointing_to="down")
        close_gripper()
        move_to_position(target, angle=sqrt(2.0) * pi / 8)
        open_gripper()
print("moved {} objects".format(len(names)), f"{len(names):d}")
'''

FINDINGS_POLICY = '''\
import os
cls = ().__class__
eval("1")
posn = get_obj_poss("cube")
move_gripper_to()
move_gripper_to("cube", colour=1)
label = "{0.real}".format(1)
robot.speed = 1
async def later():
    pass
'''

PROGRAMS = [
    ("a clean policy", CLEAN_POLICY, []),
    ("a policy with one finding of each kind", FINDINGS_POLICY, [
        "import of 'os' is not allowed",
        "attribute '__class__' starts with an underscore",
        "name 'eval' is not available in policies",
        "name 'get_obj_poss' is not defined",
        "did you mean 'get_obj_pos'?",
        "missing its argument 'obj_name'",
        "has no parameter 'colour'",
        "str.format is only allowed",
        "modules cannot be modified",
        "async functions are not available",
    ]),
    ("a misspelt builtin", "total = summ([1, 2])\n", ["did you mean 'sum'?"]),
    ("a syntax error", "def broken(:\n    pass\n", ["syntax error"]),
    ("a null byte", "x = 1\0\n", ["invalid source: a null byte"]),
    ("deeply nested unary operators", "x = " + "-" * 100000 + "1\n", ["invalid source"]),
    ("a deeply nested expression", "x = " + "+".join(["(1"] * 180) + ")" * 180 + "\n", []),
    # NFKC normalisation of identifiers makes the parser import unicodedata.
    ("a non-ASCII identifier", "\uff58 = 1\nprint(x)\n", []),
    # An invalid escape makes the compiler warn (DeprecationWarning or SyntaxWarning).
    ("a string with an invalid escape", 'pattern = "\\d"\nprint(pattern)\n', []),
]


def _numpy_exercise(np):
    """Calls across the numpy subset; returns a list of (what, ok)."""
    a = np.array([1.0, 2.0, 3.0])
    m = np.array([[1.0, 2.0], [3.0, 4.0]])
    results = [
        ("array arithmetic", (2 * a - a / 2 + 1).tolist() == [2.5, 4.0, 5.5]),
        ("dot", np.dot(a, a) == 14.0),
        ("cross", np.cross(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])).tolist() == [0.0, 0.0, 1.0]),
        ("linalg.norm", abs(np.linalg.norm(np.array([3.0, 4.0])) - 5.0) < 1e-12),
        ("transpose", m.T.tolist() == [[1.0, 3.0], [2.0, 4.0]]),
        ("shape and size", m.shape == (2, 2) and m.size == 4 and m.ndim == 2),
        ("indexing", m[1, 0] == 3.0 and m[0].tolist() == [1.0, 2.0]),
        ("mean over an axis", np.mean(m, axis=0).tolist() == [2.0, 3.0]),
        ("sum, min, max", np.sum(a) == 6.0 and np.amin(a) == 1.0 and np.amax(a) == 3.0),
        ("clip", np.clip(a, 1.5, 2.5).tolist() == [1.5, 2.0, 2.5]),
        ("sqrt and allclose", np.allclose(np.sqrt(np.array([4.0, 9.0])), np.array([2.0, 3.0]))),
        ("trigonometry",
         abs(np.arctan2(1.0, 1.0) - np.pi / 4) < 1e-12 and abs(np.cos(0.0) - 1.0) < 1e-12),
        ("argmax", np.argmax(a) == 2),
        ("linspace and arange",
         np.linspace(0.0, 1.0, 3).tolist() == [0.0, 0.5, 1.0] and list(np.arange(3)) == [0, 1, 2]),
        ("zeros, ones, reshape",
         np.zeros((2, 3)).shape == (2, 3) and np.ones(3).reshape(3, 1).shape == (3, 1)),
        ("concatenate", np.concatenate([a, a]).size == 6),
        ("comparisons", bool((a == a).all()) and bool((a > 2.0).any())),
        ("round", np.round(np.array([1.234, 5.678]), 1).tolist() == [1.2, 5.7]),
        ("repr", "1.0" in repr(a)),
    ]
    try:
        np.array([[1.0, 2.0], [3.0]])
        results.append(("ragged rows are refused", False))
    except ValueError:
        results.append(("ragged rows are refused", True))
    return results


# ---------------------------------------------------------------------------------------------
# Parent: build the zip, start the child, relay its verdict


def _load_stdlib_zip():
    import importlib.util
    spec = importlib.util.spec_from_file_location("nesy_stdlib_zip", os.path.join(HERE, "stdlib_zip.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _static_builtins():
    """Names of the C modules built into the static libpython, or None if its config.c is
    not installed (then the child lets every C extension of this interpreter through)."""
    import re
    try:
        with open(STATIC_LIBPYTHON_CONFIG, encoding="utf-8") as f:
            return sorted(set(re.findall(r'\{\s*"([\w.]+)"\s*,', f.read())))
    except OSError:
        return None


def _rust_list(stdlib_zip, root, path, pattern):
    """The quoted names in the first match of `pattern` in a Rust file (comments ignored)."""
    import re
    with open(os.path.join(root, path), encoding="utf-8") as f:
        _literals, code = stdlib_zip.rust_tokens(f.read())
    found = re.search(pattern, code, re.S)
    names = re.findall(r'"(\w+)"', found.group(1)) if found else []
    if not names:
        raise SystemExit(f"check_stdlib_zip: cannot read {pattern!r} from {path}; the check mirrors it")
    return names


def main():
    import json
    import re
    import subprocess
    import tempfile
    import time

    started = time.monotonic()
    sys.dont_write_bytecode = True  # no __pycache__ in the checkout for stdlib_zip.py
    stdlib_zip = _load_stdlib_zip()
    root = stdlib_zip.repository_root()
    result = stdlib_zip.derive(root)
    static_builtins = _static_builtins()
    stdlib_zip.report_problems(result, static_builtins=static_builtins)
    modules = stdlib_zip.zip_modules(result)
    with open(os.path.join(root, ROBOT_MODULE_RS), encoding="utf-8") as f:
        api_names = re.findall(r"\bsig!\(\s*(\w+)", f.read())
    if not api_names:
        raise SystemExit(f"check_stdlib_zip: no sig!(...) entries in {ROBOT_MODULE_RS}; the check mirrors them")
    with tempfile.TemporaryDirectory(prefix="nesy-stdlib-check-") as tmp:
        zip_path = os.path.join(tmp, "stdlib.zip")
        count, size = stdlib_zip.write_zip(zip_path, modules)
        config = {
            "root": root,
            "zip": zip_path,
            "files": result["runtime"]["files"],
            "rust_imports": [(name, where) for name, where in result["runtime"]["imports"]
                             if result["kinds"].get(name, ("missing",))[0] != "missing"],
            "static_builtins": static_builtins,
            "allowed_builtins": _rust_list(stdlib_zip, root, BUILTINS_RS,
                                           r"ALLOWED_BUILTINS[^=]*=\s*&\[(.*?)\]"),
            "allowed_modules": _rust_list(stdlib_zip, root, BUILTINS_RS,
                                          r"ALLOWED_MODULES[^=]*=\s*&\[(.*?)\]"),
            "policy_globals": _rust_list(stdlib_zip, root, INTERPRETER_RS,
                                         r"POLICY_GLOBALS[^=]*=\s*\[(.*?)\]"),
            "api_names": api_names,
        }
        child = subprocess.run(
            [sys.executable, "-I", "-S", os.path.abspath(__file__), "--child"],
            input=json.dumps(config), capture_output=True, text=True)
    sys.stdout.write(child.stdout)
    sys.stderr.write(child.stderr)
    elapsed = time.monotonic() - started
    if child.returncode != 0:
        print(f"check_stdlib_zip: FAILED (zip of {count} modules built by Python "
              f"{sys.version.split()[0]}; {elapsed:.1f} s)", file=sys.stderr)
        return 1
    print(f"check_stdlib_zip: ok: {count} modules ({size / 1e6:.2f} MB of bytecode) cover the runtime "
          f"under Python {sys.version.split()[0]} with sys.path = [the zip] ({elapsed:.1f} s)")
    return 0


# ---------------------------------------------------------------------------------------------
# Child: runs the runtime from the zip alone. After the switch it only uses builtins and
# objects it bound beforehand.


class _Failure(Exception):
    pass


def _child():
    import _imp
    import builtins
    import importlib
    import importlib.machinery
    import importlib.util
    import json
    import zipimport

    config = json.loads(sys.stdin.read())
    root = config["root"]
    zip_path = config["zip"]
    relative = lambda path: os.path.relpath(path, root)  # noqa: E731
    is_frozen = _imp.is_frozen
    invalidate_caches = importlib.invalidate_caches
    spec_from_file_location = importlib.util.spec_from_file_location
    ExtensionFileLoader = importlib.machinery.ExtensionFileLoader
    BuiltinImporter = importlib.machinery.BuiltinImporter
    FrozenImporter = importlib.machinery.FrozenImporter
    PathFinder = importlib.machinery.PathFinder
    extension_suffixes = list(importlib.machinery.EXTENSION_SUFFIXES)
    dynload = [p for p in sys.path if os.path.basename(p) == "lib-dynload"]
    static_builtins = config["static_builtins"]
    startup_files = [n for n in _STARTUP
                     if n != "__main__" and getattr(getattr(sys.modules[n], "__spec__", None), "origin", None)
                     not in (None, "built-in", "frozen")]

    emulated = {}  # name -> file: C extensions standing in for modules built into the static libpython
    wanted = []  # (name, phase) of imports no finder could satisfy

    class StaticLibpython:
        """Offers the C modules the static libpython has built in but this interpreter keeps
        in lib-dynload (all of lib-dynload when the static libpython's table is unknown)."""

        @classmethod
        def find_spec(cls, name, path=None, target=None):
            if name in sys.builtin_module_names or "." in name:
                return None
            if static_builtins is not None and name not in static_builtins:
                return None
            for directory in dynload:
                for suffix in extension_suffixes:
                    file = os.path.join(directory, name + suffix)
                    if os.path.isfile(file):
                        emulated[name] = file
                        return spec_from_file_location(name, file, loader=ExtensionFileLoader(name, file))
            return None

    class Unavailable:
        """Last on sys.meta_path: notes what nothing could import."""
        phase = "start-up"

        @classmethod
        def find_spec(cls, name, path=None, target=None):
            wanted.append((name, cls.phase))
            return None

    # The switch: the zip alone, then forget every module that came from a file. The import
    # caches are invalidated first, while the full library is still reachable (3.13's
    # invalidate_caches imports importlib.metadata); emptying sys.path_importer_cache then
    # makes the path finder build a fresh zipimporter for the zip on the first import.
    invalidate_caches()
    sys.path[:] = [zip_path]
    sys.path_hooks[:] = [zipimport.zipimporter]
    sys.path_importer_cache.clear()
    sys.meta_path[:] = [BuiltinImporter, FrozenImporter, StaticLibpython, PathFinder, Unavailable]
    for name, module in list(sys.modules.items()):
        origin = getattr(getattr(module, "__spec__", None), "origin", None)
        if name != "__main__" and origin not in ("built-in", "frozen"):
            del sys.modules[name]

    def where_in_zip(module):
        origin = getattr(getattr(module, "__spec__", None), "origin", None) or ""
        return origin.startswith(zip_path + os.sep)

    def describe_missing(name):
        if any(os.path.isfile(os.path.join(d, name + s)) for d in dynload for s in extension_suffixes):
            return (f"module {name!r} is a C extension that the static libpython does not have built in "
                    f"(not in {STATIC_LIBPYTHON_CONFIG}); a static binary cannot load it")
        return f"module {name!r} is not in the zip (and not built into or frozen in libpython)"

    def runtime_frames(tb, files):
        """(file, line) of the traceback's frames from the innermost one in a runtime file
        on (library code it called, which ended in the failed import); none of the
        harness's own or importlib's frames."""
        frames = []
        while tb is not None:
            frames.append((tb.tb_frame.f_code.co_filename, tb.tb_lineno))
            tb = tb.tb_next
        inner = max((k for k, (f, _l) in enumerate(frames) if f in files), default=None)
        if inner is None:
            return []
        return [(f, line) for f, line in frames[inner:] if not f.startswith("<frozen ")]

    def source_line(file, line):
        try:
            with open(file, encoding="utf-8") as f:
                return f.read().splitlines()[line - 1].strip()
        except (OSError, IndexError, UnicodeDecodeError):
            return ""

    files = list(config["files"])
    loaded_by = {}
    failures = []
    notes = []

    def phase(label, action, blame=None):
        """Runs `action()`; on failure records which module was missing and who imported it."""
        Unavailable.phase = label
        before = set(sys.modules)
        try:
            action()
        except ImportError as err:
            missing = isinstance(err, ModuleNotFoundError) and err.name
            lines = [describe_missing(err.name) if missing else f"{type(err).__name__}: {err}"]
            if blame:
                lines.append(f"imported by {blame}")
            for file, line in runtime_frames(err.__traceback__, files):
                shown = relative(file) if file in files else file
                text = source_line(file, line) if not file.startswith("<") else ""
                lines.append(f"at {shown}:{line}: {text}".rstrip(": "))
            lines.append(f"while {label}")
            failures.append(lines)
        except _Failure as err:
            failures.append([str(err), f"while {label}"])
        except Exception as err:
            lines = [f"{type(err).__name__}: {err}"]
            for file, line in runtime_frames(err.__traceback__, files):
                shown = relative(file) if file in files else file
                lines.append(f"at {shown}:{line}: {source_line(file, line)}".rstrip(": "))
            lines.append(f"while {label}")
            failures.append(lines)
        for name in set(sys.modules) - before:
            loaded_by.setdefault(name, label)

    def run_module(path, name, module_builtins):
        module = type(sys)(name)
        module.__dict__["__builtins__"] = module_builtins
        with open(path, encoding="utf-8") as f:
            code = compile(f.read(), path, "exec", dont_inherit=True)
        exec(code, module.__dict__)
        return module

    # 1. What the interpreter loaded from files at start-up, now from the zip.
    for name in startup_files:
        phase("re-importing what start-up loaded", lambda name=name: __import__(name),
              blame=f"the interpreter's start-up ({name})")

    # 2. The modules the Rust side imports while preparing the runtime; `robot` is nesy's own
    #    module (built into the binary), stood in for by a module with the API's names.
    robot = type(sys)("robot")
    for api in config["api_names"]:
        setattr(robot, api, lambda *args, **kwargs: None)
    for error in ("RobotError", "SandboxViolation"):
        setattr(robot, error, type(error, (Exception,), {}))
    sys.modules["robot"] = robot
    for name, where in config["rust_imports"]:
        phase(f"importing {name} as {where} does", lambda name=name: __import__(name), blame=where)

    checker_path = next((f for f in files if os.path.basename(f) == "checker.py"), None)
    numpy_path = next((f for f in files if os.path.basename(f) == "numpy_shim.py"), None)
    if checker_path is None or numpy_path is None:
        print("check_stdlib_zip: checker.py or numpy_shim.py is not among the runtime's files", file=sys.stderr)
        return 1
    state = {}

    # 3. The checker runs with the real builtins, the numpy subset with the curated ones.
    def run_checker():
        state["checker"] = run_module(checker_path, "nesy_checker", builtins)

    phase(f"running {relative(checker_path)} as a module", run_checker)

    importable = {"robot": robot}
    if "math" in sys.modules:
        importable["math"] = sys.modules["math"]

    def restricted_import(name, globals=None, locals=None, fromlist=None, level=0):
        if level != 0 or name not in config["allowed_modules"]:
            raise ImportError(f"import of '{name}' is not allowed in policies")
        if name not in importable:
            raise ImportError(f"module '{name}' is not available")
        return importable[name]

    curated = {name: getattr(builtins, name) for name in config["allowed_builtins"]}
    curated["__import__"] = restricted_import
    curated["__name__"] = "builtins"

    def run_numpy():
        state["numpy"] = importable["numpy"] = run_module(numpy_path, "numpy", curated)

    phase(f"running {relative(numpy_path)} as a module under the curated builtins", run_numpy)

    # 4. What interpreter.rs tells the checker.
    def tell_checker():
        checker = state["checker"]
        known = set(curated) | set(config["policy_globals"]) | set(config["api_names"])
        checker.KNOWN_GLOBALS = frozenset(known)
        checker.API_PARAMETERS = dict(API_PARAMETERS)
        checker.STAR_EXPORTS = {
            name: frozenset(n for n in dir(module) if not n.startswith("_"))
            for name, module in importable.items()
        }

    if "checker" in state and "numpy" in state:
        phase("giving the checker the policy globals", tell_checker)

    # 5. The checker on policies that take each of its paths.
    class Captured:
        def __init__(self):
            self.text = []

        def write(self, text):
            self.text.append(text)
            return len(text)

        def flush(self):
            pass

    if "checker" in state:
        for what, source, expected in PROGRAMS:
            def check(source=source, expected=expected, what=what):
                saved = sys.stderr
                sys.stderr = Captured()  # the compiler's warnings land here
                try:
                    findings = state["checker"].check(source)
                finally:
                    sys.stderr = saved
                messages = [message for _line, _column, message in findings]
                for piece in expected:
                    if not any(piece in message for message in messages):
                        raise _Failure(f"checker.check on {what} gave {findings!r}; expected a finding with {piece!r}")
                if not expected and findings:
                    raise _Failure(f"checker.check on {what} gave {findings!r}; expected none")

            phase(f"running {relative(checker_path)}: check() on {what}", check)

    # 6. The numpy subset.
    if "numpy" in state:
        def exercise():
            wrong = [what for what, ok in _numpy_exercise(state["numpy"]) if not ok]
            if wrong:
                raise _Failure(f"numpy subset gave unexpected results for: {', '.join(wrong)}")

        phase(f"calling the functions of {relative(numpy_path)}", exercise)

    # 7. Any other runtime Python file, at least as a module.
    for path in files:
        if path not in (checker_path, numpy_path):
            phase(f"running {relative(path)} as a module",
                  lambda path=path: run_module(path, "nesy_runtime_file", builtins))

    # 8. Everything loaded must be something the static binary has.
    for name, module in sorted(sys.modules.items()):
        origin = getattr(getattr(module, "__spec__", None), "origin", None)
        if name in ("__main__", "robot", "numpy") or module is state.get("checker"):
            continue
        if origin in ("built-in", "frozen") or name in sys.builtin_module_names or is_frozen(name):
            continue
        if where_in_zip(module) or name in emulated:
            continue
        failures.append([f"module {name!r} was loaded from {origin!r}, which a static binary does not have",
                         f"loaded while {loaded_by.get(name, 'the harness started')}"])

    seen = set()
    for name, label in wanted:
        if (name, label) not in seen and not any(label in " ".join(f) for f in failures):
            seen.add((name, label))
            notes.append(f"note: {name} was looked for while {label} and is not available; the code carried on without it")
    for note in notes:
        print(note)
    if static_builtins is None:
        print(f"note: {STATIC_LIBPYTHON_CONFIG} is not installed, so C extension modules were not "
              "checked against the static libpython")
    if failures:
        for lines in failures:
            print("check_stdlib_zip: " + lines[0], file=sys.stderr)
            for line in lines[1:]:
                print("    " + line, file=sys.stderr)
        return 1
    checked = len(PROGRAMS)
    print(f"child: {len(startup_files)} start-up modules re-imported, checker.py ran on {checked} policies, "
          f"numpy_shim.py exercised; {sum(1 for m in sys.modules.values() if where_in_zip(m))} modules came "
          f"from the zip, {len(emulated)} C modules stood in for built-in ones")
    return 0


if __name__ == "__main__":
    sys.exit(_child() if sys.argv[1:] == ["--child"] else main())
