# nesy's static checks of a policy's source. Runs inside the embedded interpreter, before
# the audit hook is armed, on the parsed AST; the policy's code is never executed here.
import ast
import difflib
from _string import formatter_parser

# Names the policy may not use at all (in addition to every name starting with "_").
DENIED_NAMES = frozenset({
    "exec", "eval", "compile", "open", "globals", "vars", "locals", "getattr", "setattr",
    "delattr", "hasattr", "breakpoint", "input", "help", "dir", "id", "type", "memoryview",
    "bytearray", "classmethod", "staticmethod", "exit", "quit", "copyright", "credits",
    "license",
})

# Attributes that lead to frames, code objects or interpreter internals without an
# underscore prefix.
DENIED_ATTRIBUTES = frozenset({
    "gi_frame", "gi_code", "gi_yieldfrom", "cr_frame", "cr_code", "cr_await", "ag_frame",
    "ag_code", "ag_await", "tb_frame", "tb_next", "f_back", "f_globals", "f_locals",
    "f_builtins", "f_code", "f_trace", "co_code", "co_consts", "func_globals", "format_map",
    "mro",
})

ALLOWED_MODULES = frozenset({"math", "numpy", "robot"})

# Set by nesy when the runtime is prepared (interpreter.rs): every name a policy's globals
# hold before it runs (the curated builtins, the robot API functions, `robot`, `np`), and
# each API function's parameters as ((name, required), ...) with its rendered signature.
KNOWN_GLOBALS = frozenset()
API_PARAMETERS = {}
# The public names of each importable module, which `from M import *` binds.
STAR_EXPORTS = {}


class Checker(ast.NodeVisitor):
    def __init__(self):
        self.findings = []
        self.module_aliases = {"robot", "np", "math", "numpy"}

    def report(self, node, message):
        self.findings.append((getattr(node, "lineno", 1), getattr(node, "col_offset", 0) + 1, message))

    def check_identifier(self, node, name, what):
        if name.startswith("_") and name != "_":
            self.report(node, f"{what} {name!r} starts with an underscore")

    def visit_Name(self, node):
        # Reading __name__ (for the usual `if __name__ == "__main__":` guard) is harmless.
        if not (node.id == "__name__" and isinstance(node.ctx, ast.Load)):
            self.check_identifier(node, node.id, "name")
        if node.id in DENIED_NAMES:
            self.report(node, f"name {node.id!r} is not available in policies")
        self.generic_visit(node)

    def visit_Attribute(self, node):
        if node.attr.startswith("_"):
            self.report(node, f"attribute {node.attr!r} starts with an underscore")
        elif node.attr in DENIED_ATTRIBUTES:
            self.report(node, f"attribute {node.attr!r} is not available in policies")
        elif node.attr == "format" and not self.is_safe_format(node.value):
            self.report(node, "str.format is only allowed on a literal without attribute or index lookups in its fields")
        if isinstance(node.ctx, (ast.Store, ast.Del)) and self.base_name(node) in self.module_aliases:
            self.report(node, f"modules cannot be modified ({self.base_name(node)!r})")
        self.generic_visit(node)

    @staticmethod
    def base_name(node):
        while isinstance(node, (ast.Attribute, ast.Subscript)):
            node = node.value
        return node.id if isinstance(node, ast.Name) else None

    @staticmethod
    def is_safe_format(value):
        if not (isinstance(value, ast.Constant) and isinstance(value.value, str)):
            return False
        try:
            fields = list(formatter_parser(value.value))
        except ValueError:
            return False
        stack = list(fields)
        while stack:
            _literal, field, spec, _conv = stack.pop()
            if field is not None and ("." in field or "[" in field):
                return False
            if spec:
                try:
                    stack.extend(formatter_parser(spec))
                except ValueError:
                    return False
        return True

    def visit_arg(self, node):
        self.check_identifier(node, node.arg, "parameter")
        self.generic_visit(node)

    def visit_keyword(self, node):
        if node.arg is not None:
            self.check_identifier(node, node.arg, "keyword argument")
        self.generic_visit(node)

    def visit_FunctionDef(self, node):
        self.check_identifier(node, node.name, "function")
        self.generic_visit(node)

    def visit_ClassDef(self, node):
        self.check_identifier(node, node.name, "class")
        self.generic_visit(node)

    def visit_AsyncFunctionDef(self, node):
        self.report(node, "async functions are not available in policies")

    def visit_Await(self, node):
        self.report(node, "await is not available in policies")

    def visit_AsyncFor(self, node):
        self.report(node, "async for is not available in policies")

    def visit_AsyncWith(self, node):
        self.report(node, "async with is not available in policies")

    def visit_Global(self, node):
        for name in node.names:
            self.check_identifier(node, name, "name")

    def visit_Nonlocal(self, node):
        for name in node.names:
            self.check_identifier(node, name, "name")

    def visit_Import(self, node):
        for alias in node.names:
            top = alias.name.split(".")[0]
            if alias.name not in ALLOWED_MODULES:
                self.report(node, f"import of {alias.name!r} is not allowed (allowed: {', '.join(sorted(ALLOWED_MODULES))})")
            if alias.asname:
                self.check_identifier(node, alias.asname, "alias")
            self.module_aliases.add(alias.asname or top)

    def visit_ImportFrom(self, node):
        if node.level or node.module not in ALLOWED_MODULES:
            name = "." * node.level + (node.module or "")
            self.report(node, f"import from {name!r} is not allowed (allowed: {', '.join(sorted(ALLOWED_MODULES))})")
        for alias in node.names:
            self.check_identifier(node, alias.name, "imported name")
            if alias.asname:
                self.check_identifier(node, alias.asname, "alias")

    def visit_MatchAs(self, node):
        if node.name:
            self.check_identifier(node, node.name, "name")
        self.generic_visit(node)

    def visit_MatchStar(self, node):
        if node.name:
            self.check_identifier(node, node.name, "name")

    def visit_MatchMapping(self, node):
        if node.rest:
            self.check_identifier(node, node.rest, "name")
        self.generic_visit(node)

    def visit_ExceptHandler(self, node):
        if node.name:
            self.check_identifier(node, node.name, "name")
        self.generic_visit(node)


