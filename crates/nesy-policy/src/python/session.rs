//! The robot behind the `robot` module during an episode, with the API-call budgets.
//!
//! There is one interpreter per process, so there is one active episode at a time; the
//! runner installs it before the policy starts and takes it back afterwards.

use std::sync::Mutex;

use nesy_sim::api::{RobotApi, TraceEntry};

use crate::episode::Episode;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use super::abort::{self, AbortReason};

/// Receives every new trace entry as soon as the call returns (the worker streams them to
/// its parent, so a killed episode still reports the calls it made).
pub(crate) type TraceSink = Box<dyn FnMut(&TraceEntry) + Send>;

/// The robot and budgets of the running episode.
pub(crate) struct ActiveEpisode {
    pub robot: Box<dyn Episode>,
    pub action_calls: usize,
    pub api_calls: usize,
    pub action_budget: usize,
    pub api_budget: usize,
    pub sink: Option<TraceSink>,
    pub streamed: usize,
}

static ACTIVE: Mutex<Option<ActiveEpisode>> = Mutex::new(None);

/// Installs the episode's robot.
pub(crate) fn install(episode: ActiveEpisode) {
    *ACTIVE.lock().unwrap_or_else(|e| e.into_inner()) = Some(episode);
}

/// Removes and returns the episode's robot.
pub(crate) fn take() -> Option<ActiveEpisode> {
    ACTIVE.lock().unwrap_or_else(|e| e.into_inner()).take()
}

/// Why a call was refused before reaching the robot.
pub(crate) enum Refusal {
    /// No episode is running (the module was used outside nesy's runner).
    NoEpisode,
    /// A budget is used up.
    Budget(AbortReason, usize),
}

impl Refusal {
    pub(crate) fn into_pyerr(self) -> PyErr {
        match self {
            Refusal::NoEpisode => {
                PyRuntimeError::new_err("the robot API is only available while a policy runs")
            }
            Refusal::Budget(reason, limit) => {
                super::robot_module::BudgetExhaustedError::new_err(format!("{} ({limit})", reason.message()))
            }
        }
    }
}

/// Runs `f` against the episode's robot with the interpreter lock released, after charging
/// the call to the budgets. New trace entries go to the sink.
pub(crate) fn call<T: Send>(
    py: Python<'_>,
    is_action: bool,
    f: impl FnOnce(&mut (dyn RobotApi + Send)) -> T + Send,
) -> Result<T, Refusal> {
    let mut guard = ACTIVE.lock().unwrap_or_else(|e| e.into_inner());
    let Some(episode) = guard.as_mut() else {
        return Err(Refusal::NoEpisode);
    };
    // Time inside a call (a long move simulating) is not idle time: the clock restarts both
    // when the call starts and when it returns.
    super::budget::mark_progress();
    episode.api_calls += 1;
    if episode.api_calls > episode.api_budget {
        abort::request(AbortReason::ApiCalls);
        return Err(Refusal::Budget(AbortReason::ApiCalls, episode.api_budget));
    }
    if is_action {
        episode.action_calls += 1;
        if episode.action_calls > episode.action_budget {
            abort::request(AbortReason::ActionCalls);
            return Err(Refusal::Budget(AbortReason::ActionCalls, episode.action_budget));
        }
    }
    let robot: &mut dyn Episode = &mut *episode.robot;
    let robot: &mut (dyn RobotApi + Send) = robot;
    super::budget::set_call_in_flight(true);
    let value = py.detach(move || f(robot));
    super::budget::set_call_in_flight(false);
    super::budget::mark_progress();
    if let Some(sink) = episode.sink.as_mut() {
        let trace = episode.robot.trace();
        for entry in &trace[episode.streamed.min(trace.len())..] {
            sink(entry);
        }
        episode.streamed = trace.len();
    }
    Ok(value)
}
