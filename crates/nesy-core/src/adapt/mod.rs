//! The adaptation loop: the paper's Algorithm 1, generic over a [`Reasoner`].
//!
//! 1. **World-model construction** ([`construct_world_model`], Eq. 3). For every
//!    demonstrated transition s_t → s_{t+1} the reasoner induces an operator; the executor
//!    checks that its preconditions hold in s_t and that applying it to s_t yields s_{t+1}
//!    ([`TransitionCheck`]); otherwise the verifier's message goes back as feedback, up to
//!    [`AdaptConfig::induction_tries`] attempts. Operators without preconditions are kept
//!    (the authors' code drops them; a transition that needs nothing still happened, and
//!    dropping it would silently shorten the procedure).
//! 2. **Goal** ([`derive_goal`]): the physics-related atoms true in s_N that the
//!    demonstration made true at some transition.
//! 3. **Counterfactual identification** (Eq. 6, [`identify`]): the procedure is replayed
//!    from the target's initial state ŝ_1; the first action whose preconditions fail is
//!    inconsistent. (Eq. 6's second clause, eff(a_t) ⊄ s_{t+1}, can never fire for a verified
//!    world model, whose effects reproduce s_{t+1} by construction, so only preconditions
//!    are checked.) If every action applies but the goal fails, the unmet goal literals are
//!    the violation.
//! 4. **Exploration** (Eq. 7–8, [`explore`]): the reasoner proposes a SEARCH/REPLACE patch;
//!    replies that do not parse, hold several patches, do not match, or do not resolve the
//!    violation are rejected with typed feedback; each reply counts against the budget.
//!    Accepted patches are re-verified from ŝ_1, until the procedure is consistent and the
//!    goal holds ([`Outcome::Adapted`]) or the budget runs out ([`Outcome::Unresolved`]).
//!
//! Everything the loop sees and decides is recorded in a serialisable [`Trace`].

mod explore;
mod reasoner;
mod symbols;
mod world_model;

pub use explore::{ExplorationResult, explore, identify, resolves};
pub use reasoner::{
    Feedback, InductionRequest, PatchRequest, Problem, Reasoner, ReasonerError, ReasonerErrorKind,
    TaskContext, ViolationKind,
};
pub use symbols::{SymbolProblem, UnknownSymbol, known_objects, unknown_atom_symbols, unknown_symbols};
pub use world_model::{WorldModel, check_transition, construct_world_model};

use serde::{Deserialize, Serialize};

use crate::embodiment::Embodiment;
use crate::exec::{Report, UnmetPrecondition};
use crate::formula::Formula;
use crate::operator::Operator;
use crate::predicates::Vocabulary;
use crate::state::State;
use crate::symbol::Symbol;
use crate::text::{InductionReply, RefinementReply};

/// How strictly an induced operator must reproduce the demonstrated transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TransitionCheck {
    /// Φ(s_t, a_t) = s_{t+1} exactly (the strict reading of Eq. 3; the default).
    #[default]
    Exact,
    /// Φ(s_t, a_t) contains every atom s_{t+1} added and none it removed; atoms the
    /// demonstration did not change may differ.
    ChangedAtoms,
}

/// Switches for the paper's Table 3 ablations. All `true` is the full method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ablation {
    /// Eq. 3: verify induced operators against the demonstration. Off: the first reply per
    /// transition that parses is accepted unchecked (parse failures are still retried).
    pub world_model: bool,
    /// Eq. 6: tell the reasoner where and why the procedure fails. Off: requests carry the
    /// procedure and the initial state only ([`ViolationKind::Unidentified`], no erroneous
    /// action, no unmet literals), and patches anchor at the first match.
    pub identification: bool,
    /// Eq. 8: verify each proposal. Off: every patch that parses and matches is accepted
    /// without checking that it resolves anything.
    pub verification: bool,
}

impl Default for Ablation {
    fn default() -> Self {
        Ablation {
            world_model: true,
            identification: true,
            verification: true,
        }
    }
}

impl Ablation {
    /// The full method.
    pub const FULL: Ablation = Ablation {
        world_model: true,
        identification: true,
        verification: true,
    };
    /// w/o Eq. 8.
    pub const NO_VERIFICATION: Ablation = Ablation {
        world_model: true,
        identification: true,
        verification: false,
    };
    /// w/o Eq. 6.
    pub const NO_IDENTIFICATION: Ablation = Ablation {
        world_model: true,
        identification: false,
        verification: true,
    };
    /// w/o Eq. 6 & Eq. 8.
    pub const NO_IDENTIFICATION_NO_VERIFICATION: Ablation = Ablation {
        world_model: true,
        identification: false,
        verification: false,
    };
    /// w/o Eq. 3.
    pub const NO_WORLD_MODEL: Ablation = Ablation {
        world_model: false,
        identification: true,
        verification: true,
    };
}

