//! A grounded forward-search planner: greedy best-first or A* over STRIPS with negative
//! preconditions, `=`, quantified and disjunctive preconditions and conditional effects
//! (all ground over the finite universe), guided by h_add, h_max or h_FF.
//!
//! Results are deterministic: operators are grounded in schema order and argument tuples in
//! universe order, the open list breaks ties by insertion order, and no hash-map iteration
//! order reaches a result.
//!
//! The relaxation behind the heuristics ignores deletes; a negative literal costs nothing
//! if it already holds and one step otherwise, disjunctions cost their cheapest part.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::time::{Duration, Instant};

use rustc_hash::{FxHashMap, FxHashSet};
use serde::{Deserialize, Serialize};

use crate::atom::Atom;
use crate::formula::{Formula, Ground, GroundError};
use crate::indexed::{Bits, Cond, Facts, get, set};
use crate::operator::{CompiledOperator, Operator};
use crate::state::State;
use crate::symbol::Symbol;
use crate::types::Universe;

/// The search algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Search {
    /// Greedy best-first search on h (fast, plans not necessarily shortest). On h_FF it
    /// uses preferred operators by default ([`PlannerConfig::preferred_operators`]).
    Gbfs,
    /// A* on g + h (shortest plans when h is admissible, i.e. with `HMax` or `Blind`).
    AStar,
}

/// The heuristic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Heuristic {
    /// Sum of relaxed atom costs (informative, inadmissible).
    HAdd,
    /// Maximum of relaxed atom costs (admissible, weak).
    HMax,
    /// Size of a relaxed plan extracted from h_add's best supporters.
    HFf,
    /// Zero everywhere (breadth-first / uniform cost).
    Blind,
}

/// How lifted schemas become ground actions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Grounding {
    /// Every argument tuple of the parameters' types, pruned by static preconditions. An
    /// untyped 4-parameter schema over 30 objects is 810 000 tuples.
    #[default]
    AllTuples,
    /// Only the tuples whose positive atomic preconditions are reachable in the delete
    /// relaxation from the initial state, as Fast Downward's translator grounds: each schema's
    /// parameters are bound by joining those preconditions with the reachable facts, to a
    /// fixpoint. Actions it leaves out can never apply, so plans are the same as with
    /// [`Grounding::AllTuples`], found in the same order.
    Reachable,
}

/// Search settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlannerConfig {
    /// The algorithm.
    pub search: Search,
    /// The heuristic.
    pub heuristic: Heuristic,
    /// Stop after expanding this many states.
    pub max_expansions: usize,
    /// Stop after this much wall-clock time; [`plan`] counts grounding in it too.
    pub time_limit: Option<Duration>,
    /// How lifted schemas are grounded.
    #[serde(default)]
    pub grounding: Grounding,
    /// Refuse to ground more than this many actions ([`PlanError::TooManyActions`]).
    #[serde(default)]
    pub max_ground_actions: Option<usize>,
    /// Greedy search on h_FF only: keep a second open list of the states reached by helpful
    /// actions (the relaxed plan's applicable actions) and favour it after each improvement
    /// (see [`Search::Gbfs`]). Off, greedy search uses one open list.
    #[serde(default = "preferred_operators_default")]
    pub preferred_operators: bool,
}

fn preferred_operators_default() -> bool {
    true
}

impl Default for PlannerConfig {
    fn default() -> Self {
        PlannerConfig {
            search: Search::Gbfs,
            heuristic: Heuristic::HFf,
            max_expansions: 200_000,
            time_limit: Some(Duration::from_secs(10)),
            preferred_operators: true,
            grounding: Grounding::AllTuples,
            max_ground_actions: None,
        }
    }
}

/// A plan found by the planner.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Plan {
    /// The ground operators, in order (instantiated schemas carry their arguments).
    pub steps: Vec<Operator>,
    /// States expanded.
    pub expanded: usize,
    /// States generated.
    pub generated: usize,
}

/// Why no plan was returned.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum PlanError {
    /// The reachable state space holds no goal state.
    #[error("no plan exists (searched {expanded} states)")]
    Unsolvable {
        /// States expanded.
        expanded: usize,
    },
    /// The expansion limit was reached.
    #[error("node limit reached after expanding {expanded} states")]
    NodeLimit {
        /// States expanded.
        expanded: usize,
    },
    /// The time limit was reached.
    #[error("time limit reached after expanding {expanded} states")]
    TimeLimit {
        /// States expanded.
        expanded: usize,
    },
    /// An operator or the goal could not be grounded.
    #[error("grounding failed: {0}")]
    Ground(#[from] GroundError),
    /// Grounding passed the cap of [`PlannerConfig::max_ground_actions`].
    #[error(
        "grounding stopped at the cap of {cap} ground actions while grounding `{schema}`; the schemas' parameters admit too many argument tuples"
    )]
    TooManyActions {
        /// The cap.
        cap: usize,
        /// The schema being grounded when the cap was passed.
        schema: String,
    },
    /// The time limit ran out while grounding, before any search.
    #[error("time limit reached while grounding (after {actions} ground actions)")]
    GroundingTimeLimit {
        /// Ground actions built by then.
        actions: usize,
    },
}

