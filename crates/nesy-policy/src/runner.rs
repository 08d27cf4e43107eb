//! Running a policy inside this process: static checks, then the policy as module
//! `__main__` under the armed audit hook, the trace budget and the watchdog.
//!
//! One episode runs at a time per process (there is one interpreter). In-process runs are
//! for tests, benchmarks and trusted code: the boundary against hostile code is the worker
//! process of [`crate::worker`], which calls this inside its rlimits.

use std::sync::Mutex;
use std::time::{Duration, Instant};

use pyo3::ffi;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::episode::Episode;
use crate::limits::Limits;
use crate::python::abort::{self, AbortReason};
use crate::python::audit;
use crate::python::budget::{self, Watchdog};
use crate::python::builtins;
use crate::python::interpreter::{self, InitError};
use crate::python::output::OutputWriter;
use crate::python::session::{self, ActiveEpisode, TraceSink};
use crate::result::{ExecutionResult, Outcome, PythonError, StaticViolation, TracebackFrame};

/// File name the policy's code is compiled under; tracebacks refer to it.
pub const POLICY_FILE: &str = "policy.py";

static ONE_EPISODE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Runs the static checks only: the findings, empty if the source may run.
pub fn check_source(source: &str) -> Result<Vec<StaticViolation>, InitError> {
    interpreter::initialize()?;
    let _serial = ONE_EPISODE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    Python::attach(|py| static_check(py, source))
}

fn static_check(py: Python<'_>, source: &str) -> Result<Vec<StaticViolation>, InitError> {
    let prepared = interpreter::prepared(py)?;
    let findings = prepared
        .checker
        .bind(py)
        .call1((source,))
        .and_then(|f| f.extract::<Vec<(u32, u32, String)>>())
        .map_err(|e| InitError::Prepare(format!("static checker failed: {e}")))?;
    Ok(findings
        .into_iter()
        .map(|(line, column, message)| StaticViolation {
            line,
            column,
            message,
        })
        .collect())
}

/// Runs `source` against `episode` in this process and finishes the episode (settle and
/// goal checks) unless the policy was rejected. `sink` receives trace entries as they
/// happen.
pub fn run_in_process(
    source: &str,
    episode: Box<dyn Episode>,
    limits: &Limits,
    sink: Option<TraceSink>,
) -> Result<ExecutionResult, InitError> {
    run(source, episode, limits, sink, true)
}

/// Like [`run_in_process`] but without the static checks (layer 1), so tests can show that
/// the later layers stop what the static checks would have rejected. Never use it for
/// untrusted code outside such tests.
#[doc(hidden)]
pub fn run_in_process_without_static_checks(
    source: &str,
    episode: Box<dyn Episode>,
    limits: &Limits,
    sink: Option<TraceSink>,
) -> Result<ExecutionResult, InitError> {
    run(source, episode, limits, sink, false)
}

fn run(
    source: &str,
    mut episode: Box<dyn Episode>,
    limits: &Limits,
    sink: Option<TraceSink>,
    static_checks: bool,
) -> Result<ExecutionResult, InitError> {
    let started = Instant::now();
    interpreter::initialize()?;
    let _serial = ONE_EPISODE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let violations = if static_checks {
        Python::attach(|py| static_check(py, source))?
    } else {
        Vec::new()
    };
    if !violations.is_empty() {
        return Ok(ExecutionResult {
            outcome: Outcome::Rejected { violations },
            trace: episode.trace().to_vec(),
            stdout: Default::default(),
            stderr: Default::default(),
            wall_time_s: started.elapsed().as_secs_f64(),
            subtasks: None,
            final_state: None,
            worker: None,
        });
    }
    session::install(ActiveEpisode {
        robot: episode,
        action_calls: 0,
        api_calls: 0,
        action_budget: limits.action_calls,
        api_budget: limits.api_calls,
        sink,
        streamed: 0,
    });
    let deadline = started + Duration::from_millis(limits.wall_time_ms);
    let ran = Python::attach(|py| execute(py, source, limits, deadline));
    episode = session::take().expect("episode installed above").robot;
    let (outcome, stdout, stderr, watchdog) = ran?;
    if let Some(watchdog) = watchdog {
        watchdog.join();
    }
    let end = episode.finish();
    Ok(ExecutionResult {
        outcome,
        trace: episode.trace().to_vec(),
        stdout,
        stderr,
        wall_time_s: started.elapsed().as_secs_f64(),
        subtasks: end.subtasks,
        final_state: end.final_state,
        worker: None,
    })
}

