//! Step and time budgets inside the interpreter: a C-level trace function that counts
//! executed lines and calls, and a watchdog thread that raises into the policy's thread
//! with `PyThreadState_SetAsyncExc`.
//!
//! Both are needed: a one-line `while True: pass` emits no trace events on 3.11, so only
//! the asynchronous exception stops it; and a policy that swallows the watchdog's exception
//! hits the trace function on its very next line. C-level hangs (`7**(10**9)`) hold the
//! interpreter lock and stop neither: the worker's parent kills those. The watchdog also
//! stops a policy that goes [`crate::Limits::idle_ms`] without a robot API call.

use std::ffi::{CString, c_int};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use pyo3::ffi;
use pyo3::prelude::*;

use super::abort::{self, AbortReason};

/// How often the watchdog re-raises once the episode must stop.
pub(crate) const WATCHDOG_PERIOD: Duration = Duration::from_millis(20);

static REMAINING: AtomicU64 = AtomicU64::new(u64::MAX);
/// When the policy last made progress (its start or a robot API call), in milliseconds since
/// [`progress_epoch`].
static LAST_PROGRESS_MS: AtomicU64 = AtomicU64::new(0);

fn progress_epoch() -> Instant {
    static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    *EPOCH.get_or_init(Instant::now)
}

/// Records that the policy made progress now (called at its start and at every robot API
/// call), restarting the idle clock.
pub(crate) fn mark_progress() {
    let elapsed = Instant::now().saturating_duration_since(progress_epoch());
    LAST_PROGRESS_MS.store(elapsed.as_millis() as u64, Ordering::Release);
}

/// True while a robot API call is in flight. A call can take longer than the idle limit on a
/// real robot (a slow move through the robot protocol); the policy is waiting for the robot
/// then, not idle.
static CALL_IN_FLIGHT: AtomicBool = AtomicBool::new(false);

/// Marks the start (`true`) or end (`false`) of a robot API call.
pub(crate) fn set_call_in_flight(in_flight: bool) {
    CALL_IN_FLIGHT.store(in_flight, Ordering::Release);
}

/// How long since the last [`mark_progress`].
fn since_progress() -> Duration {
    let last = progress_epoch() + Duration::from_millis(LAST_PROGRESS_MS.load(Ordering::Acquire));
    Instant::now().saturating_duration_since(last)
}
/// The exception type raised for sandbox violations (`robot.SandboxViolation`).
static VIOLATION_TYPE: AtomicPtr<ffi::PyObject> = AtomicPtr::new(std::ptr::null_mut());

/// Registers the exception type raised when the audit hook terminated the episode.
pub(crate) fn set_violation_type(ty: *mut ffi::PyObject) {
    VIOLATION_TYPE.store(ty, Ordering::Release);
}

/// The exception type to raise for `reason`.
fn exception_for(reason: AbortReason) -> *mut ffi::PyObject {
    match reason {
        AbortReason::SandboxViolation => {
            let ty = VIOLATION_TYPE.load(Ordering::Acquire);
            // SAFETY: reading an immortal static exception type.
            if ty.is_null() {
                unsafe { ffi::PyExc_PermissionError }
            } else {
                ty
            }
        }
        // SAFETY: as above.
        _ => unsafe { ffi::PyExc_TimeoutError },
    }
}

unsafe extern "C" fn trace(
    _obj: *mut ffi::PyObject,
    _frame: *mut ffi::PyFrameObject,
    what: c_int,
    _arg: *mut ffi::PyObject,
) -> c_int {
    if what != ffi::PyTrace_LINE && what != ffi::PyTrace_CALL {
        return 0;
    }
    if REMAINING.fetch_sub(1, Ordering::Relaxed) <= 1 {
        REMAINING.store(0, Ordering::Relaxed);
        abort::request(AbortReason::Instructions);
    }
    match abort::current() {
        None => 0,
        Some(reason) => {
            let message = CString::new(reason.message()).unwrap_or_default();
            // SAFETY: the trace function runs with the GIL held.
            unsafe { ffi::PyErr_SetString(exception_for(reason), message.as_ptr()) };
            -1
        }
    }
}