/// What grounding may spend: [`PlannerConfig`]'s grounding mode and cap, and a deadline.
#[derive(Debug, Clone, Copy, Default)]
pub struct GroundingLimits {
    /// How schemas are grounded.
    pub grounding: Grounding,
    /// The most ground actions.
    pub max_actions: Option<usize>,
    /// When to give up.
    pub deadline: Option<Instant>,
}

impl GroundingLimits {
    fn check(&self, actions: usize, schema: &Operator) -> Result<(), PlanError> {
        if let Some(cap) = self.max_actions
            && actions > cap
        {
            return Err(PlanError::TooManyActions {
                cap,
                schema: schema.name.clone(),
            });
        }
        if self.deadline.is_some_and(|d| Instant::now() > d) {
            return Err(PlanError::GroundingTimeLimit { actions });
        }
        Ok(())
    }
}

/// A search node: state, (parent, action) and path cost.
type Node = (Bits, Option<(usize, usize)>, usize);

struct GroundAction {
    op: Operator,
    pre: Cond,
    adds: Vec<u32>,
    dels: Vec<u32>,
    conditional: Vec<(Cond, u32, bool)>,
}

/// Three-valued truth of a ground formula when only static atoms are known.
fn static_truth(g: &Ground, is_static: &dyn Fn(Atom) -> bool, init: &State) -> Option<bool> {
    match g {
        Ground::True => Some(true),
        Ground::False => Some(false),
        Ground::Atom(a) => is_static(*a).then(|| init.contains(a)),
        Ground::Not(x) => static_truth(x, is_static, init).map(|v| !v),
        Ground::And(gs) => {
            let vals: Vec<Option<bool>> = gs.iter().map(|g| static_truth(g, is_static, init)).collect();
            if vals.contains(&Some(false)) {
                Some(false)
            } else if vals.iter().all(|v| *v == Some(true)) {
                Some(true)
            } else {
                None
            }
        }
        Ground::Or(gs) => {
            let vals: Vec<Option<bool>> = gs.iter().map(|g| static_truth(g, is_static, init)).collect();
            if vals.contains(&Some(true)) {
                Some(true)
            } else if vals.iter().all(|v| *v == Some(false)) {
                Some(false)
            } else {
                None
            }
        }
    }
}

/// The positive atoms among a schema's top-level precondition conjuncts: the ones a
/// reachable binding must find among the reachable facts.
fn positive_atoms(schema: &Operator) -> Vec<crate::formula::AtomPattern> {
    schema
        .pre
        .iter()
        .flat_map(|f| f.conjuncts())
        .filter_map(|f| match f {
            Formula::Atom(p) => Some(p),
            _ => None,
        })
        .collect()
}

/// The argument tuples of `schema` whose positive atomic preconditions are all in `facts`,
/// in the order [`tuples`] would list them: parameters that such an atom mentions are bound
/// by matching it against the facts of its predicate, the others range over their domain.
fn joined_tuples(schema: &Operator, domains: &[Vec<Symbol>], by_pred: &FactIndex) -> Vec<Vec<Symbol>> {
    use crate::formula::Term;
    let index: FxHashMap<Symbol, usize> = schema
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| (p.name, i))
        .collect();
    let patterns = positive_atoms(schema);
    // Partial bindings, extended one precondition at a time.
    let mut partial: Vec<Vec<Option<Symbol>>> = vec![vec![None; domains.len()]];
    for pattern in &patterns {
        let candidates = by_pred.get(&pattern.pred).map(Vec::as_slice).unwrap_or_default();
        let mut next = Vec::new();
        for binding in &partial {
            'fact: for fact in candidates {
                if fact.args().len() != pattern.args.len() {
                    continue;
                }
                let mut extended = binding.clone();
                for (term, value) in pattern.args.iter().zip(fact.args()) {
                    match term {
                        Term::Const(c) if c != value => continue 'fact,
                        Term::Const(_) => {}
                        Term::Var(v) => {
                            let Some(&i) = index.get(v) else { continue };
                            match extended[i] {
                                Some(bound) if bound != *value => continue 'fact,
                                Some(_) => {}
                                None if !domains[i].contains(value) => continue 'fact,
                                None => extended[i] = Some(*value),
                            }
                        }
                    }
                }
                next.push(extended);
            }
        }
        next.sort();
        next.dedup();
        partial = next;
        if partial.is_empty() {
            return Vec::new();
        }
    }
    let mut out: Vec<Vec<Symbol>> = Vec::new();
    for binding in partial {
        let choices: Vec<Vec<Symbol>> = binding
            .iter()
            .zip(domains)
            .map(|(b, d)| b.map_or_else(|| d.clone(), |v| vec![v]))
            .collect();
        out.extend(tuples(&choices));
    }
    // Universe order, as `tuples` over the full domains lists them.
    let rank = |args: &Vec<Symbol>| -> Vec<usize> {
        args.iter()
            .zip(domains)
            .map(|(a, d)| d.iter().position(|x| x == a).unwrap_or(usize::MAX))
            .collect()
    };
    out.sort_by_key(rank);
    out.dedup();
    out
}