type Ran = (
    Outcome,
    crate::result::CapturedText,
    crate::result::CapturedText,
    Option<Watchdog>,
);

fn execute(py: Python<'_>, source: &str, limits: &Limits, deadline: Instant) -> Result<Ran, InitError> {
    let prepared = interpreter::prepared(py)?;
    let setup = || -> PyResult<_> {
        let code =
            py.import("builtins")?
                .getattr("compile")?
                .call1((source, POLICY_FILE, "exec", 0, true))?;
        let globals = PyDict::new(py);
        // Exactly interpreter::POLICY_GLOBALS, which the static checker counts as defined.
        globals.set_item("__builtins__", builtins::curated(py)?)?;
        globals.set_item("__name__", "__main__")?;
        globals.set_item("robot", prepared.robot.bind(py))?;
        globals.set_item("np", prepared.numpy.bind(py))?;
        for (name, function) in &prepared.api {
            globals.set_item(*name, function.bind(py))?;
        }
        let sys = py.import("sys")?;
        let saved = (sys.getattr("stdout")?, sys.getattr("stderr")?);
        let (out, out_buf) = OutputWriter::new(limits.output_cap_bytes);
        let (err, err_buf) = OutputWriter::new(limits.output_cap_bytes);
        sys.setattr("stdout", Bound::new(py, out)?)?;
        sys.setattr("stderr", Bound::new(py, err)?)?;
        Ok((code, globals, sys, saved, out_buf, err_buf))
    };
    let (code, globals, sys, saved, out_buf, err_buf) =
        setup().map_err(|e| InitError::Prepare(format!("episode setup failed: {e}")))?;

    abort::reset();
    budget::start_tracing(py, limits.instruction_budget);
    budget::mark_progress();
    let mut watchdog = Watchdog::start(py, deadline, Duration::from_millis(limits.idle_ms));
    audit::arm();
    // SAFETY: GIL held; `code` is a code object, `globals` a dict.
    let result = unsafe { ffi::PyEval_EvalCode(code.as_ptr(), globals.as_ptr(), globals.as_ptr()) };
    let error = if result.is_null() {
        let err = PyErr::fetch(py);
        Some(describe_error(py, &err, source))
    } else {
        // SAFETY: a new reference we own.
        unsafe { ffi::Py_DECREF(result) };
        None
    };
    // Still armed and traced: finalizers the policy left behind run under the sandbox.
    globals.clear();
    drop(globals);
    // SAFETY: GIL held.
    unsafe { ffi::PyGC_Collect() };
    watchdog.stop(py, prepared.noop.bind(py));
    let violation = audit::disarm();
    budget::stop_tracing(py);
    // SAFETY: GIL held; drop anything raised by finalizers after the policy ended.
    unsafe { ffi::PyErr_Clear() };
    let _ = sys.setattr("stdout", &saved.0);
    let _ = sys.setattr("stderr", &saved.1);

    let outcome = classify(abort::current(), violation, error);
    let stdout = out_buf.lock().map(|b| b.clone()).unwrap_or_default();
    let stderr = err_buf.lock().map(|b| b.clone()).unwrap_or_default();
    Ok((outcome, stdout, stderr, Some(watchdog)))
}

fn classify(
    abort: Option<AbortReason>,
    violation: Option<audit::Violation>,
    error: Option<PythonError>,
) -> Outcome {
    if violation.is_some() || abort == Some(AbortReason::SandboxViolation) {
        let violation = violation.unwrap_or(audit::Violation {
            event: "unknown".to_owned(),
            detail: None,
        });
        return Outcome::SandboxViolation {
            event: violation.event,
            detail: violation.detail,
            error,
        };
    }
    if let Some(limit) = abort.and_then(AbortReason::time_limit) {
        return Outcome::Timeout { limit, error };
    }
    match error {
        None => Outcome::Ok,
        Some(error) if error.exception == "MemoryError" => Outcome::Memory { error: Some(error) },
        Some(error) if error.exception == "TimeoutError" && abort.is_none() => {
            // Raised by the policy itself: an ordinary error.
            Outcome::PythonError(error)
        }
        Some(error) => Outcome::PythonError(error),
    }
}

