//! # nesy-policy
//!
//! Runs untrusted, model-written Python code policies in an embedded CPython against
//! nesy-sim's robot API, inside a layered sandbox:
//!
//! 1. static checks of the source (Python's own `ast`, see [`check_source`]);
//! 2. curated builtins and an import function that only hands out `math`, `numpy` (a small
//!    vetted subset) and `robot`;
//! 3. a deny-by-default audit hook installed before the interpreter starts;
//! 4. a trace-event budget, a watchdog raising `TimeoutError`, and API-call budgets;
//! 5. a worker process with rlimits, no-new-privs, a seccomp filter and a parent-enforced
//!    wall-clock kill ([`worker`]).
//!
//! The entry point for pipelines is [`worker::run_policy`]: source + [`EpisodeSpec`] +
//! [`Limits`] in, [`ExecutionResult`] out.

pub mod episode;
pub mod limits;
pub mod python;
pub mod result;
pub mod runner;
pub mod sim_episode;
pub mod testing;
pub mod worker;

pub use episode::{Episode, EpisodeBuildError, EpisodeEnd, EpisodeFactory, EpisodeSpec};
pub use limits::Limits;
pub use python::interpreter::{InitError, StartupTimes, initialize};
pub use result::{
    CapturedText, ExecutionResult, Outcome, PythonError, StaticViolation, SubtaskResult, SubtaskStatus,
    TimeLimit, TracebackFrame, WorkerReport,
};
pub use runner::{POLICY_FILE, api_function_names, api_signatures, check_source, run_in_process};
pub use sim_episode::{SETTLE_STEPS, SimEpisodes};
pub use worker::{RunError, WorkerCommand, run_policy};
