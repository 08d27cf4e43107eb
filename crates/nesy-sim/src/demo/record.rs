//! Recording a demo: the scripted expert runs in the simulator while a hook captures a
//! keyframe (three views plain and labelled, the observer's state, the call) after every
//! completed action call, plus the initial keyframe. Optionally a second hook films one
//! camera at a fixed frame rate throughout ([`record_scene_video`]).

use std::sync::mpsc::SyncSender;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use serde::Serialize;

use super::video::{StateSpan, TrueKeyframe, VIDEO_TRUTH_VERSION, VideoFrame, VideoOptions, VideoTruth};
use super::{
    CameraImages, CameraName, Demo, DemoMetadata, Demonstrator, Keyframe, KeyframeViews, NESY_VERSION,
};
use crate::api::{ApiError, ApiValue, RobotApi, TraceEntry};
use crate::perception::render::{Camera, Image, View, draw_label, render_camera, render_views};
use crate::scene::{SceneError, SceneSpec};
use crate::tasks::experts::{self, ExpertError};
use crate::tasks::goal::{EpisodeOutcome, GoalError, GoalMonitor};
use crate::world::{FurnitureContact, FurnitureContactProbe, Sim, SimHook};

/// How to record.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordOptions {
    /// Side of the square views in pixels (the benchmark uses 384).
    pub image_size: u32,
    /// Renderer threads.
    pub render_threads: usize,
    /// Scenario id for the metadata.
    pub scenario_id: Option<String>,
    /// `source` or `target`, for the metadata.
    pub side: Option<String>,
    /// The scene the demo is to be adapted to, for the metadata.
    pub target_scene: Option<SceneSpec>,
}

impl Default for RecordOptions {
    fn default() -> Self {
        RecordOptions {
            image_size: crate::perception::render::VIEW_SIZE,
            render_threads: crate::perception::render::default_threads(),
            scenario_id: None,
            side: None,
            target_scene: None,
        }
    }
}

/// A finished recording.
#[derive(Clone, Debug)]
pub struct Recording {
    /// The demo (also when the expert failed part-way: its keyframes up to the failure).
    pub demo: Demo,
    /// The goal checker's verdict after the end-of-episode settle.
    pub outcome: EpisodeOutcome,
    /// Why the expert stopped early, if it did.
    pub expert_error: Option<ExpertError>,
    /// Wall time spent simulating (everything except rendering and PNG encoding).
    pub sim_wall: Duration,
    /// Wall time spent rendering and encoding the views.
    pub render_wall: Duration,
    /// Simulated seconds from the first to the last keyframe.
    pub sim_seconds: f64,
}

impl Recording {
    /// True when the expert finished and every subtask reached `full_success`.
    pub fn full_success(&self) -> bool {
        self.expert_error.is_none() && self.outcome.full_success()
    }

    /// [`Recording::full_success`], and no counted object was knocked out of place later:
    /// the demo's final state shows its goal, which adaptation derives from it.
    pub fn demonstrates_goal(&self) -> bool {
        self.expert_error.is_none() && self.outcome.demonstrates_goal()
    }
}

