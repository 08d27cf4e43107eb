//! Running a policy on a robot through the robot protocol (`--robot` of `nesy run` and `nesy
//! adapt --execute`): the dry run's verdict, the relayed run and its record.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context;
use nesy_core::Embodiment;
use nesy_core::metrics::SubtaskResult;
use nesy_policy::{ExecutionResult, Limits, Outcome, WorkerCommand, run_relayed};
use nesy_robot::{Bridge, ClientOptions, RobotAddress, RobotClient, Workspace};
use serde_json::json;

/// The robot flags shared by `nesy run` and `nesy adapt`.
#[derive(Debug, Clone, clap::Args)]
pub(crate) struct RobotArgs {
    /// Run the policy on the robot served at this address (`HOST:PORT`, `tcp://HOST:PORT` or
    /// `unix:PATH`; see docs/robot-protocol.md), after it reached its goal in simulation.
    #[arg(long, value_name = "ADDRESS")]
    pub robot: Option<RobotAddress>,
    /// Reach the robot without the dry run in simulation (stated in the run record).
    #[arg(long, requires = "robot")]
    pub skip_dry_run: bool,
    /// The box the tool must stay in: XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX in metres, in the
    /// robot's world frame (default: the simulated table's workspace).
    #[arg(long, value_name = "BOX", requires = "robot")]
    pub workspace: Option<Workspace>,
    /// Fraction of the robot's nominal speed, in (0, 1]; the robot must confirm it.
    #[arg(long, value_name = "SCALE", default_value_t = 0.5, requires = "robot")]
    pub speed_scale: f64,
    /// Ask on the terminal before each call is sent.
    #[arg(long, requires = "robot")]
    pub confirm: bool,
    /// Longest wait for the robot's answer to one call, in seconds.
    #[arg(long, value_name = "SECS", default_value_t = 60.0, requires = "robot")]
    pub call_timeout: f64,
    /// Interval between heartbeats, in seconds.
    #[arg(long, value_name = "SECS", default_value_t = 0.5, requires = "robot")]
    pub heartbeat: f64,
}

/// Why a dry run does not clear a policy for the robot, or `None` if it does: the policy ran
/// to its end, and every goal check of the scene passed.
pub(crate) fn dry_run_verdict(result: &ExecutionResult) -> Option<String> {
    if !result.is_ok() {
        return Some(format!(
            "the policy ended with {} in simulation",
            result.outcome.kind()
        ));
    }
    let failed: Vec<&str> = result
        .subtasks
        .iter()
        .flatten()
        .filter(|s| s.status == SubtaskResult::Fail)
        .map(|s| s.subtask.as_str())
        .collect();
    (!failed.is_empty()).then(|| format!("the goal checks failed in simulation: {}", failed.join(", ")))
}

/// What cleared the policy for the robot.
pub(crate) enum DryRun<'a> {
    /// The policy reached its goal on this scene in simulation.
    Passed {
        /// The scene.
        scene: &'a Path,
        /// The simulated run.
        result: &'a ExecutionResult,
    },
    /// `--skip-dry-run`.
    Skipped,
}

/// One program's run on the robot: what runs, under which limits, what cleared it, and where
/// its record goes.
pub(crate) struct RobotRun<'a> {
    /// The policy's source.
    pub source: &'a str,
    /// The policy's file name, for tracebacks and the record.
    pub policy_file: &'a str,
    /// The sandbox's budgets.
    pub limits: &'a Limits,
    /// The dry run that cleared it, or the skip.
    pub dry_run: DryRun<'a>,
    /// Where `robot-calls.jsonl` and `robot-run.json` go.
    pub run_dir: &'a Path,
    /// The tool the policy was made for, when known.
    pub expected: Option<Embodiment>,
}

/// A run directory's default: `robot-runs/<UTC time>` (`20261206T060505Z`).
pub(crate) fn default_run_dir() -> PathBuf {
    PathBuf::from("robot-runs").join(compact_stamp(&nesy_vlm::now_rfc3339()))
}

/// An RFC 3339 time without its separators, for a directory name.
fn compact_stamp(rfc3339: &str) -> String {
    rfc3339.chars().filter(|c| !matches!(c, '-' | ':')).collect()
}