/// Facts by predicate, for [`joined_tuples`].
type FactIndex = FxHashMap<Symbol, Vec<Atom>>;

fn index_by_predicate(facts: &FxHashSet<Atom>) -> FactIndex {
    let mut by_pred = FactIndex::default();
    for atom in facts {
        by_pred.entry(atom.pred()).or_default().push(*atom);
    }
    by_pred
}

/// The facts reachable from `init` in the delete relaxation, by predicate: each round
/// grounds every schema by [`joined_tuples`] over the facts of the rounds before, until a
/// round adds nothing.
fn relaxed_reachable(
    actions: &[Operator],
    universe: &Universe,
    init: &State,
    limits: &GroundingLimits,
) -> Result<FactIndex, PlanError> {
    let domains: Vec<Vec<Vec<Symbol>>> = actions
        .iter()
        .map(|schema| {
            schema
                .params
                .iter()
                .map(|p| universe.objects_of(p.ty))
                .collect::<Result<_, _>>()
        })
        .collect::<Result<_, _>>()
        .map_err(GroundError::from)?;
    let mut facts: FxHashSet<Atom> = init.iter().copied().collect();
    loop {
        let index = index_by_predicate(&facts);
        let mut added = false;
        let mut grounded = 0usize;
        for (schema, domains) in actions.iter().zip(&domains) {
            let candidates = if schema.params.is_empty() {
                vec![Vec::new()]
            } else {
                joined_tuples(schema, domains, &index)
            };
            grounded += candidates.len();
            limits.check(grounded, schema)?;
            for args in candidates {
                let c = schema.compile_with(&args, universe)?;
                for atom in c
                    .effects
                    .adds
                    .iter()
                    .copied()
                    .chain(c.effects.conditional.iter().filter(|e| e.add).map(|e| e.atom))
                {
                    added |= facts.insert(atom);
                }
            }
        }
        if !added {
            return Ok(index);
        }
    }
}

fn tuples(types: &[Vec<Symbol>]) -> Vec<Vec<Symbol>> {
    let mut out = vec![Vec::new()];
    for choices in types {
        let mut next = Vec::with_capacity(out.len() * choices.len());
        for prefix in &out {
            for c in choices {
                let mut t = prefix.clone();
                t.push(*c);
                next.push(t);
            }
        }
        out = next;
    }
    out
}

/// A grounded planning task, reusable across searches from different initial states.
pub struct Task {
    facts: Facts,
    actions: Vec<GroundAction>,
}

impl Task {
    /// Grounds `actions` (lifted schemas or ground operators) over `universe`, every
    /// argument tuple. Operators whose static preconditions (over predicates no action
    /// changes) are false in `init` are pruned.
    pub fn ground(actions: &[Operator], universe: &Universe, init: &State) -> Result<Task, PlanError> {
        Task::ground_within(actions, universe, init, &GroundingLimits::default())
    }

    /// [`Task::ground`] with a grounding mode, a cap on ground actions and a deadline.
    pub fn ground_within(
        actions: &[Operator],
        universe: &Universe,
        init: &State,
        limits: &GroundingLimits,
    ) -> Result<Task, PlanError> {
        let reachable = match limits.grounding {
            Grounding::AllTuples => None,
            Grounding::Reachable => Some(relaxed_reachable(actions, universe, init, limits)?),
        };
        let mut compiled: Vec<(Operator, CompiledOperator)> = Vec::new();
        for schema in actions {
            if schema.params.is_empty() {
                compiled.push((schema.clone(), schema.compile(universe)?));
                continue;
            }
            let domains: Vec<Vec<Symbol>> = schema
                .params
                .iter()
                .map(|p| universe.objects_of(p.ty))
                .collect::<Result<_, _>>()
                .map_err(GroundError::from)?;
            let candidates = match &reachable {
                None => tuples(&domains),
                Some(facts) => joined_tuples(schema, &domains, facts),
            };
            for args in candidates {
                let op = schema.instantiate(&args, universe)?;
                let c = op.compile(universe)?;
                compiled.push((op, c));
                if compiled.len().is_multiple_of(1024) {
                    limits.check(compiled.len(), schema)?;
                }
            }
            limits.check(compiled.len(), schema)?;
        }
        let mut changing: FxHashSet<Symbol> = FxHashSet::default();
        for (_, c) in &compiled {
            changing.extend(c.effects.adds.iter().chain(&c.effects.dels).map(|a| a.pred()));
            changing.extend(c.effects.conditional.iter().map(|e| e.atom.pred()));
        }
        let is_static = |a: Atom| !changing.contains(&a.pred());
        let mut facts = Facts {
            index: FxHashMap::default(),
            atoms: Vec::new(),
        };
        for a in init.sorted_by_text() {
            facts.id(*a);
        }
        let mut ground = Vec::new();
        for (op, c) in compiled {
            let pre = Ground::And(c.pre.iter().map(|(_, g)| g.clone()).collect());
            if static_truth(&pre, &is_static, init) == Some(false) {
                continue;
            }
            let pre = facts.cond(&pre);
            let adds = c.effects.adds.iter().map(|a| facts.id(*a)).collect();
            let dels = c.effects.dels.iter().map(|a| facts.id(*a)).collect();
            let conditional = c
                .effects
                .conditional
                .iter()
                .map(|e| (facts.cond(&e.condition), facts.id(e.atom), e.add))
                .collect();
            ground.push(GroundAction {
                op,
                pre,
                adds,
                dels,
                conditional,
            });
        }
        Ok(Task {
            facts,
            actions: ground,
        })
    }

