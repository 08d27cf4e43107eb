//! Goal checks (`docs/benchmark.md` §2–§3, §7): which subtasks an episode achieved, in what order.
//!
//! A [`GoalChecker`] holds one [`SubtaskChecker`] per scene goal. Every
//! [`CHECK_INTERVAL`] control steps it looks at the world through a [`GoalView`]:
//! objects that satisfy their subtask's condition are latched (they stay satisfied even if
//! they leave later); once all of a subtask's objects are latched, an articulated subtask
//! also needs its lid or drawer closed at a later check instant, and then the subtask is
//! decided: `full_success` when the objects were latched in label order, `partial_success`
//! otherwise (sweep has no partial: it is always full once every piece is in). With the
//! final call, undecided subtasks become `fail`.
//!
//! [`GoalMonitor`] runs a checker as a [`SimHook`]; [`GoalMonitor::finish`] runs `docs/benchmark.md` §7's
//! post-run settle (100 steps; if anything is still undecided, the final call and 100 more)
//! and returns an [`EpisodeOutcome`].
//!
//! The latch is the authors' metric (`docs/benchmark.md` §10.9) and SR/GC keep it. Beyond it, the outcome
//! lists the latched objects that are out of place when the episode ends
//! ([`EpisodeOutcome::displaced`]): a demonstration is adapted towards its final state, so
//! a demonstration whose arm knocked a counted object out again does not show its goal
//! ([`EpisodeOutcome::demonstrates_goal`]).

use std::sync::{Arc, Mutex, MutexGuard};

pub(crate) use nesy_core::metrics::SubtaskResult;
use nesy_core::metrics::{EpisodeResult, Scoring, achieved_in_time_order};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::scene::parts::LID_CLOSED;
use crate::scene::{SubtaskGoal, SubtaskKind};
use crate::world::geometry::Aabb;
use crate::world::{Sim, SimHook};

/// Control steps between goal checks (the authors' `STATE_CHECK_INTERVAL`).
pub const CHECK_INTERVAL: u64 = 30;
/// Control steps of each post-run settle phase (`docs/benchmark.md` §7): every episode, with
/// or without goal checks, settles this long after the policy before it is judged.
pub const POST_RUN_SETTLE_STEPS: u32 = 100;
/// Largest speed (m/s) at which a placed object counts (pick_place, put_in_hinge).
pub const REST_SPEED: f64 = 0.02;
/// Lid closed: |q − (−0.785)| below this (rad).
pub const HINGE_CLOSED_TOLERANCE: f64 = 0.2;
/// Drawer closed: q below this (m).
pub const DRAWER_CLOSED_BELOW: f64 = 0.04;

/// What the goal checks need to know about the world.
pub trait GoalView {
    /// World AABB of an object or part.
    fn aabb(&self, name: &str) -> Option<Aabb>;
    /// Linear speed (m/s).
    fn speed(&self, name: &str) -> Option<f64>;
    /// True if the robot holds the object: welded to it, or in the grasp region with the
    /// gripper closed (the authors' `obj_in_gripper and not gripper_open`).
    fn held(&self, name: &str) -> bool;
    /// Joint position of `hinge_lid`, `top_drawer` or `bottom_drawer`.
    fn joint(&self, name: &str) -> Option<f64>;
}

impl GoalView for Sim {
    fn aabb(&self, name: &str) -> Option<Aabb> {
        self.object_aabb(name)
    }

    fn speed(&self, name: &str) -> Option<f64> {
        self.object_velocity(name)
            .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())
    }

    fn held(&self, name: &str) -> bool {
        self.held_object() == Some(name)
            || (self.is_closed() && self.part_index(name).is_some_and(|i| self.part_in_gripper(i)))
    }

    fn joint(&self, name: &str) -> Option<f64> {
        self.articulation_q(name)
    }
}

/// One entry of an achieved sequence.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct Achievement {
    /// Object name, or `hinge` / `bottom_drawer` for a closure.
    pub name: String,
    /// Control step of the check that saw it.
    pub step: u64,
}

/// The outcome of one subtask.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SubtaskOutcome {
    /// The subtask type.
    pub subtask: SubtaskKind,
    /// The verdict.
    pub result: SubtaskResult,
    /// Control step of the check that decided it.
    pub decided_at_step: u64,
    /// Its goal label.
    pub label: Vec<String>,
    /// What it achieved, in time order (also for a failed subtask: the objects it did
    /// place).
    pub achieved: Vec<Achievement>,
    /// Its objects that were counted (latched) but are out of place when the outcome was
    /// taken, in label order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub displaced: Vec<String>,
}