/// Installs the trace function on the calling thread with a fresh budget. Must run before
/// the audit hook is armed (`PyEval_SetTrace` raises the `sys.settrace` event).
pub(crate) fn start_tracing(_py: Python<'_>, budget: u64) {
    REMAINING.store(budget.max(1), Ordering::Relaxed);
    // SAFETY: GIL held (the `Python` token proves it).
    unsafe { ffi::PyEval_SetTrace(Some(trace), std::ptr::null_mut()) };
}

/// Removes the trace function from the calling thread (after the hook is disarmed).
pub(crate) fn stop_tracing(_py: Python<'_>) {
    // SAFETY: GIL held.
    unsafe { ffi::PyEval_SetTrace(None, std::ptr::null_mut()) };
}

/// A running watchdog thread for one episode.
pub(crate) struct Watchdog {
    stop: Arc<AtomicBool>,
    handle: Option<JoinHandle<()>>,
}

impl Watchdog {
    /// Starts watching the calling thread (which must hold the GIL) until `deadline`, and
    /// for stretches longer than `idle` without a robot API call.
    pub(crate) fn start(_py: Python<'_>, deadline: Instant, idle: Duration) -> Watchdog {
        // `PyThreadState_SetAsyncExc` matches the thread's pthread id (what
        // `threading.get_ident()` returns), not `PyThreadState_GetID`.
        // SAFETY: pthread_self has no preconditions.
        let thread_id = unsafe { libc::pthread_self() } as std::ffi::c_long;
        let stop = Arc::new(AtomicBool::new(false));
        let stop_flag = Arc::clone(&stop);
        let handle = std::thread::Builder::new()
            .name("nesy-policy-watchdog".into())
            .spawn(move || watch(thread_id, deadline, idle, &stop_flag))
            .ok();
        Watchdog { stop, handle }
    }

    /// Stops the watchdog and consumes any exception it queued that the policy never saw.
    /// Called with the GIL held, so the watchdog cannot be between its check and its raise.
    ///
    /// `PyThreadState_SetAsyncExc(id, NULL)` must not be used to drop a pending exception:
    /// on 3.11 it leaves the interpreter's eval breaker signalled with nothing to deliver,
    /// and the next frame that starts on the thread spins at its first instruction. Instead
    /// a no-op code object is evaluated until no queued exception is left.
    pub(crate) fn stop(&mut self, py: Python<'_>, noop: &Bound<'_, PyAny>) {
        self.stop.store(true, Ordering::Release);
        let globals = pyo3::types::PyDict::new(py);
        for _ in 0..3 {
            // SAFETY: GIL held; `noop` is a code object and `globals` a dict.
            let result = unsafe { ffi::PyEval_EvalCode(noop.as_ptr(), globals.as_ptr(), globals.as_ptr()) };
            if result.is_null() {
                // SAFETY: GIL held; discard the delivered exception.
                unsafe { ffi::PyErr_Clear() };
            } else {
                // SAFETY: a new reference we own.
                unsafe { ffi::Py_DECREF(result) };
                break;
            }
        }
    }

    /// Waits for the watchdog thread to end. Call without holding the GIL.
    pub(crate) fn join(mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(handle) = self.handle.take() {
            handle.thread().unpark();
            let _ = handle.join();
        }
    }
}

fn watch(thread_id: std::ffi::c_long, deadline: Instant, idle: Duration, stop: &AtomicBool) {
    loop {
        let now = Instant::now();
        let in_call = CALL_IN_FLIGHT.load(Ordering::Acquire);
        let wait = if now < deadline && abort::current().is_none() && !in_call {
            (deadline - now)
                .min(idle.saturating_sub(since_progress()))
                .clamp(Duration::from_millis(1), WATCHDOG_PERIOD)
        } else {
            WATCHDOG_PERIOD
        };
        // Parked rather than slept, so `Watchdog::join` can wake it at once.
        std::thread::park_timeout(wait);
        if stop.load(Ordering::Acquire) {
            return;
        }
        if Instant::now() >= deadline {
            abort::request(AbortReason::WallClock);
        } else if !CALL_IN_FLIGHT.load(Ordering::Acquire) && since_progress() >= idle {
            abort::request(AbortReason::Idle);
        }
        let Some(reason) = abort::current() else { continue };
        Python::attach(|_py| {
            if stop.load(Ordering::Acquire) {
                return;
            }
            // SAFETY: GIL held; the exception type is a valid static type object.
            unsafe { ffi::PyThreadState_SetAsyncExc(thread_id, exception_for(reason)) };
        });
    }
}
