//! The forward executor Φ: precondition checks, effect application and procedure
//! verification, with violations that name every unmet precondition as written.

use std::fmt;
use std::sync::Arc;

use rustc_hash::FxHashMap;

use serde::{Deserialize, Serialize};

use crate::atom::Atom;
use crate::formula::{AtomTruth, Bindings, Effect, Formula, Ground, GroundEffects, GroundError};
use crate::indexed::{Bits, Cond, Facts, get, set};
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
    CompiledProcedure::new(universe, ops, goal).verify(init)
}

/// A goal conjunct as written, grounded, and indexed.
type GoalConjunct = (Formula, Ground, Cond);

/// One compiled step: its display name, its operator (for violation reports) and its
/// indexed form.
/// One operator grounded over a universe; shared between the compiled procedures that
/// contain it (see [`GroundingCache`]).
#[derive(Debug)]
struct Grounded {
    source: Operator,
    name: String,
    compiled: Result<CompiledOperator, GroundError>,
}

#[derive(Debug, Clone)]
struct CompiledStep {
    grounded: Arc<Grounded>,
    /// The effects and preconditions over this procedure's fact indices, or why the
    /// operator could not be grounded.
    indexed: Result<(IndexedEffects, Vec<Cond>), GroundError>,
}

/// Grounded operators kept across verifications over one universe.
///
/// Grounding (expanding quantifiers over every object, interning atoms) is most of the cost
/// of verifying a procedure, and the adaptation loop re-verifies procedures that differ from
/// the previous version by one patch: with a cache, an unchanged action is grounded once.
/// The cache is keyed by the whole operator (name, preconditions, effects, parameters), so a
/// changed literal is a different entry; when the universe changes (e.g. a patch mentions a
/// new object) it drops every entry that quantifies, since quantifiers then range over other
/// objects.
///
/// Ground operators (no parameters) are grounded conjunct by conjunct, and each distinct
/// precondition conjunct and top-level effect is grounded once too: actions of one procedure
/// share most of them (`(VacuumSuction)`, `(forall (?y - thing) (not (GripperHolding ?y)))`).
/// The result is the same as [`Operator::compile`]'s.
#[derive(Debug, Default)]
pub(crate) struct GroundingCache {
    universe: Option<Universe>,
    entries: FxHashMap<Operator, Arc<Grounded>>,
    conjuncts: FxHashMap<Formula, Ground>,
    effects: FxHashMap<Effect, GroundEffects>,
}

impl GroundingCache {
    fn grounded(&mut self, universe: &Universe, op: &Operator) -> Arc<Grounded> {
        if self.universe.as_ref() != Some(universe) {
            self.universe = Some(universe.clone());
            self.entries.clear();
            // Without quantifiers a conjunct or effect grounds to the same atoms over any
            // universe, so only the quantified ones go: a patch that names a new object then
            // re-grounds a few `forall`s, not every literal of the procedure.
            self.conjuncts.retain(|f, _| f.is_quantifier_free());
            self.effects.retain(|e, _| e.is_quantifier_free());
        }
        if let Some(g) = self.entries.get(op) {
            return g.clone();
        }
        let compiled = if op.params.is_empty() && op.args.is_empty() {
            self.compile_ground(universe, op)
        } else {
            op.compile(universe)
        };
        let g = Arc::new(Grounded {
            source: op.clone(),
            name: op.display_name(),
            compiled,
        });
        self.entries.insert(op.clone(), g.clone());
        g
    }

    /// [`Operator::compile`] for an operator without parameters, whose conjuncts and effects
    /// then ground independently of the operator they belong to.
    fn compile_ground(
        &mut self,
        universe: &Universe,
        op: &Operator,
    ) -> Result<CompiledOperator, GroundError> {
        let mut pre = Vec::with_capacity(op.pre.len());
        for (i, f) in op.pre.iter().enumerate() {
            let g = match self.conjuncts.get(f) {
                Some(g) => g.clone(),
                None => {
                    let g = f.ground(universe, &mut Bindings::new())?;
                    self.conjuncts.insert(f.clone(), g.clone());
                    g
                }
            };
            if g != Ground::True {
                pre.push((i, g));
            }
        }
        let mut effects = GroundEffects::default();
        for e in op.eff.iter() {
            if !self.effects.contains_key(e) {
                let mut part = GroundEffects::default();
                e.ground(universe, &mut Bindings::new(), None, &mut part)?;
                self.effects.insert(e.clone(), part);
            }
            if let Some(part) = self.effects.get(e) {
                effects.adds.extend_from_slice(&part.adds);
                effects.dels.extend_from_slice(&part.dels);
                effects.conditional.extend(part.conditional.iter().cloned());
            }
        }
        effects.normalize();
        Ok(CompiledOperator {
            name: op.display_name(),
            pre,
            effects,
        })
    }
}

#[derive(Debug, Clone)]
struct IndexedEffects {
    adds: Vec<u32>,
    dels: Vec<u32>,
    conditional: Vec<(Cond, u32, bool)>,
}

