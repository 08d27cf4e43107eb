//! The benchmark's tasks (`docs/benchmark.md` §2–§3): the four subtasks with their
//! generation parameters (`variant`, `offset`, `multi_level`, `obst_level`) and composites of
//! two to four of them, each turned into a [`SceneSpec`] with its goals, instruction and goal
//! label; and everything built on them:
//!
//! - [`goal`]: the goal checks that score an episode;
//! - [`experts`]: the scripted experts that demonstrate each subtask;
//! - [`layout`]: where the experts (and the template compiler) put things;
//! - [`scenario`]: the 440-scenario suite of source/target pairs.
//!
//! Layouts follow the authors' rules and distributions but draw from nesy's own seeded
//! streams (`world::rng::Stream`, internal): a subtask's base layout depends only on its kind
//! and `variant` (and its offset), and the obstruction on a separate stream of the same
//! variant, so a source and a target that share a variant differ only by the obstruction.

mod drawers;
pub mod experts;
pub mod goal;
mod hinge;
pub mod layout;
mod pick_place;
mod prismatic;
pub mod scenario;
mod sweep;
mod tools;

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::api::Embodiment;
use crate::scene::{
    ObjectKind, ObjectSpec, PoseSpec, SCENE_SCHEMA_VERSION, SceneError, SceneSpec, SubtaskGoal, SubtaskKind,
};
use crate::world::rng::Stream;
/// Gap left between objects placed on each other, so they never start interpenetrating.
const REST_GAP: f64 = 0.0005;

/// One subtask's generation parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SubtaskConfig {
    /// Which subtask.
    pub kind: SubtaskKind,
    /// Seed of its layout (positions, colours, yaws, which objects are obstacles).
    pub variant: u64,
    /// Obstruction level 0–2 (`docs/benchmark.md` §2).
    pub obst_level: u8,
    /// Object-count level 0–2 (`docs/benchmark.md` §2).
    pub multi_level: u8,
}

/// A task: one subtask at the default offset, or a composite of two to four.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TaskConfig {
    /// The subtasks in instruction and label order (each kind at most once).
    pub subtasks: Vec<SubtaskConfig>,
    /// Seed of the composite offsets (the authors' episode id).
    pub episode: u64,
    /// The robot's end effector.
    pub embodiment: Embodiment,
    /// Emit `(FingerGripper)` / `(VacuumSuction)` in symbolic states.
    #[serde(default)]
    pub embodiment_in_state: bool,
}

/// A generated task.
#[derive(Clone, Debug, PartialEq)]
pub struct GeneratedTask {
    /// The scene, with goals and instruction.
    pub scene: SceneSpec,
    /// The goal label: the subtask labels concatenated in config order (`docs/benchmark.md` §3).
    pub goal_label: Vec<String>,
    /// The offset each subtask was laid out at, in config order.
    pub offsets: Vec<[f64; 2]>,
}

