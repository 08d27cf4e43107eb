//! Starting the embedded interpreter: the audit hook and the `robot` module are registered
//! first, then CPython starts from an isolated `PyConfig` (no environment variables, no
//! site-packages, no user directory, no signal handlers). In static builds the standard
//! library comes from a zip embedded in the binary and served from a memfd.
//!
//! After start-up nesy imports everything a policy may ever need (the allowlisted modules,
//! the static checker and its `ast` dependencies), so the armed audit hook can refuse every
//! later import.

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use pyo3::ffi;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyModule};

use super::robot_module::robot;
use super::{audit, budget, builtins, robot_module};

/// Why the interpreter could not start.
#[derive(Clone, Debug, thiserror::Error)]
pub enum InitError {
    /// `Py_InitializeFromConfig` failed.
    #[error("embedded Python failed to start: {0}")]
    Startup(String),
    /// Importing the modules policies need failed.
    #[error("embedded Python could not prepare the policy runtime: {0}")]
    Prepare(String),
    /// The embedded standard library could not be served.
    #[error("cannot serve the embedded standard library: {0}")]
    Stdlib(String),
}

const CHECKER_SOURCE: &str = include_str!("checker.py");
const NUMPY_SHIM_SOURCE: &str = include_str!("numpy_shim.py");
/// The same sources compiled at build time by the interpreter pyo3 links (see build.rs);
/// empty if that was not possible.
const CHECKER_CODE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/checker.marshal"));
const NUMPY_SHIM_CODE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/numpy_shim.marshal"));

/// The stdlib zip, only in static builds (`--features embedded-stdlib`, with
/// `NESY_STDLIB_ZIP` pointing at the zip when compiling).
#[cfg(feature = "embedded-stdlib")]
const EMBEDDED_STDLIB: Option<&[u8]> = Some(include_bytes!(env!("NESY_STDLIB_ZIP")));
#[cfg(not(feature = "embedded-stdlib"))]
const EMBEDDED_STDLIB: Option<&[u8]> = None;

static STARTED: OnceLock<Result<StartupTimes, InitError>> = OnceLock::new();

/// How long the interpreter took to start, measured once per process.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StartupTimes {
    /// `Py_InitializeFromConfig` with the isolated config (and the memfd stdlib, if embedded).
    pub interpreter: Duration,
    /// Preparing the policy runtime: importing `robot`, `math`, the static checker (with
    /// `ast` and `string`) and compiling the `numpy` subset.
    pub prepare: Duration,
}

impl StartupTimes {
    /// Both phases together.
    pub fn total(&self) -> Duration {
        self.interpreter + self.prepare
    }
}

/// Starts the interpreter once per process; later calls return the times of the first.
pub fn initialize() -> Result<StartupTimes, InitError> {
    STARTED
        .get_or_init(|| {
            let t0 = Instant::now();
            // SAFETY: runs once, before anything else touches the interpreter.
            unsafe { start()? };
            let interpreter = t0.elapsed();
            let t1 = Instant::now();
            Python::attach(|py| prepared(py).map(|_| ()))?;
            Ok(StartupTimes {
                interpreter,
                prepare: t1.elapsed(),
            })
        })
        .clone()
}

fn wide(s: &str) -> Vec<libc::wchar_t> {
    s.chars()
        .map(|c| c as libc::wchar_t)
        .chain(std::iter::once(0))
        .collect()
}

unsafe fn check(status: ffi::PyStatus, what: &str) -> Result<(), InitError> {
    // SAFETY: `status` came from a PyConfig call.
    if unsafe { ffi::PyStatus_Exception(status) } == 0 {
        return Ok(());
    }
    let message = if status.err_msg.is_null() {
        "unknown error".to_owned()
    } else {
        // SAFETY: CPython sets a static NUL-terminated message.
        unsafe { std::ffi::CStr::from_ptr(status.err_msg) }
            .to_string_lossy()
            .into_owned()
    };
    Err(InitError::Startup(format!("{what}: {message}")))
}

