//! What running a policy produced: [`ExecutionResult`] and its [`Outcome`].

use nesy_core::State;
use nesy_core::metrics::SubtaskResult;
use nesy_sim::api::TraceEntry;
use serde::{Deserialize, Serialize};

use crate::relay::RobotStopReason;

/// Everything an episode produced. Serialised as JSON by `nesy run --json` and carried from
/// the worker process to the parent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExecutionResult {
    /// How the policy ended.
    pub outcome: Outcome,
    /// Every robot API call, in order (the simulator's own trace).
    pub trace: Vec<TraceEntry>,
    /// What the policy printed to `sys.stdout` (capped).
    pub stdout: CapturedText,
    /// What the policy printed to `sys.stderr` (capped).
    pub stderr: CapturedText,
    /// Wall-clock time from the start of the episode to its end, in seconds (for worker
    /// runs: from spawning the worker to collecting its result).
    pub wall_time_s: f64,
    /// Goal-check results after the post-run settle steps of `docs/benchmark.md` §7; `None` when the robot
    /// behind the episode has no goal checks (e.g. the sandbox test double).
    pub subtasks: Option<Vec<SubtaskReport>>,
    /// The observed symbolic state after the settle steps (`None` for robots without a
    /// world, such as the test double, and for episodes that were killed or rejected).
    pub final_state: Option<State>,
    /// Details of the worker process, for runs through [`run_policy`](crate::run_policy).
    pub worker: Option<WorkerReport>,
}

impl ExecutionResult {
    /// True if the policy ran to its end without an uncaught exception or a limit.
    pub fn is_ok(&self) -> bool {
        matches!(self.outcome, Outcome::Ok)
    }

    /// Names the policy's file `file` in every traceback and frame, in place of the
    /// [`crate::POLICY_FILE`] it was compiled under, so a user running their own `tilt.py`
    /// reads `File "tilt.py", line 3`. Other frames (`<nesy-robot>`, ...) keep their names.
    pub fn name_policy_file(&mut self, file: &str) {
        let errors = match &mut self.outcome {
            Outcome::PythonError(error) => vec![error],
            Outcome::SandboxViolation { error, .. }
            | Outcome::Timeout { error, .. }
            | Outcome::Memory { error } => error.iter_mut().collect(),
            Outcome::Ok
            | Outcome::Rejected { .. }
            | Outcome::Killed { .. }
            | Outcome::RobotStopped { .. } => Vec::new(),
        };
        let compiled_as = format!("File \"{}\"", crate::POLICY_FILE);
        let named = format!("File \"{file}\"");
        for error in errors {
            error.traceback = error.traceback.replace(&compiled_as, &named);
            for frame in &mut error.frames {
                if frame.file == crate::POLICY_FILE {
                    frame.file = file.to_owned();
                }
            }
        }
    }
}

/// How an episode ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Outcome {
    /// The policy ran to its end.
    Ok,
    /// The static checks refused the source before anything ran.
    Rejected {
        /// Every finding, in source order.
        violations: Vec<StaticViolation>,
    },
    /// An uncaught Python exception ended the policy.
    PythonError(PythonError),
    /// The audit hook refused an operation (opening files, imports, frame access, ...).
    /// The episode is terminated even if the policy catches the exception.
    SandboxViolation {
        /// The refused audit event, e.g. `open` or `object.__getattr__`.
        event: String,
        /// Its first argument when that is a string (a path, a module or attribute name).
        detail: Option<String>,
        /// The exception and traceback the policy ended with.
        error: Option<PythonError>,
    },
    /// A time or step budget ran out.
    Timeout {
        /// Which budget.
        limit: TimeLimit,
        /// The exception and traceback at the point the policy was stopped, when the
        /// interpreter could still report it.
        error: Option<PythonError>,
    },
    /// The policy ran out of memory (`MemoryError`, or the worker hit its address-space limit).
    Memory {
        /// The exception and traceback, when the interpreter could still report them.
        error: Option<PythonError>,
    },
    /// The worker process died without reporting a result.
    Killed {
        /// Why, in words (signal name or exit status).
        reason: String,
    },
    /// A relayed run on a robot was stopped at a call: nesy refused or the operator
    /// declined it, the robot had already failed a call, or the robot did not answer, answered
    /// garbage or hung up ([`crate::run_relayed`]).
    RobotStopped {
        /// The call the run stopped at, as a caption (`move_to_position(0.90, 0.00, 0.60)`).
        call: String,
        /// The kind of stop.
        reason: RobotStopReason,
        /// What happened, in words.
        message: String,
    },
}