/// Why a scene could not be recorded at all.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The scene does not build.
    #[error("scene: {0}")]
    Scene(#[from] SceneError),
    /// The scene's goals cannot be checked.
    #[error("goals: {0}")]
    Goal(#[from] GoalError),
}

/// What the hook collects.
#[derive(Default)]
struct Captured {
    keyframes: Vec<Keyframe>,
    render_wall: Duration,
}

/// The keyframe-capturing hook.
struct KeyframeHook {
    captured: Arc<Mutex<Captured>>,
    image_size: u32,
    render_threads: usize,
}

impl KeyframeHook {
    fn capture(&self, sim: &Sim, action: Option<TraceEntry>) {
        let started = Instant::now();
        let views = render_views(sim, self.image_size, self.render_threads);
        let views = encode_views(&views);
        let state = crate::perception::observer::observe(sim);
        let mut captured = self.captured.lock().unwrap_or_else(|e| e.into_inner());
        let index = captured.keyframes.len();
        captured.keyframes.push(Keyframe {
            index,
            time: super::mcap_format::stored_time(sim.time()),
            views,
            state: Some(state),
            action,
        });
        captured.render_wall += started.elapsed();
    }
}

impl SimHook for KeyframeHook {
    fn on_call(&mut self, sim: &Sim, entry: &TraceEntry) {
        if entry.call.is_action() && entry.result.is_ok() {
            self.capture(sim, Some(entry.clone()));
        }
    }
}

fn encode_views(views: &[View]) -> KeyframeViews {
    let images = |camera: CameraName| {
        views
            .iter()
            .find(|v| v.camera == camera.as_str())
            .map(|v| CameraImages {
                raw: v.image.to_png(),
                marked: Some(v.marked.to_png()),
            })
            .ok_or(())
    };
    // The renderer always produces the three benchmark cameras.
    KeyframeViews::from_fn(images).unwrap_or_default()
}

/// What the video hook collects besides the frames it sends.
#[derive(Default)]
struct Filmed {
    frames: usize,
    states: Vec<StateSpan>,
    /// The receiver hung up: frames are no longer rendered.
    closed: bool,
    render_wall: Duration,
}

/// The filming hook: one camera every `interval` control steps.
struct VideoHook {
    camera: Camera,
    size: u32,
    render_threads: usize,
    interval: u64,
    frames: SyncSender<VideoFrame>,
    fps: u32,
    filmed: Arc<Mutex<Filmed>>,
    /// Text written along each frame's bottom edge (a rollout's current call); `None` films
    /// the picture alone, as a demonstration's keyframe detection must see it.
    caption: Option<Arc<Mutex<String>>>,
}

impl VideoHook {
    fn film(&self, sim: &Sim) {
        let mut filmed = self.filmed.lock().unwrap_or_else(|e| e.into_inner());
        if filmed.closed {
            return;
        }
        let started = Instant::now();
        let mut image = render_camera(sim, &self.camera, self.size, self.size, self.render_threads);
        if let Some(caption) = &self.caption {
            let text = caption.lock().unwrap_or_else(|e| e.into_inner()).clone();
            write_caption(&mut image, &text);
        }
        let state = crate::perception::observer::observe(sim);
        let index = filmed.frames;
        if filmed.states.last().is_none_or(|s| s.state != state) {
            filmed.states.push(StateSpan {
                first_frame: index,
                state,
            });
        }
        filmed.frames += 1;
        let frame = VideoFrame {
            index,
            time: index as f64 / f64::from(self.fps),
            image,
        };
        if self.frames.send(frame).is_err() {
            filmed.closed = true;
        }
        filmed.render_wall += started.elapsed();
    }
}

/// Writes `text` centred along the bottom edge of `image`, cut to the width with `...`.
fn write_caption(image: &mut Image, text: &str) {
    if text.is_empty() {
        return;
    }
    let fits = (image.width as usize).saturating_sub(8) / CAPTION_ADVANCE;
    let shown: String = if text.chars().count() > fits {
        let mut cut: String = text.chars().take(fits.saturating_sub(3)).collect();
        cut.push_str("...");
        cut
    } else {
        text.to_owned()
    };
    draw_label(
        image,
        &shown,
        i64::from(image.width) / 2,
        i64::from(image.height) - 8,
    );
}

/// Pixels per caption character ([`draw_label`]'s glyph advance).
const CAPTION_ADVANCE: usize = 7;

impl SimHook for VideoHook {
    fn step_interval(&self) -> Option<u64> {
        Some(self.interval)
    }

    fn on_step(&mut self, sim: &Sim) {
        self.film(sim);
    }
}

/// Builds `scene`, runs the scripted expert on its goals while recording keyframes, and
/// finishes the episode with the goal checker.
pub fn record_scene(scene: &SceneSpec, options: &RecordOptions) -> Result<Recording, RecordError> {
    record(scene, options, None).map(|(recording, _)| recording)
}

/// [`record_scene`] while filming `video.camera` at `video.fps` from the first keyframe to
/// the end of the episode: each frame goes to `frames` as soon as it is rendered (a closed
/// receiver stops the filming, not the recording), and the robot holds still for
/// `video.hold_seconds` after each action. Returns the recording and the video's ground
/// truth: the true keyframes' frames and the observer's state at every frame.
pub fn record_scene_video(
    scene: &SceneSpec,
    options: &RecordOptions,
    video: &VideoOptions,
    frames: SyncSender<VideoFrame>,
) -> Result<(Recording, VideoTruth), RecordError> {
    let (recording, filmed) = record(scene, options, Some((video, frames)))?;
    let truth = video_truth(&recording.demo, video, filmed);
    Ok((recording, truth))
}

/// The ground truth of a filmed recording.
fn video_truth(demo: &Demo, video: &VideoOptions, filmed: Filmed) -> VideoTruth {
    VideoTruth {
        format_version: VIDEO_TRUTH_VERSION,
        instruction: demo.metadata.instruction.clone(),
        objects: demo.metadata.objects.clone(),
        embodiment: demo.metadata.embodiment,
        scenario_id: demo.metadata.scenario_id.clone(),
        side: demo.metadata.side.clone(),
        camera: video.camera.name.to_owned(),
        width: video.size,
        height: video.size,
        fps: video.fps,
        hold_seconds: video.hold_seconds,
        frames: filmed.frames,
        keyframes: demo
            .keyframes
            .iter()
            .map(|k| TrueKeyframe {
                index: k.index,
                time: k.time,
                frame: ((k.time * f64::from(video.fps)).round() as usize)
                    .min(filmed.frames.saturating_sub(1)),
                action: k.action.clone(),
            })
            .collect(),
        states: filmed.states,
    }
}

fn record(
    scene: &SceneSpec,
    options: &RecordOptions,
    video: Option<(&VideoOptions, SyncSender<VideoFrame>)>,
) -> Result<(Recording, Filmed), RecordError> {
    let film = video.map(|(video, frames)| Filming {
        video,
        frames,
        caption: None,
        hold: true,
    });
    let driven = drive(scene, options, film, |sim| experts::run(sim, scene).err())?;
    // A demonstration is of a task: a scene without goals was refused by the goal monitor.
    let outcome = driven.outcome.ok_or(RecordError::Goal(GoalError::NoGoals))?;
    let recording = Recording {
        demo: driven.demo,
        outcome,
        expert_error: driven.driver,
        sim_wall: driven.sim_wall,
        render_wall: driven.render_wall,
        sim_seconds: driven.sim_seconds,
    };
    Ok((recording, driven.filmed))
}

/// How to film while a driver works the robot.
struct Filming<'a> {
    video: &'a VideoOptions,
    frames: SyncSender<VideoFrame>,
    /// The caption written on every frame, which the driver updates.
    caption: Option<Arc<Mutex<String>>>,
    /// Whether the robot holds still after each action (a demonstration's pauses).
    hold: bool,
}

