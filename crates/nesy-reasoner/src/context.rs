//! The task context every prompt-building call attaches to its request: a typed,
//! serde-serialisable description of what is being asked, for transports that answer
//! offline (the reference responder answers from simulator ground truth).
//!
//! The context travels in [`nesy_vlm::ChatRequest::task`] as a [`nesy_vlm::TaskContext`] whose
//! `kind` is [`VlmTask::kind`] and whose `data` is the variant's JSON. It is never sent to a
//! server and never part of a cassette key. [`VlmTask::from_task_context`] reads it back.
//!
//! It holds what the prompt was built from and nothing of the simulator: an offline responder
//! that needs the demonstration's recorded robot calls is given them when it is built.
//! [`Embodiment`] is nesy-core's, shared with the simulator.

use nesy_core::Operator;
use nesy_core::State;
use nesy_core::Tier;
use nesy_core::adapt::{InductionRequest, PatchRequest};
use serde::{Deserialize, Serialize};

use nesy_vlm::TaskContext;

pub(crate) use nesy_core::Embodiment;

/// Operator induction for one demonstrated transition.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InductionContext {
    /// The loop's request: step, attempt, s_t, s_{t+1}, their diff, the task and the
    /// feedback on earlier attempts.
    pub request: InductionRequest,
    /// The demonstration's end effector.
    pub embodiment: Embodiment,
}

/// A refinement (patch) proposal.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PatchContext {
    /// The loop's request: procedure, executed/erroneous/remaining actions, states, unmet
    /// literals and feedback on earlier proposals.
    pub request: PatchRequest,
    /// The target scene's end effector.
    pub target_embodiment: Embodiment,
}

/// State translation of one set of views.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct StateTranslationContext {
    /// Which views these are, e.g. `demo/keyframe/3` or `target/initial`.
    pub view_set: String,
    /// The instruction shown.
    pub instruction: String,
    /// The objects shown, in order.
    pub objects: Vec<String>,
    /// The predicate tier the prompt defines.
    pub tier: Tier,
    /// Atoms given to the model as already known.
    pub known: State,
    /// The scene's true state, when the caller has it (never shown to the model).
    pub ground_truth: Option<State>,
}

/// Code generation for an adapted procedure.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CodeGenerationContext {
    /// The instruction shown.
    pub instruction: String,
    /// The objects shown, in order.
    pub objects: Vec<String>,
    /// The verified procedure the summary was made from.
    pub procedure: Vec<Operator>,
    /// The demonstration summary as shown: `1. Name`, one per action.
    pub action_names: Vec<String>,
    /// The target robot's end effector.
    pub embodiment: Embodiment,
    /// Whether the extended prompt (both end effectors' functions) was used.
    pub extended: bool,
    /// Whether the target robot's protective stop is on (what a template compilation of the
    /// procedure takes into account).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub protective_stop: bool,
}

/// The typed context of one VLM call, by task.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "task", rename_all = "snake_case")]
pub enum VlmTask {
    /// Operator induction (purpose `induce`).
    Induction(InductionContext),
    /// Patch proposal (purpose `patch`).
    Patch(PatchContext),
    /// State translation (purpose `translate`).
    StateTranslation(StateTranslationContext),
    /// Code generation (purpose `codegen`).
    CodeGeneration(CodeGenerationContext),
}

/// Why a [`TaskContext`] could not be read as a [`VlmTask`].
#[derive(Debug, thiserror::Error)]
pub enum ContextError {
    /// The kind is not one the reasoner produces.
    #[error(
        "unknown task context kind {kind:?}; expected induction, patch, state_translation or code_generation"
    )]
    UnknownKind {
        /// The kind found.
        kind: String,
    },
    /// The data does not match the kind's schema.
    #[error("task context of kind {kind:?} does not match its schema: {error}")]
    Schema {
        /// The kind.
        kind: String,
        /// The serde error (with the JSON path of the mismatch where serde gives one).
        error: serde_json::Error,
    },
}

impl VlmTask {
    /// Kind names, as in [`TaskContext::kind`].
    pub const KINDS: [&'static str; 4] = ["induction", "patch", "state_translation", "code_generation"];

    /// The kind name: `induction`, `patch`, `state_translation` or `code_generation`.
    pub fn kind(&self) -> &'static str {
        match self {
            VlmTask::Induction(_) => "induction",
            VlmTask::Patch(_) => "patch",
            VlmTask::StateTranslation(_) => "state_translation",
            VlmTask::CodeGeneration(_) => "code_generation",
        }
    }

    /// The accounting purpose of calls of this kind: `induce`, `patch`, `translate`,
    /// `codegen`.
    pub fn purpose(&self) -> &'static str {
        match self {
            VlmTask::Induction(_) => "induce",
            VlmTask::Patch(_) => "patch",
            VlmTask::StateTranslation(_) => "translate",
            VlmTask::CodeGeneration(_) => "codegen",
        }
    }

    /// The client-level context: `kind` plus the variant's fields as JSON (without the tag).
    pub fn to_task_context(&self) -> TaskContext {
        let data = match self {
            VlmTask::Induction(c) => serde_json::to_value(c),
            VlmTask::Patch(c) => serde_json::to_value(c),
            VlmTask::StateTranslation(c) => serde_json::to_value(c),
            VlmTask::CodeGeneration(c) => serde_json::to_value(c),
        };
        // Every field is plain data (strings, numbers, sequences, maps with string keys),
        // so serialisation cannot fail; keep the kind even if it somehow did.
        TaskContext::new(self.kind(), data.unwrap_or(serde_json::Value::Null))
    }

    /// Reads a client-level context back (what an offline transport does).
    pub fn from_task_context(context: &TaskContext) -> Result<VlmTask, ContextError> {
        let data = (*context.data).clone();
        let schema = |error| ContextError::Schema {
            kind: context.kind.clone(),
            error,
        };
        match context.kind.as_str() {
            "induction" => serde_json::from_value(data)
                .map(VlmTask::Induction)
                .map_err(schema),
            "patch" => serde_json::from_value(data).map(VlmTask::Patch).map_err(schema),
            "state_translation" => serde_json::from_value(data)
                .map(VlmTask::StateTranslation)
                .map_err(schema),
            "code_generation" => serde_json::from_value(data)
                .map(VlmTask::CodeGeneration)
                .map_err(schema),
            other => Err(ContextError::UnknownKind { kind: other.into() }),
        }
    }
}