impl SubtaskOutcome {
    /// The verdict under `scoring` (strict: a displaced object fails the subtask).
    pub fn verdict(&self, scoring: Scoring) -> SubtaskResult {
        scoring.verdict(self.result, !self.displaced.is_empty())
    }
}

/// The outcome of an episode.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct EpisodeOutcome {
    /// One entry per scene goal, in scene (config) order.
    pub subtasks: Vec<SubtaskOutcome>,
    /// Indices into `subtasks` in the order they were decided (the authors' result list).
    pub decision_order: Vec<usize>,
    /// The goal label: the subtask labels concatenated in config order.
    pub goal_label: Vec<String>,
    /// Everything achieved, all subtasks merged in time order (ties: config order, then
    /// label order), without the `…_check` markers.
    pub achieved_sequence: Vec<String>,
    /// True if the final call was needed (something was undecided after the first settle).
    pub final_call: bool,
    /// Control step at which the episode ended.
    pub end_step: u64,
    /// Objects that were counted as placed (latched) but no longer meet their subtask's
    /// placement condition when the outcome was taken, in config then label order. The
    /// verdicts above do not look at it (the authors' latch); a recorded demonstration does.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub displaced: Vec<String>,
}

impl EpisodeOutcome {
    /// The episode as the metrics score it under `scoring`: verdicts, goal label and
    /// achieved sequence.
    pub fn episode_result(&self, scoring: Scoring) -> EpisodeResult {
        EpisodeResult {
            subtasks: self.subtasks.iter().map(|s| s.verdict(scoring)).collect(),
            label: self.goal_label.clone(),
            achieved: self.achieved_sequence.clone(),
        }
    }

    /// SR with the authors' latch (`docs/benchmark.md` §7): every subtask full or partial.
    pub fn success(&self) -> bool {
        self.episode_result(Scoring::Latched).success() == 1.0
    }

    /// Every subtask `full_success`.
    pub fn full_success(&self) -> bool {
        !self.subtasks.is_empty()
            && self
                .subtasks
                .iter()
                .all(|s| s.result == SubtaskResult::FullSuccess)
    }

    /// GC with the authors' latch (`docs/benchmark.md` §7): the fraction of successful
    /// subtasks.
    pub fn goal_condition(&self) -> f64 {
        self.episode_result(Scoring::Latched).goal_condition()
    }

    /// Every subtask `full_success` and every counted object still in place at the end: the
    /// episode's final state shows its goal, which is what a demonstration must do (its
    /// final state becomes the goal of adaptation).
    pub fn demonstrates_goal(&self) -> bool {
        self.full_success() && self.displaced.is_empty()
    }

    /// One line per subtask, e.g. `pick_place: full_success`.
    pub fn summary(&self) -> String {
        self.subtasks
            .iter()
            .map(|s| format!("{}: {}", s.subtask, s.result))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Why a goal monitor could not be set up.
#[derive(Debug, thiserror::Error)]
pub enum GoalError {
    /// The scene has no goals to check.
    #[error("the scene has no goals to check")]
    NoGoals,
    /// A goal names something the world does not have.
    #[error("goals[{goal}] refers to {name:?}, which is not in the world")]
    UnknownObject {
        /// Index of the goal.
        goal: usize,
        /// The missing name.
        name: String,
    },
}

/// Articulation progress of a subtask.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Closure {
    /// Not articulated, or objects not all latched yet.
    NotChecked,
    /// All objects latched but the container was open at a check (the authors'
    /// `…_check` marker).
    Pending,
    /// Closed at this step.
    Closed(u64),
}

/// The goal check of one subtask.
#[derive(Clone, Debug)]
pub struct SubtaskChecker {
    goal: SubtaskGoal,
    /// Latch step per object (label order).
    latched: Vec<Option<u64>>,
    closure: Closure,
    decided: Option<(SubtaskResult, u64)>,
}

impl SubtaskChecker {
    /// A checker for one goal.
    pub fn new(goal: SubtaskGoal) -> SubtaskChecker {
        let n = goal.objects().len();
        SubtaskChecker {
            goal,
            latched: vec![None; n],
            closure: Closure::NotChecked,
            decided: None,
        }
    }

    /// The goal.
    pub fn goal(&self) -> &SubtaskGoal {
        &self.goal
    }

    /// The verdict so far.
    pub fn decided(&self) -> Option<(SubtaskResult, u64)> {
        self.decided
    }