/// What [`drive`] collected.
struct Driven<T> {
    demo: Demo,
    /// The goal checker's verdict (`None` for a scene without goals).
    outcome: Option<EpisodeOutcome>,
    filmed: Filmed,
    driver: T,
    sim_wall: Duration,
    render_wall: Duration,
    sim_seconds: f64,
}

/// Builds `scene`, lets `driver` work the robot while keyframes are captured (and a camera
/// films, with `film`), and finishes the episode with the goal checker (or the settle steps,
/// for a scene without goals).
fn drive<T>(
    scene: &SceneSpec,
    options: &RecordOptions,
    film: Option<Filming<'_>>,
    driver: impl FnOnce(&mut Sim) -> T,
) -> Result<Driven<T>, RecordError> {
    let started = Instant::now();
    let mut sim = Sim::new(scene)?;
    let monitor = if scene.goals.is_empty() {
        None
    } else {
        Some(GoalMonitor::attach(&mut sim)?)
    };
    let captured = Arc::new(Mutex::new(Captured::default()));
    let hook = KeyframeHook {
        captured: captured.clone(),
        image_size: options.image_size,
        render_threads: options.render_threads.max(1),
    };
    hook.capture(&sim, None);
    sim.add_hook(Box::new(hook));
    let filmed = Arc::new(Mutex::new(Filmed::default()));
    if let Some(film) = film {
        let hook = VideoHook {
            camera: film.video.camera,
            size: film.video.size,
            render_threads: options.render_threads.max(1),
            interval: film.video.step_interval(),
            frames: film.frames,
            fps: film.video.fps,
            filmed: filmed.clone(),
            caption: film.caption,
        };
        hook.film(&sim);
        sim.add_hook(Box::new(hook));
        if film.hold {
            sim.set_action_pause(film.video.hold_steps());
        }
    }
    let driver = driver(&mut sim);
    let outcome = match monitor {
        Some(monitor) => Some(monitor.finish(&mut sim)),
        None => {
            sim.step_idle(crate::tasks::goal::POST_RUN_SETTLE_STEPS);
            None
        }
    };
    // The recorder is done: later calls (the object list below) add no keyframes.
    drop(sim.take_hooks());
    let objects = sim.get_obj_names();
    let mut captured = std::mem::take(&mut *captured.lock().unwrap_or_else(|e| e.into_inner()));
    let mut filmed = std::mem::take(&mut *filmed.lock().unwrap_or_else(|e| e.into_inner()));
    captured.render_wall += std::mem::take(&mut filmed.render_wall);
    let sim_seconds = match (captured.keyframes.first(), captured.keyframes.last()) {
        (Some(a), Some(b)) => b.time - a.time,
        _ => 0.0,
    };
    let demo = Demo {
        metadata: DemoMetadata {
            instruction: scene.instruction.clone(),
            objects,
            embodiment: scene.embodiment,
            demonstrator: Demonstrator::Robot,
            imported_from: None,
            scenario_id: options.scenario_id.clone(),
            side: options.side.clone(),
            nesy_version: Some(NESY_VERSION.to_owned()),
            target_scene: options.target_scene.clone(),
        },
        keyframes: captured.keyframes,
    };
    Ok(Driven {
        demo,
        outcome,
        filmed,
        driver,
        sim_wall: started.elapsed().saturating_sub(captured.render_wall),
        render_wall: captured.render_wall,
        sim_seconds,
    })
}

