//! Step 1: the demo and the target scene.
//!
//! The demo is read with `nesy_sim::demo::read` (`demo.mcap`, a folder holding it, or a
//! folder with `manifest.json`). The target scene is built in nesy-sim, which observes its
//! ground-truth initial state and renders the three views (plain and marked).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use nesy_core::State;
use nesy_sim::api::Embodiment;
use nesy_sim::demo::{CameraName, Demo};
use nesy_sim::perception::render::{self, View};
use nesy_sim::scene::{SceneSpec, parts};
use nesy_sim::{Sim, observe};
use nesy_vlm::{Image, KeyframeImages, Views};

use crate::PipelineError;

/// A demo as the pipeline uses it.
#[derive(Debug, Clone)]
pub struct DemoInput {
    /// Where it was read from.
    pub path: PathBuf,
    /// The demo.
    pub demo: Demo,
    /// Time spent reading it.
    pub load_time: Duration,
}

impl DemoInput {
    /// Reads a demo; errors name the file and what was wrong with it.
    pub fn load(path: &Path) -> Result<DemoInput, PipelineError> {
        let started = Instant::now();
        // DemoError's message names the file and the field already (and its I/O cause).
        let demo = nesy_sim::demo::read(path).map_err(|e| PipelineError::Demo {
            path: path.to_owned(),
            message: format!("reading the demo: {e}"),
        })?;
        if demo.keyframes.len() < 2 {
            return Err(PipelineError::Demo {
                path: path.to_owned(),
                message: format!(
                    "a demo needs at least two keyframes (the initial state and one action), found {}",
                    demo.keyframes.len()
                ),
            });
        }
        Ok(DemoInput {
            path: path.to_owned(),
            demo,
            load_time: started.elapsed(),
        })
    }

    /// A demo already in memory (tests, benchmarks).
    pub fn from_demo(path: impl Into<PathBuf>, demo: Demo) -> DemoInput {
        DemoInput {
            path: path.into(),
            demo,
            load_time: Duration::ZERO,
        }
    }

    /// The objects prompts list: the demo's objects without the robot's own
    /// (`gripper`, `vacuum_gripper`), as the authors do.
    pub fn objects(&self) -> Vec<String> {
        scene_objects(&self.demo.metadata.objects)
    }
}

/// Object names without the robot's own.
pub fn scene_objects(names: &[String]) -> Vec<String> {
    names
        .iter()
        .filter(|n| ![parts::GRIPPER, parts::VACUUM_GRIPPER].contains(&n.as_str()))
        .cloned()
        .collect()
}

/// The target scene, built, observed and rendered.
#[derive(Debug, Clone)]
pub struct TargetInput {
    /// Where the scene came from (`<demo>#target_scene` when the demo carried it).
    pub path: PathBuf,
    /// The scene as used (with `embodiment_in_state` set when the embodiment changed).
    pub scene: SceneSpec,
    /// The observed ground-truth initial state.
    pub observed: State,
    /// Object names, without the robot's own, in scene order.
    pub objects: Vec<String>,
    /// The rendered views (top, front, back; plain and marked).
    pub views: Vec<View>,
    /// Time spent building, observing and rendering.
    pub sim_time: Duration,
}

impl TargetInput {
    /// Reads `path` (or, without one, the target scene recorded in the demo), builds it and
    /// observes and renders it. Embodiment atoms go into the state when the target's end
    /// effector differs from the demo's (the authors' `ee_set`).
    pub fn load(path: Option<&Path>, demo: &DemoInput) -> Result<TargetInput, PipelineError> {
        let (path, scene) = match path {
            Some(path) => {
                let scene = SceneSpec::from_file(path).map_err(|e| PipelineError::Target {
                    path: path.to_owned(),
                    message: format!("reading the target scene: {e}"),
                })?;
                (path.to_owned(), scene)
            }
            None => {
                let scene = demo
                    .demo
                    .metadata
                    .target_scene
                    .clone()
                    .ok_or_else(|| PipelineError::Demo {
                        path: demo.path.clone(),
                        message: "no target scene given, and the demo records none (metadata `target_scene`)"
                            .into(),
                    })?;
                (
                    PathBuf::from(format!("{}#target_scene", demo.path.display())),
                    scene,
                )
            }
        };
        Self::from_scene(path, scene, demo.demo.metadata.embodiment)
    }

