//! `nesy task new`: a task from a user's pair of scenes, with a recorded demonstration and
//! no scripted expert. The demonstration is planned over the world's true domain from the
//! source scene's observed state to its goal, compiled by the template compiler, run in the
//! sandbox on the source scene, and kept only if every goal was met (in any order) with
//! nothing displaced;
//! the demo is then recorded by replaying that run's calls on a fresh copy of the scene.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use nesy_core::{Formula, Symbol, format_procedure};
use nesy_policy::{EpisodeSpec, Limits, WorkerCommand, run_policy};
use nesy_sim::codegen::compile_policy;
use nesy_sim::demo::{RecordOptions, replay_execution, write_mcap_file};
use nesy_sim::domain::{WorldDomain, control_planner_config, plan_to_goal};
use nesy_sim::perception::observer::observe;
use nesy_sim::perception::render::{MAX_RENDER_THREADS, VIEW_SIZE, default_threads};
use nesy_sim::scene::{SceneSpec, parts};
use nesy_sim::tasks::goal::EpisodeOutcome;
use nesy_sim::world::Sim;
use serde_json::json;

/// Arguments of `nesy task`.
#[derive(Debug, clap::Args)]
pub(crate) struct TaskArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: TaskCommand,
}

/// The subcommands of `nesy task`.
#[derive(Debug, clap::Subcommand)]
pub(crate) enum TaskCommand {
    /// Make a task from a source and a target scene: plan, execute and record the
    /// demonstration in the source scene, with no scripted expert.
    New(NewArgs),
}

/// Arguments of `nesy task new`.
#[derive(Debug, clap::Args)]
pub(crate) struct NewArgs {
    /// The demonstration's scene (`scene.json` with its `goals`).
    #[arg(long)]
    pub source: PathBuf,
    /// The scene the demonstration is to be adapted to (`scene.json` with its `goals`).
    #[arg(long)]
    pub target: PathBuf,
    /// Where the task goes: `demo.mcap`, `source.json`, `target.json`, `plan.txt`,
    /// `policy.py` and `task.json`.
    #[arg(long)]
    pub out: PathBuf,
    /// The task's name in the demo's metadata (default: the output folder's name).
    #[arg(long)]
    pub name: Option<String>,
    /// Side of the demo's square views in pixels.
    #[arg(long, default_value_t = VIEW_SIZE)]
    pub size: u32,
    /// Renderer threads (default: all cores, at most 8).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_RENDER_THREADS as u64))]
    pub threads: Option<u64>,
}

/// Runs `nesy task`.
pub(crate) fn run(args: TaskArgs) -> anyhow::Result<ExitCode> {
    match args.command {
        TaskCommand::New(args) => new(args),
    }
}

/// A scene with goals, read from `path`.
fn scene_with_goals(path: &Path, role: &str) -> anyhow::Result<SceneSpec> {
    let scene = SceneSpec::from_file(path).with_context(|| format!("reading the {role} scene"))?;
    anyhow::ensure!(
        !scene.goals.is_empty(),
        "{}: the {role} scene has no `goals`: a task needs them, to plan its demonstration and to score an adaptation",
        path.display()
    );
    Ok(scene)
}

/// A plan from `scene`'s observed initial state to its goal over the true domain, with the
/// names the template compiler resolves actions against.
fn plan(
    scene: &SceneSpec,
    path: &Path,
    role: &str,
) -> anyhow::Result<(Vec<nesy_core::Operator>, Vec<String>)> {
    let sim = Sim::new(scene).with_context(|| format!("building the {role} scene {}", path.display()))?;
    let state = observe(&sim);
    let objects: Vec<String> = sim
        .names()
        .into_iter()
        .filter(|n| ![parts::GRIPPER, parts::VACUUM_GRIPPER].contains(&n.as_str()))
        .collect();
    let symbols: Vec<Symbol> = objects.iter().map(|o| Symbol::new(o)).collect();
    let goal = Formula::And(scene.symbolic_goal().into_iter().map(Formula::atom).collect());
    let world = WorldDomain::builtin().context("loading the true domain")?;
    let procedure = plan_to_goal(world, &state, &goal, scene.embodiment, &symbols, &control_planner_config())
        .map_err(|reason| {
            anyhow::anyhow!(
                "{}: the {role} scene's goal cannot be planned from its initial state over the true domain ({reason})",
                path.display()
            )
        })?;
    Ok((procedure, objects))
}