    /// Number of ground actions after pruning.
    pub fn num_actions(&self) -> usize {
        self.actions.len()
    }

    fn encode(&self, state: &State) -> Bits {
        self.facts.encode(state)
    }

    fn successor(&self, a: &GroundAction, s: &Bits) -> Bits {
        let mut next = s.clone();
        let mut adds: Vec<u32> = a.adds.clone();
        let mut dels: Vec<u32> = a.dels.clone();
        for (c, f, add) in &a.conditional {
            if c.holds(s) {
                if *add { adds.push(*f) } else { dels.push(*f) }
            }
        }
        for d in dels {
            set(&mut next, d, false);
        }
        for ad in adds {
            set(&mut next, ad, true);
        }
        next
    }

    /// Plans from `init` to `goal`.
    pub fn plan(
        &mut self,
        universe: &Universe,
        init: &State,
        goal: &Formula,
        config: &PlannerConfig,
    ) -> Result<Plan, PlanError> {
        let goal_ground = goal.ground(universe, &mut Default::default())?;
        let goal = self.facts.cond(&goal_ground);
        let started = Instant::now();
        let start = self.encode(init);
        let mut heuristic = Relaxed::new(self);
        let mut nodes: Vec<Node> = Vec::new();
        let mut seen: FxHashMap<Bits, usize> = FxHashMap::default();
        let mut open = Frontier::new(
            config.preferred_operators && config.search == Search::Gbfs && config.heuristic == Heuristic::HFf,
        );
        let key = |g: usize, h: u64| match config.search {
            Search::Gbfs => (h, g as u64),
            Search::AStar => (g as u64 + h, h),
        };
        if let Some(h) = heuristic.eval(self, &start, &goal, config.heuristic) {
            open.push(key(0, h), 0, false);
            open.progress(h);
        }
        nodes.push((start.clone(), None, 0));
        seen.insert(start, 0);
        let mut expanded = 0;
        let mut closed: FxHashSet<usize> = FxHashSet::default();
        let mut preferred: FxHashSet<usize> = FxHashSet::default();
        while let Some(id) = open.pop() {
            if !closed.insert(id) {
                continue;
            }
            let (state, g) = (nodes[id].0.clone(), nodes[id].2);
            if goal.holds(&state) {
                return Ok(self.extract(&nodes, id, expanded, nodes.len()));
            }
            expanded += 1;
            if expanded > config.max_expansions {
                return Err(PlanError::NodeLimit {
                    expanded: expanded - 1,
                });
            }
            if expanded % 256 == 0 && config.time_limit.is_some_and(|t| started.elapsed() > t) {
                return Err(PlanError::TimeLimit { expanded });
            }
            // The helpful actions of this state: its relaxed plan's applicable actions.
            preferred.clear();
            if open.dual() {
                heuristic.eval(self, &state, &goal, config.heuristic);
                preferred.extend(heuristic.relaxed_plan.iter().copied());
            }
            for (ai, a) in self.actions.iter().enumerate() {
                if !a.pre.holds(&state) {
                    continue;
                }
                let next = self.successor(a, &state);
                let ng = g + 1;
                match seen.get(&next) {
                    Some(&old) if nodes[old].2 <= ng || config.search == Search::Gbfs => continue,
                    _ => {}
                }
                let Some(h) = heuristic.eval(self, &next, &goal, config.heuristic) else {
                    continue;
                };
                let nid = nodes.len();
                nodes.push((next.clone(), Some((id, ai)), ng));
                seen.insert(next, nid);
                open.push(key(ng, h), nid, preferred.contains(&ai));
                open.progress(h);
            }
        }
        Err(PlanError::Unsolvable { expanded })
    }

    fn extract(&self, nodes: &[Node], mut id: usize, expanded: usize, generated: usize) -> Plan {
        let mut steps = Vec::new();
        while let Some((parent, action)) = nodes[id].1 {
            steps.push(self.actions[action].op.clone());
            id = parent;
        }
        steps.reverse();
        Plan {
            steps,
            expanded,
            generated,
        }
    }
}

/// The open list. A* and the other heuristics use one queue; greedy search on h_FF keeps a
/// second queue of the states reached by helpful actions (FF's preferred operators) and
/// alternates between the two, favouring the preferred one for a while whenever the best h
/// improves (Fast Downward's boosted dual queue). Without it the search drowned in plateaus:
/// in a high-complexity scene, once the cubes and chess pieces were in place, opening the
/// closed lid raised h as much as it lowered it, and greedy search expanded every ordering
/// of the finished subtasks first (over 300,000 states for a 66-step plan).
struct Frontier {
    all: BinaryHeap<Reverse<(u64, u64, usize)>>,
    preferred: Option<BinaryHeap<Reverse<(u64, u64, usize)>>>,
    /// Pops owed to each queue: the one with the lower count goes next.
    turns: [i64; 2],
    best_h: u64,
}

