//! The forward executor Φ: precondition checks, effect application and procedure
//! verification, with violations that name every unmet precondition as written.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::atom::Atom;
use crate::formula::{AtomTruth, Formula, GroundError};
use crate::operator::{CompiledOperator, Operator};
use crate::state::State;
use crate::symbol::Symbol;
use crate::types::Universe;

/// One unmet precondition (or goal literal): the literal as written and the truth of the
/// ground atoms under it that made it fail.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct UnmetPrecondition {
    /// The conjunct as written, e.g. `(not (Closed hinge_lid))`.
    pub literal: Formula,
    /// The atoms that decided its falsity, with their truth values.
    pub atoms: Vec<AtomTruth>,
}

/// An action whose preconditions do not hold.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Violation {
    /// The action's display name.
    pub action: String,
    /// Every unmet precondition, in the order the operator lists them.
    pub unmet: Vec<UnmetPrecondition>,
}

/// Prints the "Unfulfilled Preconditions" list the refinement prompt embeds:
/// one `- (literal)` line per unmet precondition.
impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&format_unmet(&self.unmet))
    }
}

/// Prints unmet literals as `- (literal)` lines (`None` if there are none).
pub fn format_unmet(unmet: &[UnmetPrecondition]) -> String {
    if unmet.is_empty() {
        return "None".to_string();
    }
    unmet
        .iter()
        .map(|u| format!("- {}", u.literal))
        .collect::<Vec<_>>()
        .join("\n")
}

impl Violation {
    /// A multi-line explanation: each unmet literal with the atom truths behind it.
    pub fn explain(&self) -> String {
        let mut out = format!("preconditions of {} are not met:", self.action);
        for u in &self.unmet {
            out.push_str(&format!("\n- {}", u.literal));
            if !u.atoms.is_empty() {
                let why: Vec<String> = u.atoms.iter().map(|t| t.to_string()).collect();
                out.push_str(&format!("  (because {})", why.join(", ")));
            }
        }
        out
    }
}

/// Why an operator could not be applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum ExecError {
    /// Some preconditions do not hold.
    #[error("{}", .0.explain())]
    Violation(Violation),
    /// The operator could not be grounded (e.g. a quantifier over an unknown type).
    #[error("cannot ground action: {0}")]
    Ground(#[from] GroundError),
}

impl CompiledOperator {
    /// Applies the operator: every unmet precondition is reported, otherwise the successor
    /// state (deletes first, then adds).
    pub fn apply(&self, state: &State, source: &Operator) -> Result<State, Violation> {
        if self.applicable(state) {
            return Ok(self.effects.apply(state));
        }
        Err(self.violation(state, source))
    }

    /// The violation in `state`, listing each failing conjunct as written in `source`.
    pub fn violation(&self, state: &State, source: &Operator) -> Violation {
        let unmet = self
            .pre
            .iter()
            .filter(|(_, g)| !g.holds(state))
            .map(|(i, g)| {
                let mut atoms = Vec::new();
                g.explain(state, &mut atoms);
                UnmetPrecondition {
                    literal: source.pre[*i].clone(),
                    atoms,
                }
            })
            .collect();
        Violation {
            action: self.name.clone(),
            unmet,
        }
    }
}

/// The universe a ground procedure ranges over when none is given: every object in the
/// initial state, the operators and the goal, typed `thing`, in order of appearance.
pub fn implicit_universe(init: &State, ops: &[Operator], goal: Option<&Formula>) -> Universe {
    let mut objects: Vec<Symbol> = Vec::new();
    for atom in init.sorted_by_text() {
        for a in atom.args() {
            if !objects.contains(a) {
                objects.push(*a);
            }
        }
    }
    for op in ops {
        for c in op.constants() {
            if !objects.contains(&c) {
                objects.push(c);
            }
        }
        for a in &op.args {
            if !objects.contains(a) {
                objects.push(*a);
            }
        }
    }
    if let Some(g) = goal {
        g.constants(&mut objects);
    }
    Universe::of_things(objects)
}

/// Applies a ground operator to a state, over the implicit universe of the state and the
/// operator ([`implicit_universe`]).
pub fn apply(state: &State, op: &Operator) -> Result<State, ExecError> {
    let universe = implicit_universe(state, std::slice::from_ref(op), None);
    apply_in(&universe, state, op)
}

/// Applies a ground operator over an explicit universe.
pub fn apply_in(universe: &Universe, state: &State, op: &Operator) -> Result<State, ExecError> {
    let compiled = op.compile(universe)?;
    compiled.apply(state, op).map_err(ExecError::Violation)
}

/// What happened to one step of a procedure.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum StepStatus {
    /// Preconditions held; the effects were applied.
    Applied {
        /// Atoms the step made true.
        added: Vec<Atom>,
        /// Atoms the step made false.
        removed: Vec<Atom>,
    },
    /// Some preconditions did not hold; execution stopped here.
    Failed {
        /// The unmet preconditions.
        violation: Violation,
    },
    /// The step could not be grounded; execution stopped here.
    Invalid {
        /// Why.
        error: GroundError,
    },
    /// An earlier step failed, so this one was not executed.
    NotExecuted,
}

