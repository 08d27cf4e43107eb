//! Step 1: the demo and the target scene.
//!
//! The demo is read with `nesy_sim::demo::read` (`demo.mcap`, a folder holding it, or a
//! folder with `manifest.json`). A target scene is built in nesy-sim, which observes its
//! ground-truth initial state and renders the three views (plain and marked); a camera target
//! is a folder in the demo layout with one keyframe, whose state comes from the model.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use nesy_core::Embodiment;
use nesy_core::State;
use nesy_core::Vocabulary;
use nesy_reasoner::{KeyframeImages, Views};
use nesy_sim::api::ApiCall;
use nesy_sim::demo::{CameraImages, Demo, Demonstrator, NamedView};
use nesy_sim::perception::observer::observe;
use nesy_sim::perception::render;
use nesy_sim::scene::{SceneSpec, parts};
use nesy_sim::world::Sim;
use nesy_vlm::Image;

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
    /// Reads a demo; errors name the file and what was wrong with it. Its ground-truth states
    /// must use `vocabulary`'s predicates (the built-ins unless a vocabulary file was given).
    pub fn load(path: &Path, vocabulary: &Vocabulary) -> Result<DemoInput, PipelineError> {
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
        check_demo(&demo, vocabulary).map_err(|message| PipelineError::Demo {
            path: path.to_owned(),
            message,
        })?;
        Ok(DemoInput {
            path: path.to_owned(),
            demo,
            load_time: started.elapsed(),
        })
    }

    /// The robot call recorded for each transition (keyframe `t` to `t + 1`), `None` where
    /// the demonstration did not record one (real-world demos record none).
    pub fn recorded_calls(&self) -> Vec<Option<ApiCall>> {
        self.demo
            .keyframes
            .iter()
            .skip(1)
            .map(|k| k.action.as_ref().map(|entry| entry.call.clone()))
            .collect()
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

/// Latest keyframe time (s) a demo may give: a day, far beyond any demonstration.
pub(crate) const MAX_KEYFRAME_TIME_S: f64 = 86_400.0;

/// What the pipeline needs of a demo's contents beyond its format: keyframe times that are
/// finite, non-negative and in order, and ground-truth states whose atoms use the
/// vocabulary's predicates at their arity (and declared kinds) over the demo's objects (the
/// scene's, the floor and the robot's own parts). Such an atom would otherwise enter the
/// world model as a fact.
pub(crate) fn check_demo(demo: &Demo, vocabulary: &Vocabulary) -> Result<(), String> {
    let known: std::collections::HashSet<&str> = demo
        .metadata
        .objects
        .iter()
        .map(String::as_str)
        .chain([parts::FLOOR, parts::GRIPPER, parts::VACUUM_GRIPPER])
        .collect();
    let mut previous_time = 0.0;
    for (i, keyframe) in demo.keyframes.iter().enumerate() {
        let time = keyframe.time;
        if !(time.is_finite() && (previous_time..=MAX_KEYFRAME_TIME_S).contains(&time)) {
            return Err(format!(
                "keyframes[{i}].time: expected seconds from {previous_time} (the keyframe before) to {MAX_KEYFRAME_TIME_S}, got {time}"
            ));
        }
        previous_time = time;
        let Some(state) = &keyframe.state else { continue };
        for atom in state.iter() {
            let at = format!("keyframes[{i}].state: {atom}");
            match vocabulary.get(atom.pred()) {
                None => {
                    let names: Vec<String> = vocabulary
                        .predicates()
                        .iter()
                        .map(|p| p.name.to_string())
                        .collect();
                    return Err(format!(
                        "{at}: `{}` is not one of the task's predicates ({}; a vocabulary file, --vocabulary, declares more)",
                        atom.pred(),
                        names.join(", ")
                    ));
                }
                Some(info) if info.arity != atom.args().len() => {
                    return Err(format!(
                        "{at}: `{}` takes {} argument(s), not {}",
                        atom.pred(),
                        info.arity,
                        atom.args().len()
                    ));
                }
                Some(_) => {}
            }
            if let Err(wrong_kind) = vocabulary.check_atom(atom) {
                return Err(format!("{at}: {wrong_kind}"));
            }
            if let Some(unknown) = atom.args().iter().find(|a| !known.contains(a.as_str())) {
                return Err(format!(
                    "{at}: `{unknown}` is not among the demo's objects (metadata.objects)"
                ));
            }
        }
    }
    Ok(())
}

/// Reads a vocabulary file (`nesy_core::parse_vocabulary_file` documents the format); the
/// error names the file, the line and the field.
pub fn load_vocabulary(path: &Path) -> Result<Vocabulary, PipelineError> {
    let text =
        nesy_input::read_text(path, nesy_input::MAX_JSON_BYTES).map_err(|e| PipelineError::TaskFile {
            path: path.to_owned(),
            message: format!("reading the vocabulary file: {e}"),
        })?;
    nesy_core::parse_vocabulary_file(&text).map_err(|e| PipelineError::TaskFile {
        path: path.to_owned(),
        message: format!("vocabulary file: {e}"),
    })
}

/// Checks that a simulated target's observed state is in the vocabulary: the simulator
/// observes the built-in predicates, so a vocabulary without them cannot describe its scene.
pub(crate) fn check_target_state(target: &TargetInput, vocabulary: &Vocabulary) -> Result<(), PipelineError> {
    for atom in target.observed.iter().flat_map(|s| s.iter()) {
        if let Err(e) = vocabulary.check_use(atom.pred(), atom.args().len()) {
            return Err(PipelineError::Target {
                path: target.path.clone(),
                message: format!(
                    "the simulated scene's state holds {atom}, but {e} in the task's vocabulary; a vocabulary for a simulated target keeps the built-in predicates (builtin = true)"
                ),
            });
        }
    }
    Ok(())
}

/// Object names without the robot's own.
pub(crate) fn scene_objects(names: &[String]) -> Vec<String> {
    names
        .iter()
        .filter(|n| ![parts::GRIPPER, parts::VACUUM_GRIPPER].contains(&n.as_str()))
        .cloned()
        .collect()
}

/// The file beside a camera target's `manifest.json` that gives its simulated scene.
pub const TARGET_SCENE_BESIDE: &str = "scene.json";

/// The target: a simulated scene (built, observed and rendered), or what a camera sees at
/// deployment (a folder in the demo layout with one keyframe: its frames, object list,
/// instruction and robot), optionally with a simulated `scene.json` beside it to execute on.
#[derive(Debug, Clone)]
pub struct TargetInput {
    /// Where the target came from (`<demo>#target_scene` when the demo carried it).
    pub path: PathBuf,
    /// The simulated scene to execute on (with `embodiment_in_state` set when the embodiment
    /// changed); `None` for a camera target without one.
    pub scene: Option<SceneSpec>,
    /// The simulator's ground-truth initial state, when there is a scene.
    pub observed: Option<State>,
    /// Object names, without the robot's own, in scene order.
    pub objects: Vec<String>,
    /// Names the target's states may use besides the objects: the floor and the parts of
    /// articulated objects.
    pub scene_names: Vec<String>,
    /// The robot that is to do the task.
    pub embodiment: Embodiment,
    /// The target's own instruction (empty: the demo's is used).
    pub own_instruction: String,
    /// Subtasks the target is to complete, when its scene says.
    pub subtasks: Option<usize>,
    /// The views, in prompt order: rendered (top, front, back) for a scene, the camera's
    /// frames for a camera target; PNG or JPEG, plain and (when present) labelled.
    pub views: Vec<NamedView>,
    /// Time spent building, observing and rendering.
    pub sim_time: Duration,
}

impl TargetInput {
    /// True when the target scene holds a tool, so that code generation offers the
    /// tool-use calls; a camera target without a scene offers none.
    pub fn holds_tool(&self) -> bool {
        self.scene.as_ref().is_some_and(SceneSpec::holds_tool)
    }

    /// True when the target scene turns the robot's protective stop on; a camera target
    /// without a scene says nothing, so off.
    pub fn protective_stop(&self) -> bool {
        self.scene.as_ref().is_some_and(|scene| scene.protective_stop)
    }

    /// Reads `path`: a scene file, or a camera target folder (`manifest.json` with one
    /// keyframe, optionally `scene.json`); without a path, the target scene recorded in the
    /// demo. A scene is built, observed and rendered. Embodiment atoms go into the state
    /// when the target's end effector differs from the demo's (the authors' `ee_set`).
    pub fn load(path: Option<&Path>, demo: &DemoInput) -> Result<TargetInput, PipelineError> {
        let (path, scene) = match path {
            Some(path) if path.is_dir() => return Self::from_camera(path, demo),
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
        scene: SceneSpec,
        source: Embodiment,
    ) -> Result<TargetInput, PipelineError> {
        let started = Instant::now();
        let built = BuiltScene::new(&path, scene, source)?;
        let views = render::render_views(&built.sim, render::VIEW_SIZE, render::default_threads())
            .into_iter()
            .map(|v| NamedView {
                name: v.camera.to_owned(),
                images: CameraImages {
                    raw: v.image.to_png(),
                    marked: Some(v.marked.to_png()),
                },
            })
            .collect();
        Ok(TargetInput {
            path,
            objects: scene_objects(&built.sim.names()),
            scene_names: built.scene_names(),
            embodiment: built.scene.embodiment,
            own_instruction: built.scene.instruction.clone(),
            subtasks: Some(built.scene.goals.len()),
            observed: Some(observe(&built.sim)),
            scene: Some(built.scene),
            views,
            sim_time: started.elapsed(),
        })
    }

    /// Reads a camera target folder: the demo layout with exactly one keyframe, a robot as
    /// its embodiment, and optionally `scene.json` (whose objects must include the listed
    /// ones) to execute on.
    pub fn from_camera(dir: &Path, demo: &DemoInput) -> Result<TargetInput, PipelineError> {
        let started = Instant::now();
        let bad = |message: String| PipelineError::Target {
            path: dir.to_owned(),
            message,
        };
        let frames =
            nesy_sim::demo::read_folder(dir).map_err(|e| bad(format!("reading the camera target: {e}")))?;
        let [keyframe] = <[_; 1]>::try_from(frames.keyframes).map_err(|found: Vec<_>| {
            bad(format!(
                "a camera target holds one keyframe (what the camera sees before the robot starts), found {}",
                found.len()
            ))
        })?;
        if frames.metadata.demonstrator == Demonstrator::Human {
            return Err(bad(
                "at embodiment: a target names the robot that is to do the task (`finger` or `vacuum`), not `human`"
                    .into(),
            ));
        }
        let embodiment = frames.metadata.embodiment;
        let objects = frames.metadata.objects;
        let beside = dir.join(TARGET_SCENE_BESIDE);
        let (scene, observed, scene_names, subtasks) = if beside.is_file() {
            let scene = SceneSpec::from_file(&beside).map_err(|e| PipelineError::Target {
                path: beside.clone(),
                message: format!("reading the target scene: {e}"),
            })?;
            let built = BuiltScene::new(&beside, scene, demo.demo.metadata.embodiment)?;
            let names = built.scene_names();
            if let Some(missing) = objects.iter().find(|o| !names.contains(o)) {
                return Err(PipelineError::Target {
                    path: beside,
                    message: format!(
                        "the camera target lists `{missing}`, which this scene does not have (its objects: {})",
                        scene_objects(&built.sim.names()).join(", ")
                    ),
                });
            }
            if built.scene.embodiment != embodiment {
                return Err(PipelineError::Target {
                    path: beside,
                    message: format!(
                        "at embodiment: the scene's robot is `{}`, the camera target's `{}`",
                        built.scene.embodiment.as_str(),
                        embodiment.as_str()
                    ),
                });
            }
            let observed = observe(&built.sim);
            let subtasks = built.scene.goals.len();
            (Some(built.scene), Some(observed), names, Some(subtasks))
        } else {
            let names = std::iter::once(parts::FLOOR.to_owned())
                .chain(objects.iter().cloned())
                .collect();
            (None, None, names, None)
        };
        Ok(TargetInput {
            path: dir.to_owned(),
            scene,
            observed,
            objects,
            scene_names,
            embodiment,
            own_instruction: frames.metadata.instruction,
            subtasks,
            views: keyframe.views.iter().cloned().collect(),
            sim_time: started.elapsed(),
        })
    }

    /// The target's instruction, falling back to the demo's when it has none.
    pub fn instruction(&self, demo: &DemoInput) -> String {
        if self.own_instruction.trim().is_empty() {
            demo.demo.metadata.instruction.clone()
        } else {
            self.own_instruction.clone()
        }
    }

    /// The marked views as the VLM sees them (plain where a view has no labelled version).
    pub fn marked_views(&self) -> Result<Views, PipelineError> {
        self.views_of(true)
    }

    /// The views without labels (the baselines show both).
    pub fn raw_views(&self) -> Result<Views, PipelineError> {
        self.views_of(false)
    }

    fn views_of(&self, marked: bool) -> Result<Views, PipelineError> {
        let mut views = Vec::with_capacity(self.views.len());
        for view in &self.views {
            let bytes = if marked {
                view.images.marked_or_raw()
            } else {
                &view.images.raw
            };
            let image = Image::from_encoded(bytes.to_vec()).map_err(|e| PipelineError::Target {
                path: self.path.clone(),
                message: format!("the {} view: {e}", view.name),
            })?;
            views.push((view.name.clone(), image));
        }
        Ok(Views::new(views))
    }

    /// The simulator's ground-truth initial state, or an error saying there is none (a
    /// camera target without `scene.json`).
    pub fn observed_state(&self) -> Result<&State, PipelineError> {
        self.observed.as_ref().ok_or_else(|| PipelineError::Target {
            path: self.path.clone(),
            message: "a camera target without a simulated scene has no ground-truth state".into(),
        })
    }

    /// The simulated scene, or an error saying there is none (a camera target without
    /// `scene.json`).
    pub fn sim_scene(&self) -> Result<&SceneSpec, PipelineError> {
        self.scene.as_ref().ok_or_else(|| PipelineError::Target {
            path: self.path.clone(),
            message: format!(
                "a camera target without a simulated scene: there is nothing to run the policy on (put a `{TARGET_SCENE_BESIDE}` beside its manifest to execute in simulation)"
            ),
        })
    }
}

/// A target scene built in the simulator.
struct BuiltScene {
    scene: SceneSpec,
    sim: Sim,
}

impl BuiltScene {
    /// Builds `scene` (marking embodiment atoms when its robot differs from `source`), which
    /// must have a goal.
    fn new(path: &Path, mut scene: SceneSpec, source: Embodiment) -> Result<BuiltScene, PipelineError> {
        if scene.embodiment != source {
            scene.embodiment_in_state = true;
        }
        if scene.goals.is_empty() {
            return Err(PipelineError::Target {
                path: path.to_owned(),
                message: "at goals: expected at least one subtask goal (the target must say what success is), found none".into(),
            });
        }
        let sim = Sim::new(&scene).map_err(|e| PipelineError::Target {
            path: path.to_owned(),
            message: format!("building the target scene: {e}"),
        })?;
        Ok(BuiltScene { scene, sim })
    }

    /// The floor, the parts of the scene's objects, and the object names.
    fn scene_names(&self) -> Vec<String> {
        std::iter::once(parts::FLOOR.to_owned())
            .chain(self.scene.part_names())
            .chain(scene_objects(&self.sim.names()))
            .collect()
    }
}

/// The demo's keyframes for the reasoner: marked views (raw where unlabelled), decoded once.
#[derive(Debug, Clone, Default)]
pub struct DemoKeyframes {
    views: Vec<Option<Views>>,
}

impl DemoKeyframes {
    /// Reads the demo's images, every view in the demo's order; a keyframe whose images
    /// are neither PNG nor JPEG is an error naming it and the view.
    pub fn from_demo(input: &DemoInput) -> Result<DemoKeyframes, PipelineError> {
        let demo: &Demo = &input.demo;
        let mut views = Vec::with_capacity(demo.keyframes.len());
        for k in &demo.keyframes {
            let mut named = Vec::with_capacity(k.views.len());
            for view in k.views.iter() {
                let image = Image::from_encoded(view.images.marked_or_raw().to_vec()).map_err(|e| {
                    PipelineError::Demo {
                        path: input.path.clone(),
                        message: format!("keyframe {}: {} view: {e}", k.index, view.name),
                    }
                })?;
                named.push((view.name.clone(), image));
            }
            views.push(Some(Views::new(named)));
        }
        Ok(DemoKeyframes { views })
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use nesy_core::Atom;

    fn fixture() -> Demo {
        let dir = nesy_testkit::workspace_root().join("fixtures/demos/adapt-realstyle");
        DemoInput::load(&dir, &Vocabulary::new())
            .expect("the fixture is a valid demo")
            .demo
    }

    fn demo_with_atom(atom: &str) -> Demo {
        let mut demo = fixture();
        let state = demo.keyframes[1].state.as_mut().unwrap();
        let mut atoms: Vec<Atom> = state.iter().copied().collect();
        atoms.push(atom.parse().unwrap());
        *state = State::from_atoms(atoms);
        demo
    }

    fn with_atom(atom: &str) -> String {
        check_demo(&demo_with_atom(atom), &Vocabulary::new()).unwrap_err()
    }

    #[test]
    fn a_vocabulary_file_admits_its_predicates_and_checks_their_kinds() {
        let demo = demo_with_atom("(Finegrained red_cylinder)");
        let err = check_demo(&demo, &Vocabulary::new()).unwrap_err();
        assert!(
            err.contains("`Finegrained` is not one of the task's predicates"),
            "{err}"
        );
        let file = "format_version = 1\n[[kinds]]\nname = \"parts\"\n[[predicates]]\nname = \"Finegrained\"\nparams = [\"x - parts\"]\nmeaning = \"?x consists of many small loose parts.\"\n[[predicates]]\nname = \"Gathered\"\nparams = [\"x\"]\nmeaning = \"the parts of ?x lie in one pile.\"\n";
        let vocabulary = nesy_core::parse_vocabulary_file(file).unwrap();
        check_demo(&demo, &vocabulary).unwrap();
        let typed = nesy_core::parse_vocabulary_file(&format!("{file}[objects]\nred_cylinder = \"thing\"\n"))
            .unwrap();
        let err = check_demo(&demo, &typed).unwrap_err();
        assert!(
            err.contains("argument 1 of `Finegrained` must be a `parts`"),
            "{err}"
        );
    }

    #[test]
    fn states_with_unknown_predicates_or_objects_are_refused_by_keyframe() {
        let err = with_atom("(Flying red_cylinder)");
        assert!(
            err.starts_with(
                "keyframes[1].state: (Flying red_cylinder): `Flying` is not one of the task's predicates"
            ),
            "{err}"
        );
        let err = with_atom("(OnTopOf unicorn floor)");
        assert!(err.contains("`unicorn` is not among the demo's objects"), "{err}");
        let err = with_atom("(GripperOpen red_cylinder)");
        assert!(err.contains("takes 0 argument(s), not 1"), "{err}");
    }

    #[test]
    fn keyframe_times_must_be_finite_and_in_order() {
        for (k, time) in [(1, -5.0), (1, 1e308), (2, 0.0)] {
            let mut demo = fixture();
            demo.keyframes[1].time = demo.keyframes[1].time.max(0.5);
            demo.keyframes[k].time = time;
            let err = check_demo(&demo, &Vocabulary::new()).unwrap_err();
            assert!(err.starts_with(&format!("keyframes[{k}].time")), "{err}");
        }
    }
}
