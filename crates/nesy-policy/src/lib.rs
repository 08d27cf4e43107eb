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
//!    wall-clock kill ([`run_policy`]).
//!
//! The entry point for pipelines is [`worker::run_policy`]: source + [`EpisodeSpec`] +
//! [`Limits`] in, [`ExecutionResult`] out. It runs the policy in a worker process, the
//! hidden `nesy policy-worker` subcommand of the running binary:
//!
//! ```no_run
//! use nesy_policy::{EpisodeSpec, Limits, WorkerCommand, run_policy};
//!
//! let worker = WorkerCommand::current_exe().unwrap(); // the running `nesy` binary
//! let spec = EpisodeSpec::Scene {
//!     path: "scene.json".into(),
//!     embodiment: None,
//! };
//! let result = run_policy(&worker, "open_gripper()\n", &spec, &Limits::default()).unwrap();
//! println!("{:?}: {} API calls", result.outcome, result.trace.len());
//! ```
//!
//! [`run_in_process`] runs the same layers but the process boundary, for tests: here against
//! the recording double, whose trace shows what the policy called.
//!
//! ```
//! use nesy_policy::RecordingRobot;
//! use nesy_policy::{Limits, run_in_process};
//! use nesy_core::Embodiment;
//!
//! let robot = Box::new(RecordingRobot::new(Embodiment::Finger));
//! let source = "move_gripper_to('red_cube')\nclose_gripper()\n";
//! let result = run_in_process(source, robot, &Limits::default(), None).unwrap();
//! assert!(result.is_ok());
//! let calls: Vec<&str> = result.trace.iter().map(|e| e.call.name()).collect();
//! assert_eq!(calls, ["move_gripper_to", "close_gripper"]);
//!
//! // A program that reaches outside the robot API never runs.
//! let escape = Box::new(RecordingRobot::new(Embodiment::Finger));
//! let result = run_in_process("import os\n", escape, &Limits::default(), None).unwrap();
//! assert!(!result.is_ok());
//! ```

mod episode;
mod limits;
mod python;
mod relay;
mod result;
mod runner;
mod sim_episode;
mod source;
mod testing;
mod worker;

pub use episode::{Episode, EpisodeBuildError, EpisodeEnd, EpisodeFactory, EpisodeSpec};
pub use limits::Limits;
pub use python::interpreter::{InitError, StartupTimes, initialize};
pub use relay::{CallRelay, RelayStop, RobotStopReason};
pub use result::{
    CapturedText, ExecutionResult, Outcome, PythonError, StaticViolation, SubtaskReport, TimeLimit,
    TracebackFrame, WorkerReport,
};
pub use runner::{
    POLICY_FILE, api_function_names, api_signatures, check_source, run_in_process,
    run_in_process_without_static_checks,
};
pub use sim_episode::SimEpisodes;
pub use source::{SourceError, decode_policy_source};
pub use testing::RecordingRobot;
pub use worker::{
    RunError, WORKER_SUBCOMMAND, WorkerCommand, install_seccomp_filter, run_policy,
    run_policy_without_static_checks, run_relayed, worker_main,
};