/// Where a replayed trace first did something else than the recorded run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReplayDivergence {
    /// Position of the call in the trace, from 0.
    pub index: usize,
    /// The call.
    pub call: String,
    /// What the recorded run got.
    pub recorded: String,
    /// What the replay got.
    pub replayed: String,
}

/// A policy's execution replayed and recorded ([`replay_execution`]).
#[derive(Clone, Debug)]
pub struct ExecutionRecording {
    /// A keyframe (three views, the observer's state, the call) before the first call and
    /// after every successful action, in the demo layout.
    pub demo: Demo,
    /// The goal checker's verdict after the settle steps (`None` for a scene without goals).
    pub outcome: Option<EpisodeOutcome>,
    /// The first call whose result differed from the recorded one; the replay stops there.
    pub divergence: Option<ReplayDivergence>,
    /// Frames filmed for the rollout video.
    pub frames: usize,
    /// Wall time spent rendering and encoding.
    pub render_wall: Duration,
}

impl ExecutionRecording {
    /// Writes the recording to `path` in the `demo.mcap` format, with the goal checks and
    /// any divergence in a second metadata record
    /// ([`EXECUTION_METADATA_NAME`](super::mcap_format::EXECUTION_METADATA_NAME)), and the
    /// rollout's frames, when given, on `/film/<camera>`
    /// ([`film_topic`](super::mcap_format::film_topic)).
    pub fn write_mcap_file(
        &self,
        path: &std::path::Path,
        film: Option<&super::mcap_format::Film>,
    ) -> Result<(), super::DemoError> {
        let mut metadata = std::collections::BTreeMap::new();
        let json = |value: serde_json::Result<String>| value.unwrap_or_else(|_| "null".to_owned());
        metadata.insert("outcome".to_owned(), json(serde_json::to_string(&self.outcome)));
        if let Some(divergence) = &self.divergence {
            metadata.insert("divergence".to_owned(), json(serde_json::to_string(divergence)));
        }
        let record = mcap::records::Metadata {
            name: super::mcap_format::EXECUTION_METADATA_NAME.to_owned(),
            metadata,
        };
        super::mcap_format::write_mcap_file_with(&self.demo, &[record], film, path)
    }
}

