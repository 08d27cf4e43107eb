//! Why the current episode must stop, shared by the audit hook, the trace function, the
//! watchdog and the robot module.
//!
//! Once a reason is set it stays set until the next episode: the trace function and the
//! watchdog keep raising into the policy, so `except BaseException: pass` cannot swallow
//! the stop (a policy that still spins is killed by the worker's parent).

use std::sync::atomic::{AtomicU8, Ordering};

use crate::result::TimeLimit;

/// Why an episode was stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(crate) enum AbortReason {
    /// The wall-clock deadline passed.
    WallClock = 1,
    /// The trace-event budget ran out.
    Instructions = 2,
    /// Too many robot action calls.
    ActionCalls = 3,
    /// Too many robot API calls.
    ApiCalls = 4,
    /// The audit hook refused an operation.
    SandboxViolation = 5,
    /// No robot API call within the idle limit.
    Idle = 6,
}

impl AbortReason {
    fn from_u8(v: u8) -> Option<AbortReason> {
        Some(match v {
            1 => AbortReason::WallClock,
            2 => AbortReason::Instructions,
            3 => AbortReason::ActionCalls,
            4 => AbortReason::ApiCalls,
            5 => AbortReason::SandboxViolation,
            6 => AbortReason::Idle,
            _ => return None,
        })
    }

    /// The time limit this reason corresponds to, if it is one.
    pub(crate) fn time_limit(self) -> Option<TimeLimit> {
        match self {
            AbortReason::WallClock => Some(TimeLimit::WallClock),
            AbortReason::Instructions => Some(TimeLimit::Instructions),
            AbortReason::ActionCalls => Some(TimeLimit::ActionCalls),
            AbortReason::ApiCalls => Some(TimeLimit::ApiCalls),
            AbortReason::Idle => Some(TimeLimit::Idle),
            AbortReason::SandboxViolation => None,
        }
    }

    /// Message of the exception raised into the policy.
    pub(crate) fn message(self) -> &'static str {
        match self {
            AbortReason::WallClock => "policy exceeded its wall-clock budget",
            AbortReason::Instructions => "policy exceeded its instruction budget",
            AbortReason::ActionCalls => "policy exceeded its budget of robot action calls",
            AbortReason::ApiCalls => "policy exceeded its budget of robot API calls",
            AbortReason::Idle => "policy made no robot API call within its idle limit",
            AbortReason::SandboxViolation => "the sandbox refused an operation; the episode is terminated",
        }
    }
}

static REASON: AtomicU8 = AtomicU8::new(0);

/// Records `reason` unless an earlier one is already set (the first reason wins).
pub(crate) fn request(reason: AbortReason) {
    let _ = REASON.compare_exchange(0, reason as u8, Ordering::AcqRel, Ordering::Acquire);
}

/// The reason the current episode must stop, if any.
pub(crate) fn current() -> Option<AbortReason> {
    AbortReason::from_u8(REASON.load(Ordering::Acquire))
}

/// Clears the reason at the start of an episode.
pub(crate) fn reset() {
    REASON.store(0, Ordering::Release);
}