/// Describes an exception without running policy code beyond `str(exception)`; frames are
/// read through the C API (reading `tb_frame` from Python would trip the audit hook).
fn describe_error(py: Python<'_>, err: &PyErr, source: &str) -> PythonError {
    let ty = err.get_type(py);
    let name = ty
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "Exception".to_owned());
    let module = ty.module().map(|m| m.to_string()).unwrap_or_default();
    let exception = if module.is_empty() || module == "builtins" {
        name
    } else {
        format!("{module}.{name}")
    };
    let message = err.value(py).str().map(|s| s.to_string()).unwrap_or_else(|_| {
        // SAFETY: GIL held; discard the error raised while formatting.
        unsafe { ffi::PyErr_Clear() };
        "<message unavailable>".to_owned()
    });
    let mut frames = Vec::new();
    let mut tb = err.traceback(py).map(|t| t.into_any());
    while let Some(current) = tb {
        if frames.len() >= 200 {
            break;
        }
        let line = current
            .getattr("tb_lineno")
            .and_then(|l| l.extract::<i64>())
            .unwrap_or(0);
        let raw = current.as_ptr().cast::<ffi::PyTracebackObject>();
        // SAFETY: `current` is a traceback object (it came from the exception's chain) and
        // the GIL is held; PyFrame_GetCode returns a new reference.
        let (file, function) = unsafe {
            let frame = (*raw).tb_frame;
            if frame.is_null() {
                ("<unknown>".to_owned(), "<unknown>".to_owned())
            } else {
                let code = ffi::PyFrame_GetCode(frame);
                let code = Bound::from_owned_ptr(py, code.cast());
                let file = code
                    .getattr("co_filename")
                    .map(|f| f.to_string())
                    .unwrap_or_default();
                let function = code.getattr("co_name").map(|f| f.to_string()).unwrap_or_default();
                (file, function)
            }
        };
        frames.push(TracebackFrame {
            file,
            line: line.max(0) as u32,
            function,
        });
        tb = current.getattr("tb_next").ok().filter(|n| !n.is_none());
    }
    // SAFETY: GIL held; clear anything left by the attribute reads.
    unsafe { ffi::PyErr_Clear() };
    let line = frames
        .iter()
        .rev()
        .find(|f| f.file == POLICY_FILE)
        .map(|f| f.line);
    let traceback = format_traceback(&frames, &exception, &message, source);
    PythonError {
        exception,
        message,
        line,
        frames,
        traceback,
    }
}

fn format_traceback(frames: &[TracebackFrame], exception: &str, message: &str, source: &str) -> String {
    let mut out = String::from("Traceback (most recent call last):\n");
    for frame in frames {
        out.push_str(&format!(
            "  File \"{}\", line {}, in {}\n",
            frame.file, frame.line, frame.function
        ));
        let text = match frame.file.as_str() {
            POLICY_FILE => source.lines().nth(frame.line.saturating_sub(1) as usize),
            _ => None,
        };
        if let Some(text) = text {
            out.push_str(&format!("    {}\n", text.trim()));
        }
    }
    if message.is_empty() {
        out.push_str(exception);
    } else {
        out.push_str(&format!("{exception}: {message}"));
    }
    out
}

/// Names of the robot API functions available to policies: the paper's, in its order, then
/// the tool-use call `gather_with_hook`.
pub fn api_function_names() -> Vec<&'static str> {
    crate::python::robot_module::SIGNATURES
        .iter()
        .map(|s| s.name)
        .collect()
}

/// Python-style signatures of the robot API functions, e.g. for prompts and docs.
pub fn api_signatures() -> Vec<String> {
    crate::python::robot_module::SIGNATURES
        .iter()
        .map(|s| s.render())
        .collect()
}