    /// Builds, observes and renders a scene.
    pub fn from_scene(
        path: PathBuf,
        mut scene: SceneSpec,
        source: Embodiment,
    ) -> Result<TargetInput, PipelineError> {
        let started = Instant::now();
        if scene.embodiment != source {
            scene.embodiment_in_state = true;
        }
        if scene.goals.is_empty() {
            return Err(PipelineError::Target {
                path,
                message: "at goals: expected at least one subtask goal (the target must say what success is), found none".into(),
            });
        }
        let sim = match Sim::new(&scene) {
            Ok(sim) => sim,
            Err(e) => {
                return Err(PipelineError::Target {
                    path,
                    message: format!("building the target scene: {e}"),
                });
            }
        };
        let observed = observe(&sim);
        let objects = scene_objects(&sim.names());
        let views = render::render_views(&sim, render::VIEW_SIZE, render::default_threads());
        Ok(TargetInput {
            path,
            scene,
            observed,
            objects,
            views,
            sim_time: started.elapsed(),
        })
    }

    /// The target's instruction, falling back to the demo's when the scene has none.
    pub fn instruction(&self, demo: &DemoInput) -> String {
        if self.scene.instruction.trim().is_empty() {
            demo.demo.metadata.instruction.clone()
        } else {
            self.scene.instruction.clone()
        }
    }

    /// The marked views as the VLM sees them.
    pub fn marked_views(&self) -> Result<Views, PipelineError> {
        let find = |name: &str| -> Result<Image, PipelineError> {
            let bad = |message: String| PipelineError::Target {
                path: self.path.clone(),
                message,
            };
            let view = self
                .views
                .iter()
                .find(|v| v.camera == name)
                .ok_or_else(|| bad(format!("the renderer produced no {name} view")))?;
            Image::png(view.marked.to_png()).map_err(|e| bad(format!("the {name} view: {e}")))
        };
        Ok(Views {
            top: find("top")?,
            front: find("front")?,
            back: find("back")?,
        })
    }
}

/// The demo's keyframes for the reasoner: marked views (raw where unlabelled) and the
/// recorded API calls, both decoded once.
#[derive(Debug, Clone, Default)]
pub struct DemoKeyframes {
    views: Vec<Option<Views>>,
    calls: Vec<Option<serde_json::Value>>,
}

impl DemoKeyframes {
    /// Decodes the demo's images; a keyframe whose images are not PNG is an error naming it.
    pub fn from_demo(input: &DemoInput) -> Result<DemoKeyframes, PipelineError> {
        let demo: &Demo = &input.demo;
        let mut views = Vec::with_capacity(demo.keyframes.len());
        for k in &demo.keyframes {
            let image = |camera: CameraName| -> Result<Image, PipelineError> {
                Image::png(k.views.get(camera).marked_or_raw().to_vec()).map_err(|e| PipelineError::Demo {
                    path: input.path.clone(),
                    message: format!("keyframe {}: {} view: {e}", k.index, camera.as_str()),
                })
            };
            views.push(Some(Views {
                top: image(CameraName::Top)?,
                front: image(CameraName::Front)?,
                back: image(CameraName::Back)?,
            }));
        }
        let calls = demo
            .keyframes
            .iter()
            .skip(1)
            .map(|k| k.action.as_ref().and_then(|a| serde_json::to_value(a).ok()))
            .collect();
        Ok(DemoKeyframes { views, calls })
    }

    /// The views of one keyframe.
    pub fn keyframe_views(&self, keyframe: usize) -> Option<&Views> {
        self.views.get(keyframe).and_then(Option::as_ref)
    }
}

impl KeyframeImages for DemoKeyframes {
    fn views(&self, keyframe: usize) -> Option<Views> {
        self.keyframe_views(keyframe).cloned()
    }

    fn demo_call(&self, step: usize) -> Option<serde_json::Value> {
        self.calls.get(step).cloned().flatten()
    }
}
