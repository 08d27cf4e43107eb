//! `nesy run`: run a code policy against a scene in the sandboxed worker process.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use nesy_core::Embodiment;
use nesy_policy::{EpisodeSpec, ExecutionResult, Limits, Outcome, WorkerCommand, run_policy};

/// Arguments of `nesy run`.
#[derive(Debug, clap::Args)]
pub(crate) struct RunArgs {
    /// The policy's Python source.
    #[arg(long)]
    pub policy: PathBuf,
    /// Scene file (`scene.json`). With `--robot`, the scene of the dry run in simulation.
    #[arg(long, required_unless_present = "robot")]
    pub scene: Option<PathBuf>,
    /// Override the scene's end effector.
    #[arg(long, value_parser = parse_embodiment)]
    pub embodiment: Option<Embodiment>,
    /// Print the full execution result as JSON.
    #[arg(long)]
    pub json: bool,
    /// Record the execution into `--out`: its calls replayed on a fresh copy of the scene
    /// give `execution.mcap` (a keyframe after every action) and `rollout.mp4` (a frame every
    /// N control steps; N divides 100). 0 records nothing.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub render_every: u32,
    /// Where `--render-every` writes its files.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Wall-clock budget of the policy in seconds.
    #[arg(long, default_value_t = 120.0)]
    pub timeout: f64,
    /// Stop the policy when it makes no robot API call for this many seconds.
    #[arg(long, value_name = "SECS", default_value_t = 10.0)]
    pub idle_timeout: f64,
    /// Maximum number of robot action calls.
    #[arg(long, default_value_t = 200)]
    pub max_actions: usize,
    /// Where a robot run's record goes (default `robot-runs/<UTC time>`).
    #[arg(long, value_name = "DIR", requires = "robot")]
    pub robot_run_dir: Option<PathBuf>,
    /// Running on a robot.
    #[command(flatten)]
    pub robot: super::robot::RobotArgs,
}

pub(crate) fn parse_embodiment(text: &str) -> Result<Embodiment, String> {
    match text {
        "finger" => Ok(Embodiment::Finger),
        "vacuum" => Ok(Embodiment::Vacuum),
        other => Err(format!("expected finger or vacuum, got {other:?}")),
    }
}

/// Runs `nesy run`: exit 0 if the policy ran to its end, 1 if it failed while running, 2 on
/// bad input, a policy the static checks reject included (it never ran).
pub(crate) fn run(args: RunArgs) -> anyhow::Result<ExitCode> {
    let bytes = nesy_input::read_bytes(&args.policy, nesy_input::MAX_POLICY_BYTES)
        .with_context(|| format!("reading the policy {}", args.policy.display()))?;
    let source = nesy_policy::decode_policy_source(&bytes)
        .with_context(|| format!("reading the policy {}", args.policy.display()))?;
    let limits = Limits {
        wall_time_ms: super::seconds_to_ms("--timeout", args.timeout)?,
        idle_ms: super::seconds_to_ms("--idle-timeout", args.idle_timeout)?,
        action_calls: args.max_actions,
        ..Limits::default()
    };
    let rollout_dir = match (args.render_every, &args.out) {
        (0, _) => None,
        (n, Some(out)) => {
            super::rollout::rollout_fps(n)?;
            Some(out.clone())
        }
        (_, None) => anyhow::bail!("--render-every needs --out DIR, where execution.mcap and rollout.mp4 go"),
    };
    let policy_file = args.policy.display().to_string();
    if let Some(address) = &args.robot.robot {
        return run_on_robot(&args, address, &source, &policy_file, &limits);
    }
    let scene = args.scene.as_ref().context("--scene is needed without --robot")?;
    let spec = EpisodeSpec::Scene {
        path: std::path::absolute(scene).unwrap_or(scene.clone()),
        embodiment: args.embodiment,
    };
    let worker = WorkerCommand::current_exe().context("locating the nesy executable")?;
    let mut result = run_policy(&worker, &source, &spec, &limits)
        .with_context(|| format!("running {} on {}", args.policy.display(), scene.display()))?;
    result.name_policy_file(&policy_file);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&result)?)?;
    } else {
        print_summary(&result, &policy_file)?;
    }
    if let Some(dir) = rollout_dir
        && !matches!(result.outcome, Outcome::Rejected { .. })
    {
        let rollout =
            super::rollout::record_rollout(scene, args.embodiment, &result.trace, &dir, args.render_every)?;
        super::rollout::announce(&rollout, "recording: ", args.json)?;
    }
    Ok(if result.is_ok() {
        ExitCode::SUCCESS
    } else if matches!(result.outcome, Outcome::Rejected { .. }) {
        ExitCode::from(crate::EXIT_BAD_INPUT)
    } else {
        ExitCode::from(1)
    })
}