fn new(args: NewArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        (16..=4096).contains(&args.size),
        "--size must be between 16 and 4096 pixels, got {}",
        args.size
    );
    let source = scene_with_goals(&args.source, "source")?;
    let target = scene_with_goals(&args.target, "target")?;
    let name = match &args.name {
        Some(name) => name.clone(),
        None => args
            .out
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "task".to_owned()),
    };

    // 1. Plan both sides: the source's plan is the demonstration; a target no planner can
    //    solve from its own state would make a task no method can succeed on.
    let (procedure, objects) = plan(&source, &args.source, "source")?;
    let (target_plan, _) = plan(&target, &args.target, "target")?;
    let compiled = compile_policy(&procedure, &objects, source.embodiment, source.protective_stop)
        .with_context(|| format!("compiling the plan for {}", args.source.display()))?;

    // 2. Run the program in the sandbox on the source scene.
    let spec = EpisodeSpec::Scene {
        path: std::path::absolute(&args.source).unwrap_or(args.source.clone()),
        embodiment: None,
    };
    let worker = WorkerCommand::current_exe().context("locating the nesy executable")?;
    let executed = run_policy(&worker, &compiled.code, &spec, &Limits::default())
        .with_context(|| format!("executing the planned demonstration on {}", args.source.display()))?;
    anyhow::ensure!(
        executed.is_ok(),
        "{}: the planned demonstration did not run to its end in simulation ({}): {}",
        args.source.display(),
        executed.outcome.kind(),
        serde_json::to_string(&executed.outcome).unwrap_or_default()
    );

    // 3. Record it: the same calls replayed on a fresh copy of the scene, filmed by the three
    //    cameras, scored by the goal checks.
    let options = RecordOptions {
        image_size: args.size,
        render_threads: args.threads.map_or_else(default_threads, |n| n as usize).max(1),
        scenario_id: Some(name.clone()),
        side: Some("source".to_owned()),
        target_scene: Some(target.clone()),
    };
    let recording = replay_execution(&source, &executed.trace, &options, None)
        .with_context(|| format!("recording the demonstration on {}", args.source.display()))?;
    if let Some(divergence) = &recording.divergence {
        anyhow::bail!(
            "{}: replaying the demonstration diverged at call {} ({}): recorded {}, replayed {}",
            args.source.display(),
            divergence.index + 1,
            divergence.call,
            divergence.recorded,
            divergence.replayed
        );
    }
    let outcome = recording
        .outcome
        .as_ref()
        .context("the source scene's goals were not checked")?;
    check_demonstration(&args.source, outcome)?;

    // 4. Write the task.
    let out = &args.out;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let write = |file: &str, text: String| -> anyhow::Result<PathBuf> {
        let path = out.join(file);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    };
    let mcap = out.join("demo.mcap");
    write_mcap_file(&recording.demo, &mcap)?;
    write("source.json", source.to_json_pretty() + "\n")?;
    let target_path = write("target.json", target.to_json_pretty() + "\n")?;
    write("plan.txt", format_procedure(&procedure))?;
    write("policy.py", compiled.code.clone())?;
    let summary = json!({
        "name": name,
        "source": args.source,
        "target": args.target,
        "embodiment": {"source": source.embodiment, "target": target.embodiment},
        "plan_steps": procedure.len(),
        "target_plan_steps": target_plan.len(),
        "api_calls": executed.trace.len(),
        "keyframes": recording.demo.keyframes.len(),
        "goals": outcome.summary(),
        "demonstrated_order": outcome.achieved_sequence,
    });
    write("task.json", serde_json::to_string_pretty(&summary)? + "\n")?;
    outln!(
        "nesy task new: {name}: {} planned steps, {} API calls, {} keyframes; {}",
        procedure.len(),
        executed.trace.len(),
        recording.demo.keyframes.len(),
        outcome.summary()
    )?;
    if !outcome.full_success() {
        outln!(
            "  order     the plan met the goal in another order than it lists: {}",
            outcome.achieved_sequence.join(", ")
        )?;
    }
    outln!("  demo      {}", mcap.display())?;
    outln!("  target    {}", target_path.display())?;
    outln!(
        "  adapt it  nesy adapt --demo {} --target {} --vlm oracle --execute",
        mcap.display(),
        target_path.display()
    )?;
    Ok(ExitCode::SUCCESS)
}

/// Keeps a recorded demonstration only if it shows its goal: every subtask met (full or
/// partial; `docs/benchmark.md` §7: partial when the objects went in another order than the
/// goal lists, as a stack can force) and nothing that was counted as placed knocked out of
/// place afterwards, since the demonstration's final state becomes the goal of adaptation.
fn check_demonstration(source: &Path, outcome: &EpisodeOutcome) -> anyhow::Result<()> {
    anyhow::ensure!(
        outcome.success(),
        "{}: the planned demonstration did not meet every goal ({}); a demonstration must show its goal",
        source.display(),
        outcome.summary()
    );
    anyhow::ensure!(
        outcome.displaced.is_empty(),
        "{}: the planned demonstration displaced {} after placing it; a demonstration must end showing its goal",
        source.display(),
        outcome.displaced.join(", ")
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An outcome as the goal monitor reports it: one `pick_place` subtask met by
    /// `red_cube`, with `displaced` the objects knocked out of place after being counted.
    fn outcome(displaced: &[&str]) -> EpisodeOutcome {
        serde_json::from_value(json!({
            "subtasks": [{
                "subtask": "pick_place",
                "result": "full_success",
                "decided_at_step": 1200,
                "label": ["red_cube"],
                "achieved": [{"name": "red_cube", "step": 1200}],
                "displaced": displaced,
            }],
            "decision_order": [0],
            "goal_label": ["red_cube"],
            "achieved_sequence": ["red_cube"],
            "final_call": false,
            "end_step": 2400,
            "displaced": displaced,
        }))
        .expect("a well-formed outcome")
    }

    #[test]
    fn a_demonstration_that_shows_its_goal_is_kept() {
        check_demonstration(Path::new("source.json"), &outcome(&[])).expect("kept");
    }

    #[test]
    fn a_demonstration_that_knocked_a_placed_object_out_is_refused_naming_it() {
        let error = check_demonstration(Path::new("scenes/source.json"), &outcome(&["red_cube"]))
            .expect_err("refused");
        assert_eq!(
            error.to_string(),
            "scenes/source.json: the planned demonstration displaced red_cube after placing it; \
             a demonstration must end showing its goal"
        );
    }

    #[test]
    fn a_demonstration_that_missed_a_goal_is_refused_with_the_verdicts() {
        let mut missed = outcome(&[]);
        missed.subtasks[0].result = nesy_core::metrics::SubtaskResult::Fail;
        let error = check_demonstration(Path::new("source.json"), &missed).expect_err("refused");
        assert_eq!(
            error.to_string(),
            "source.json: the planned demonstration did not meet every goal (pick_place: fail); \
             a demonstration must show its goal"
        );
    }
}
