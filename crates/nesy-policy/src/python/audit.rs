//! The deny-by-default audit hook (PEP 578), installed from Rust before the interpreter
//! starts, so Python code can neither see nor remove it.
//!
//! It lets everything through while nesy itself starts the interpreter and prepares an
//! episode, and refuses every event while the policy runs ("armed"), except attribute
//! writes on the policy's own classes. A refusal raises `PermissionError` into the policy
//! and terminates the episode (see [`super::abort`]).

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use pyo3::ffi;

use super::abort::{self, AbortReason};

unsafe extern "C" {
    /// `int PySys_AddAuditHook(Py_AuditHookFunction hook, void *userData)`; not exported
    /// by pyo3-ffi. Callable before `Py_Initialize`.
    fn PySys_AddAuditHook(
        hook: Option<unsafe extern "C" fn(*const c_char, *mut ffi::PyObject, *mut c_void) -> c_int>,
        user_data: *mut c_void,
    ) -> c_int;
}

static ARMED: AtomicBool = AtomicBool::new(false);
static INSTALLED: AtomicBool = AtomicBool::new(false);
static FIRST_VIOLATION: Mutex<Option<Violation>> = Mutex::new(None);

/// A refused audit event.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Violation {
    /// Event name, e.g. `open`.
    pub event: String,
    /// The event's first argument if it is a `str`.
    pub detail: Option<String>,
}

/// Installs the hook. Must run before the interpreter is initialised; later calls do nothing.
pub(crate) fn install() {
    if INSTALLED.swap(true, Ordering::AcqRel) {
        return;
    }
    // SAFETY: the hook is a plain function valid for the program's lifetime.
    unsafe {
        PySys_AddAuditHook(Some(hook), std::ptr::null_mut());
    }
}

/// Starts refusing events (just before the policy's code runs).
pub(crate) fn arm() {
    if let Ok(mut v) = FIRST_VIOLATION.lock() {
        *v = None;
    }
    ARMED.store(true, Ordering::Release);
}

/// Stops refusing events and returns the first refused one of this episode.
pub(crate) fn disarm() -> Option<Violation> {
    ARMED.store(false, Ordering::Release);
    FIRST_VIOLATION.lock().ok().and_then(|mut v| v.take())
}

/// Events a running policy may raise: attribute writes on objects whose attribute name is
/// public (the policy's own classes; `_` names are refused).
fn allowed_while_armed(event: &[u8], args: *mut ffi::PyObject) -> bool {
    if event == b"object.__setattr__" || event == b"object.__delattr__" {
        // SAFETY: called with the GIL held; `args` is the event's argument tuple.
        let name = unsafe { tuple_str(args, 1) };
        return matches!(name, Some(n) if !n.starts_with('_'));
    }
    false
}

/// The `index`-th item of `args` if it is a `str`, copied out.
unsafe fn tuple_str(args: *mut ffi::PyObject, index: ffi::Py_ssize_t) -> Option<String> {
    // SAFETY: the caller holds the GIL; every pointer is checked before use.
    unsafe {
        if args.is_null() || ffi::PyTuple_Check(args) == 0 || ffi::PyTuple_Size(args) <= index {
            return None;
        }
        let item = ffi::PyTuple_GetItem(args, index);
        if item.is_null() || ffi::PyUnicode_Check(item) == 0 {
            return None;
        }
        let mut len: ffi::Py_ssize_t = 0;
        let data = ffi::PyUnicode_AsUTF8AndSize(item, &mut len);
        if data.is_null() {
            ffi::PyErr_Clear();
            return None;
        }
        let bytes = std::slice::from_raw_parts(data.cast::<u8>(), len as usize);
        let text = String::from_utf8_lossy(&bytes[..bytes.len().min(200)]).into_owned();
        Some(text)
    }
}

unsafe extern "C" fn hook(event: *const c_char, args: *mut ffi::PyObject, _user: *mut c_void) -> c_int {
    if !ARMED.load(Ordering::Acquire) {
        return 0;
    }
    // SAFETY: CPython passes a valid NUL-terminated event name.
    let event = unsafe { CStr::from_ptr(event) };
    if allowed_while_armed(event.to_bytes(), args) {
        return 0;
    }
    let name = event.to_string_lossy().into_owned();
    // SAFETY: the hook runs with the GIL held.
    let detail = unsafe { tuple_str(args, 0) };
    if let Ok(mut first) = FIRST_VIOLATION.try_lock()
        && first.is_none()
    {
        *first = Some(Violation {
            event: name.clone(),
            detail,
        });
    }
    abort::request(AbortReason::SandboxViolation);
    let message = CString::new(format!("sandbox: operation '{name}' is not permitted"))
        .unwrap_or_else(|_| c"sandbox: operation not permitted".to_owned());
    // SAFETY: GIL held; PyExc_PermissionError is a static exception type.
    unsafe {
        ffi::PyErr_SetString(ffi::PyExc_PermissionError, message.as_ptr());
    }
    -1
}
