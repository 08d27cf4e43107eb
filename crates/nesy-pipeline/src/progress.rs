//! Progress reporting for long steps: the pipeline names its stage and details (the
//! transition being induced, the proposal being checked); the CLI shows them with a spinner.

/// Receives progress messages. Implementations must be cheap: the pipeline calls them once
/// per model call.
pub trait Progress: Send + Sync {
    /// A new stage begins (e.g. `world model and adaptation`).
    fn stage(&self, name: &str);
    /// Detail within the current stage (e.g. `operator 3/12, attempt 1`).
    fn detail(&self, message: &str);
}

/// Progress that goes nowhere (tests, `--json`).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn stage(&self, _name: &str) {}
    fn detail(&self, _message: &str) {}
}

/// Progress as `tracing` events (used when stderr is not a terminal).
#[derive(Debug, Clone, Copy, Default)]
pub struct LogProgress;

impl Progress for LogProgress {
    fn stage(&self, name: &str) {
        tracing::info!(stage = name, "nesy adapt");
    }
    fn detail(&self, message: &str) {
        tracing::debug!("{message}");
    }
}
