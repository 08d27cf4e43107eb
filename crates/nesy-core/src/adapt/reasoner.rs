//! The reasoner interface (the VLM Ψ's two jobs in the loop) and what it is asked.

use std::future::Future;

use serde::{Deserialize, Serialize};

use crate::atom::Atom;
use crate::exec::{UnmetPrecondition, format_unmet};
use crate::formula::GroundError;
use crate::operator::{Operator, format_procedure};
use crate::patch::PatchError;
use crate::predicates::{Tier, Vocabulary};
use crate::state::{State, StateDiff};
use crate::symbol::Symbol;
use crate::text::ParseError;

/// What every request carries about the task.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TaskContext {
    /// The natural-language instruction.
    pub instruction: String,
    /// The objects in the scene, in the order prompts list them.
    pub objects: Vec<Symbol>,
    /// Which predicates the prompt defines.
    pub tier: Tier,
    /// The predicate vocabulary (built-ins plus extras).
    pub vocabulary: Vocabulary,
}

impl TaskContext {
    /// The "predicate definitions" block for this task's tier.
    pub fn predicate_definitions(&self) -> String {
        self.vocabulary.render_definitions(self.tier)
    }

    /// The objects as a comma-separated list.
    pub fn object_list(&self) -> String {
        self.objects
            .iter()
            .map(|o| o.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Why an earlier reply for the same step or violation was rejected. Its `message` is what
/// a prompt shows the model; `problem` keeps the typed detail.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Feedback {
    /// 0-based attempt (induction) or loop iteration (patches) that produced the reply.
    pub attempt: usize,
    /// The rejected reply text.
    pub reply: String,
    /// What was wrong, typed.
    pub problem: Problem,
    /// The verifier's message, in prose.
    pub message: String,
}

/// What was wrong with a reply.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Problem {
    /// The reply could not be parsed.
    Unparsable {
        /// The parse error.
        error: ParseError,
    },
    /// The reply parsed but names predicates (or arities) or objects the task does not have.
    UnknownSymbols {
        /// Each unknown name once, in order, with the nearest known one.
        unknown: Vec<super::UnknownSymbol>,
    },
    /// The operator could not be grounded (e.g. a quantifier over an unknown type).
    Ungroundable {
        /// The grounding error.
        error: GroundError,
    },
    /// An induced operator's preconditions do not hold in s_t.
    PreconditionsUnmet {
        /// The unmet preconditions.
        unmet: Vec<UnmetPrecondition>,
    },
    /// Applying an induced operator to s_t does not give s_{t+1}.
    EffectMismatch {
        /// Atoms of s_{t+1} the operator does not produce.
        missing: Vec<Atom>,
        /// Atoms the operator produces that s_{t+1} does not hold.
        unexpected: Vec<Atom>,
    },
    /// The reply held more than one SEARCH/REPLACE block.
    MultiplePatches {
        /// How many.
        count: usize,
    },
    /// The SEARCH block did not match.
    PatchDidNotApply {
        /// The patch error.
        error: PatchError,
    },
    /// The patched procedure does not resolve the violation it was asked to fix.
    NotResolved {
        /// 0-based index of the first failing step after the patch, if any.
        failing_step: Option<usize>,
        /// Unmet preconditions (or goal literals) after the patch.
        unmet: Vec<UnmetPrecondition>,
    },
}

impl Problem {
    /// True when the reply could not be read (it did not parse, used unknown names, or held
    /// several patches): nothing about it was verified. The prompts word the two apart.
    pub fn is_unreadable(&self) -> bool {
        matches!(
            self,
            Problem::Unparsable { .. } | Problem::UnknownSymbols { .. } | Problem::MultiplePatches { .. }
        )
    }
}

/// A request to induce the operator of one demonstrated transition s_t → s_{t+1}.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InductionRequest {
    /// The transition index t (0-based: the transition from `states[t]` to `states[t + 1]`);
    /// implementations may key keyframe images by it.
    pub step: usize,
    /// 0-based attempt for this transition.
    pub attempt: usize,
    /// s_t.
    pub previous: State,
    /// s_{t+1}.
    pub next: State,
    /// s_{t+1} relative to s_t.
    pub diff: StateDiff,
    /// The task.
    pub task: TaskContext,
    /// Why earlier attempts for this transition were rejected, oldest first.
    pub feedback: Vec<Feedback>,
}

/// What the loop asks a patch for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ViolationKind {
    /// An action's preconditions fail.
    Precondition,
    /// Every action applies but the goal does not hold.
    Goal,
    /// Identification is ablated: the loop does not say what is wrong.
    Unidentified,
}