/// Extra turns of the preferred queue after each improvement of the best h.
const PREFERRED_BOOST: i64 = 1000;

impl Frontier {
    fn new(dual: bool) -> Self {
        Frontier {
            all: BinaryHeap::new(),
            preferred: dual.then(BinaryHeap::new),
            turns: [0, 0],
            best_h: u64::MAX,
        }
    }

    fn dual(&self) -> bool {
        self.preferred.is_some()
    }

    fn push(&mut self, key: (u64, u64), id: usize, preferred: bool) {
        self.all.push(Reverse((key.0, key.1, id)));
        if preferred && let Some(q) = &mut self.preferred {
            q.push(Reverse((key.0, key.1, id)));
        }
    }

    /// Records a generated state's h; a new best boosts the preferred queue.
    fn progress(&mut self, h: u64) {
        if h < self.best_h {
            self.best_h = h;
            if self.preferred.is_some() {
                self.turns[1] -= PREFERRED_BOOST;
            }
        }
    }

    fn pop(&mut self) -> Option<usize> {
        if let Some(q) = &mut self.preferred
            && self.turns[1] <= self.turns[0]
            && let Some(Reverse((_, _, id))) = q.pop()
        {
            self.turns[1] += 1;
            return Some(id);
        }
        self.turns[0] += 1;
        match self.all.pop() {
            Some(Reverse((_, _, id))) => Some(id),
            None => self.preferred.as_mut()?.pop().map(|Reverse((_, _, id))| id),
        }
    }
}

/// One way the delete relaxation can reach literals: an action's unconditional effects, or
/// one of its conditional effects (whose condition joins the precondition). Literals are
/// numbered over twice the facts: fact `f` true is `f`, fact `f` false is `n + f`. Negative
/// preconditions thus get achievers (the actions deleting the fact) instead of a fixed cost,
/// so the heuristic sees that a drawer must be closed or a blocker moved first.
struct Unit {
    /// The action it belongs to.
    action: usize,
    /// Which conditional effect, if it is one.
    conditional: Option<usize>,
    /// The precondition as distinct literals, or `None` when it holds a disjunction or a
    /// negated compound (then the general condition is costed).
    pre: Option<Vec<u32>>,
    /// The literals it makes true.
    effects: Vec<u32>,
}

/// The conjunction of literals a condition is, if it is one.
fn literals(c: &Cond, n: u32, out: &mut Vec<u32>) -> bool {
    match c {
        Cond::True => true,
        Cond::Fact(f) => {
            out.push(*f);
            true
        }
        Cond::NotFact(f) => {
            out.push(n + *f);
            true
        }
        Cond::And(cs) => cs.iter().all(|c| literals(c, n, out)),
        Cond::False | Cond::Not(_) | Cond::Or(_) => false,
    }
}

/// Relaxed-reachability costs for h_add, h_max and h_FF, over literals (see [`Unit`]).
///
/// When every precondition is a conjunction of literals (nesy's world domain and most
/// induced ones), costs come from a generalized Dijkstra with a counter per unit: each
/// literal is settled once and each precondition edge visited once. Otherwise the general
/// conditions are costed by sweeping every unit until nothing changes.
struct Relaxed {
    facts: u32,
    units: Vec<Unit>,
    /// Units by precondition literal (flat units only).
    watchers: Vec<Vec<u32>>,
    /// Whether some unit has a general precondition.
    general: bool,
    cost: Vec<u64>,
    supporter: Vec<Option<u32>>,
    /// Per unit: precondition literals not settled yet, and the cost accumulated so far.
    remaining: Vec<u32>,
    accumulated: Vec<u64>,
    /// Literals to settle, bucketed by cost (costs are small integers).
    buckets: Vec<Vec<u32>>,
    /// After an h_FF evaluation: the relaxed plan's actions applicable in the state.
    relaxed_plan: Vec<usize>,
}

const INF: u64 = u64::MAX / 4;

impl Relaxed {
    fn new(task: &Task) -> Self {
        let n = task.facts.atoms.len() as u32;
        let flat = |c: &Cond| {
            let mut out = Vec::new();
            literals(c, n, &mut out).then(|| {
                out.sort_unstable();
                out.dedup();
                out
            })
        };
        let mut units = Vec::new();
        for (ai, a) in task.actions.iter().enumerate() {
            let pre = flat(&a.pre);
            units.push(Unit {
                action: ai,
                conditional: None,
                pre: pre.clone(),
                effects: a
                    .adds
                    .iter()
                    .copied()
                    .chain(a.dels.iter().map(|d| n + d))
                    .collect(),
            });
            for (k, (c, f, add)) in a.conditional.iter().enumerate() {
                let both = match (&pre, flat(c)) {
                    (Some(p), Some(q)) => {
                        let mut l: Vec<u32> = p.iter().chain(&q).copied().collect();
                        l.sort_unstable();
                        l.dedup();
                        Some(l)
                    }
                    _ => None,
                };
                units.push(Unit {
                    action: ai,
                    conditional: Some(k),
                    pre: both,
                    effects: vec![if *add { *f } else { n + f }],
                });
            }
        }
        let mut watchers = vec![Vec::new(); 2 * n as usize];
        for (ui, u) in units.iter().enumerate() {
            for &l in u.pre.iter().flatten() {
                watchers[l as usize].push(ui as u32);
            }
        }
        let general = units.iter().any(|u| u.pre.is_none());
        Relaxed {
            facts: n,
            remaining: vec![0; units.len()],
            accumulated: vec![0; units.len()],
            units,
            watchers,
            general,
            cost: vec![INF; 2 * n as usize],
            supporter: vec![None; 2 * n as usize],
            buckets: Vec::new(),
            relaxed_plan: Vec::new(),
        }
    }