/// Why a task configuration cannot be generated.
#[derive(Debug, thiserror::Error)]
pub enum TaskError {
    /// No subtasks, or more than four.
    #[error("a task has 1 to 4 subtasks, got {0}")]
    SubtaskCount(usize),
    /// A subtask kind appears twice (their objects would share names).
    #[error("subtasks[{index}]: {kind} appears more than once; each subtask kind may appear once")]
    DuplicateSubtask {
        /// Position of the repeat.
        index: usize,
        /// The repeated kind.
        kind: SubtaskKind,
    },
    /// A level outside 0–2.
    #[error("subtasks[{index}].{field}: expected a level 0, 1 or 2, found {value}")]
    Level {
        /// Position of the subtask.
        index: usize,
        /// `obst_level` or `multi_level`.
        field: &'static str,
        /// The value.
        value: u8,
    },
    /// The generated scene did not validate (a generator bug).
    #[error("generated scene is invalid: {0}")]
    Scene(#[from] SceneError),
}

/// One subtask's contribution to a scene.
pub(crate) struct SubtaskLayout {
    pub objects: Vec<ObjectSpec>,
    pub articulations: Vec<(String, f64)>,
    /// One goal, or one per container a subtask fills (a drawer in each of two cabinets).
    pub goals: Vec<SubtaskGoal>,
}

/// An object resting at `(x, y)` with its lowest point at `z`.
pub(crate) fn object(name: &str, kind: ObjectKind, x: f64, y: f64, z: f64, yaw: f64) -> ObjectSpec {
    ObjectSpec {
        name: name.to_owned(),
        kind,
        pose: PoseSpec {
            position: [round(x), round(y), round(z)],
            yaw: round(yaw),
        },
        colour: None,
        size: None,
        pieces: None,
    }
}

/// Rounds to 0.1 mm / 0.1 mrad so scene files stay short and identical across platforms.
fn round(v: f64) -> f64 {
    let r = (v * 10_000.0).round() / 10_000.0;
    if r == 0.0 { 0.0 } else { r }
}

/// The layout stream of a subtask.
pub(crate) fn layout_stream(kind: SubtaskKind, variant: u64) -> Stream {
    Stream::new(&format!("{}/layout", kind.as_str()), variant)
}

/// The obstruction stream of a subtask (separate, so obstruction never shifts the layout).
pub(crate) fn obstruction_stream(kind: SubtaskKind, variant: u64) -> Stream {
    Stream::new(&format!("{}/obstruction", kind.as_str()), variant)
}

/// Lays out one subtask at `offset`.
pub(crate) fn layout(config: &SubtaskConfig, offset: [f64; 2]) -> SubtaskLayout {
    match config.kind {
        SubtaskKind::PickPlace => pick_place::layout(config, offset),
        SubtaskKind::Sweep => sweep::layout(config, offset),
        SubtaskKind::PutInHinge => hinge::layout(config, offset),
        SubtaskKind::PutInPrismatic => prismatic::layout(config, offset),
        SubtaskKind::SortIntoDrawers => drawers::layout(config, offset),
        SubtaskKind::StowTools => tools::layout(config, offset),
    }
}

/// Offset of a lone subtask (`docs/benchmark.md` §2 default).
pub const DEFAULT_OFFSET: [f64; 2] = [0.5, 0.0];

/// Composite offsets (`docs/benchmark.md` §3): the two near slots shuffled, the two far slots shuffled;
/// articulated subtasks take far slots, the others near slots (far ones once the near ones
/// are used up), in config order.
pub fn composite_offsets(kinds: &[SubtaskKind], episode: u64) -> Vec<[f64; 2]> {
    if kinds.len() == 1 {
        return vec![DEFAULT_OFFSET];
    }
    let mut rng = Stream::new("composite/offsets", episode);
    let mut near = vec![[0.35, 0.2], [0.35, -0.2]];
    let mut far = vec![[0.65, 0.2], [0.65, -0.2]];
    rng.shuffle(&mut near);
    rng.shuffle(&mut far);
    kinds
        .iter()
        .map(|k| {
            if k.is_articulated() || near.is_empty() {
                far.remove(0)
            } else {
                near.remove(0)
            }
        })
        .collect()
}

impl TaskConfig {
    /// One subtask alone, at the default offset, with the episode numbered by the variant
    /// (as the experts' tests, sweeps and fixtures lay it out) and no embodiment atoms in the
    /// states.
    pub fn single(
        kind: SubtaskKind,
        variant: u64,
        obst_level: u8,
        multi_level: u8,
        embodiment: Embodiment,
    ) -> TaskConfig {
        TaskConfig {
            subtasks: vec![SubtaskConfig {
                kind,
                variant,
                obst_level,
                multi_level,
            }],
            episode: variant,
            embodiment,
            embodiment_in_state: false,
        }
    }

    /// Checks counts, levels and duplicates.
    pub fn validate(&self) -> Result<(), TaskError> {
        if self.subtasks.is_empty() || self.subtasks.len() > 4 {
            return Err(TaskError::SubtaskCount(self.subtasks.len()));
        }
        for (index, s) in self.subtasks.iter().enumerate() {
            if self.subtasks[..index].iter().any(|o| o.kind == s.kind) {
                return Err(TaskError::DuplicateSubtask { index, kind: s.kind });
            }
            for (field, value) in [("obst_level", s.obst_level), ("multi_level", s.multi_level)] {
                if value > 2 {
                    return Err(TaskError::Level { index, field, value });
                }
            }
        }
        Ok(())
    }