/// A request to propose a SEARCH/REPLACE patch.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PatchRequest {
    /// 0-based iteration of the exploration loop (counts against the budget).
    pub iteration: usize,
    /// The task (target scene).
    pub task: TaskContext,
    /// What kind of violation this is.
    pub kind: ViolationKind,
    /// The whole current procedure.
    pub procedure: Vec<Operator>,
    /// The actions executed before the failure (the whole procedure for a goal violation).
    pub executed: Vec<Operator>,
    /// The action whose preconditions failed.
    pub erroneous: Option<Operator>,
    /// The actions after the erroneous one.
    pub remaining: Vec<Operator>,
    /// 0-based index of the erroneous action.
    pub failing_step: Option<usize>,
    /// The counterfactual initial state ŝ_1.
    pub initial_state: State,
    /// The state in which the error occurred (ŝ_t), or the final state for a goal violation.
    pub error_state: State,
    /// The unmet preconditions (or unmet goal literals).
    pub unmet: Vec<UnmetPrecondition>,
    /// Why earlier proposals for this violation were rejected, oldest first.
    pub feedback: Vec<Feedback>,
}

impl PatchRequest {
    /// The "Unfulfilled Preconditions" list: `- (literal)` lines.
    pub fn unfulfilled_preconditions(&self) -> String {
        format_unmet(&self.unmet)
    }

    /// The executed actions as action blocks (`None` if empty).
    pub fn executed_text(&self) -> String {
        format_procedure(&self.executed)
    }

    /// The erroneous action as an action block (`None` if there is none).
    pub fn erroneous_text(&self) -> String {
        self.erroneous
            .as_ref()
            .map_or_else(|| "None".to_string(), |o| o.to_string())
    }

    /// The remaining actions as action blocks (`None` if empty).
    pub fn remaining_text(&self) -> String {
        format_procedure(&self.remaining)
    }
}

/// A reasoner failed to produce a reply at all: this ends the run, unlike a bad reply,
/// which becomes feedback. The [`ReasonerErrorKind`] tells a caller (the benchmark harness)
/// whether to retry the unit later or to score it as the method's failure.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
#[error("reasoner failed ({}): {message}", kind.as_str())]
pub struct ReasonerError {
    /// What kind of failure it was.
    pub kind: ReasonerErrorKind,
    /// What went wrong, with the call that failed.
    pub message: String,
}

/// The kinds of [`ReasonerError`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReasonerErrorKind {
    /// The call did not complete: the network, a timeout, a rate limit or a server error.
    /// Worth retrying later; says nothing about the method.
    Transport,
    /// The endpoint refused the request as built (too many images, too long, bad
    /// parameters): retrying the same request will not help.
    Refused,
    /// A reply arrived but cannot be used at all (not a chat response, cut off at the token
    /// cap, a model refusal).
    Reply,
    /// A recorded exchange is missing or unreadable (cassette replay).
    Replay,
    /// The request could not be built (a prompt template failed, bad settings).
    Request,
    /// A scripted or offline responder has no answer (a test double ran out, an offline
    /// responder gave up).
    Exhausted,
}

impl ReasonerErrorKind {
    /// `transport`, `refused`, `reply`, `replay`, `request` or `exhausted`.
    pub fn as_str(self) -> &'static str {
        match self {
            ReasonerErrorKind::Transport => "transport",
            ReasonerErrorKind::Refused => "refused",
            ReasonerErrorKind::Reply => "reply",
            ReasonerErrorKind::Replay => "replay",
            ReasonerErrorKind::Request => "request",
            ReasonerErrorKind::Exhausted => "exhausted",
        }
    }
}

impl ReasonerError {
    /// An error of `kind` with a message.
    pub fn new(kind: ReasonerErrorKind, message: impl Into<String>) -> Self {
        ReasonerError {
            kind,
            message: message.into(),
        }
    }

    /// A scripted or offline responder has no answer ([`ReasonerErrorKind::Exhausted`]).
    pub fn exhausted(message: impl Into<String>) -> Self {
        ReasonerError::new(ReasonerErrorKind::Exhausted, message)
    }
}

/// The neural half of the loop: returns the model's **reply text**; nesy-core parses it with
/// its own tolerant parsers and turns bad replies into feedback.
///
/// The futures must be `Send` so that a caller can run the loop on a multi-threaded
/// runtime; implementations write `async fn` as usual. nesy-core itself has no runtime.
pub trait Reasoner {
    /// Induces the operator of one demonstrated transition: a reply in the Action
    /// Prediction format (see [`crate::text::parse_induction_reply`]).
    fn induce_operator(
        &mut self,
        request: &InductionRequest,
    ) -> impl Future<Output = Result<String, ReasonerError>> + Send;

    /// Proposes a patch for a violation: a reply in the Refinement Proposal format (see
    /// [`crate::text::parse_refinement_reply`]).
    fn propose_patch(
        &mut self,
        request: &PatchRequest,
    ) -> impl Future<Output = Result<String, ReasonerError>> + Send;
}
