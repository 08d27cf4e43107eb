//! `nesy verify`: check a plan against a PDDL domain and problem.

use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `nesy verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {
    /// PDDL domain file.
    #[arg(long)]
    pub domain: PathBuf,
    /// PDDL problem file.
    #[arg(long)]
    pub problem: PathBuf,
    /// Plan file: one `(action args...)` per line, `;` comments.
    #[arg(long)]
    pub plan: PathBuf,
    /// Print the verdict as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `nesy verify`.
pub fn run(args: VerifyArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "nesy verify is not implemented yet (domain {}, problem {}, plan {})",
        args.domain.display(),
        args.problem.display(),
        args.plan.display()
    )
}