    /// Does `object` (index `i` in label order) satisfy the subtask's placement condition?
    fn placed(&self, view: &dyn GoalView, i: usize) -> bool {
        let object = self.goal.objects()[i];
        let (Some(aabb), false) = (view.aabb(object), view.held(object)) else {
            return false;
        };
        let at_rest = || view.speed(object).is_some_and(|s| s <= REST_SPEED);
        match &self.goal {
            SubtaskGoal::PickPlace { container, .. } => view.aabb(container).is_some_and(|c| {
                c.padded([-0.02, -0.02, -0.01], [0.02, 0.02, 0.25])
                    .contains_box(&aabb)
                    && at_rest()
            }),
            SubtaskGoal::Sweep { placements } => view.aabb(&placements[i].container).is_some_and(|c| {
                let region = Aabb {
                    min: [c.min[0], c.min[1], c.min[2] - 0.15],
                    max: [c.max[0], c.max[1], c.min[2] + 0.04 + 0.1],
                };
                region.contains_box(&aabb)
            }),
            SubtaskGoal::PutInHinge { container, .. } => view.aabb(container).is_some_and(|c| {
                c.padded([-0.02, -0.02, -0.02], [0.02, 0.02, 0.05])
                    .contains_box(&aabb)
                    && at_rest()
            }),
            SubtaskGoal::PutInPrismatic { drawer, .. } => {
                view.aabb(drawer).is_some_and(|c| c.contains_box(&aabb))
            }
        }
    }

    /// Is the articulated container closed (always true for the others)?
    fn container_closed(&self, view: &dyn GoalView) -> bool {
        match &self.goal {
            SubtaskGoal::PutInHinge { lid, .. } => view
                .joint(lid)
                .is_some_and(|q| (q - LID_CLOSED).abs() < HINGE_CLOSED_TOLERANCE),
            SubtaskGoal::PutInPrismatic { drawer, .. } => {
                view.joint(drawer).is_some_and(|q| q.abs() < DRAWER_CLOSED_BELOW)
            }
            _ => true,
        }
    }

    /// One check at `step`. With `final_call`, an undecided subtask becomes `fail`.
    pub fn check(&mut self, view: &dyn GoalView, step: u64, final_call: bool) {
        if self.decided.is_some() {
            return;
        }
        for i in 0..self.latched.len() {
            if self.latched[i].is_none() && self.placed(view, i) {
                self.latched[i] = Some(step);
            }
        }
        if self.latched.iter().all(Option::is_some) {
            let closed = match self.goal.closure_label() {
                None => true,
                Some(_) => {
                    if self.container_closed(view) {
                        self.closure = Closure::Closed(step);
                        true
                    } else {
                        self.closure = Closure::Pending;
                        false
                    }
                }
            };
            if closed {
                let in_order = matches!(self.goal, SubtaskGoal::Sweep { .. })
                    || self.latch_order().iter().enumerate().all(|(k, &i)| k == i);
                let result = if in_order {
                    SubtaskResult::FullSuccess
                } else {
                    SubtaskResult::PartialSuccess
                };
                self.decided = Some((result, step));
                return;
            }
        }
        if final_call {
            self.decided = Some((SubtaskResult::Fail, step));
        }
    }

    /// Object indices sorted by latch step (ties in label order), latched ones only.
    fn latch_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.latched.len())
            .filter(|&i| self.latched[i].is_some())
            .collect();
        order.sort_by_key(|&i| (self.latched[i], i));
        order
    }

    /// What this subtask achieved so far, in time order; the pending `…_check` marker is
    /// left out, as in the authors' achieved sequence.
    pub fn achieved(&self) -> Vec<Achievement> {
        let objects = self.goal.objects();
        let mut out: Vec<Achievement> = self
            .latch_order()
            .into_iter()
            .map(|i| Achievement {
                name: objects[i].to_owned(),
                step: self.latched[i].unwrap_or_default(),
            })
            .collect();
        if let (Closure::Closed(step), Some(name)) = (self.closure, self.goal.closure_label()) {
            out.push(Achievement {
                name: name.to_owned(),
                step,
            });
        }
        out
    }

    /// True while the container is open after all objects were latched.
    pub fn closure_pending(&self) -> bool {
        self.closure == Closure::Pending
    }

    /// The latched objects that do not meet the placement condition in `view` now (label
    /// order).
    pub fn displaced(&self, view: &dyn GoalView) -> Vec<String> {
        (0..self.latched.len())
            .filter(|&i| self.latched[i].is_some() && !self.placed(view, i))
            .map(|i| self.goal.objects()[i].to_owned())
            .collect()
    }
}

/// The goal checks of a whole scene.
#[derive(Clone, Debug)]
pub struct GoalChecker {
    subtasks: Vec<SubtaskChecker>,
    decision_order: Vec<usize>,
    final_call: bool,
    last_step: u64,
}

