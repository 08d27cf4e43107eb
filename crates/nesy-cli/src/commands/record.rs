//! `nesy record`: run the scripted expert on one side of a benchmark scenario and write the
//! demonstration as `DIR/demo.mcap`, with the scenario's target scene as `DIR/target.json`;
//! with `--video`, also a continuous video of one camera (`DIR/demo.mp4`) and its ground truth
//! (`DIR/demo.video.json`).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use nesy_sim::demo::{
    RecordOptions, Recording, VIDEO_TRUTH_FILE, VideoOptions, VideoTruth, record_scene, record_scene_video,
    write_mcap_file,
};
use nesy_sim::perception::render::{
    CORNER_CAMERA, Camera, MAX_RENDER_THREADS, VIEW_SIZE, default_threads, filming_camera,
};
use nesy_sim::tasks::scenario::{self, Side};

use super::scenarios::{SideArg, suite_of};

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
    /// Also film the demonstration: `DIR/demo.mp4` (H.264, one camera, a fixed frame rate,
    /// from the first keyframe to the end of the episode) and `DIR/demo.video.json` (the true
    /// keyframe times and the state at every frame). The robot then holds still for `--hold`
    /// seconds after each action.
    #[arg(long)]
    pub video: bool,
    /// The camera filmed: `corner` (above the table's front-right corner, where a person
    /// filming would stand; not a benchmark view) or one of the benchmark's three.
    #[arg(long, value_enum, default_value = "corner")]
    pub video_view: VideoViewArg,
    /// Video frames per second (it must divide the simulator's 100 control steps per second).
    #[arg(long, default_value_t = 10)]
    pub video_fps: u32,
    /// Video frame side in pixels (even).
    #[arg(long, default_value_t = 256)]
    pub video_size: u32,
    /// Seconds the robot holds still after each action while filming.
    #[arg(long, default_value_t = 0.5)]
    pub hold: f64,
}

/// A camera to film, as the command line writes it.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub(crate) enum VideoViewArg {
    /// Above and beyond the table's front-right corner.
    Corner,
    /// Looking down on the table.
    Top,
    /// Facing the robot from beyond the table.
    Front,
    /// From behind the robot.
    Back,
}

impl VideoViewArg {
    fn camera(self) -> Camera {
        let name = match self {
            VideoViewArg::Corner => CORNER_CAMERA.name,
            VideoViewArg::Top => "top",
            VideoViewArg::Front => "front",
            VideoViewArg::Back => "back",
        };
        filming_camera(name).unwrap_or(CORNER_CAMERA)
    }
}

/// Records `scene` while a second thread encodes the video's frames as they come.
fn record_with_video(
    scene: &nesy_sim::scene::SceneSpec,
    options: &RecordOptions,
    video: &VideoOptions,
    path: &std::path::Path,
) -> anyhow::Result<(Recording, VideoTruth)> {
    let (recorded, written, _) = super::rollout::with_video_encoder(path, video.fps, false, |frames| {
        record_scene_video(scene, options, video, frames)
    })?;
    let recorded = recorded?;
    anyhow::ensure!(
        written == recorded.1.frames,
        "{}: {written} frame(s) written of {} rendered",
        path.display(),
        recorded.1.frames
    );
    Ok(recorded)
}

/// Runs `nesy record`. Exit 1 when the expert does not reach `full_success`, or knocks a
/// placed object out of place again so the final state lacks the goal (the demo is still
/// written).
pub(crate) fn run(args: RecordArgs) -> anyhow::Result<ExitCode> {
    if !(16..=4096).contains(&args.size) {
        anyhow::bail!("--size must be between 16 and 4096 pixels, got {}", args.size);
    }
    let files = suite_of(args.suite.as_deref(), &args.scenario)?;
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
    let video = VideoOptions {
        camera: args.video_view.camera(),
        size: args.video_size,
        fps: args.video_fps,
        hold_seconds: args.hold,
    };
    if args.video {
        video.check().map_err(anyhow::Error::msg)?;
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let started = Instant::now();
    let video_path = args.out.join("demo.mp4");
    let (recording, truth) = if args.video {
        let (recording, truth) = record_with_video(&scene, &options, &video, &video_path)
            .with_context(|| format!("recording {} with a video", scenario.id))?;
        (recording, Some(truth))
    } else {
        let recording =
            record_scene(&scene, &options).with_context(|| format!("recording {}", scenario.id))?;
        (recording, None)
    };
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
    if let Some(truth) = &truth {
        let truth_path = args.out.join(VIDEO_TRUTH_FILE);
        truth.write(&truth_path)?;
        outln!("{}", video_path.display())?;
        outln!("{}", truth_path.display())?;
        eprintln!(
            "video: {} frames at {} fps ({}, {}x{}), {} true keyframes, {} state changes",
            truth.frames,
            truth.fps,
            truth.camera,
            truth.width,
            truth.height,
            truth.keyframes.len(),
            truth.states.len().saturating_sub(1)
        );
    }
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