    /// The instruction: the subtask instructions in config order, separated by spaces.
    pub fn instruction(&self) -> String {
        self.subtasks
            .iter()
            .map(|s| s.kind.instruction())
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// Generates the scene.
    pub fn generate(&self) -> Result<GeneratedTask, TaskError> {
        self.validate()?;
        let kinds: Vec<SubtaskKind> = self.subtasks.iter().map(|s| s.kind).collect();
        let offsets = composite_offsets(&kinds, self.episode);
        let mut objects = Vec::new();
        let mut articulations = BTreeMap::new();
        let mut goals = Vec::new();
        for (config, offset) in self.subtasks.iter().zip(&offsets) {
            let part = layout(config, *offset);
            objects.extend(part.objects);
            articulations.extend(part.articulations);
            goals.extend(part.goals);
        }
        let goal_label = goals.iter().flat_map(SubtaskGoal::label).collect();
        let scene = SceneSpec {
            schema_version: SCENE_SCHEMA_VERSION,
            embodiment: self.embodiment,
            embodiment_in_state: self.embodiment_in_state,
            instruction: self.instruction(),
            seed: self.episode,
            objects,
            articulations,
            goals,
            protective_stop: false,
        };
        scene.validate()?;
        Ok(GeneratedTask {
            scene,
            goal_label,
            offsets,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(kinds: &[SubtaskKind], obst: u8, multi: u8) -> TaskConfig {
        TaskConfig {
            subtasks: kinds
                .iter()
                .enumerate()
                .map(|(i, &kind)| SubtaskConfig {
                    kind,
                    variant: 10 + i as u64,
                    obst_level: obst,
                    multi_level: multi,
                })
                .collect(),
            episode: 5,
            embodiment: Embodiment::Finger,
            embodiment_in_state: false,
        }
    }

    #[test]
    fn offsets_follow_the_assignment_rules() {
        for episode in 0..20 {
            let all = composite_offsets(&SubtaskKind::ALL, episode);
            for (kind, offset) in SubtaskKind::ALL.iter().zip(&all) {
                let far = (offset[0] - 0.65).abs() < 1e-9;
                assert_eq!(far, kind.is_articulated(), "{kind} at {offset:?}");
            }
            let mut sorted = all.clone();
            sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
            sorted.dedup();
            assert_eq!(sorted.len(), 4, "four distinct slots");
        }
        assert_eq!(composite_offsets(&[SubtaskKind::Sweep], 3), vec![DEFAULT_OFFSET]);
        // Two articulated subtasks take both far slots.
        let two = composite_offsets(&[SubtaskKind::PutInHinge, SubtaskKind::PutInPrismatic], 1);
        assert!(two.iter().all(|o| o[0] == 0.65) && two[0] != two[1]);
    }

    #[test]
    fn every_level_generates_a_valid_scene() {
        for obst in 0..3 {
            for multi in 0..3 {
                for kind in SubtaskKind::ALL {
                    let task = config(&[kind], obst, multi).generate().unwrap();
                    assert_eq!(task.scene.goals.len(), 1);
                    let n = kind.object_count(multi);
                    let extra = usize::from(kind.is_articulated());
                    assert_eq!(task.goal_label.len(), n + extra, "{kind} multi {multi}");
                }
                let all = config(&SubtaskKind::ALL, obst, multi).generate().unwrap();
                assert_eq!(all.scene.goals.len(), 4);
                all.scene.validate().unwrap();
            }
        }
    }

    #[test]
    fn instruction_is_concatenated_once() {
        let task = config(&[SubtaskKind::Sweep, SubtaskKind::PickPlace], 0, 0);
        let text = task.generate().unwrap().scene.instruction;
        assert_eq!(
            text,
            "Sweep the chess pieces into their corresponding boxes. Place the cube blocks in to the box."
        );
        // Generating again (the authors' reset) does not duplicate it.
        assert_eq!(task.generate().unwrap().scene.instruction, text);
    }

    #[test]
    fn bad_configs_are_refused() {
        assert!(matches!(
            config(&[], 0, 0).generate(),
            Err(TaskError::SubtaskCount(0))
        ));
        let dup = config(&[SubtaskKind::Sweep, SubtaskKind::Sweep], 0, 0);
        assert!(matches!(
            dup.generate(),
            Err(TaskError::DuplicateSubtask { index: 1, .. })
        ));
        let mut high = config(&[SubtaskKind::Sweep], 0, 0);
        high.subtasks[0].obst_level = 3;
        let err = high.generate().unwrap_err().to_string();
        assert!(
            err.contains("subtasks[0].obst_level") && err.contains('3'),
            "{err}"
        );
    }

    #[test]
    fn obstruction_only_moves_what_it_obstructs() {
        for kind in SubtaskKind::ALL {
            let clear = config(&[kind], 0, 2).generate().unwrap().scene;
            let blocked = config(&[kind], 2, 2).generate().unwrap().scene;
            let names = |s: &SceneSpec| s.objects.iter().map(|o| o.name.clone()).collect::<Vec<_>>();
            assert_eq!(names(&clear), names(&blocked), "{kind}: same objects");
            let moved = clear
                .objects
                .iter()
                .zip(&blocked.objects)
                .filter(|(a, b)| a.pose != b.pose)
                .count();
            match kind {
                SubtaskKind::PutInPrismatic => assert_eq!(moved, 0),
                SubtaskKind::PutInHinge => assert_eq!(moved, 1),
                _ => assert!(moved >= 1, "{kind}"),
            }
            if kind.is_articulated() {
                assert_ne!(clear.articulations, blocked.articulations, "{kind}");
            } else {
                assert!(clear.articulations.is_empty() && blocked.articulations.is_empty());
            }
        }
    }
}