    fn cond_cost(&self, c: &Cond, max: bool) -> u64 {
        match c {
            Cond::True => 0,
            Cond::False => INF,
            Cond::Fact(f) => self.cost[*f as usize],
            Cond::NotFact(f) => self.cost[(self.facts + f) as usize],
            // A negated compound is not relaxed: it costs nothing.
            Cond::Not(_) => 0,
            Cond::And(cs) => {
                let it = cs.iter().map(|c| self.cond_cost(c, max));
                if max {
                    it.max().unwrap_or(0)
                } else {
                    it.fold(0, |a, b| (a + b).min(INF))
                }
            }
            Cond::Or(cs) => cs.iter().map(|c| self.cond_cost(c, max)).min().unwrap_or(INF),
        }
    }

    /// A unit's precondition cost under the current literal costs.
    fn unit_cost(&self, task: &Task, u: &Unit, max: bool) -> u64 {
        let combine = |a: u64, b: u64| if max { a.max(b) } else { (a + b).min(INF) };
        match &u.pre {
            Some(lits) => lits.iter().map(|&l| self.cost[l as usize]).fold(0, combine),
            None => {
                let action = &task.actions[u.action];
                let pre = self.cond_cost(&action.pre, max);
                match u.conditional {
                    Some(k) => combine(pre, self.cond_cost(&action.conditional[k].0, max)),
                    None => pre,
                }
            }
        }
    }

    /// The literals a condition needs in the relaxed plan (a disjunction: its cheapest part).
    fn needed(&self, c: &Cond, out: &mut Vec<u32>) {
        match c {
            Cond::Fact(f) => out.push(*f),
            Cond::NotFact(f) => out.push(self.facts + f),
            Cond::And(cs) => cs.iter().for_each(|c| self.needed(c, out)),
            Cond::Or(cs) => {
                if let Some(best) = cs.iter().min_by_key(|c| self.cond_cost(c, false)) {
                    self.needed(best, out);
                }
            }
            _ => {}
        }
    }

    /// Offers a unit's effects at precondition cost `c`; returns whether a literal got
    /// cheaper.
    fn reach(&mut self, ui: usize, c: u64) -> bool {
        if c >= INF {
            return false;
        }
        let mut improved = false;
        for &l in &self.units[ui].effects {
            if c + 1 < self.cost[l as usize] {
                self.cost[l as usize] = c + 1;
                self.supporter[l as usize] = Some(ui as u32);
                improved = true;
                // Only literals some precondition waits for need settling.
                if !self.watchers[l as usize].is_empty() {
                    let b = (c + 1) as usize;
                    if self.buckets.len() <= b {
                        self.buckets.resize_with(b + 1, Vec::new);
                    }
                    self.buckets[b].push(l);
                }
            }
        }
        improved
    }

    /// Settles the literal costs from the state's literals (all at cost 0).
    fn explore(&mut self, task: &Task, s: &Bits, max: bool) {
        let n = self.facts as usize;
        self.buckets.iter_mut().for_each(Vec::clear);
        if self.buckets.is_empty() {
            self.buckets.push(Vec::new());
        }
        for i in 0..n {
            let holds = get(s, i as u32);
            let (t, f) = if holds { (i, n + i) } else { (n + i, i) };
            self.cost[t] = 0;
            self.cost[f] = INF;
            self.supporter[t] = None;
            self.supporter[f] = None;
            if !self.watchers[t].is_empty() {
                self.buckets[0].push(t as u32);
            }
        }
        for (ui, u) in self.units.iter().enumerate() {
            self.remaining[ui] = u.pre.as_ref().map_or(u32::MAX, |p| p.len() as u32);
            self.accumulated[ui] = 0;
        }
        for ui in 0..self.units.len() {
            if self.remaining[ui] == 0 {
                self.reach(ui, 0);
            }
        }
        loop {
            // Each bucket in the order its literals arrived.
            let (mut b, mut next) = (0, 0);
            while b < self.buckets.len() {
                let Some(&l) = self.buckets[b].get(next) else {
                    b += 1;
                    next = 0;
                    continue;
                };
                next += 1;
                let c = b as u64;
                if c > self.cost[l as usize] {
                    continue;
                }
                for wi in 0..self.watchers[l as usize].len() {
                    let ui = self.watchers[l as usize][wi] as usize;
                    self.remaining[ui] -= 1;
                    self.accumulated[ui] = if max {
                        self.accumulated[ui].max(c)
                    } else {
                        self.accumulated[ui] + c
                    };
                    if self.remaining[ui] == 0 {
                        self.reach(ui, self.accumulated[ui]);
                    }
                }
            }
            if !self.general {
                return;
            }
            // General preconditions: sweep every unit until no literal gets cheaper (the
            // buckets' entries are stale for the counters, which the sweep replaces).
            let mut changed = false;
            for ui in 0..self.units.len() {
                let c = self.unit_cost(task, &self.units[ui], max);
                changed |= self.reach(ui, c);
            }
            self.buckets.iter_mut().for_each(Vec::clear);
            if !changed {
                return;
            }
        }
    }