/// Loop settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct AdaptConfig {
    /// Attempts per demonstrated transition during world-model construction.
    pub induction_tries: usize,
    /// Maximum patch proposals (reasoner calls) during exploration; the benchmark's budget is
    /// [`crate::benchmark::iteration_budget`].
    pub budget: usize,
    /// What "Φ(s_t, a_t) ⊨ s_{t+1}" means.
    pub transition_check: TransitionCheck,
    /// Ablation switches.
    pub ablation: Ablation,
    /// Require the derived goal to hold at the end (the full method). Off: the loop stops as
    /// soon as every precondition holds, as the authors' released code does.
    #[serde(default = "yes")]
    pub goal_check: bool,
    /// Drop induced operators without preconditions from the procedure, as the authors'
    /// released code does (off in the full method: a transition that needs nothing still
    /// happened).
    #[serde(default)]
    pub drop_unconditioned: bool,
}

fn yes() -> bool {
    true
}

impl Default for AdaptConfig {
    fn default() -> Self {
        AdaptConfig {
            induction_tries: 5,
            budget: 10,
            transition_check: TransitionCheck::Exact,
            ablation: Ablation::FULL,
            goal_check: true,
            drop_unconditioned: false,
        }
    }
}

/// The goal-relevant atoms of a demonstration: atoms true in the last state whose
/// predicate is physics-related (built-in OverOf/OnTopOf/InsideOf/Open/Closed, and any
/// predicate the vocabulary does not mark embodiment-specific) and that some transition
/// made true. Embodiment atoms are excluded, so a finger→vacuum change cannot make the goal
/// unreachable; atoms true from the start and never changed are scene context, not goals.
/// The result is a conjunction sorted by text (`(and)` if nothing qualifies).
///
/// When the demonstration ends with the end effector at rest, the goal also says so: for
/// each end effector's holding predicate the vocabulary has (`GripperHolding`,
/// `VacuumAttached`) and the last state does not hold, `(forall (?x - thing) (not (P ?x)))`
/// follows the atoms. The goal checks require every object let go, so a procedure that
/// carries the last object over its box and never releases it is a goal violation for the
/// loop to fix, not a success that fails in execution. Both end effectors are named, so
/// the goal means the same after a finger→vacuum change.
pub fn derive_goal(states: &[State], vocabulary: &Vocabulary) -> Formula {
    let Some(last) = states.last() else {
        return Formula::And(Vec::new());
    };
    let mut made_true = Vec::new();
    for w in states.windows(2) {
        made_true.extend(w[0].diff(&w[1]).added);
    }
    let mut goal: Vec<Formula> = last
        .sorted_by_text()
        .into_iter()
        .filter(|a| vocabulary.is_physics(a.pred()) && made_true.contains(a))
        .map(|a| Formula::atom(*a))
        .collect();
    for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
        let holding = Symbol::new(embodiment.holding_predicate());
        if vocabulary.get(holding).is_some() && !last.iter().any(|a| a.pred() == holding) {
            goal.push(nothing_held(holding));
        }
    }
    Formula::And(goal)
}

/// `(forall (?x - thing) (not (P ?x)))`.
fn nothing_held(holding: Symbol) -> Formula {
    crate::text::parse_formula(&format!("(forall (?x - thing) (not ({holding} ?x)))"))
        .expect("a well-formed formula over a vocabulary name")
}

/// The demonstration as the loop needs it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Demonstration {
    /// s_1 … s_N.
    pub states: Vec<State>,
    /// The source task.
    pub task: TaskContext,
}

/// The deployment scene.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Target {
    /// The counterfactual initial state ŝ_1.
    pub init: State,
    /// The target task (objects, tier).
    pub task: TaskContext,
    /// Every name the target scene has: its objects, their parts (lids, handles, drawers)
    /// and `floor`. A patch may only name these. Empty when unknown: names are then not
    /// checked (predicates still are).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scene_names: Vec<Symbol>,
    /// The target task's goal when its instruction states one beyond what the
    /// demonstration shows (the complexity-gap suite's added subtasks). It replaces the goal
    /// derived from the demonstration ([`derive_goal`]) in exploration and in the world
    /// model [`run`] returns. `None`: the derived goal, as when source and target share their
    /// subtasks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goal: Option<Formula>,
}

