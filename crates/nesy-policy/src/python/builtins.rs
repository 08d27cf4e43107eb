//! The curated builtins a policy sees, and the import function that only hands out the
//! pre-imported allowlisted modules.

use pyo3::exceptions::PyImportError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyDict;

/// Builtins copied from the real `builtins` module. Everything that reaches code objects,
/// frames, files, the import system or arbitrary attributes is left out (`open`, `exec`,
/// `eval`, `compile`, `getattr`, `setattr`, `delattr`, `globals`, `locals`, `vars`, `dir`,
/// `type`, `id`, `input`, `breakpoint`, `memoryview`, `__import__`, ...).
pub(crate) const ALLOWED_BUILTINS: &[&str] = &[
    "abs",
    "all",
    "any",
    "bin",
    "bool",
    "callable",
    "chr",
    "dict",
    "divmod",
    "enumerate",
    "filter",
    "float",
    "format",
    "frozenset",
    "hash",
    "hex",
    "int",
    "isinstance",
    "issubclass",
    "iter",
    "len",
    "list",
    "map",
    "max",
    "min",
    "next",
    "object",
    "oct",
    "ord",
    "pow",
    "print",
    "property",
    "range",
    "repr",
    "reversed",
    "round",
    "set",
    "slice",
    "sorted",
    "staticmethod",
    "classmethod",
    "str",
    "sum",
    "super",
    "tuple",
    "zip",
    "True",
    "False",
    "None",
    "Ellipsis",
    "NotImplemented",
    "__build_class__",
    // exceptions a policy may raise or catch
    "BaseException",
    "Exception",
    "ArithmeticError",
    "AssertionError",
    "AttributeError",
    "IndexError",
    "KeyError",
    "LookupError",
    "NameError",
    "NotImplementedError",
    "OverflowError",
    "RecursionError",
    "RuntimeError",
    "StopIteration",
    "TimeoutError",
    "TypeError",
    "ValueError",
    "ZeroDivisionError",
];

/// Modules a policy may import, by the name it imports them under.
pub(crate) const ALLOWED_MODULES: &[&str] = &["math", "numpy", "robot"];

/// `__import__` for policies: returns the pre-imported module for an allowlisted name and
/// refuses everything else (relative imports included).
#[pyfunction(signature = (name, globals=None, locals=None, fromlist=None, level=0))]
#[allow(unused_variables)]
pub(crate) fn restricted_import<'py>(
    py: Python<'py>,
    name: &str,
    globals: Option<&Bound<'py, PyAny>>,
    locals: Option<&Bound<'py, PyAny>>,
    fromlist: Option<&Bound<'py, PyAny>>,
    level: i64,
) -> PyResult<Bound<'py, PyAny>> {
    if level != 0 || !ALLOWED_MODULES.contains(&name) {
        return Err(PyImportError::new_err(format!(
            "import of '{name}' is not allowed in policies (allowed: {})",
            ALLOWED_MODULES.join(", ")
        )));
    }
    match IMPORTABLE.get(py).map(|d| d.bind(py).get_item(name)) {
        Some(Ok(Some(module))) => Ok(module),
        _ => Err(PyImportError::new_err(format!(
            "module '{name}' is not available"
        ))),
    }
}

/// The modules [`restricted_import`] hands out, filled while the runtime is prepared.
static IMPORTABLE: PyOnceLock<Py<PyDict>> = PyOnceLock::new();

/// Makes a pre-imported module importable by policies under `name`.
pub(crate) fn register_module(py: Python<'_>, name: &str, module: &Bound<'_, PyAny>) -> PyResult<()> {
    IMPORTABLE
        .get_or_init(py, || PyDict::new(py).unbind())
        .bind(py)
        .set_item(name, module)
}

/// Builds the curated builtins dict from the interpreter's real builtins.
pub(crate) fn curated<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let real = py.import("builtins")?;
    let dict = PyDict::new(py);
    for name in ALLOWED_BUILTINS {
        dict.set_item(name, real.getattr(*name)?)?;
    }
    dict.set_item("__import__", wrap_pyfunction!(restricted_import, py)?)?;
    dict.set_item("__name__", "builtins")?;
    Ok(dict)
}