/// A procedure (and goal) compiled once against a universe: every quantifier expanded, every
/// atom mapped to a dense index. [`CompiledProcedure::verify`] runs over bitset states and
/// builds [`State`]s only for the report, so verifying from many initial states, or timing
/// pure execution, pays the grounding once.
#[derive(Debug, Clone)]
pub struct CompiledProcedure {
    facts: Facts,
    steps: Vec<CompiledStep>,
    goal: Option<Result<Vec<GoalConjunct>, GroundError>>,
}

impl CompiledProcedure {
    /// Compiles `ops` and `goal` against `universe`. Steps that cannot be grounded are
    /// kept and reported as [`StepStatus::Invalid`] when reached.
    pub fn new(universe: &Universe, ops: &[Operator], goal: Option<&Formula>) -> Self {
        Self::new_cached(universe, ops, goal, &mut GroundingCache::default())
    }

    /// [`CompiledProcedure::new`], taking already grounded operators from `cache`.
    pub(crate) fn new_cached(
        universe: &Universe,
        ops: &[Operator],
        goal: Option<&Formula>,
        cache: &mut GroundingCache,
    ) -> Self {
        let mut facts = Facts::new();
        let steps = ops
            .iter()
            .map(|op| {
                let grounded = cache.grounded(universe, op);
                let indexed = grounded.compiled.as_ref().map_err(Clone::clone).map(|c| {
                    let pre = c.pre.iter().map(|(_, g)| facts.cond(g)).collect();
                    let eff = IndexedEffects {
                        adds: c.effects.adds.iter().map(|a| facts.id(*a)).collect(),
                        dels: c.effects.dels.iter().map(|a| facts.id(*a)).collect(),
                        conditional: c
                            .effects
                            .conditional
                            .iter()
                            .map(|e| (facts.cond(&e.condition), facts.id(e.atom), e.add))
                            .collect(),
                    };
                    (eff, pre)
                });
                CompiledStep { grounded, indexed }
            })
            .collect();
        let goal = goal.map(|g| {
            g.conjuncts()
                .into_iter()
                .map(|c| {
                    let ground = c.ground(universe, &mut Default::default())?;
                    let cond = facts.cond(&ground);
                    Ok((c, ground, cond))
                })
                .collect::<Result<Vec<_>, GroundError>>()
        });
        CompiledProcedure { facts, steps, goal }
    }

    /// Number of steps.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// True if the procedure has no steps.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    fn state_of(&self, bits: &Bits, untouched: &[Atom]) -> State {
        let mut state = self.facts.decode(bits);
        if !untouched.is_empty() {
            state = State::from_atoms(state.iter().copied().chain(untouched.iter().copied()));
        }
        state
    }

    /// Verifies the procedure from `init`, stopping at the first failing step; checks the
    /// goal if every step applied.
    pub fn verify(&self, init: &State) -> Report {
        let (mut bits, untouched) = self.encode_init(init);
        let mut steps = Vec::with_capacity(self.steps.len());
        let mut first_failure = None;
        let mut failing_state = None;
        let mut scratch = EffectScratch::default();
        for (index, step) in self.steps.iter().enumerate() {
            let action = step.grounded.name.clone();
            if first_failure.is_some() {
                steps.push(StepOutcome {
                    index,
                    action,
                    status: StepStatus::NotExecuted,
                });
                continue;
            }
            let status = match &step.indexed {
                Err(error) => StepStatus::Invalid { error: error.clone() },
                Ok((eff, pre)) => {
                    if pre.iter().all(|c| c.holds(&bits)) {
                        self.apply_effects(eff, &mut bits, &mut scratch)
                    } else {
                        self.failed_status(step, &bits, &untouched)
                    }
                }
            };
            if !matches!(status, StepStatus::Applied { .. }) {
                first_failure = Some(index);
                failing_state = Some(self.state_of(&bits, &untouched));
            }
            steps.push(StepOutcome {
                index,
                action,
                status,
            });
        }
        let final_state = self.state_of(&bits, &untouched);
        let (goal, goal_error) = self.check_goal(first_failure, &bits, &final_state);
        Report {
            steps,
            first_failure,
            failing_state,
            final_state,
            goal,
            goal_error,
        }
    }

    /// `init` as bits over this procedure's facts, and the atoms of `init` outside them.
    fn encode_init(&self, init: &State) -> (Bits, Vec<Atom>) {
        // Atoms of `init` that no step or goal mentions can never change or matter; they
        // ride along untouched and rejoin the reported states.
        let mut bits = vec![0u64; self.facts.words()];
        let mut untouched = Vec::new();
        for a in init.iter() {
            match self.facts.index.get(a) {
                Some(&i) => set(&mut bits, i, true),
                None => untouched.push(*a),
            }
        }
        (bits, untouched)
    }

    /// Applies a step whose preconditions hold to `bits` and reports the atoms it changed.
    /// Deletions go first, so an atom a step both adds and deletes ends up true.
    fn apply_effects(
        &self,
        eff: &IndexedEffects,
        bits: &mut Bits,
        scratch: &mut EffectScratch,
    ) -> StepStatus {
        let EffectScratch { adds, dels } = scratch;
        adds.clear();
        dels.clear();
        adds.extend_from_slice(&eff.adds);
        dels.extend_from_slice(&eff.dels);
        for (c, f, add) in &eff.conditional {
            if c.holds(bits) {
                if *add { adds.push(*f) } else { dels.push(*f) }
            }
        }
        let added: Vec<Atom> = adds
            .iter()
            .filter(|&&f| !get(bits, f))
            .map(|&f| self.facts.atoms[f as usize])
            .collect();
        let removed: Vec<Atom> = dels
            .iter()
            .filter(|&&f| get(bits, f) && !adds.contains(&f))
            .map(|&f| self.facts.atoms[f as usize])
            .collect();
        for &d in dels.iter() {
            set(bits, d, false);
        }
        for &a in adds.iter() {
            set(bits, a, true);
        }
        let mut added = added;
        added.sort_unstable();
        added.dedup();
        let mut removed = removed;
        removed.sort_unstable();
        removed.dedup();
        StepStatus::Applied { added, removed }
    }

    /// The status of a step whose preconditions do not hold in `bits`: the violation,
    /// explained over the full state.
    fn failed_status(&self, step: &CompiledStep, bits: &Bits, untouched: &[Atom]) -> StepStatus {
        let state = self.state_of(bits, untouched);
        match &step.grounded.compiled {
            Ok(compiled) => StepStatus::Failed {
                violation: compiled.violation(&state, &step.grounded.source),
            },
            Err(error) => StepStatus::Invalid { error: error.clone() },
        }
    }

    /// The goal check once every step applied (`first_failure` is `None`), or why the goal
    /// could not be grounded; neither if a step failed or there is no goal.
    fn check_goal(
        &self,
        first_failure: Option<usize>,
        bits: &Bits,
        final_state: &State,
    ) -> (Option<GoalCheck>, Option<GroundError>) {
        match (&self.goal, first_failure) {
            (Some(Ok(conjuncts)), None) => {
                let unmet: Vec<UnmetPrecondition> = conjuncts
                    .iter()
                    .filter(|(_, _, cond)| !cond.holds(bits))
                    .map(|(literal, ground, _)| {
                        let mut atoms = Vec::new();
                        ground.explain(final_state, &mut atoms);
                        UnmetPrecondition {
                            literal: literal.clone(),
                            atoms,
                        }
                    })
                    .collect();
                (
                    Some(GoalCheck {
                        satisfied: unmet.is_empty(),
                        unmet,
                    }),
                    None,
                )
            }
            (Some(Err(e)), None) => (None, Some(e.clone())),
            _ => (None, None),
        }
    }
}