/// Runs `source` on the robot at `args.robot`, relayed from the sandbox, and writes the run
/// record into `run_dir`: `robot-calls.jsonl` (every call, check and answer) and
/// `robot-run.json` (the settings, the dry run and the result).
pub(crate) fn run_on_robot(
    args: &RobotArgs,
    address: &RobotAddress,
    run: RobotRun<'_>,
) -> anyhow::Result<(ExecutionResult, serde_json::Value)> {
    let RobotRun {
        source,
        policy_file,
        limits,
        dry_run,
        run_dir,
        expected,
    } = run;
    anyhow::ensure!(
        args.speed_scale > 0.0 && args.speed_scale <= 1.0,
        "--speed-scale must be in (0, 1], got {}",
        args.speed_scale
    );
    let options = ClientOptions {
        call_timeout: Duration::from_millis(super::seconds_to_ms("--call-timeout", args.call_timeout)?),
        heartbeat_period: Duration::from_millis(super::seconds_to_ms("--heartbeat", args.heartbeat)?),
        speed_scale: args.speed_scale,
        ..ClientOptions::default()
    };
    let workspace = args.workspace.unwrap_or_else(Workspace::simulated);
    let confirm = if args.confirm {
        Some(terminal_confirmation().context("--confirm asks on the terminal")?)
    } else {
        None
    };
    std::fs::create_dir_all(run_dir)
        .with_context(|| format!("creating the run directory {}", run_dir.display()))?;
    let calls_path = run_dir.join("robot-calls.jsonl");
    let log =
        std::fs::File::create(&calls_path).with_context(|| format!("creating {}", calls_path.display()))?;
    let client = RobotClient::connect(address, options)
        .with_context(|| format!("connecting to the robot at {address}"))?;
    let welcome = client.welcome().clone();
    check_embodiment(expected, welcome.embodiment)?;
    let mut bridge = Bridge::new(client, workspace, log);
    if let Some(confirm) = confirm {
        bridge = bridge.with_confirmation(confirm);
    }
    let worker = WorkerCommand::current_exe().context("locating the nesy executable")?;
    let ran = run_relayed(&worker, source, welcome.embodiment, limits, &mut bridge);
    let sent = bridge.calls_sent();
    let reason = match &ran {
        Ok(result) => format!("the run ended: {}", result.outcome.kind()),
        Err(err) => format!("the run could not start: {err}"),
    };
    bridge.close(&reason);
    let mut result = ran.with_context(|| format!("running {policy_file} on the robot at {address}"))?;
    result.name_policy_file(policy_file);
    let dry = match dry_run {
        DryRun::Passed { scene, result } => passed_dry_run_json(scene, result),
        DryRun::Skipped => json!({"skipped": true}),
    };
    let record = json!({
        "contacted": true,
        "policy": policy_file,
        "robot": {"address": address.to_string(), "welcome": welcome},
        "workspace": {"min": workspace.min, "max": workspace.max},
        "speed_scale": args.speed_scale,
        "confirm": args.confirm,
        "dry_run": dry,
        "calls_sent": sent,
        "result": result,
    });
    let record_path = run_dir.join("robot-run.json");
    std::fs::write(&record_path, serde_json::to_string_pretty(&record)? + "\n")
        .with_context(|| format!("writing {}", record_path.display()))?;
    Ok((result, record))
}

/// What `--json` prints when the dry run kept the robot out: the dry run and why.
pub(crate) fn not_contacted_json(scene: &Path, result: &ExecutionResult, why: &str) -> serde_json::Value {
    json!({
        "contacted": false,
        "reason": why,
        "dry_run": passed_dry_run_json(scene, result),
    })
}

/// A dry run that ran, as the records show it.
fn passed_dry_run_json(scene: &Path, result: &ExecutionResult) -> serde_json::Value {
    json!({
        "skipped": false,
        "scene": scene,
        "outcome": result.outcome.kind(),
        "subtasks": result.subtasks,
        "api_calls": result.trace.len(),
    })
}

/// Asks `send CALL to the robot? [y/N]` on the controlling terminal before each call.
fn terminal_confirmation() -> anyhow::Result<nesy_robot::Confirm> {
    let tty = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open("/dev/tty")
        .context("no terminal to ask on (/dev/tty)")?;
    let mut reader = std::io::BufReader::new(tty.try_clone()?);
    let mut writer = tty;
    Ok(Box::new(move |call| {
        let _ = write!(writer, "send {} to the robot? [y/N] ", call.label());
        let _ = writer.flush();
        let mut answer = String::new();
        reader.read_line(&mut answer).is_ok() && matches!(answer.trim(), "y" | "Y" | "yes")
    }))
}

/// The embodiment check between a scene's and the robot's: a policy for one tool does not
/// run on the other.
fn check_embodiment(expected: Option<Embodiment>, robot: Embodiment) -> anyhow::Result<()> {
    if let Some(expected) = expected {
        anyhow::ensure!(
            expected == robot,
            "the policy was made for the {expected} robot, but the robot carries the {robot} tool"
        );
    }
    Ok(())
}

/// One line on what happened on the robot, for the summaries.
pub(crate) fn describe_stop(outcome: &Outcome) -> Option<String> {
    match outcome {
        Outcome::RobotStopped {
            call,
            reason,
            message,
        } => Some(format!("stopped at {call} ({}): {message}", reason.as_str())),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_directories_are_named_by_the_time() {
        assert_eq!(
            compact_stamp(&nesy_vlm::rfc3339(1_796_537_105)),
            "20261206T060505Z"
        );
    }
}