    fn eval(&mut self, task: &Task, s: &Bits, goal: &Cond, h: Heuristic) -> Option<u64> {
        self.relaxed_plan.clear();
        if h == Heuristic::Blind {
            return Some(0);
        }
        let max = h == Heuristic::HMax;
        self.explore(task, s, max);
        let g = self.cond_cost(goal, max);
        if g >= INF {
            return None;
        }
        if h != Heuristic::HFf {
            return Some(g);
        }
        // Relaxed plan: best supporters of the goal's literals, recursively.
        let mut used: FxHashSet<usize> = FxHashSet::default();
        let mut queue = Vec::new();
        self.needed(goal, &mut queue);
        let mut visited: FxHashSet<u32> = FxHashSet::default();
        let mut seen_units: FxHashSet<u32> = FxHashSet::default();
        while let Some(l) = queue.pop() {
            if !visited.insert(l) {
                continue;
            }
            let Some(ui) = self.supporter[l as usize] else {
                continue;
            };
            if !seen_units.insert(ui) {
                continue;
            }
            let u = &self.units[ui as usize];
            used.insert(u.action);
            match &u.pre {
                Some(lits) => queue.extend(lits.iter().copied()),
                None => {
                    let action = &task.actions[u.action];
                    self.needed(&action.pre, &mut queue);
                    if let Some(k) = u.conditional {
                        self.needed(&action.conditional[k].0, &mut queue);
                    }
                }
            }
        }
        self.relaxed_plan
            .extend(used.iter().copied().filter(|&ai| task.actions[ai].pre.holds(s)));
        self.relaxed_plan.sort_unstable();
        // A goal that needs a step the relaxation cannot name still needs one.
        Some(used.len() as u64 + u64::from(g > 0 && used.is_empty()))
    }
}

