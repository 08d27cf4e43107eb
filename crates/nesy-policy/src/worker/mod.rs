//! Process isolation: each episode runs in a worker process, the `nesy` binary re-executed
//! as a hidden subcommand.
//!
//! The parent ([`run_policy`]) sends a [`protocol::WorkerRequest`] on the worker's stdin and
//! reads JSON-line messages from a dedicated pipe that the worker sees as fd 3. The
//! policy's `print` goes into the result; whatever reaches the worker's raw fds 1 and 2 is
//! captured (capped) by the parent separately, so nothing the policy does to fd 1/2 can
//! corrupt the result channel. Every message carries a per-episode nonce that exists only
//! in the two processes' Rust memory, so code inside the interpreter cannot forge a result.
//!
//! The worker ([`worker_main`]) applies `RLIMIT_AS`, `RLIMIT_CPU` and `RLIMIT_CORE` before
//! the interpreter starts, and `PR_SET_NO_NEW_PRIVS`, a seccomp filter, `RLIMIT_NOFILE` and
//! `RLIMIT_FSIZE` after start-up; the parent kills it (whole process group) when the wall
//! clock runs out and reports that as a timeout.

mod child;
mod limits;
mod parent;
pub(crate) mod protocol;
pub(crate) mod seccomp;

pub use child::worker_main;
pub use parent::{
    RunError, WORKER_SUBCOMMAND, WorkerCommand, run_policy, run_policy_without_static_checks, run_relayed,
};
pub use seccomp::install as install_seccomp_filter;
