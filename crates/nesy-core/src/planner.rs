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
    /// Greedy best-first search on h (fast, plans not necessarily shortest).
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

/// Search settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlannerConfig {
    /// The algorithm.
    pub search: Search,
    /// The heuristic.
    pub heuristic: Heuristic,
    /// Stop after expanding this many states.
    pub max_expansions: usize,
    /// Stop after this much wall-clock time.
    pub time_limit: Option<Duration>,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        PlannerConfig {
            search: Search::Gbfs,
            heuristic: Heuristic::HFf,
            max_expansions: 200_000,
            time_limit: Some(Duration::from_secs(10)),
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
    /// Grounds `actions` (lifted schemas or ground operators) over `universe`. Operators
    /// whose static preconditions (over predicates no action changes) are false in `init`
    /// are pruned.
    pub fn ground(actions: &[Operator], universe: &Universe, init: &State) -> Result<Task, GroundError> {
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
                .collect::<Result<_, _>>()?;
            for args in tuples(&domains) {
                let op = schema.instantiate(&args, universe)?;
                let c = op.compile(universe)?;
                compiled.push((op, c));
            }
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
        let mut open: BinaryHeap<Reverse<(u64, u64, usize)>> = BinaryHeap::new();
        let h0 = heuristic.eval(self, &start, &goal, config.heuristic);
        nodes.push((start.clone(), None, 0));
        seen.insert(start, 0);
        let key = |g: usize, h: u64| match config.search {
            Search::Gbfs => (h, g as u64),
            Search::AStar => (g as u64 + h, h),
        };
        if let Some(h) = h0 {
            open.push(Reverse((key(0, h).0, key(0, h).1, 0)));
        }
        let mut expanded = 0;
        let mut closed: FxHashSet<usize> = FxHashSet::default();
        while let Some(Reverse((_, _, id))) = open.pop() {
            if !closed.insert(id) {
                continue;
            }
            let (state, _, g) = (nodes[id].0.clone(), nodes[id].1, nodes[id].2);
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
                let (k1, k2) = key(ng, h);
                open.push(Reverse((k1, k2, nid)));
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

/// Relaxed-reachability costs for h_add, h_max and h_FF.
struct Relaxed {
    cost: Vec<u64>,
    supporter: Vec<Option<usize>>,
}

const INF: u64 = u64::MAX / 4;

impl Relaxed {
    fn new(task: &Task) -> Self {
        let n = task.facts.atoms.len();
        Relaxed {
            cost: vec![INF; n],
            supporter: vec![None; n],
        }
    }

    fn cond_cost(&self, c: &Cond, s: &Bits, max: bool) -> u64 {
        match c {
            Cond::True => 0,
            Cond::False => INF,
            Cond::Fact(f) => self.cost[*f as usize],
            Cond::NotFact(f) => u64::from(get(s, *f)),
            Cond::Not(_) => 0,
            Cond::And(cs) => {
                let it = cs.iter().map(|c| self.cond_cost(c, s, max));
                if max {
                    it.max().unwrap_or(0)
                } else {
                    it.fold(0, |a, b| (a + b).min(INF))
                }
            }
            Cond::Or(cs) => cs.iter().map(|c| self.cond_cost(c, s, max)).min().unwrap_or(INF),
        }
    }

    fn needed(&self, c: &Cond, s: &Bits, out: &mut Vec<u32>) {
        match c {
            Cond::Fact(f) => out.push(*f),
            Cond::And(cs) => cs.iter().for_each(|c| self.needed(c, s, out)),
            Cond::Or(cs) => {
                if let Some(best) = cs.iter().min_by_key(|c| self.cond_cost(c, s, false)) {
                    self.needed(best, s, out);
                }
            }
            _ => {}
        }
    }

    fn eval(&mut self, task: &Task, s: &Bits, goal: &Cond, h: Heuristic) -> Option<u64> {
        if h == Heuristic::Blind {
            return Some(0);
        }
        let max = h == Heuristic::HMax;
        for (i, c) in self.cost.iter_mut().enumerate() {
            *c = if get(s, i as u32) { 0 } else { INF };
        }
        self.supporter.iter_mut().for_each(|x| *x = None);
        loop {
            let mut changed = false;
            for (ai, a) in task.actions.iter().enumerate() {
                let c = self.cond_cost(&a.pre, s, max);
                if c >= INF {
                    continue;
                }
                let effects = a
                    .adds
                    .iter()
                    .copied()
                    .chain(a.conditional.iter().filter(|e| e.2).map(|e| e.1));
                for f in effects {
                    if c + 1 < self.cost[f as usize] {
                        self.cost[f as usize] = c + 1;
                        self.supporter[f as usize] = Some(ai);
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        let g = self.cond_cost(goal, s, max);
        if g >= INF {
            return None;
        }
        if h != Heuristic::HFf {
            return Some(g);
        }
        // Relaxed plan: best supporters of the goal's atoms, recursively.
        let mut used: FxHashSet<usize> = FxHashSet::default();
        let mut queue = Vec::new();
        self.needed(goal, s, &mut queue);
        let mut visited: FxHashSet<u32> = FxHashSet::default();
        while let Some(f) = queue.pop() {
            if !visited.insert(f) {
                continue;
            }
            if let Some(ai) = self.supporter[f as usize]
                && used.insert(ai)
            {
                self.needed(&task.actions[ai].pre, s, &mut queue);
            }
        }
        // Negative goal literals that hold now each need at least one step.
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
    let mut task = Task::ground(actions, universe, init)?;
    task.plan(universe, init, goal, config)
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
}