/// Plans from `init` to `goal` with `actions` (lifted schemas are grounded over `universe`).
pub fn plan(
    actions: &[Operator],
    universe: &Universe,
    init: &State,
    goal: &Formula,
    config: &PlannerConfig,
) -> Result<Plan, PlanError> {
    let started = Instant::now();
    let limits = GroundingLimits {
        grounding: config.grounding,
        max_actions: config.max_ground_actions,
        deadline: config.time_limit.map(|t| started + t),
    };
    let mut task = Task::ground_within(actions, universe, init, &limits)?;
    // The search gets what grounding left of the limit.
    let config = PlannerConfig {
        time_limit: config.time_limit.map(|t| t.saturating_sub(started.elapsed())),
        ..*config
    };
    task.plan(universe, init, goal, &config)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::verify_procedure_in;
    use crate::pddl::{parse_domain, parse_problem};

    pub(crate) const BW: &str = "(define (domain bw) (:requirements :strips :typing)
     (:types block)
     (:predicates (on ?x ?y - block) (ontable ?x - block) (clear ?x - block) (holding ?x - block) (handempty))
     (:action pick-up :parameters (?x - block) :precondition (and (clear ?x) (ontable ?x) (handempty))
        :effect (and (not (ontable ?x)) (not (clear ?x)) (not (handempty)) (holding ?x)))
     (:action put-down :parameters (?x - block) :precondition (holding ?x)
        :effect (and (not (holding ?x)) (clear ?x) (handempty) (ontable ?x)))
     (:action stack :parameters (?x ?y - block) :precondition (and (holding ?x) (clear ?y) (not (= ?x ?y)))
        :effect (and (not (holding ?x)) (not (clear ?y)) (clear ?x) (handempty) (on ?x ?y)))
     (:action unstack :parameters (?x ?y - block) :precondition (and (on ?x ?y) (clear ?x) (handempty))
        :effect (and (holding ?x) (clear ?y) (not (clear ?x)) (not (handempty)) (not (on ?x ?y)))))";

    #[test]
    fn solves_sussman_and_is_deterministic() {
        let d = parse_domain(BW).unwrap();
        let p = parse_problem(
            "(define (problem s) (:domain bw) (:objects a b c - block)
              (:init (on c a) (ontable a) (ontable b) (clear b) (clear c) (handempty))
              (:goal (and (on a b) (on b c))))",
            &d,
        )
        .unwrap();
        let u = d.universe(&p).unwrap();
        for search in [Search::Gbfs, Search::AStar] {
            for heuristic in [Heuristic::HFf, Heuristic::HAdd, Heuristic::HMax, Heuristic::Blind] {
                let cfg = PlannerConfig {
                    search,
                    heuristic,
                    ..Default::default()
                };
                let plan1 = plan(&d.actions, &u, &p.init, &p.goal, &cfg).unwrap();
                let plan2 = plan(&d.actions, &u, &p.init, &p.goal, &cfg).unwrap();
                assert_eq!(plan1, plan2);
                assert!(verify_procedure_in(&u, &p.init, &plan1.steps, Some(&p.goal)).is_valid());
                if search == Search::AStar && heuristic != Heuristic::HAdd && heuristic != Heuristic::HFf {
                    assert_eq!(plan1.steps.len(), 6, "{search:?} {heuristic:?}");
                }
            }
        }
    }

    #[test]
    fn reports_unsolvable_and_limits() {
        let d = parse_domain(BW).unwrap();
        let p = parse_problem(
            "(define (problem s) (:domain bw) (:objects a b - block)
              (:init (ontable a) (ontable b) (clear a) (clear b))
              (:goal (on a b)))",
            &d,
        )
        .unwrap();
        let u = d.universe(&p).unwrap();
        let cfg = PlannerConfig {
            heuristic: Heuristic::Blind,
            ..Default::default()
        };
        assert!(matches!(
            plan(&d.actions, &u, &p.init, &p.goal, &cfg),
            Err(PlanError::Unsolvable { .. })
        ));
    }

    /// An untyped domain in the style of a model-written one: a 4-parameter move between
    /// linked places, over `n` places and one robot.
    fn untyped_chain(n: usize) -> (crate::pddl::Domain, crate::pddl::Problem) {
        let d = parse_domain(
            "(define (domain chain) (:requirements :strips)
             (:predicates (at ?r ?p) (link ?a ?b) (robot ?r) (free ?p))
             (:action move :parameters (?r ?from ?to ?via)
               :precondition (and (robot ?r) (at ?r ?from) (link ?from ?to) (free ?via))
               :effect (and (at ?r ?to) (not (at ?r ?from)))))",
        )
        .unwrap();
        let places: Vec<String> = (0..n).map(|i| format!("p{i}")).collect();
        let links: String = (1..n).map(|i| format!("(link p{} p{i}) ", i - 1)).collect();
        let p = parse_problem(
            &format!(
                "(define (problem c) (:domain chain) (:objects r {})
                  (:init (robot r) (at r p0) (free p0) {links})
                  (:goal (at r p{})))",
                places.join(" "),
                n - 1
            ),
            &d,
        )
        .unwrap();
        (d, p)
    }

    #[test]
    fn reachable_grounding_keeps_the_plans_and_drops_actions_that_never_apply() {
        let d = parse_domain(BW).unwrap();
        let p = parse_problem(
            "(define (problem s) (:domain bw) (:objects a b c - block)
              (:init (on c a) (ontable a) (ontable b) (clear b) (clear c) (handempty))
              (:goal (and (on a b) (on b c))))",
            &d,
        )
        .unwrap();
        let u = d.universe(&p).unwrap();
        for search in [Search::Gbfs, Search::AStar] {
            for heuristic in [Heuristic::HFf, Heuristic::HMax] {
                let all = PlannerConfig {
                    search,
                    heuristic,
                    ..Default::default()
                };
                let reachable = PlannerConfig {
                    grounding: Grounding::Reachable,
                    ..all
                };
                assert_eq!(
                    plan(&d.actions, &u, &p.init, &p.goal, &all).unwrap(),
                    plan(&d.actions, &u, &p.init, &p.goal, &reachable).unwrap(),
                    "{search:?} {heuristic:?}"
                );
            }
        }
        // Over the untyped chain, every tuple of 31 objects is 923 521 actions; the
        // reachable ones are the moves along links, times the one free place.
        let (d, p) = untyped_chain(30);
        let u = d.universe(&p).unwrap();
        let limits = GroundingLimits {
            grounding: Grounding::Reachable,
            ..Default::default()
        };
        let task = Task::ground_within(&d.actions, &u, &p.init, &limits).unwrap();
        assert_eq!(task.num_actions(), 29);
        let optimal = PlannerConfig {
            search: Search::AStar,
            heuristic: Heuristic::HMax,
            grounding: Grounding::Reachable,
            max_ground_actions: Some(10_000),
            ..Default::default()
        };
        let found = plan(&d.actions, &u, &p.init, &p.goal, &optimal).unwrap();
        assert_eq!(found.steps.len(), 29);
    }

    #[test]
    fn grounding_stops_at_its_cap_and_inside_the_time_limit() {
        let (d, p) = untyped_chain(30);
        let u = d.universe(&p).unwrap();
        let capped = PlannerConfig {
            max_ground_actions: Some(100_000),
            ..Default::default()
        };
        match plan(&d.actions, &u, &p.init, &p.goal, &capped) {
            Err(e @ PlanError::TooManyActions { cap: 100_000, .. }) => {
                assert!(e.to_string().contains("`move`"), "{e}");
            }
            other => panic!("{other:?}"),
        }
        let no_time = PlannerConfig {
            time_limit: Some(Duration::ZERO),
            ..Default::default()
        };
        assert!(matches!(
            plan(&d.actions, &u, &p.init, &p.goal, &no_time),
            Err(PlanError::GroundingTimeLimit { .. })
        ));
    }
}