/// Writes the embedded zip to a sealed memfd and returns its `/proc/self/fd/N` path.
fn serve_stdlib(zip: &[u8]) -> Result<String, InitError> {
    // SAFETY: plain syscalls on a fresh descriptor.
    unsafe {
        let fd = libc::memfd_create(c"nesy-stdlib".as_ptr(), libc::MFD_ALLOW_SEALING);
        if fd < 0 {
            return Err(InitError::Stdlib(format!(
                "memfd_create: {}",
                std::io::Error::last_os_error()
            )));
        }
        let mut written = 0;
        while written < zip.len() {
            let n = libc::write(fd, zip[written..].as_ptr().cast(), zip.len() - written);
            if n <= 0 {
                return Err(InitError::Stdlib(format!(
                    "write: {}",
                    std::io::Error::last_os_error()
                )));
            }
            written += n as usize;
        }
        libc::fcntl(
            fd,
            libc::F_ADD_SEALS,
            libc::F_SEAL_WRITE | libc::F_SEAL_GROW | libc::F_SEAL_SHRINK | libc::F_SEAL_SEAL,
        );
        Ok(format!("/proc/self/fd/{fd}"))
    }
}

unsafe fn start() -> Result<(), InitError> {
    audit::install();
    pyo3::append_to_inittab!(robot);
    let stdlib_path = EMBEDDED_STDLIB.map(serve_stdlib).transpose()?;
    // SAFETY: PyConfig is plain data initialised by PyConfig_InitIsolatedConfig; it is
    // cleared before returning.
    unsafe {
        let mut config = std::mem::MaybeUninit::<ffi::PyConfig>::zeroed();
        ffi::PyConfig_InitIsolatedConfig(config.as_mut_ptr());
        let config = config.assume_init_mut();
        config.site_import = 0;
        config.write_bytecode = 0;
        config.install_signal_handlers = 0;
        config.user_site_directory = 0;
        config.parse_argv = 0;
        config.pathconfig_warnings = 0;
        config.faulthandler = 0;
        let result = (|| {
            if let Some(path) = &stdlib_path {
                let path = wide(path);
                check(
                    ffi::PyWideStringList_Append(&mut config.module_search_paths, path.as_ptr()),
                    "search path",
                )?;
                config.module_search_paths_set = 1;
                let home = wide("/nonexistent");
                check(
                    ffi::PyConfig_SetString(config, &mut config.home, home.as_ptr()),
                    "home",
                )?;
            }
            check(ffi::Py_InitializeFromConfig(config), "Py_InitializeFromConfig")
        })();
        ffi::PyConfig_Clear(config);
        result?;
        ffi::PyEval_SaveThread();
    }
    Ok(())
}