impl GoalChecker {
    /// Checks for these goals (config order).
    pub fn new(goals: &[SubtaskGoal]) -> GoalChecker {
        GoalChecker {
            subtasks: goals.iter().cloned().map(SubtaskChecker::new).collect(),
            decision_order: Vec::new(),
            final_call: false,
            last_step: 0,
        }
    }

    /// The per-subtask checkers.
    pub fn subtasks(&self) -> &[SubtaskChecker] {
        &self.subtasks
    }

    /// From now on, checks are final: undecided subtasks become `fail`.
    pub fn set_final_call(&mut self) {
        self.final_call = true;
    }

    /// True once every subtask is decided.
    pub fn all_decided(&self) -> bool {
        self.subtasks.iter().all(|s| s.decided.is_some())
    }

    /// One check of every undecided subtask at `step`.
    pub fn check(&mut self, view: &dyn GoalView, step: u64) {
        self.last_step = step;
        for (i, s) in self.subtasks.iter_mut().enumerate() {
            let before = s.decided.is_some();
            s.check(view, step, self.final_call);
            if !before && s.decided.is_some() {
                self.decision_order.push(i);
            }
        }
    }

    /// The outcome so far (undecided subtasks are reported as `fail` at the last check;
    /// use [`GoalMonitor::finish`] for the real end of an episode), without
    /// [`EpisodeOutcome::displaced`] (it needs the world: [`GoalChecker::outcome_in`]).
    pub fn outcome(&self, end_step: u64) -> EpisodeOutcome {
        let mut decision_order = self.decision_order.clone();
        let subtasks: Vec<SubtaskOutcome> = self
            .subtasks
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let (result, decided_at_step) = s.decided.unwrap_or_else(|| {
                    decision_order.push(i);
                    (SubtaskResult::Fail, self.last_step)
                });
                SubtaskOutcome {
                    subtask: s.goal.kind(),
                    result,
                    decided_at_step,
                    label: s.goal.label(),
                    achieved: s.achieved(),
                    displaced: Vec::new(),
                }
            })
            .collect();
        let achieved_sequence = achieved_in_time_order(
            subtasks
                .iter()
                .map(|s| s.achieved.iter().map(|a| (a.name.as_str(), a.step))),
        );
        EpisodeOutcome {
            goal_label: subtasks.iter().flat_map(|s| s.label.clone()).collect(),
            subtasks,
            decision_order,
            achieved_sequence,
            final_call: self.final_call,
            end_step,
            displaced: Vec::new(),
        }
    }

    /// [`GoalChecker::outcome`] with [`EpisodeOutcome::displaced`] filled from `view`.
    pub fn outcome_in(&self, view: &dyn GoalView, end_step: u64) -> EpisodeOutcome {
        let mut outcome = self.outcome(end_step);
        for (o, s) in outcome.subtasks.iter_mut().zip(&self.subtasks) {
            o.displaced = s.displaced(view);
        }
        outcome.displaced = outcome
            .subtasks
            .iter()
            .flat_map(|s| s.displaced.clone())
            .collect();
        outcome
    }
}

/// The goal checker as a simulator hook: checks every [`CHECK_INTERVAL`] control steps.
/// Cloning gives another handle to the same checker.
#[derive(Clone)]
pub struct GoalMonitor {
    checker: Arc<Mutex<GoalChecker>>,
}

/// The hook half of a [`GoalMonitor`] (what the simulator holds).
struct GoalHook {
    checker: Arc<Mutex<GoalChecker>>,
}

impl SimHook for GoalHook {
    fn step_interval(&self) -> Option<u64> {
        Some(CHECK_INTERVAL)
    }

    fn on_step(&mut self, sim: &Sim) {
        lock(&self.checker).check(sim, sim.step_count());
    }
}