/// The add and delete lists of the step being applied, kept across steps so their
/// buffers are allocated once per verification.
#[derive(Default)]
struct EffectScratch {
    adds: Vec<u32>,
    dels: Vec<u32>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::{parse_effect, parse_formula};

    fn op(pre: &[&str], eff: &[&str]) -> Operator {
        Operator::new(
            "Act",
            pre.iter().map(|p| parse_formula(p).unwrap()).collect::<Vec<_>>(),
            eff.iter().map(|e| parse_effect(e).unwrap()).collect::<Vec<_>>(),
        )
    }

    #[test]
    fn quantifier_freedom() {
        assert!(
            parse_formula("(not (and (A x) (= x y)))")
                .unwrap()
                .is_quantifier_free()
        );
        assert!(
            !parse_formula("(or (A x) (exists (?y - thing) (B ?y)))")
                .unwrap()
                .is_quantifier_free()
        );
        assert!(parse_effect("(when (A x) (B x))").unwrap().is_quantifier_free());
        assert!(
            !parse_effect("(when (forall (?y - thing) (A ?y)) (B x))")
                .unwrap()
                .is_quantifier_free()
        );
        assert!(
            !parse_effect("(forall (?y - thing) (not (B ?y)))")
                .unwrap()
                .is_quantifier_free()
        );
    }

    #[test]
    fn cache_across_a_universe_change_grounds_like_compile() {
        let action = op(
            &["(A x)", "(forall (?y - thing) (not (Held ?y)))"],
            &["(B x)", "(forall (?y - thing) (not (Over x ?y)))"],
        );
        let mut cache = GroundingCache::default();
        let small = Universe::of_things([Symbol::new("x"), Symbol::new("y")]);
        let big = Universe::of_things([Symbol::new("x"), Symbol::new("y"), Symbol::new("z")]);
        for universe in [&small, &big, &small] {
            let cached = cache.grounded(universe, &action);
            let fresh = action.compile(universe).unwrap();
            let cached = cached.compiled.as_ref().unwrap();
            assert_eq!(cached.pre, fresh.pre);
            assert_eq!(cached.effects, fresh.effects);
        }
        // The quantifier-free literals survived the changes; the quantified ones were
        // re-grounded for the last universe only.
        assert_eq!(cache.conjuncts.len(), 2);
        assert_eq!(cache.effects.len(), 2);
    }
}
