//! Few-shot examples, kept as data files under `prompts/examples/` and embedded at compile
//! time. Every example comes from nesy's own simulated scenes (`prompts/examples/scenes/`):
//! the induction and state-translation examples hold observer states that
//! `tests/integration/examples.rs` reproduces by replaying the recorded calls in nesy-sim,
//! and the code examples are programs that `tests/integration/examples.rs` runs against
//! those scenes.

use nesy_core::Operator;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::text::{parse_effects, parse_formula, parse_state_list};
use nesy_core::{Effect, Formula};
use nesy_core::{Tier, Vocabulary};
use serde::Deserialize;

use super::PromptError;
use crate::context::Embodiment;

/// An embedded data file: its path under `prompts/` and its text.
#[derive(Debug, Clone, Copy)]
pub struct EmbeddedFile {
    /// Path relative to `crates/nesy-reasoner/prompts/`.
    pub path: &'static str,
    /// The file's contents.
    pub text: &'static str,
}

macro_rules! embed {
    ($($path:literal),* $(,)?) => {
        &[$(EmbeddedFile { path: $path, text: include_str!(concat!("../../prompts/", $path)) }),*]
    };
}

/// The induction example files, in prompt order.
pub const INDUCTION_FILES: &[EmbeddedFile] = embed![
    "examples/induction/1_surround.toml",
    "examples/induction/2_grasp.toml",
    "examples/induction/3_carry.toml",
    "examples/induction/4_drop_into_hinge.toml",
    "examples/induction/5_sweep.toml",
    "examples/induction/6_vacuum_attach.toml",
];

/// The state-translation example files, in prompt order.
pub const STATE_FILES: &[EmbeddedFile] = embed!["examples/state/1_hinge.toml"];

/// The finger-gripper code example files, in prompt order.
pub const FINGER_CODE_FILES: &[EmbeddedFile] = embed![
    "examples/code/finger/1_pick.toml",
    "examples/code/finger/2_box_grid.toml",
    "examples/code/finger/3_hinge.toml",
    "examples/code/finger/4_drawer.toml",
    "examples/code/finger/5_sweep.toml",
];

/// The vacuum code example files, in prompt order.
pub const VACUUM_CODE_FILES: &[EmbeddedFile] = embed![
    "examples/code/vacuum/1_pick.toml",
    "examples/code/vacuum/2_box_grid.toml",
    "examples/code/vacuum/3_hinge.toml",
    "examples/code/vacuum/4_drawer.toml",
    "examples/code/vacuum/5_sweep.toml",
];

/// The scenes the examples come from (`prompts/examples/scenes/*.json`, nesy-sim's
/// `scene.json` format).
pub const SCENE_FILES: &[EmbeddedFile] = embed![
    "examples/scenes/pick.json",
    "examples/scenes/hinge.json",
    "examples/scenes/drawer.json",
    "examples/scenes/sweep.json",
];

/// How a scene was driven to the example's states: robot API calls in nesy-sim's `ApiCall`
/// JSON form (`{"call": "move_gripper_to", "obj_name": ..., ...}`).
pub type RecordedCall = serde_json::Value;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct InductionFile {
    title: String,
    scene: String,
    embodiment: Embodiment,
    #[serde(default)]
    extended_only: bool,
    instruction: String,
    objects: Vec<String>,
    #[serde(default)]
    setup: Vec<RecordedCall>,
    action: RecordedCall,
    previous: Vec<String>,
    current: Vec<String>,
    rationale: String,
    semantic: String,
    preconditions: Vec<String>,
    effects: Vec<String>,
}

