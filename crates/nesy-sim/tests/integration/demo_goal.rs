//! A demonstration's final state against its goal checks, on the scene where they
//! disagreed: the source side of `grip_high_00_s0` (all four subtasks, finger gripper).
//!
//! The expert pushes the black rook into its box and the sweep check latches it there. When
//! Rapier still recycled contacts, the rising finger kept a stale contact with the rook and
//! lifted it out onto the table: the goal checks kept the latch (the authors' metric), so the
//! expert reported `full_success`, while the final state, the goal `nesy adapt` derives from
//! a demonstration, had `(OnTopOf black_rook floor)`. [`EpisodeOutcome::displaced`] names
//! such objects.

use nesy_core::Atom;
use nesy_sim::perception::observer::observe;
use nesy_sim::scene::SubtaskGoal;
use nesy_sim::tasks::goal::{EpisodeOutcome, GoalMonitor};
use nesy_sim::tasks::scenario::{self, Side};
use nesy_sim::world::Sim;

/// Runs the expert on the source scene of `id`; returns the outcome and the final state.
fn demonstrate(id: &str) -> (Vec<SubtaskGoal>, EpisodeOutcome, nesy_core::State) {
    let scenario = scenario::scenarios(&scenario::generate_suite())
        .into_iter()
        .find(|s| s.id == id)
        .unwrap_or_else(|| panic!("no scenario {id}"));
    let scene = scenario.generate(Side::Source).unwrap().scene;
    let mut sim = Sim::new(&scene).unwrap();
    let monitor = GoalMonitor::attach(&mut sim).unwrap();
    nesy_sim::tasks::experts::run(&mut sim, &scene).unwrap();
    let outcome = monitor.finish(&mut sim);
    (scene.goals.clone(), outcome, observe(&sim))
}

/// `(object, container)` of every placement of the goals.
fn placements(goals: &[SubtaskGoal]) -> Vec<(String, String)> {
    goals
        .iter()
        .flat_map(|g| {
            let container = |i: usize| match g {
                SubtaskGoal::PickPlace { container, .. } | SubtaskGoal::PutInHinge { container, .. } => {
                    container.clone()
                }
                SubtaskGoal::Sweep { placements } => placements[i].container.clone(),
                SubtaskGoal::PutInPrismatic { drawer, .. } => drawer.clone(),
            };
            g.objects()
                .into_iter()
                .enumerate()
                .map(move |(i, o)| (o.to_owned(), container(i)))
        })
        .collect()
}

/// The outcome's `displaced` agrees with the observer: a counted object that stayed reads
/// `InsideOf` its container in the final state, a displaced one does not. This holds whether
/// or not the expert knocks the rook out.
#[test]
fn displaced_objects_are_the_ones_the_final_state_shows_out_of_place() {
    let (goals, outcome, state) = demonstrate("grip_high_00_s0");
    assert!(outcome.full_success(), "{}", outcome.summary());
    for (object, container) in placements(&goals) {
        let inside = state.contains(&Atom::new("InsideOf", &[&object, &container]));
        let displaced = outcome.displaced.contains(&object);
        assert_eq!(
            inside, !displaced,
            "{object} in {container}: observed inside {inside}, displaced {displaced}\n{state}"
        );
    }
}

/// The demonstration shows its goal: nothing counted is out of place at the end.
#[test]
fn the_grip_high_00_demonstration_shows_its_goal() {
    let (_, outcome, state) = demonstrate("grip_high_00_s0");
    assert!(
        outcome.demonstrates_goal(),
        "displaced {:?}\n{state}",
        outcome.displaced
    );
}