/// One step of a verified procedure.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct StepOutcome {
    /// 0-based index in the procedure.
    pub index: usize,
    /// The action's display name.
    pub action: String,
    /// What happened.
    #[serde(flatten)]
    pub status: StepStatus,
}

/// Whether the goal holds after the procedure.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct GoalCheck {
    /// True if every goal conjunct holds.
    pub satisfied: bool,
    /// The goal conjuncts that do not hold, as written.
    pub unmet: Vec<UnmetPrecondition>,
}

/// The result of verifying a procedure from an initial state.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Report {
    /// Per-step outcomes, one per operator.
    pub steps: Vec<StepOutcome>,
    /// Index of the first step that failed or could not be grounded.
    pub first_failure: Option<usize>,
    /// The state in which the first failing step was attempted.
    pub failing_state: Option<State>,
    /// The state after the last applied step.
    pub final_state: State,
    /// The goal check: present when a goal was given and every step applied.
    pub goal: Option<GoalCheck>,
    /// The goal could not be grounded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goal_error: Option<GroundError>,
}

impl Report {
    /// True if every step applied and the goal (if any) holds.
    pub fn is_valid(&self) -> bool {
        self.first_failure.is_none()
            && self.goal_error.is_none()
            && self.goal.as_ref().is_none_or(|g| g.satisfied)
    }

    /// The first failing step's violation, if it failed on preconditions.
    pub fn first_violation(&self) -> Option<&Violation> {
        self.first_failure.and_then(|i| match &self.steps[i].status {
            StepStatus::Failed { violation } => Some(violation),
            _ => None,
        })
    }

    /// Number of steps applied before the first failure.
    pub fn applied_steps(&self) -> usize {
        self.first_failure.unwrap_or(self.steps.len())
    }
}

/// Checks a goal formula in a state: each top-level conjunct that fails is reported.
pub fn check_goal(universe: &Universe, state: &State, goal: &Formula) -> Result<GoalCheck, GroundError> {
    let mut unmet = Vec::new();
    for conjunct in goal.conjuncts() {
        let g = conjunct.ground(universe, &mut Default::default())?;
        if !g.holds(state) {
            let mut atoms = Vec::new();
            g.explain(state, &mut atoms);
            unmet.push(UnmetPrecondition {
                literal: conjunct,
                atoms,
            });
        }
    }
    Ok(GoalCheck {
        satisfied: unmet.is_empty(),
        unmet,
    })
}

/// Verifies a procedure of ground operators from `init` over the implicit universe
/// ([`implicit_universe`]), stopping at the first failing step; checks the goal if every
/// step applied.
pub fn verify_procedure(init: &State, ops: &[Operator], goal: Option<&Formula>) -> Report {
    let universe = implicit_universe(init, ops, goal);
    verify_procedure_in(&universe, init, ops, goal)
}

/// [`verify_procedure`] over an explicit universe.
pub fn verify_procedure_in(
    universe: &Universe,
    init: &State,
    ops: &[Operator],
    goal: Option<&Formula>,
) -> Report {
    let compiled: Vec<Result<CompiledOperator, GroundError>> =
        ops.iter().map(|o| o.compile(universe)).collect();
    verify_compiled(universe, init, ops, &compiled, goal)
}

/// Verifies a procedure whose operators were compiled once against `universe`; this is the
/// fast path the adaptation loop and the benchmarks use.
pub fn verify_compiled(
    universe: &Universe,
    init: &State,
    ops: &[Operator],
    compiled: &[Result<CompiledOperator, GroundError>],
    goal: Option<&Formula>,
) -> Report {
    let mut state = init.clone();
    let mut steps = Vec::with_capacity(ops.len());
    let mut first_failure = None;
    let mut failing_state = None;
    for (index, (op, c)) in ops.iter().zip(compiled).enumerate() {
        let action = op.display_name();
        if first_failure.is_some() {
            steps.push(StepOutcome {
                index,
                action,
                status: StepStatus::NotExecuted,
            });
            continue;
        }
        let status = match c {
            Err(error) => StepStatus::Invalid { error: error.clone() },
            Ok(c) => match c.apply(&state, op) {
                Ok(next) => {
                    let diff = state.diff(&next);
                    state = next;
                    StepStatus::Applied {
                        added: diff.added,
                        removed: diff.removed,
                    }
                }
                Err(violation) => StepStatus::Failed { violation },
            },
        };
        if !matches!(status, StepStatus::Applied { .. }) {
            first_failure = Some(index);
            failing_state = Some(state.clone());
        }
        steps.push(StepOutcome {
            index,
            action,
            status,
        });
    }
    let (goal, goal_error) = match (goal, first_failure) {
        (Some(g), None) => match check_goal(universe, &state, g) {
            Ok(check) => (Some(check), None),
            Err(e) => (None, Some(e)),
        },
        _ => (None, None),
    };
    Report {
        steps,
        first_failure,
        failing_state,
        final_state: state,
        goal,
        goal_error,
    }
}