impl Outcome {
    /// Short lower-case name of the outcome kind, as in the JSON `kind` field.
    pub fn kind(&self) -> &'static str {
        match self {
            Outcome::Ok => "ok",
            Outcome::Rejected { .. } => "rejected",
            Outcome::PythonError(_) => "python_error",
            Outcome::SandboxViolation { .. } => "sandbox_violation",
            Outcome::Timeout { .. } => "timeout",
            Outcome::Memory { .. } => "memory",
            Outcome::Killed { .. } => "killed",
            Outcome::RobotStopped { .. } => "robot_stopped",
        }
    }
}

/// Which limit stopped a policy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeLimit {
    /// The in-interpreter watchdog saw the wall-clock deadline pass.
    WallClock,
    /// The policy made no robot API call for `Limits::idle_ms` (stopped by the watchdog, or
    /// killed by the worker's parent when the interpreter itself was stuck in C code).
    Idle,
    /// The trace-event (line and call) budget ran out.
    Instructions,
    /// The policy made more robot action calls than allowed.
    ActionCalls,
    /// The policy made more robot API calls (perception included) than allowed.
    ApiCalls,
    /// The worker overran the deadline plus grace and the parent killed it.
    ParentKill,
    /// The worker used up its CPU-time rlimit (`SIGXCPU`).
    CpuTime,
}

/// An uncaught Python exception with its traceback.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PythonError {
    /// Exception class name, e.g. `TypeError` or `robot.UnknownObjectError`.
    pub exception: String,
    /// `str(exception)`.
    pub message: String,
    /// Innermost line of the policy source involved, 1-based.
    pub line: Option<u32>,
    /// Frames, outermost first.
    pub frames: Vec<TracebackFrame>,
    /// The traceback formatted like Python's, with source lines from the policy.
    pub traceback: String,
}

/// One frame of a traceback.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TracebackFrame {
    /// File name: `policy.py` for the policy itself.
    pub file: String,
    /// 1-based line number.
    pub line: u32,
    /// Function name (`<module>` for top-level code).
    pub function: String,
}

/// A finding of the static checks.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct StaticViolation {
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub column: u32,
    /// What is not allowed, e.g. `name '__import__' starts with an underscore`.
    pub message: String,
}

impl StaticViolation {
    /// `file:line:column: message`, the way compilers name a finding.
    pub fn located(&self, file: &str) -> String {
        format!("{file}:{}:{}: {}", self.line, self.column, self.message)
    }
}

impl std::fmt::Display for StaticViolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.located(crate::POLICY_FILE))
    }
}

/// Text captured from the policy, cut at a byte cap.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CapturedText {
    /// The first bytes written, up to the cap (cut at a character boundary).
    pub text: String,
    /// How many bytes were dropped after the cap.
    pub truncated_bytes: u64,
}

impl CapturedText {
    /// Appends `s`, keeping at most `cap` bytes in total.
    pub fn push_capped(&mut self, s: &str, cap: usize) {
        let room = cap.saturating_sub(self.text.len());
        if s.len() <= room {
            self.text.push_str(s);
        } else {
            let mut cut = room;
            while !s.is_char_boundary(cut) {
                cut -= 1;
            }
            self.text.push_str(&s[..cut]);
            self.truncated_bytes += (s.len() - cut) as u64;
        }
    }
}

/// The goal-check result of one subtask after the post-run settle (`docs/benchmark.md` §7).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SubtaskReport {
    /// Subtask name, e.g. `pick_place`.
    pub subtask: String,
    /// The verdict.
    pub status: SubtaskResult,
    /// The subtask's goal label (`docs/benchmark.md` §2): its objects in the demonstrated order, then the
    /// closure (`hinge`, `bottom_drawer`) for the articulated subtasks.
    #[serde(default)]
    pub label: Vec<String>,
    /// What it achieved, in time order, each with the control step of the check that saw it
    /// (for the procedure deviation, PD, over all subtasks merged in time order).
    #[serde(default)]
    pub achieved: Vec<(String, u64)>,
    /// Its objects that were counted as placed but are out of place at the end.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub displaced: Vec<String>,
}

/// How the worker process ended, reported by the parent.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorkerReport {
    /// Exit code, if it exited.
    pub exit_code: Option<i32>,
    /// Terminating signal, if it was killed.
    pub signal: Option<i32>,
    /// Anything the worker process wrote to its raw fds 1 and 2 (the policy's `print` goes
    /// to [`ExecutionResult::stdout`] instead), capped.
    pub raw_output: CapturedText,
    /// Time from spawn to the worker being ready to run the policy, in seconds, when known.
    pub startup_s: Option<f64>,
}
