//! Messages between the parent and the worker process.

use nesy_core::Embodiment;
use nesy_sim::api::{ApiCall, ApiError, ApiValue, TraceEntry};
use serde::{Deserialize, Serialize};

use crate::episode::{EpisodeEnd, EpisodeSpec};
use crate::limits::Limits;
use crate::result::ExecutionResult;

/// File descriptor on which the worker writes its messages.
pub(crate) const RESULT_FD: i32 = 3;

/// File descriptor on which a relayed episode's worker reads the parent's answers.
pub(crate) const RELAY_FD: i32 = 4;

/// Largest answer line the worker accepts from the parent on [`RELAY_FD`].
pub(crate) const MAX_RELAY_LINE_BYTES: u64 = 4 << 20;

/// Largest request the worker accepts on stdin.
pub(crate) const MAX_REQUEST_BYTES: u64 = 16 << 20;

/// What the parent asks the worker to run (JSON on the worker's stdin).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub(crate) struct WorkerRequest {
    /// Random per-episode token; every message back must carry it.
    pub nonce: String,
    /// The policy's Python source.
    pub source: String,
    /// The episode to run.
    pub episode: WorkerEpisode,
    /// Budgets.
    pub limits: Limits,
    /// Run the static checks (always, except in tests that show the later layers).
    #[serde(default = "yes")]
    pub static_checks: bool,
}

fn yes() -> bool {
    true
}

/// The robot a worker runs its policy against.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "robot", rename_all = "snake_case")]
pub(crate) enum WorkerEpisode {
    /// One the worker builds itself with its episode factory.
    Built {
        /// What to build.
        spec: EpisodeSpec,
    },
    /// A robot outside the worker: calls go to the parent ([`WorkerMessage::Call`]) and the
    /// answers come back on [`RELAY_FD`].
    Relayed {
        /// The robot's embodiment.
        embodiment: Embodiment,
    },
}

/// One JSON line from the parent on [`RELAY_FD`], answering a [`WorkerMessage::Call`] or a
/// [`WorkerMessage::Finish`].
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub(crate) enum RelayReply {
    /// What the robot answered to the call.
    Call {
        /// Its value or its error.
        result: Result<ApiValue, ApiError>,
    },
    /// The robot's end-of-episode report.
    Finish {
        /// Goal checks and observed state, where the robot has them.
        end: EpisodeEnd,
    },
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
    /// A relayed episode's policy calls the robot; the worker waits for a [`RelayReply`].
    Call {
        /// The request's nonce.
        nonce: String,
        /// The call.
        call: ApiCall,
    },
    /// A relayed episode's policy ended; the worker waits for the robot's end report.
    Finish {
        /// The request's nonce.
        nonce: String,
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
            | WorkerMessage::Call { nonce, .. }
            | WorkerMessage::Finish { nonce }
            | WorkerMessage::Result { nonce, .. }
            | WorkerMessage::Error { nonce, .. } => nonce,
        }
    }
}
