//! Recording a demo: the scripted expert runs in the simulator while a hook captures a
//! keyframe (three views plain and labelled, the observer's state, the call) after every
//! completed action call, plus the initial keyframe.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::{
    CameraImages, CameraName, Demo, DemoMetadata, Demonstrator, Keyframe, KeyframeViews, NESY_VERSION,
};
use crate::api::{RobotApi, TraceEntry};
use crate::perception::render::{View, render_views};
use crate::scene::{SceneError, SceneSpec};
use crate::tasks::experts::{self, ExpertError};
use crate::tasks::goal::{EpisodeOutcome, GoalError, GoalMonitor};
use crate::world::{Sim, SimHook};

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

/// Builds `scene`, runs the scripted expert on its goals while recording keyframes, and
/// finishes the episode with the goal checker.
pub fn record_scene(scene: &SceneSpec, options: &RecordOptions) -> Result<Recording, RecordError> {
    let started = Instant::now();
    let mut sim = Sim::new(scene)?;
    let monitor = GoalMonitor::attach(&mut sim)?;
    let captured = Arc::new(Mutex::new(Captured::default()));
    let hook = KeyframeHook {
        captured: captured.clone(),
        image_size: options.image_size,
        render_threads: options.render_threads.max(1),
    };
    hook.capture(&sim, None);
    sim.add_hook(Box::new(hook));
    let expert_error = experts::run(&mut sim, scene).err();
    let outcome = monitor.finish(&mut sim);
    // The recorder is done: later calls (the object list below) add no keyframes.
    drop(sim.take_hooks());
    let objects = sim.get_obj_names();
    let captured = std::mem::take(&mut *captured.lock().unwrap_or_else(|e| e.into_inner()));
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
    Ok(Recording {
        demo,
        outcome,
        expert_error,
        sim_wall: started.elapsed().saturating_sub(captured.render_wall),
        render_wall: captured.render_wall,
        sim_seconds,
    })
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
}

impl ExpertRun {
    /// True when the expert finished and every subtask reached `full_success`.
    pub fn full_success(&self) -> bool {
        self.expert_error.is_none() && self.outcome.full_success()
    }
}

/// Runs the scripted expert on `scene` and checks the goals (no images).
pub fn run_expert(scene: &SceneSpec) -> Result<ExpertRun, RecordError> {
    let mut sim = Sim::new(scene)?;
    let monitor = GoalMonitor::attach(&mut sim)?;
    let start = sim.time();
    let expert_error = experts::run(&mut sim, scene).err();
    let outcome = monitor.finish(&mut sim);
    Ok(ExpertRun {
        outcome,
        expert_error,
        actions: sim.actions_used(),
        sim_seconds: sim.time() - start,
    })
}
