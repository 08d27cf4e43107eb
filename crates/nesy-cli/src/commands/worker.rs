//! `nesy policy-worker` (hidden): the worker process of `nesy run`. It reads a request on
//! stdin and reports on fd 3; see `nesy_policy::worker`. Not for direct use.

use std::process::ExitCode;

/// Arguments of the hidden worker subcommand (none: the request comes on stdin).
#[derive(Debug, clap::Args)]
pub(crate) struct WorkerArgs {}

/// Runs one policy episode in this process under the worker's limits.
pub(crate) fn run(_args: WorkerArgs) -> anyhow::Result<ExitCode> {
    Ok(nesy_policy::worker_main(&nesy_policy::SimEpisodes))
}
