//! The checks a generated program must pass before code generation accepts it.
//!
//! The sandbox that will run the program (nesy-policy, an embedded CPython) owns these
//! checks. The reasoner asks for them through [`ProgramCheck`] rather than linking the
//! interpreter itself, so that the crates that only prompt a model (the baselines among
//! them) do not link CPython and the simulator. The pipeline plugs in nesy-policy's checks.

use std::fmt;

/// One reason a program may not run, at a 1-based line and column of the program.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// 1-based line.
    pub line: u32,
    /// 1-based column.
    pub column: u32,
    /// What is wrong, in words the model can act on.
    pub message: String,
}

/// Why the checks could not run at all (as opposed to a program they refused).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct CheckUnavailable(pub String);

/// The static checks of the sandbox that will run a generated program: syntax, the
/// sandbox's refusals, names nothing defines, robot API calls whose arguments do not bind.
pub trait ProgramCheck: Send + Sync + fmt::Debug {
    /// The findings for `program`, empty when it may run.
    fn check(&self, program: &str) -> Result<Vec<Finding>, CheckUnavailable>;
}
