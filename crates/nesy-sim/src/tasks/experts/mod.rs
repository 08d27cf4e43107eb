//! Scripted experts: one per subtask, driving only the public [`RobotApi`] on either
//! embodiment and at every obstruction level. They follow the authors' demo recipes
//! (`docs/benchmark.md` §2, "Demo") adapted to this simulator; the README lists the differences.
//!
//! The experts decide what to do from perception calls (`get_obj_bbox`, ...), not from the
//! generator's obstruction level: a stack is cleared when something rests on a cube, a piece
//! is lifted back to the board when it is in a box, the fruit on the lid is moved away when
//! there is one, and lids and drawers are opened when they are closed.
//!
//! Which objects are loose (and may be moved aside) comes from the scene's object kinds.
//! `hand` holds the robot with the moves every expert shares; each subtask's expert has a
//! module of its own, mirroring the task generators.

mod hand;
mod hinge;
mod pick_place;
mod prismatic;
mod sweep;

use hand::{Hand, Tools};

use crate::api::{ApiError, RobotApi};
use crate::scene::{ObjectKind, SceneError, SceneSpec, SubtaskGoal, SubtaskKind};
use crate::tasks::goal::{EpisodeOutcome, GoalError, GoalMonitor};
use crate::world::Sim;

/// Why an expert stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{subtask} expert: {step} failed: {error}")]
pub struct ExpertError {
    /// The subtask it was working on.
    pub subtask: SubtaskKind,
    /// The call that failed, e.g. `move_gripper_to(red_cube)`.
    pub step: String,
    /// The robot's answer.
    pub error: ApiError,
}

/// Why an expert episode could not be run at all.
#[derive(Debug, thiserror::Error)]
pub enum EpisodeError {
    /// The scene does not build.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The goals cannot be checked.
    #[error(transparent)]
    Goal(#[from] GoalError),
}

/// One expert run on a scene, judged by the goal checks.
#[derive(Debug)]
pub struct ExpertEpisode {
    /// The goal checks' verdict after the post-run settle.
    pub outcome: EpisodeOutcome,
    /// Why the expert stopped early, if it did.
    pub error: Option<ExpertError>,
    /// Robot API action calls made.
    pub actions: usize,
    /// Simulated time at the end of the episode (s).
    pub sim_time: f64,
}

impl ExpertEpisode {
    /// The expert finished and every subtask is `full_success`.
    pub fn full_success(&self) -> bool {
        self.error.is_none() && self.outcome.full_success()
    }

    /// Why the episode is not a full success (`None` when it is).
    pub fn failure(&self) -> Option<String> {
        match &self.error {
            Some(e) => Some(format!("{e} ({})", self.outcome.summary())),
            None if !self.outcome.full_success() => Some(format!(
                "{}; achieved {:?}",
                self.outcome.summary(),
                self.outcome.achieved_sequence
            )),
            None => None,
        }
    }
}

/// Builds the scene, runs the experts of all its goals with goal checks attached, and
/// finishes the episode (`docs/benchmark.md` §7's settle and final call).
pub fn run_scene(scene: &SceneSpec) -> Result<ExpertEpisode, EpisodeError> {
    let mut sim = Sim::new(scene)?;
    let monitor = GoalMonitor::attach(&mut sim)?;
    let error = run(&mut sim, scene).err();
    let outcome = monitor.finish(&mut sim);
    Ok(ExpertEpisode {
        outcome,
        error,
        actions: sim.actions_used(),
        sim_time: sim.time(),
    })
}

/// Runs the expert of every goal of `scene`, in order, on `robot` (a world built from that
/// scene).
///
/// When the scene's protective stop is on ([`SceneSpec::protective_stop`]) the expert moves
/// as a robot that knows its furniture: it also keeps its turned fruit grasps, sideways
/// handle approaches and set-down spots off furniture, and takes a handle from above when a
/// sideways approach is stopped.
pub fn run<R: RobotApi + ?Sized>(robot: &mut R, scene: &SceneSpec) -> Result<(), ExpertError> {
    let furniture_aware = scene.protective_stop;
    let loose: Vec<String> = scene
        .objects
        .iter()
        .filter(|o| o.kind.is_loose())
        .map(|o| o.name.clone())
        .collect();
    let named = |keep: fn(ObjectKind) -> bool| -> Vec<String> {
        scene
            .objects
            .iter()
            .filter(|o| keep(o.kind))
            .map(|o| o.name.clone())
            .collect()
    };
    let (hooks, fine) = (named(ObjectKind::is_tool), named(ObjectKind::is_fine_grained));
    let tools = Tools {
        hooks: &hooks,
        fine: &fine,
    };
    let mut goals = scene.goals.iter().peekable();
    while let Some(goal) = goals.next() {
        let mut hand = Hand::new(robot, goal.kind(), &loose).with_tools(tools);
        hand.furniture_aware = furniture_aware;
        match goal {
            SubtaskGoal::PickPlace { objects, container } => pick_place::run(&mut hand, objects, container)?,
            SubtaskGoal::Sweep { placements } => {
                let pairs: Vec<(&str, &str)> = placements
                    .iter()
                    .map(|p| (p.object.as_str(), p.container.as_str()))
                    .collect();
                sweep::run(&mut hand, &pairs)?
            }
            SubtaskGoal::PutInHinge {
                objects,
                container,
                lid,
            } => hinge::run(&mut hand, objects, container, lid)?,
            // Loads for the bottom drawers of several cabinets in a row are made together
            // (see `prismatic::run`).
            SubtaskGoal::PutInPrismatic { objects, drawer } => {
                let mut loads: Vec<(&[String], &str)> = vec![(objects, drawer)];
                while let Some(SubtaskGoal::PutInPrismatic { objects, drawer }) = goals.peek() {
                    loads.push((objects, drawer));
                    goals.next();
                }
                prismatic::run(&mut hand, &loads)?
            }
        }
    }
    Ok(())
}
