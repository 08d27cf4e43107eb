//! The budgets an episode runs under.

use serde::{Deserialize, Serialize};

/// Budgets and caps for one episode. The defaults suit the benchmark: the longest scenario
/// of the paper needs 116 API calls.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Limits {
    /// Wall-clock budget of the policy itself, in milliseconds (watchdog deadline).
    pub wall_time_ms: u64,
    /// Longest stretch, in milliseconds, the policy may go without a robot API call before it
    /// is stopped as idle: a policy that spins (`while True: pass`, or a C-level hang such as
    /// `7 ** (10 ** 9)`) ends within this plus `kill_grace_ms`, not at the wall-clock budget.
    /// The longest gap between calls of a working policy is a few milliseconds of Python.
    pub idle_ms: u64,
    /// Extra time the parent grants a worker beyond `wall_time_ms` or `idle_ms` (start-up,
    /// settle steps, reporting) before killing it.
    pub kill_grace_ms: u64,
    /// Trace events (Python lines executed plus function calls) allowed.
    pub instruction_budget: u64,
    /// Robot action calls allowed (spec: a max number of action calls, e.g. 200).
    pub action_calls: usize,
    /// Robot API calls of any kind allowed (bounds perception floods and the trace size).
    pub api_calls: usize,
    /// Bytes kept of each of stdout and stderr.
    pub output_cap_bytes: usize,
    /// Address-space limit of the worker process in bytes (`RLIMIT_AS`).
    pub memory_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            wall_time_ms: 120_000,
            idle_ms: 10_000,
            kill_grace_ms: 3_000,
            instruction_budget: 50_000_000,
            action_calls: 200,
            api_calls: 5_000,
            output_cap_bytes: 64 * 1024,
            memory_bytes: 2 << 30,
        }
    }
}
