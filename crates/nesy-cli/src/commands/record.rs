//! `nesy record`: run the scripted expert on one side of a benchmark scenario and write the
//! demonstration as `DIR/demo.mcap`, with the scenario's target scene as `DIR/target.json`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use nesy_sim::demo::{RecordOptions, record_scene, write_mcap_file};
use nesy_sim::perception::render::{MAX_RENDER_THREADS, VIEW_SIZE, default_threads};
use nesy_sim::tasks::scenario::{self, Side};

use super::scenarios::{SideArg, load_suite};

/// Arguments of `nesy record`.
#[derive(Debug, clap::Args)]
pub(crate) struct RecordArgs {
    /// Scenario id, e.g. `obst_low_00_s0` (`nesy scenarios list --ids` lists them).
    #[arg(long)]
    pub scenario: String,
    /// Which side to demonstrate (the demo is normally the source).
    #[arg(long, value_enum, default_value = "source")]
    pub side: SideArg,
    /// Output directory; receives `demo.mcap` and `target.json`.
    #[arg(long)]
    pub out: PathBuf,
    /// Image side in pixels.
    #[arg(long, default_value_t = VIEW_SIZE)]
    pub size: u32,
    /// Render threads (default: available cores, at most 4; at most 64).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_RENDER_THREADS as u64))]
    pub threads: Option<u64>,
    /// Read the configurations from this directory instead of generating them.
    #[arg(long)]
    pub suite: Option<PathBuf>,
}

/// Runs `nesy record`. Exit 1 when the expert does not reach `full_success`, or knocks a
/// placed object out of place again so the final state lacks the goal (the demo is still
/// written).
pub(crate) fn run(args: RecordArgs) -> anyhow::Result<ExitCode> {
    if !(16..=4096).contains(&args.size) {
        anyhow::bail!("--size must be between 16 and 4096 pixels, got {}", args.size);
    }
    let files = load_suite(args.suite.as_deref())?;
    let scenario = scenario::find(&files, &args.scenario)?;
    let side: Side = args.side.into();
    let scene = scenario.generate(side)?.scene;
    let target = scenario.generate(Side::Target)?.scene;
    let options = RecordOptions {
        image_size: args.size,
        render_threads: args.threads.map_or_else(default_threads, |n| n as usize).max(1),
        scenario_id: Some(scenario.id.clone()),
        side: Some(side.as_str().to_owned()),
        target_scene: Some(target.clone()),
    };
    let started = Instant::now();
    let recording = record_scene(&scene, &options).with_context(|| format!("recording {}", scenario.id))?;
    let mcap = args.out.join("demo.mcap");
    write_mcap_file(&recording.demo, &mcap)?;
    let target_path = args.out.join("target.json");
    std::fs::write(&target_path, target.to_json_pretty() + "\n")
        .with_context(|| format!("writing {}", target_path.display()))?;
    let wall = started.elapsed().as_secs_f64();
    let keyframes = recording.demo.keyframes.len();
    let size = std::fs::metadata(&mcap).map(|m| m.len()).unwrap_or(0);
    outln!("{}", mcap.display())?;
    outln!("{}", target_path.display())?;
    eprintln!(
        "{} {side}: {keyframes} keyframes, {:.1} simulated s; {}; {:.2} s wall ({:.2} s simulating, {:.2} s rendering; {:.0} ms simulating per keyframe); {:.2} MB",
        scenario.id,
        recording.sim_seconds,
        recording.outcome.summary(),
        wall,
        recording.sim_wall.as_secs_f64(),
        recording.render_wall.as_secs_f64(),
        1e3 * recording.sim_wall.as_secs_f64() / keyframes.max(1) as f64,
        size as f64 / 1e6
    );
    if let Some(error) = &recording.expert_error {
        eprintln!("expert stopped: {error}");
    }
    if !recording.outcome.displaced.is_empty() {
        eprintln!(
            "placed but out of place at the end, so the demo's final state lacks them: {}",
            recording.outcome.displaced.join(", ")
        );
    }
    Ok(if recording.demonstrates_goal() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