/// Replays a policy's recorded robot API calls, in order and with their recorded arguments,
/// on a fresh copy of `scene` while recording it: the keyframes of [`record_scene`] and, with
/// `video`, a rollout filmed at `video.fps` with each frame captioned by the call under way
/// (no pause after actions: the rollout runs as the policy ran). The simulator is
/// deterministic, so the replay is the execution; every call's result is compared with the
/// recorded one and the first difference is reported (and ends the replay). Recording this
/// way keeps the untrusted policy's sandbox free of any file it could write.
pub fn replay_execution(
    scene: &SceneSpec,
    trace: &[TraceEntry],
    options: &RecordOptions,
    video: Option<(&VideoOptions, SyncSender<VideoFrame>)>,
) -> Result<ExecutionRecording, RecordError> {
    let caption = Arc::new(Mutex::new(String::new()));
    let film = video.map(|(video, frames)| Filming {
        video,
        frames,
        caption: Some(caption.clone()),
        hold: false,
    });
    let driven = drive(scene, options, film, |sim| {
        for entry in trace {
            *caption.lock().unwrap_or_else(|e| e.into_inner()) =
                format!("{} {}", entry.index + 1, entry.call.label());
            let replayed = entry.call.perform(sim);
            if !same_result(&replayed, &entry.result) {
                return Some(ReplayDivergence {
                    index: entry.index,
                    call: entry.call.label(),
                    recorded: describe(&entry.result),
                    replayed: describe(&replayed),
                });
            }
        }
        caption.lock().unwrap_or_else(|e| e.into_inner()).clear();
        None
    })?;
    Ok(ExecutionRecording {
        demo: driven.demo,
        outcome: driven.outcome,
        divergence: driven.driver,
        frames: driven.filmed.frames,
        render_wall: driven.render_wall,
    })
}

/// Whether two results agree: the same value (positions within 1 µm, as a JSON round trip
/// keeps them) or the same refusal.
fn same_result(a: &Result<ApiValue, ApiError>, b: &Result<ApiValue, ApiError>) -> bool {
    match (a, b) {
        (Ok(x), Ok(y)) => {
            let (x, y) = (serde_json::to_value(x).ok(), serde_json::to_value(y).ok());
            match (x, y) {
                (Some(x), Some(y)) => close(&x, &y),
                _ => false,
            }
        }
        (Err(x), Err(y)) => x.to_string() == y.to_string(),
        _ => false,
    }
}

fn close(a: &serde_json::Value, b: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(x), Some(y)) => (x - y).abs() <= 1e-6,
            _ => x == y,
        },
        (Value::Array(x), Value::Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(x, y)| close(x, y)),
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| close(v, w)))
        }
        _ => a == b,
    }
}

fn describe(result: &Result<ApiValue, ApiError>) -> String {
    match result {
        Ok(value) => serde_json::to_string(value).unwrap_or_else(|_| format!("{value:?}")),
        Err(error) => format!("error: {error}"),
    }
}

/// The outcome of running the expert on a scene without recording.
#[derive(Clone, Debug)]
pub struct ExpertRun {
    /// The goal checker's verdict.
    pub outcome: EpisodeOutcome,
    /// Why the expert stopped early, if it did.
    pub expert_error: Option<ExpertError>,
    /// Action calls the expert made.
    pub actions: usize,
    /// Simulated seconds.
    pub sim_seconds: f64,
    /// How deep the arm and what it carried went into furniture, deepest first
    /// ([`FurnitureContactProbe`]).
    pub furniture_contacts: Vec<FurnitureContact>,
}

impl ExpertRun {
    /// True when the expert finished and every subtask reached `full_success`.
    pub fn full_success(&self) -> bool {
        self.expert_error.is_none() && self.outcome.full_success()
    }
}

/// Runs the scripted expert on `scene` and checks the goals (no images), with the robot as
/// the scene sets it up (its protective stop included).
pub fn run_expert(scene: &SceneSpec) -> Result<ExpertRun, RecordError> {
    let mut sim = Sim::new(scene)?;
    let monitor = GoalMonitor::attach(&mut sim)?;
    sim.add_hook(Box::new(FurnitureContactProbe::default()));
    let start = sim.time();
    let expert_error = experts::run(&mut sim, scene).err();
    let outcome = monitor.finish(&mut sim);
    let furniture_contacts = sim
        .hook::<FurnitureContactProbe>()
        .map(FurnitureContactProbe::contacts)
        .unwrap_or_default();
    Ok(ExpertRun {
        outcome,
        expert_error,
        actions: sim.actions_used(),
        sim_seconds: sim.time() - start,
        furniture_contacts,
    })
}
