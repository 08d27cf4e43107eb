//! # nesy-cli
//!
//! Command-line front end of nesy. The binary is a thin shell over this library so that
//! integration tests can drive the same code paths.
//!
//! Exit codes follow one convention across subcommands: 0 success, 1 a negative verdict
//! (invalid plan, failed episode), 2 bad input or usage.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use tracing_subscriber::layer::SubscriberExt as _;
use tracing_subscriber::util::SubscriberInitExt as _;

/// `println!` that returns the write error instead of panicking, so that a closed pipe
/// (`nesy … | head`) ends the command quietly (see [`run`]).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
    }};
}

/// `print!` counterpart of `outln!`.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*)
    }};
}

mod commands;

/// Turn a demonstration recorded in one setting into a verified robot program for another.
#[derive(Debug, Parser)]
#[command(name = "nesy", version, about, long_about = None)]
pub(crate) struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub(crate) command: Command,
}

/// The subcommands. Each lives in its own module under [`commands`].
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Adapt a demonstration to a target scene and synthesize (and run) a verified code policy.
    Adapt(Box<commands::adapt::AdaptArgs>),
    /// Run the benchmark over the 440 scenarios: methods, resumable and sharded runs, reports.
    Bench(commands::bench::BenchArgs),
    /// Inspect, prune or verify VLM cassettes (recorded model calls for offline replay).
    Cassette(commands::cassette::CassetteArgs),
    /// Import a real-world demonstration (frames, or the authors' format) as a demo folder.
    Demo(commands::demo::DemoArgs),
    /// Export or list the prompt templates NeSyCR's model calls are rendered from.
    Prompts(commands::prompts::PromptsArgs),
    /// Record a scripted-expert demonstration of a benchmark scenario as MCAP.
    Record(commands::record::RecordArgs),
    /// Render a scene's top, front and back views as PNG (plain and labelled).
    Render(commands::render::RenderArgs),
    /// Serve the simulator over the robot protocol (test a robot set-up without hardware).
    RobotServer(commands::robot_server::RobotServerArgs),
    /// Run a code policy in the sandboxed Python worker against a scene, or on a robot.
    Run(commands::run::RunArgs),
    /// Generate, list, show and sweep the benchmark's 440 scenarios; write one's planning problem.
    Scenarios(commands::scenarios::ScenariosArgs),
    /// Serve a folder of runs and their HTML reports to a browser (read-only, loopback by default).
    Serve(commands::serve::ServeArgs),
    /// Make a task from a pair of scenes: its demonstration planned, executed and recorded.
    Task(commands::task::TaskArgs),
    /// Verify a plan against a PDDL domain and problem, like VAL.
    Verify(commands::verify::VerifyArgs),
    /// Worker process of `nesy run` (internal).
    #[command(name = "policy-worker", hide = true)]
    PolicyWorker(commands::worker::WorkerArgs),
}

/// Exit code for bad input or usage errors.
pub(crate) const EXIT_BAD_INPUT: u8 = 2;

/// Parses the command line, sets up logging from `RUST_LOG`, and runs the subcommand.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    tracing_subscriber::fmt()
        .with_writer(std::io::stderr)
        // Colour codes only for a terminal, not in logs captured to a file.
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .finish()
        .with(log_filter(std::env::var("RUST_LOG").ok().as_deref()))
        .init();
    run(cli)
}

/// Which events are logged: `RUST_LOG`'s `target=level` directives (for example
/// `warn,nesy_vlm=debug`), or errors only when it is unset. A value that cannot be read is
/// reported once and leaves errors only, so a typo never silences a run's errors.
fn log_filter(directives: Option<&str>) -> tracing_subscriber::filter::Targets {
    use tracing_subscriber::filter::{LevelFilter, Targets};
    let errors_only = || Targets::new().with_default(LevelFilter::ERROR);
    match directives.map(str::trim).filter(|d| !d.is_empty()) {
        None => errors_only(),
        Some(directives) => directives.parse::<Targets>().unwrap_or_else(|err| {
            eprintln!(
                "warning: RUST_LOG={directives:?} was ignored ({err}); expected comma-separated \
                 `level` or `target=level` directives, e.g. `warn,nesy_vlm=debug`"
            );
            errors_only()
        }),
    }
}

/// Runs a parsed command line and maps errors to exit code 2 with their full context.
pub(crate) fn run(cli: Cli) -> ExitCode {
    let result = match cli.command {
        Command::Adapt(args) => commands::adapt::run(*args),
        Command::Bench(args) => commands::bench::run(args),
        Command::Cassette(args) => commands::cassette::run(args),
        Command::Demo(args) => commands::demo::run(args),
        Command::Prompts(args) => commands::prompts::run(args),
        Command::Record(args) => commands::record::run(args),
        Command::Render(args) => commands::render::run(args),
        Command::RobotServer(args) => commands::robot_server::run(args),
        Command::Run(args) => commands::run::run(args),
        Command::Scenarios(args) => commands::scenarios::run(args),
        Command::Serve(args) => commands::serve::run(args),
        Command::Task(args) => commands::task::run(args),
        Command::Verify(args) => commands::verify::run(args),
        Command::PolicyWorker(args) => commands::worker::run(args),
    };
    match result {
        Ok(code) => code,
        // The reader went away (`nesy … | head`): stop quietly with the shell's code for a
        // process ended by SIGPIPE, as tools that die of the signal report.
        Err(err) if is_broken_pipe(&err) => ExitCode::from(EXIT_BROKEN_PIPE),
        Err(err) => {
            eprintln!("error: {}", error_chain(&err));
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

/// The error and its causes joined by `: `, leaving out a cause whose text the message
/// before it already ends with (library errors show their source in their own message, so
/// anyhow's `{:#}` printed it twice: `…: Is a directory (os error 21): Is a directory (os
/// error 21)`).
pub(crate) fn error_chain(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let part = cause.to_string();
        if text.is_empty() {
            text = part;
        } else if !text.ends_with(&part) {
            text.push_str(": ");
            text.push_str(&part);
        }
    }
    text
}

/// Exit code when standard output was closed by its reader (128 + SIGPIPE).
pub(crate) const EXIT_BROKEN_PIPE: u8 = 141;

/// True if `err` was caused by writing to a closed pipe.
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_filter_reads_targets_and_falls_back_to_errors() {
        use tracing::Level;
        let filter = log_filter(Some("warn,nesy_vlm=debug"));
        assert!(filter.would_enable("nesy_vlm::client", &Level::DEBUG));
        assert!(filter.would_enable("nesy_core", &Level::WARN));
        assert!(!filter.would_enable("nesy_core", &Level::INFO));
        for unset in [None, Some(""), Some("nesy=loud")] {
            let filter = log_filter(unset);
            assert!(filter.would_enable("nesy_core", &Level::ERROR), "{unset:?}");
            assert!(!filter.would_enable("nesy_core", &Level::WARN), "{unset:?}");
        }
    }

    #[test]
    fn a_cause_already_in_the_message_is_not_repeated() {
        let io = std::io::Error::new(std::io::ErrorKind::IsADirectory, "Is a directory (os error 21)");
        let scene = nesy_sim::scene::SceneError::Io {
            path: "x.json".into(),
            source: io,
        };
        let err = anyhow::Error::new(scene).context("running p.py on x.json");
        assert_eq!(
            error_chain(&err),
            "running p.py on x.json: cannot read scene x.json: Is a directory (os error 21)"
        );
    }
}