/// Objects prepared once after start-up.
pub(crate) struct Prepared {
    pub checker: Py<PyAny>,
    pub robot: Py<PyModule>,
    pub numpy: Py<PyModule>,
    /// `name -> function` of the robot API, injected into every policy's globals.
    pub api: Vec<(&'static str, Py<PyAny>)>,
    /// `None` compiled in eval mode: evaluated to consume queued asynchronous exceptions.
    pub noop: Py<PyAny>,
}

static PREPARED: PyOnceLock<Result<Prepared, InitError>> = PyOnceLock::new();

/// The prepared runtime objects (created on first use).
pub(crate) fn prepared(py: Python<'_>) -> Result<&Prepared, InitError> {
    PREPARED
        .get_or_init(py, || prepare(py).map_err(|e| InitError::Prepare(e.to_string())))
        .as_ref()
        .map_err(Clone::clone)
}

/// The names a policy's module globals hold besides the curated builtins and the robot API
/// functions; `runner::execute` sets exactly these.
pub(crate) const POLICY_GLOBALS: [&str; 4] = ["__builtins__", "__name__", "robot", "np"];

/// Gives the static checker what the policy's globals will hold (`KNOWN_GLOBALS`) and the
/// robot API's parameters (`API_PARAMETERS`), so it can refuse undefined names and API calls
/// whose arguments cannot bind before anything runs.
fn tell_checker_the_globals(
    py: Python<'_>,
    checker: &Bound<'_, PyModule>,
    importable: [(&str, &Bound<'_, PyModule>); 3],
) -> PyResult<()> {
    // The curated builtins' own keys (so `__import__` and every allowed name come from the one
    // list that builds them), the module globals, and the API functions.
    let mut known: Vec<String> = builtins::curated(py)?
        .keys()
        .iter()
        .map(|k| k.extract::<String>())
        .collect::<PyResult<_>>()?;
    known.extend(POLICY_GLOBALS.iter().map(|s| s.to_string()));
    known.extend(robot_module::SIGNATURES.iter().map(|s| s.name.to_string()));
    checker.setattr("KNOWN_GLOBALS", pyo3::types::PyFrozenSet::new(py, &known)?)?;
    let parameters = PyDict::new(py);
    for sig in robot_module::SIGNATURES {
        let params: Vec<(&str, bool)> = sig
            .params
            .iter()
            .map(|(name, default)| (*name, default.is_none()))
            .collect();
        parameters.set_item(sig.name, (params, sig.render()))?;
    }
    checker.setattr("API_PARAMETERS", parameters)?;
    let exports = PyDict::new(py);
    for (name, module) in importable {
        let public: Vec<String> = module
            .dir()?
            .iter()
            .filter_map(|n| n.extract::<String>().ok())
            .filter(|n| !n.starts_with('_'))
            .collect();
        exports.set_item(name, pyo3::types::PyFrozenSet::new(py, &public)?)?;
    }
    checker.setattr("STAR_EXPORTS", exports)
}

fn prepare(py: Python<'_>) -> PyResult<Prepared> {
    let robot = py.import("robot")?;
    let math = py.import("math")?;
    builtins::register_module(py, "robot", robot.as_any())?;
    builtins::register_module(py, "math", math.as_any())?;
    // The checker runs with the real builtins: it is nesy's code and never sees the policy run.
    let checker_module = PyModule::new(py, "nesy_checker")?;
    run_module_code(
        py,
        &checker_module,
        CHECKER_CODE,
        CHECKER_SOURCE,
        "<nesy-checker>",
    )?;
    let checker = checker_module.getattr("check")?.unbind();
    // The numpy subset runs with the policy's curated builtins.
    let numpy = PyModule::new(py, "numpy")?;
    numpy.dict().set_item("__builtins__", builtins::curated(py)?)?;
    run_module_code(py, &numpy, NUMPY_SHIM_CODE, NUMPY_SHIM_SOURCE, "<numpy-subset>")?;
    builtins::register_module(py, "numpy", numpy.as_any())?;
    robot_module::set_array_constructor(py, numpy.getattr("array")?.unbind());
    budget::set_violation_type(py.get_type::<robot_module::SandboxViolation>().as_ptr());
    tell_checker_the_globals(
        py,
        &checker_module,
        [("robot", &robot), ("math", &math), ("numpy", &numpy)],
    )?;
    let mut api = Vec::with_capacity(robot_module::SIGNATURES.len());
    for sig in robot_module::SIGNATURES {
        api.push((sig.name, robot.getattr(sig.name)?.unbind()));
    }
    let noop = py
        .import("builtins")?
        .getattr("compile")?
        .call1(("None", "<nesy-noop>", "eval"))?
        .unbind();
    Ok(Prepared {
        checker,
        robot: robot.unbind(),
        numpy: numpy.unbind(),
        api,
        noop,
    })
}

/// Executes nesy's own module code in `module`: the build-time compiled code object when it
/// loads (same interpreter version), else the source compiled now.
fn run_module_code(
    py: Python<'_>,
    module: &Bound<'_, PyModule>,
    marshalled: &[u8],
    source: &str,
    file: &str,
) -> PyResult<()> {
    let precompiled = if marshalled.is_empty() {
        None
    } else {
        py.import("marshal")?
            .getattr("loads")?
            .call1((pyo3::types::PyBytes::new(py, marshalled),))
            .ok()
    };
    let code = match precompiled {
        Some(code) => code,
        None => py
            .import("builtins")?
            .getattr("compile")?
            .call1((source, file, "exec"))?,
    };
    let globals: Bound<'_, PyDict> = module.dict();
    if !globals.contains("__builtins__")? {
        globals.set_item("__builtins__", py.import("builtins")?)?;
    }
    // SAFETY: GIL held; `code` is a code object and `globals` a dict.
    let ran = unsafe { ffi::PyEval_EvalCode(code.as_ptr(), globals.as_ptr(), globals.as_ptr()) };
    if ran.is_null() {
        return Err(PyErr::fetch(py));
    }
    // SAFETY: `ran` is a new reference we own.
    unsafe { ffi::Py_DECREF(ran) };
    Ok(())
}