/// One worked operator-induction example: a real transition of nesy-sim and the operator
/// that explains it.
#[derive(Debug, Clone)]
pub struct InductionExample {
    /// Where it was loaded from.
    pub file: &'static str,
    /// A short title shown in the prompt.
    pub title: String,
    /// The scene file (under `prompts/examples/scenes/`).
    pub scene: String,
    /// The robot in the scene.
    pub embodiment: Embodiment,
    /// Shown only when the prompt's tier is `extended` (vacuum examples).
    pub extended_only: bool,
    /// The instruction shown.
    pub instruction: String,
    /// The objects shown.
    pub objects: Vec<String>,
    /// Calls that bring the scene to the previous state.
    pub setup: Vec<RecordedCall>,
    /// The call of the transition.
    pub action: RecordedCall,
    /// The observed state before the action (with the embodiment atom).
    pub previous: State,
    /// The observed state after it.
    pub current: State,
    /// The example answer's rationale.
    pub rationale: String,
    /// The action semantic line.
    pub semantic: String,
    /// The operator (named by the semantic; the preconditions and effects as written).
    pub operator: Operator,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StateFile {
    title: String,
    scene: String,
    embodiment: Embodiment,
    instruction: String,
    objects: Vec<String>,
    #[serde(default)]
    setup: Vec<RecordedCall>,
    known: Vec<String>,
    answer: Vec<String>,
}

/// One state-translation example: what was known and the further atoms observed.
#[derive(Debug, Clone)]
pub struct StateExample {
    /// Where it was loaded from.
    pub file: &'static str,
    /// A short title shown in the prompt.
    pub title: String,
    /// The scene file.
    pub scene: String,
    /// The robot in the scene.
    pub embodiment: Embodiment,
    /// The instruction shown.
    pub instruction: String,
    /// The objects shown.
    pub objects: Vec<String>,
    /// Calls that bring the scene to the example's state.
    pub setup: Vec<RecordedCall>,
    /// The atoms given as known.
    pub known: State,
    /// The atoms the answer lists.
    pub answer: State,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CodeFile {
    title: String,
    scene: String,
    instruction: String,
    objects: Vec<String>,
    summary: Vec<String>,
    expect: Vec<String>,
    code: String,
}

/// One code-generation example: a specification and the program that carries it out in
/// nesy-sim.
#[derive(Debug, Clone)]
pub struct CodeExample {
    /// Where it was loaded from.
    pub file: &'static str,
    /// A short title shown in the prompt.
    pub title: String,
    /// The scene the program is validated on.
    pub scene: String,
    /// The robot it is written for.
    pub embodiment: Embodiment,
    /// The instruction shown.
    pub instruction: String,
    /// The objects shown.
    pub objects: Vec<String>,
    /// The demonstration summary's action names, in order.
    pub summary: Vec<String>,
    /// Atoms the observed state holds after the program ran (checked by the tests).
    pub expect: Vec<String>,
    /// The program.
    pub code: String,
}

fn invalid(file: &'static str, message: impl Into<String>) -> PromptError {
    PromptError::Example {
        file,
        message: message.into(),
    }
}

fn state_of(file: &'static str, field: &str, atoms: &[String]) -> Result<State, PromptError> {
    let text = if atoms.is_empty() {
        "None".to_string()
    } else {
        atoms
            .iter()
            .map(|a| format!("- {a}"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    parse_state_list(&text).map_err(|e| invalid(file, format!("{field}: {e}")))
}

fn load_toml<T: serde::de::DeserializeOwned>(file: &EmbeddedFile) -> Result<T, PromptError> {
    toml::from_str(file.text).map_err(|e| invalid(file.path, e.to_string()))
}

/// Loads the induction examples.
pub fn induction_examples() -> Result<Vec<InductionExample>, PromptError> {
    INDUCTION_FILES
        .iter()
        .map(|file| {
            let f: InductionFile = load_toml(file)?;
            let mut pre = Vec::with_capacity(f.preconditions.len());
            for (i, p) in f.preconditions.iter().enumerate() {
                pre.push(
                    parse_formula(p).map_err(|e| invalid(file.path, format!("preconditions[{i}]: {e}")))?,
                );
            }
            let mut eff = Vec::with_capacity(f.effects.len());
            for (i, e) in f.effects.iter().enumerate() {
                eff.extend(parse_effects(e).map_err(|e| invalid(file.path, format!("effects[{i}]: {e}")))?);
            }
            let name = nesy_core::text::normalize_action_name(&f.semantic)
                .ok_or_else(|| invalid(file.path, "semantic: not an action name"))?;
            Ok(InductionExample {
                file: file.path,
                previous: state_of(file.path, "previous", &f.previous)?,
                current: state_of(file.path, "current", &f.current)?,
                title: f.title,
                scene: f.scene,
                embodiment: f.embodiment,
                extended_only: f.extended_only,
                instruction: f.instruction,
                objects: f.objects,
                setup: f.setup,
                action: f.action,
                rationale: f.rationale.trim().to_string(),
                semantic: f.semantic,
                operator: Operator::new(name, pre, eff),
            })
        })
        .collect()
}

/// Loads the state-translation examples.
pub fn state_examples() -> Result<Vec<StateExample>, PromptError> {
    STATE_FILES
        .iter()
        .map(|file| {
            let f: StateFile = load_toml(file)?;
            Ok(StateExample {
                file: file.path,
                known: state_of(file.path, "known", &f.known)?,
                answer: state_of(file.path, "answer", &f.answer)?,
                title: f.title,
                scene: f.scene,
                embodiment: f.embodiment,
                instruction: f.instruction,
                objects: f.objects,
                setup: f.setup,
            })
        })
        .collect()
}

/// Loads the code examples of one end effector.
pub fn code_examples(embodiment: Embodiment) -> Result<Vec<CodeExample>, PromptError> {
    let files = match embodiment {
        Embodiment::Finger => FINGER_CODE_FILES,
        Embodiment::Vacuum => VACUUM_CODE_FILES,
    };
    files
        .iter()
        .map(|file| {
            let f: CodeFile = load_toml(file)?;
            if f.code.trim().is_empty() {
                return Err(invalid(file.path, "code: empty"));
            }
            Ok(CodeExample {
                file: file.path,
                title: f.title,
                scene: f.scene,
                embodiment,
                instruction: f.instruction,
                objects: f.objects,
                summary: f.summary,
                expect: f.expect,
                code: f.code.trim().to_string(),
            })
        })
        .collect()
}

/// Keeps only what a prompt tier can express: atoms of the tier's predicates.
pub fn project_state(state: &State, vocabulary: &Vocabulary, tier: Tier) -> State {
    let shown = tier_predicates(vocabulary, tier);
    State::from_atoms(state.iter().copied().filter(|a| shown.contains(&a.pred())))
}

/// Drops the precondition conjuncts and effects that are (negated) atoms of predicates the
/// tier does not define (the embodiment markers outside the extended tier).
pub fn project_operator(op: &Operator, vocabulary: &Vocabulary, tier: Tier) -> Operator {
    let shown = tier_predicates(vocabulary, tier);
    let literal_pred = |f: &Formula| match f {
        Formula::Atom(p) => Some(p.pred),
        Formula::Not(inner) => match inner.as_ref() {
            Formula::Atom(p) => Some(p.pred),
            _ => None,
        },
        _ => None,
    };
    let pre = op
        .pre
        .iter()
        .filter(|f| literal_pred(f).is_none_or(|p| shown.contains(&p)))
        .cloned()
        .collect();
    let eff = op
        .eff
        .iter()
        .filter(|e| match e {
            Effect::Add(p) | Effect::Del(p) => shown.contains(&p.pred),
            _ => true,
        })
        .cloned()
        .collect();
    Operator {
        pre,
        eff,
        ..op.clone()
    }
}

fn tier_predicates(vocabulary: &Vocabulary, tier: Tier) -> Vec<Symbol> {
    vocabulary.tier(tier).iter().map(|p| p.name).collect()
}
