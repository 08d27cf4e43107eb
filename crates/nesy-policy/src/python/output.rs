//! `sys.stdout` / `sys.stderr` replacements that keep a capped copy of what the policy prints.

use std::sync::{Arc, Mutex};

use pyo3::prelude::*;

use crate::result::CapturedText;

/// A write-only text stream backed by a capped buffer.
#[pyclass(frozen, module = "robot")]
pub(crate) struct OutputWriter {
    buffer: Arc<Mutex<CapturedText>>,
    cap: usize,
}

impl OutputWriter {
    /// A writer that keeps at most `cap` bytes, plus a handle to read them afterwards.
    pub(crate) fn new(cap: usize) -> (OutputWriter, Arc<Mutex<CapturedText>>) {
        let buffer = Arc::new(Mutex::new(CapturedText::default()));
        (
            OutputWriter {
                buffer: Arc::clone(&buffer),
                cap,
            },
            buffer,
        )
    }
}

#[pymethods]
impl OutputWriter {
    /// Appends text; returns its length like `io.TextIOBase.write`.
    fn write(&self, text: &str) -> usize {
        if let Ok(mut buffer) = self.buffer.lock() {
            buffer.push_capped(text, self.cap);
        }
        text.chars().count()
    }

    /// Nothing is buffered.
    fn flush(&self) {}

    /// Not a terminal.
    fn isatty(&self) -> bool {
        false
    }

    /// Always writable.
    fn writable(&self) -> bool {
        true
    }
}