class Bindings(ast.NodeVisitor):
    """Every name the program binds anywhere (any scope): assignments, loop and `with`
    targets, definitions, parameters, imports, `except ... as`, `global`, match captures."""

    def __init__(self):
        self.names = set()

    def visit_Name(self, node):
        if isinstance(node.ctx, (ast.Store, ast.Del)):
            self.names.add(node.id)

    def visit_FunctionDef(self, node):
        self.names.add(node.name)
        self.generic_visit(node)

    visit_AsyncFunctionDef = visit_FunctionDef
    visit_ClassDef = visit_FunctionDef

    def visit_arg(self, node):
        self.names.add(node.arg)

    def visit_ImportFrom(self, node):
        for alias in node.names:
            if alias.name == "*":
                self.names.update(STAR_EXPORTS.get(node.module, ()))
            else:
                self.names.add(alias.asname or alias.name)

    def visit_alias(self, node):
        # `import a.b` binds `a`; (ImportFrom's aliases are handled above).
        self.names.add(node.asname or node.name.split(".")[0])

    def visit_ExceptHandler(self, node):
        if node.name:
            self.names.add(node.name)
        self.generic_visit(node)

    def visit_Global(self, node):
        self.names.update(node.names)

    visit_Nonlocal = visit_Global

    def visit_MatchAs(self, node):
        if node.name:
            self.names.add(node.name)
        self.generic_visit(node)

    def visit_MatchStar(self, node):
        if node.name:
            self.names.add(node.name)

    def visit_MatchMapping(self, node):
        if node.rest:
            self.names.add(node.rest)
        self.generic_visit(node)


def api_call_problem(node):
    """Why a call of a robot API function cannot bind to its parameters, or None. Calls
    with *args or **kwargs are left to the run time."""
    params, rendered = API_PARAMETERS[node.func.id]
    if any(isinstance(a, ast.Starred) for a in node.args) or any(k.arg is None for k in node.keywords):
        return None
    names = [name for name, _required in params]
    given = len(node.args)
    if given > len(params):
        return f"{node.func.id}() takes at most {len(params)} argument(s) ({given} given); signature: {rendered}"
    for keyword in node.keywords:
        if keyword.arg not in names:
            return f"{node.func.id}() has no parameter {keyword.arg!r}; signature: {rendered}"
        if names.index(keyword.arg) < given:
            return f"{node.func.id}() got two values for {keyword.arg!r}; signature: {rendered}"
    passed = set(names[:given]) | {k.arg for k in node.keywords}
    for name, required in params:
        if required and name not in passed:
            return f"{node.func.id}() is missing its argument {name!r}; signature: {rendered}"
    return None


def name_findings(tree):
    """Names the program reads that nothing defines (each would be a NameError once the
    robot has already moved), and robot API calls whose arguments do not fit."""
    bindings = Bindings()
    bindings.visit(tree)
    known = KNOWN_GLOBALS | bindings.names
    findings = []
    reported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load):
            # Underscore names are refused by the Checker already.
            if node.id in known or node.id.startswith("_") or node.id in reported:
                continue
            reported.add(node.id)
            close = difflib.get_close_matches(node.id, sorted(known), n=1, cutoff=0.7)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            findings.append((node.lineno, node.col_offset + 1,
                             f"name {node.id!r} is not defined: not a robot API function, an available builtin or a name the program assigns{hint}"))
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
              and node.func.id in API_PARAMETERS and node.func.id not in bindings.names):
            problem = api_call_problem(node)
            if problem:
                findings.append((node.lineno, node.col_offset + 1, problem))
    return findings


def check(source):
    """Returns a list of (line, column, message); empty if the source may run."""
    # CPython 3.11 refuses a null byte with ValueError, 3.12 and later with SyntaxError and
    # other wording: checked here so every version gives the same finding at its position.
    if "\0" in source:
        before = source[: source.index("\0")]
        line = before.count("\n") + 1
        column = len(before) - (before.rfind("\n") + 1) + 1
        return [(line, column, "invalid source: a null byte")]
    try:
        tree = ast.parse(source, filename="policy.py", mode="exec")
    except SyntaxError as err:
        return [(err.lineno or 1, err.offset or 1, f"syntax error: {err.msg}")]
    except ValueError as err:
        return [(1, 1, f"invalid source: {err}")]
    except (MemoryError, RecursionError):
        # CPython's parser gives up on deep nesting with an empty MemoryError (a long chain
        # of unary operators) or a RecursionError, neither with a position.
        return [(1, 1, "invalid source: nested too deeply for the parser")]
    checker = Checker()
    try:
        checker.visit(tree)
        names = name_findings(tree)
    except RecursionError:
        return [(1, 1, "invalid source: nested too deeply to check")]
    return sorted(checker.findings + names)