fn lock(m: &Mutex<GoalChecker>) -> MutexGuard<'_, GoalChecker> {
    // A panic inside a check cannot leave the checker half-updated in a way that matters
    // more than losing the episode, so a poisoned lock is still read.
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl GoalMonitor {
    /// Attaches goal checks for the scene's goals to `sim` (call before the policy runs).
    pub fn attach(sim: &mut Sim) -> Result<GoalMonitor, GoalError> {
        let goals = sim.scene().goals.clone();
        if goals.is_empty() {
            return Err(GoalError::NoGoals);
        }
        for (g, goal) in goals.iter().enumerate() {
            for (_, name) in goal.referenced_names() {
                if sim.object_aabb(name).is_none() {
                    return Err(GoalError::UnknownObject {
                        goal: g,
                        name: name.to_owned(),
                    });
                }
            }
        }
        let checker = Arc::new(Mutex::new(GoalChecker::new(&goals)));
        sim.add_hook(Box::new(GoalHook {
            checker: checker.clone(),
        }));
        Ok(GoalMonitor { checker })
    }

    /// The outcome so far, without stepping (undecided subtasks shown as `fail`).
    pub fn peek(&self, sim: &Sim) -> EpisodeOutcome {
        lock(&self.checker).outcome_in(sim, sim.step_count())
    }

    /// Ends the episode (`docs/benchmark.md` §7): the world settles for 100 control steps with the robot
    /// still; if some subtask is still undecided, the next checks are final and the world
    /// settles for 100 more. Returns the outcome, with the latched objects that are out of
    /// place after the settle in [`EpisodeOutcome::displaced`].
    pub fn finish(&self, sim: &mut Sim) -> EpisodeOutcome {
        sim.step_idle(POST_RUN_SETTLE_STEPS);
        if !lock(&self.checker).all_decided() {
            lock(&self.checker).set_final_call();
            sim.step_idle(POST_RUN_SETTLE_STEPS);
            // 100 steps always include a check instant; this only guards a checker that was
            // detached meanwhile.
            let mut checker = lock(&self.checker);
            if !checker.all_decided() {
                checker.check(sim, sim.step_count());
            }
        }
        lock(&self.checker).outcome_in(sim, sim.step_count())
    }
}

/// Finishes the episode of a simulator whose goal monitor was attached with
/// [`GoalMonitor::attach`] (found among its hooks); `None` if none is attached.
pub fn finish_episode(sim: &mut Sim) -> Option<EpisodeOutcome> {
    let checker = sim.hook::<GoalHook>()?.checker.clone();
    Some(GoalMonitor { checker }.finish(sim))
}

/// Hand-made world geometry for testing goal checks.
#[derive(Clone, Debug, Default)]
pub struct GoalSnapshot {
    /// AABB per name.
    pub aabbs: std::collections::HashMap<String, Aabb>,
    /// Speed per name (missing = at rest).
    pub speeds: std::collections::HashMap<String, f64>,
    /// Held objects.
    pub held: Vec<String>,
    /// Joint positions.
    pub joints: std::collections::HashMap<String, f64>,
}

impl GoalView for GoalSnapshot {
    fn aabb(&self, name: &str) -> Option<Aabb> {
        self.aabbs.get(name).copied()
    }

    fn speed(&self, name: &str) -> Option<f64> {
        Some(self.speeds.get(name).copied().unwrap_or(0.0))
    }

    fn held(&self, name: &str) -> bool {
        self.held.iter().any(|h| h == name)
    }

    fn joint(&self, name: &str) -> Option<f64> {
        self.joints.get(name).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Placement;

    fn cube(centre: [f64; 3], half: f64) -> Aabb {
        Aabb {
            min: centre.map(|c| c - half),
            max: centre.map(|c| c + half),
        }
    }

    /// A toy box at the origin of x/y, table at 0.5, and three cubes beside it.
    fn pick_place_world() -> (SubtaskGoal, GoalSnapshot) {
        let goal = SubtaskGoal::PickPlace {
            objects: vec!["red".into(), "green".into(), "blue".into()],
            container: "box".into(),
        };
        let mut world = GoalSnapshot::default();
        world.aabbs.insert(
            "box".into(),
            Aabb {
                min: [-0.07, -0.05, 0.5],
                max: [0.07, 0.05, 0.545],
            },
        );
        for (i, name) in ["red", "green", "blue"].into_iter().enumerate() {
            world
                .aabbs
                .insert(name.into(), cube([0.3, 0.1 * i as f64, 0.52], 0.02));
        }
        (goal, world)
    }

    fn put_in_box(world: &mut GoalSnapshot, name: &str, dx: f64) {
        world.aabbs.insert(name.into(), cube([dx, 0.0, 0.525], 0.02));
    }

    /// Red, green and blue side by side in the box, in label order.
    fn put_all_in_box(world: &mut GoalSnapshot) {
        for (k, name) in ["red", "green", "blue"].into_iter().enumerate() {
            put_in_box(world, name, -0.04 + 0.04 * k as f64);
        }
    }

    /// The white rook into the left chess box, the black rook into the right one.
    fn rook_sweep_goal() -> SubtaskGoal {
        SubtaskGoal::Sweep {
            placements: vec![
                Placement {
                    object: "white_rook".into(),
                    container: "left_chess_box".into(),
                },
                Placement {
                    object: "black_rook".into(),
                    container: "right_chess_box".into(),
                },
            ],
        }
    }

    /// A chess box centred at `y` on the benchmark's x range.
    fn chess_box(y: f64) -> Aabb {
        Aabb {
            min: [0.27, y - 0.04, 0.5],
            max: [0.43, y + 0.04, 0.5245],
        }
    }

    fn names(achieved: &[Achievement]) -> Vec<&str> {
        achieved.iter().map(|a| a.name.as_str()).collect()
    }

    #[test]
    fn objects_in_label_order_give_full_success() {
        let (goal, mut world) = pick_place_world();
        let mut checker = GoalChecker::new(&[goal]);
        checker.check(&world, 30);
        assert!(!checker.all_decided());
        for (k, name) in ["red", "green", "blue"].into_iter().enumerate() {
            put_in_box(&mut world, name, -0.04 + 0.04 * k as f64);
            checker.check(&world, 60 + 30 * k as u64);
        }
        assert!(checker.all_decided());
        let outcome = checker.outcome(200);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::FullSuccess);
        assert_eq!(outcome.subtasks[0].decided_at_step, 120);
        assert_eq!(outcome.achieved_sequence, ["red", "green", "blue"]);
        assert!(outcome.full_success() && outcome.success());
        assert_eq!(outcome.goal_condition(), 1.0);
    }