/// One recorded event of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum TraceEvent {
    /// An induction attempt and its verdict.
    Induction {
        /// Transition index t.
        step: usize,
        /// 0-based attempt.
        attempt: usize,
        /// The reply text.
        reply: String,
        /// The parsed reply, if it parsed.
        parsed: Option<InductionReply>,
        /// Accepted or not, and why.
        verdict: Verdict,
    },
    /// The world model after construction.
    WorldModel {
        /// The demonstrated procedure.
        procedure: Vec<Operator>,
        /// The derived goal.
        goal: Formula,
        /// Transitions whose operator never verified (kept from the last parsable attempt).
        unverified_steps: Vec<usize>,
    },
    /// Identification: the procedure replayed from ŝ_1.
    Identification {
        /// 0-based loop iteration.
        iteration: usize,
        /// The procedure that was verified.
        procedure: Vec<Operator>,
        /// The executor's full report.
        report: Report,
    },
    /// The reasoner had no proposal at all and said so; the loop stopped, unresolved.
    GaveUp {
        /// 0-based loop iteration.
        iteration: usize,
        /// What the reasoner said.
        message: String,
    },
    /// A patch proposal and its verdict.
    Proposal {
        /// 0-based loop iteration.
        iteration: usize,
        /// The reply text.
        reply: String,
        /// The parsed reply, if it parsed.
        parsed: Option<RefinementReply>,
        /// Accepted or not, and why.
        verdict: Verdict,
        /// The procedure after the patch, when accepted.
        procedure_after: Option<Vec<Operator>>,
    },
}

/// The verdict on one reply.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "verdict", rename_all = "snake_case")]
pub enum Verdict {
    /// Accepted; `checked` says whether the executor verified it (false under ablations).
    Accepted {
        /// Whether the symbolic tool checked the reply.
        checked: bool,
    },
    /// Rejected with feedback for the next attempt.
    Rejected {
        /// The feedback.
        feedback: Feedback,
    },
}

/// Every proposal, verdict and state of a run, in order.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    /// The events.
    pub events: Vec<TraceEvent>,
}

/// The violation the loop last fed to the reasoner.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ViolationInfo {
    /// Precondition or goal.
    pub kind: ViolationKind,
    /// The failing step, for precondition violations.
    pub failing_step: Option<usize>,
    /// The failing action's name.
    pub action: Option<String>,
    /// The unmet literals.
    pub unmet: Vec<UnmetPrecondition>,
    /// The state where it occurred.
    pub state: State,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "outcome", rename_all = "snake_case")]
pub enum Outcome {
    /// The procedure is consistent from ŝ_1 and reaches the goal.
    Adapted {
        /// The adapted procedure.
        procedure: Vec<Operator>,
        /// Its verification report.
        report: Report,
        /// Patch proposals used.
        iterations: usize,
    },
    /// The budget ran out (or, with both identification and verification ablated, the
    /// single revision did not yield a consistent procedure).
    Unresolved {
        /// The procedure that got furthest (most steps applied, then fewest unmet literals).
        best: Vec<Operator>,
        /// The last accepted procedure (what the authors' code would compile anyway).
        last: Vec<Operator>,
        /// The last violation fed to the reasoner, if any.
        last_violation: Option<ViolationInfo>,
        /// Patch proposals used.
        iterations: usize,
    },
}

impl Outcome {
    /// True for [`Outcome::Adapted`].
    pub fn is_adapted(&self) -> bool {
        matches!(self, Outcome::Adapted { .. })
    }

    /// The procedure to compile: the adapted one, or the best unresolved one.
    pub fn procedure(&self) -> &[Operator] {
        match self {
            Outcome::Adapted { procedure, .. } => procedure,
            Outcome::Unresolved { best, .. } => best,
        }
    }
}

/// A full run: world model, outcome and trace.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Adaptation {
    /// The world model built from the demonstration.
    pub world_model: WorldModel,
    /// How exploration ended.
    pub outcome: Outcome,
    /// Everything that happened.
    pub trace: Trace,
}

/// Why a run could not even produce an outcome.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum AdaptError {
    /// The reasoner itself failed.
    #[error(transparent)]
    Reasoner(#[from] ReasonerError),
    /// No reply for a transition even parsed within the allowed attempts.
    #[error("no parsable operator for transition {} after {attempts} attempt(s)", step + 1)]
    NoOperator {
        /// The transition, 0-based; messages count transitions from 1, as the reasoner's
        /// own errors and the prompts do.
        step: usize,
        /// Attempts made.
        attempts: usize,
    },
    /// The demonstration has fewer than two states.
    #[error("a demonstration needs at least two states, got {0}")]
    TooShort(usize),
}

/// Runs both phases: world-model construction on the demonstration, then identification
/// and exploration on the target.
pub async fn run<R: Reasoner>(
    reasoner: &mut R,
    demo: &Demonstration,
    target: &Target,
    config: &AdaptConfig,
) -> Result<Adaptation, AdaptError> {
    let mut trace = Trace::default();
    let mut world_model = construct_world_model(reasoner, demo, config, &mut trace).await?;
    // A goal the target states outright replaces the demonstrated one; without the goal
    // check there is no goal to replace.
    if let Some(goal) = target.goal.as_ref().filter(|_| config.goal_check) {
        world_model.goal = goal.clone();
    }
    let result = explore(reasoner, &world_model, target, config, &mut trace).await?;
    Ok(Adaptation {
        world_model,
        outcome: result.outcome,
        trace,
    })
}

#[cfg(test)]
mod tests;
