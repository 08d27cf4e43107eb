//! `nesy prompts`: the prompt templates NeSyCR renders its model calls from.
//!
//! - `export DIR` writes the bundled templates and `physical_constraints.txt` as a starting
//!   point for `nesy adapt --prompts DIR`;
//! - `list` names every template with the variables its render call gives it.

use std::path::PathBuf;
use std::process::ExitCode;

use nesy_reasoner::prompts::{PHYSICAL_CONSTRAINTS_FILE, Prompts};

/// Arguments of `nesy prompts`.
#[derive(Debug, clap::Args)]
pub(crate) struct PromptsArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: PromptsAction,
}

/// The `nesy prompts` actions.
#[derive(Debug, clap::Subcommand)]
pub(crate) enum PromptsAction {
    /// Write the bundled templates into DIR (an existing file is never overwritten); edit any
    /// of them, delete the rest, and pass DIR to `nesy adapt --prompts`.
    Export {
        /// The folder to write (created if missing).
        dir: PathBuf,
    },
    /// List the templates and the variables each is given.
    List,
}

/// Runs `nesy prompts`.
pub(crate) fn run(args: PromptsArgs) -> anyhow::Result<ExitCode> {
    match args.action {
        PromptsAction::Export { dir } => {
            let written = Prompts::export_bundled(&dir)?;
            outln!(
                "wrote {} prompt file(s) to {}; pass the folder to `nesy adapt --prompts` (files left out keep the bundled text)",
                written.len(),
                dir.display()
            )?;
        }
        PromptsAction::List => {
            outln!("{PHYSICAL_CONSTRAINTS_FILE:<36} (text; every template sees it as physical_constraints)")?;
            for name in Prompts::template_names() {
                let variables = Prompts::template_variables(name).unwrap_or_default();
                outln!("{name:<36} {}", variables.join(", "))?;
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