    #[test]
    fn another_order_gives_partial_success() {
        let (goal, mut world) = pick_place_world();
        let mut checker = GoalChecker::new(&[goal]);
        for (k, name) in ["green", "red", "blue"].into_iter().enumerate() {
            put_in_box(&mut world, name, -0.04 + 0.04 * k as f64);
            checker.check(&world, 30 * (k as u64 + 1));
        }
        let outcome = checker.outcome(100);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::PartialSuccess);
        assert_eq!(outcome.achieved_sequence, ["green", "red", "blue"]);
        assert!(outcome.success() && !outcome.full_success());
    }

    #[test]
    fn objects_placed_together_count_in_label_order() {
        let (goal, mut world) = pick_place_world();
        let mut checker = GoalChecker::new(&[goal]);
        for (k, name) in ["blue", "green", "red"].into_iter().enumerate() {
            put_in_box(&mut world, name, -0.04 + 0.04 * k as f64);
        }
        checker.check(&world, 30);
        let outcome = checker.outcome(30);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::FullSuccess);
        assert_eq!(outcome.achieved_sequence, ["red", "green", "blue"]);
    }

    #[test]
    fn latched_objects_stay_latched_and_moving_or_held_ones_do_not_count() {
        let (goal, mut world) = pick_place_world();
        let mut checker = GoalChecker::new(&[goal]);
        put_in_box(&mut world, "red", -0.04);
        // Still falling: not placed yet.
        world.speeds.insert("red".into(), 0.3);
        checker.check(&world, 30);
        assert!(checker.subtasks()[0].achieved().is_empty());
        world.speeds.clear();
        // Held by the robot inside the box: not placed either.
        world.held.push("red".into());
        checker.check(&world, 60);
        assert!(checker.subtasks()[0].achieved().is_empty());
        world.held.clear();
        checker.check(&world, 90);
        assert_eq!(names(&checker.subtasks()[0].achieved()), ["red"]);
        // Red leaves the box again: it stays latched.
        world.aabbs.insert("red".into(), cube([0.3, 0.0, 0.52], 0.02));
        put_in_box(&mut world, "green", 0.0);
        put_in_box(&mut world, "blue", 0.04);
        checker.check(&world, 120);
        assert_eq!(
            checker.outcome(120).subtasks[0].result,
            SubtaskResult::FullSuccess
        );
    }

    #[test]
    fn the_final_call_fails_what_is_unfinished() {
        let (goal, mut world) = pick_place_world();
        let mut checker = GoalChecker::new(&[goal]);
        put_in_box(&mut world, "red", -0.04);
        put_in_box(&mut world, "green", 0.0);
        checker.check(&world, 30);
        assert!(!checker.all_decided());
        checker.set_final_call();
        checker.check(&world, 60);
        let outcome = checker.outcome(60);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::Fail);
        assert_eq!(outcome.subtasks[0].decided_at_step, 60);
        // The objects it did place are still reported.
        assert_eq!(outcome.achieved_sequence, ["red", "green"]);
        assert!(outcome.final_call && !outcome.success());
        assert_eq!(outcome.goal_condition(), 0.0);
    }

    fn hinge_world() -> (SubtaskGoal, GoalSnapshot) {
        let goal = SubtaskGoal::PutInHinge {
            objects: vec!["apple".into(), "lemon".into()],
            container: "hinge_body".into(),
            lid: "hinge_lid".into(),
        };
        let mut world = GoalSnapshot::default();
        world.aabbs.insert(
            "hinge_body".into(),
            Aabb {
                min: [0.6, 0.1, 0.5],
                max: [0.7, 0.3, 0.6165],
            },
        );
        world.aabbs.insert("apple".into(), cube([0.5, 0.1, 0.53], 0.03));
        world.aabbs.insert("lemon".into(), cube([0.5, 0.2, 0.53], 0.03));
        world
            .joints
            .insert("hinge_lid".into(), crate::scene::parts::LID_OPEN);
        (goal, world)
    }

    #[test]
    fn the_lid_must_close_after_the_objects() {
        let (goal, mut world) = hinge_world();
        let mut checker = GoalChecker::new(&[goal]);
        // The lid closed before anything is in does not count.
        world.joints.insert("hinge_lid".into(), LID_CLOSED);
        checker.check(&world, 30);
        world
            .joints
            .insert("hinge_lid".into(), crate::scene::parts::LID_OPEN);
        world.aabbs.insert("apple".into(), cube([0.65, 0.15, 0.54], 0.03));
        world.aabbs.insert("lemon".into(), cube([0.65, 0.25, 0.54], 0.03));
        checker.check(&world, 60);
        assert!(checker.subtasks()[0].closure_pending());
        assert!(!checker.all_decided());
        world.joints.insert("hinge_lid".into(), LID_CLOSED + 0.1);
        checker.check(&world, 90);
        let outcome = checker.outcome(90);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::FullSuccess);
        assert_eq!(outcome.achieved_sequence, ["apple", "lemon", "hinge"]);
        assert_eq!(outcome.goal_label, ["apple", "lemon", "hinge"]);
    }

    #[test]
    fn an_open_lid_at_the_end_fails_the_subtask() {
        let (goal, mut world) = hinge_world();
        let mut checker = GoalChecker::new(&[goal]);
        world.aabbs.insert("lemon".into(), cube([0.65, 0.25, 0.54], 0.03));
        checker.check(&world, 30);
        world.aabbs.insert("apple".into(), cube([0.65, 0.15, 0.54], 0.03));
        checker.check(&world, 60);
        checker.set_final_call();
        checker.check(&world, 90);
        let outcome = checker.outcome(90);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::Fail);
        assert_eq!(outcome.achieved_sequence, ["lemon", "apple"]);
    }

    #[test]
    fn a_drawer_closed_after_objects_in_another_order_is_partial() {
        let goal = SubtaskGoal::PutInPrismatic {
            objects: vec!["red_cylinder".into(), "blue_cylinder".into()],
            drawer: "bottom_drawer".into(),
        };
        let mut world = GoalSnapshot::default();
        world.aabbs.insert(
            "bottom_drawer".into(),
            Aabb {
                min: [0.58, -0.2, 0.505],
                max: [0.72, -0.05, 0.59],
            },
        );
        world.joints.insert("bottom_drawer".into(), 0.12);
        world
            .aabbs
            .insert("blue_cylinder".into(), cube([0.62, -0.1, 0.53], 0.015));
        world
            .aabbs
            .insert("red_cylinder".into(), cube([0.3, 0.0, 0.515], 0.015));
        let mut checker = GoalChecker::new(&[goal]);
        checker.check(&world, 30);
        world
            .aabbs
            .insert("red_cylinder".into(), cube([0.68, -0.1, 0.53], 0.015));
        checker.check(&world, 60);
        world.joints.insert("bottom_drawer".into(), 0.0);
        checker.check(&world, 90);
        let outcome = checker.outcome(90);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::PartialSuccess);
        assert_eq!(
            outcome.achieved_sequence,
            ["blue_cylinder", "red_cylinder", "bottom_drawer"]
        );
    }

    #[test]
    fn sweep_is_full_success_in_any_order() {
        let goal = rook_sweep_goal();
        let mut world = GoalSnapshot::default();
        world.aabbs.insert("left_chess_box".into(), chess_box(-0.09));
        world.aabbs.insert("right_chess_box".into(), chess_box(0.09));
        world
            .aabbs
            .insert("white_rook".into(), cube([0.3, 0.0, 0.53], 0.015));
        world
            .aabbs
            .insert("black_rook".into(), cube([0.35, 0.09, 0.52], 0.015));
        let mut checker = GoalChecker::new(&[goal]);
        checker.check(&world, 30);
        // A piece in the other colour's box does not count.
        world
            .aabbs
            .insert("white_rook".into(), cube([0.3, 0.09, 0.52], 0.015));
        checker.check(&world, 60);
        assert!(!checker.all_decided());
        world
            .aabbs
            .insert("white_rook".into(), cube([0.3, -0.09, 0.52], 0.015));
        checker.check(&world, 90);
        let outcome = checker.outcome(90);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::FullSuccess);
        assert_eq!(outcome.achieved_sequence, ["black_rook", "white_rook"]);
    }

    /// The grip_high_00_s0 demonstration: the sweep latched the black rook in its box, then
    /// the lifting finger carried it out and dropped it on the table.
    #[test]
    fn a_latched_object_knocked_out_again_is_displaced_but_still_counts() {
        let goal = rook_sweep_goal();
        let mut world = GoalSnapshot::default();
        world.aabbs.insert("left_chess_box".into(), chess_box(-0.287));
        world.aabbs.insert("right_chess_box".into(), chess_box(-0.113));
        world
            .aabbs
            .insert("white_rook".into(), cube([0.31, -0.275, 0.53], 0.015));
        // Measured in the replay: in the box at the check after the push ...
        world.aabbs.insert(
            "black_rook".into(),
            Aabb {
                min: [0.391, -0.142, 0.504],
                max: [0.420, -0.109, 0.558],
            },
        );
        let mut checker = GoalChecker::new(&[goal]);
        checker.check(&world, 3750);
        assert!(checker.all_decided());
        assert!(checker.outcome_in(&world, 3750).demonstrates_goal());
        // ... and lying on the table at the end.
        world.aabbs.insert(
            "black_rook".into(),
            Aabb {
                min: [0.541, -0.003, 0.500],
                max: [0.591, 0.054, 0.529],
            },
        );
        let outcome = checker.outcome_in(&world, 9000);
        assert_eq!(outcome.subtasks[0].result, SubtaskResult::FullSuccess);
        assert!(outcome.full_success() && outcome.success());
        assert_eq!(outcome.displaced, ["black_rook"]);
        assert!(!outcome.demonstrates_goal());
        // Without the world there is nothing to compare with.
        assert!(checker.outcome(9000).displaced.is_empty());
    }

    #[test]
    fn a_latched_object_held_at_the_end_is_displaced() {
        let (goal, mut world) = pick_place_world();
        let mut checker = GoalChecker::new(&[goal]);
        put_all_in_box(&mut world);
        checker.check(&world, 30);
        world.held.push("green".into());
        let outcome = checker.outcome_in(&world, 60);
        assert!(outcome.full_success());
        assert_eq!(outcome.displaced, ["green"]);
        world.held.clear();
        assert!(checker.outcome_in(&world, 90).demonstrates_goal());
    }

    #[test]
    fn displaced_is_left_out_of_the_json_when_empty_and_read_back() {
        let (goal, mut world) = pick_place_world();
        let mut checker = GoalChecker::new(&[goal]);
        put_all_in_box(&mut world);
        checker.check(&world, 30);
        let clean = checker.outcome_in(&world, 30);
        let text = serde_json::to_string(&clean).unwrap();
        assert!(!text.contains("displaced"), "{text}");
        assert_eq!(serde_json::from_str::<EpisodeOutcome>(&text).unwrap(), clean);
        world.aabbs.insert("red".into(), cube([0.3, 0.0, 0.52], 0.02));
        let knocked = checker.outcome_in(&world, 60);
        let text = serde_json::to_string(&knocked).unwrap();
        assert!(text.contains(r#""displaced":["red"]"#), "{text}");
        assert_eq!(serde_json::from_str::<EpisodeOutcome>(&text).unwrap(), knocked);
    }

    #[test]
    fn a_composite_merges_achievements_in_time_order_and_records_decisions() {
        let (pick, mut world) = pick_place_world();
        let (hinge, hinge_world) = hinge_world();
        world.aabbs.extend(hinge_world.aabbs);
        world.joints.extend(hinge_world.joints);
        let mut checker = GoalChecker::new(&[pick, hinge]);
        world.aabbs.insert("apple".into(), cube([0.65, 0.15, 0.54], 0.03));
        checker.check(&world, 30);
        put_in_box(&mut world, "red", -0.04);
        world.aabbs.insert("lemon".into(), cube([0.65, 0.25, 0.54], 0.03));
        checker.check(&world, 60);
        world.joints.insert("hinge_lid".into(), LID_CLOSED);
        put_in_box(&mut world, "green", 0.0);
        checker.check(&world, 90);
        put_in_box(&mut world, "blue", 0.04);
        checker.check(&world, 120);
        let outcome = checker.outcome(120);
        assert!(outcome.full_success());
        assert_eq!(
            outcome.achieved_sequence,
            ["apple", "red", "lemon", "green", "hinge", "blue"]
        );
        assert_eq!(outcome.decision_order, [1, 0]);
        assert_eq!(
            outcome.goal_label,
            ["red", "green", "blue", "apple", "lemon", "hinge"]
        );
        assert_eq!(
            outcome.summary(),
            "pick_place: full_success, put_in_hinge: full_success"
        );
    }
}
