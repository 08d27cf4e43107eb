//! Messages between the parent and the worker process.

use nesy_sim::api::TraceEntry;
use serde::{Deserialize, Serialize};

use crate::episode::EpisodeSpec;
use crate::limits::Limits;
use crate::result::ExecutionResult;

/// File descriptor on which the worker writes its messages.
pub(crate) const RESULT_FD: i32 = 3;

/// Largest request the worker accepts on stdin.
pub(crate) const MAX_REQUEST_BYTES: u64 = 16 << 20;

/// What the parent asks the worker to run (JSON on the worker's stdin).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(crate) struct WorkerRequest {
    /// Random per-episode token; every message back must carry it.
    pub nonce: String,
    /// The policy's Python source.
    pub source: String,
    /// The episode to build.
    pub episode: EpisodeSpec,
    /// Budgets.
    pub limits: Limits,
    /// Run the static checks (always, except in tests that show the later layers).
    #[serde(default = "yes")]
    pub static_checks: bool,
}

fn yes() -> bool {
    true
}

/// One JSON line from the worker on [`RESULT_FD`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub(crate) enum WorkerMessage {
    /// The interpreter is up and the limits are in place; the policy starts now.
    Ready {
        /// The request's nonce.
        nonce: String,
        /// Seconds from the worker's `main` to this point.
        startup_s: f64,
    },
    /// A robot API call just returned.
    Trace {
        /// The request's nonce.
        nonce: String,
        /// The call.
        entry: TraceEntry,
    },
    /// The episode ended; the last message.
    Result {
        /// The request's nonce.
        nonce: String,
        /// Everything the episode produced.
        result: Box<ExecutionResult>,
    },
    /// The worker could not run the episode (bad scene, interpreter failure).
    Error {
        /// The request's nonce.
        nonce: String,
        /// What went wrong.
        message: String,
    },
}

impl WorkerMessage {
    /// The nonce the message carries.
    pub(crate) fn nonce(&self) -> &str {
        match self {
            WorkerMessage::Ready { nonce, .. }
            | WorkerMessage::Trace { nonce, .. }
            | WorkerMessage::Result { nonce, .. }
            | WorkerMessage::Error { nonce, .. } => nonce,
        }
    }
}