/// `nesy run --robot`: the dry run in simulation on `--scene` (unless `--skip-dry-run`), then
/// the same program on the robot; exit 0 if it ran to its end there, 1 if the dry run or the
/// robot run failed, 2 on bad input.
fn run_on_robot(
    args: &RunArgs,
    address: &nesy_robot::RobotAddress,
    source: &str,
    policy_file: &str,
    limits: &Limits,
) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.render_every == 0,
        "--render-every records a simulated run; it does not apply with --robot"
    );
    let worker = WorkerCommand::current_exe().context("locating the nesy executable")?;
    let dry_result;
    let dry_run = match (&args.scene, args.robot.skip_dry_run) {
        (_, true) => {
            say(args.json, "dry run: skipped (--skip-dry-run)")?;
            super::robot::DryRun::Skipped
        }
        (None, false) => anyhow::bail!(
            "--robot needs --scene for the dry run in simulation (or --skip-dry-run to go without one)"
        ),
        (Some(scene), false) => {
            let spec = EpisodeSpec::Scene {
                path: std::path::absolute(scene).unwrap_or(scene.clone()),
                embodiment: args.embodiment,
            };
            let mut result = run_policy(&worker, source, &spec, limits)
                .with_context(|| format!("dry run of {policy_file} on {}", scene.display()))?;
            result.name_policy_file(policy_file);
            if args.json {
                eprintln!("dry run on {}: {}", scene.display(), result.outcome.kind());
            } else {
                outln!("dry run on {}:", scene.display())?;
                print_summary(&result, policy_file)?;
            }
            if let Some(why) = super::robot::dry_run_verdict(&result) {
                if args.json {
                    let record = super::robot::not_contacted_json(scene, &result, &why);
                    outln!("{}", serde_json::to_string_pretty(&record)?)?;
                } else {
                    outln!("robot: not contacted, {why}")?;
                }
                return Ok(ExitCode::from(1));
            }
            dry_result = result;
            super::robot::DryRun::Passed {
                scene,
                result: &dry_result,
            }
        }
    };
    let expected = match (args.embodiment, &args.scene) {
        (Some(embodiment), _) => Some(embodiment),
        (None, Some(scene)) => Some(
            nesy_sim::scene::SceneSpec::from_file(scene)
                .with_context(|| format!("reading {}", scene.display()))?
                .embodiment,
        ),
        (None, None) => None,
    };
    let run_dir = args
        .robot_run_dir
        .clone()
        .unwrap_or_else(super::robot::default_run_dir);
    let run = super::robot::RobotRun {
        source,
        policy_file,
        limits,
        dry_run,
        run_dir: &run_dir,
        expected,
    };
    let (result, record) = super::robot::run_on_robot(&args.robot, address, run)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&record)?)?;
    } else {
        outln!("on the robot at {address}:")?;
        print_summary(&result, policy_file)?;
    }
    say(args.json, &format!("record: {}", run_dir.display()))?;
    Ok(if result.is_ok() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// A line for the reader: on stdout, or on stderr when stdout carries `--json`'s object.
fn say(json: bool, line: &str) -> std::io::Result<()> {
    if json {
        eprintln!("{line}");
        Ok(())
    } else {
        outln!("{line}")
    }
}

fn print_summary(result: &ExecutionResult, policy_file: &str) -> std::io::Result<()> {
    if !result.stdout.text.is_empty() {
        out!("{}", result.stdout.text)?;
    }
    if !result.stderr.text.is_empty() {
        eprint!("{}", result.stderr.text);
    }
    let actions = result.trace.iter().filter(|e| e.call.is_action()).count();
    let refused = result.trace.iter().filter(|e| e.result.is_err()).count();
    outln!(
        "outcome: {} ({} API calls, {actions} actions, {refused} refused, {:.2} s)",
        result.outcome.kind(),
        result.trace.len(),
        result.wall_time_s
    )?;
    match &result.outcome {
        Outcome::Ok => {}
        Outcome::Rejected { violations } => {
            for v in violations {
                outln!("  {}", v.located(policy_file))?;
            }
        }
        Outcome::PythonError(error) => outln!("{}", error.traceback)?,
        Outcome::SandboxViolation { event, detail, .. } => outln!(
            "  refused: {event}{}",
            detail.as_ref().map(|d| format!(" ({d})")).unwrap_or_default()
        )?,
        Outcome::Timeout { limit, error } => {
            outln!("  limit: {limit:?}")?;
            if let Some(error) = error {
                outln!("{}", error.traceback)?;
            }
        }
        Outcome::Memory { .. } => outln!("  out of memory")?,
        Outcome::Killed { reason } => outln!("  {reason}")?,
        Outcome::RobotStopped { .. } => outln!(
            "  {}",
            super::robot::describe_stop(&result.outcome).unwrap_or_default()
        )?,
    }
    match &result.subtasks {
        Some(subtasks) => {
            for s in subtasks {
                outln!("subtask {}: {:?}", s.subtask, s.status)?;
            }
        }
        None => outln!("subtasks: goal checks not available")?,
    }
    if let Some(state) = &result.final_state {
        outln!("final state:\n{state}")?;
    }
    Ok(())
}
