//! What a policy runs against: an [`Episode`] is a robot (the [`RobotApi`]) that can also
//! finish the episode with the post-run settle and goal checks of `docs/benchmark.md` §7.

use std::path::PathBuf;

use nesy_core::Embodiment;
use nesy_core::State;
use nesy_sim::api::RobotApi;
use serde::{Deserialize, Serialize};

use crate::result::SubtaskReport;

/// A robot a policy can drive, plus the end-of-episode goal checks.
pub trait Episode: RobotApi + Send {
    /// Called once after the policy ended (in any way but a kill): runs the post-run
    /// settle steps (`docs/benchmark.md` §7: 100 steps, then, if undecided, 100 more with the final check)
    /// and returns what the episode achieved.
    fn finish(&mut self) -> EpisodeEnd;

    /// Where the tool tip is now (world frame, metres), if this robot can say: what a robot
    /// bridge checks a relative move against before it sends it.
    fn tool_position(&self) -> Option<[f64; 3]> {
        None
    }
}

/// What an episode reports after the policy and the settle steps.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EpisodeEnd {
    /// Goal-check results; `None` if this robot has no goal checks.
    pub subtasks: Option<Vec<SubtaskReport>>,
    /// The observed symbolic state after settling; `None` if the robot has no world.
    pub final_state: Option<State>,
}

/// Which episode a worker should build. Sent from the parent to the worker process.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum EpisodeSpec {
    /// A simulated scene loaded from a scene file.
    Scene {
        /// Path of the scene JSON.
        path: PathBuf,
        /// Overrides the scene's embodiment.
        embodiment: Option<Embodiment>,
    },
    /// The recording test double of [`RecordingRobot`](crate::RecordingRobot): records calls, moves nothing.
    /// For sandbox tests, which exercise the interpreter and the worker, not the robot.
    RecordingDouble {
        /// The double's embodiment.
        embodiment: Embodiment,
    },
}

/// Builds the [`Episode`] an [`EpisodeSpec`] names. The CLI supplies one that knows the
/// simulator; the policy crate itself does not depend on simulator internals.
pub trait EpisodeFactory {
    /// Builds the episode, or explains why it cannot.
    fn build(&self, spec: &EpisodeSpec) -> Result<Box<dyn Episode>, EpisodeBuildError>;
}

/// Why an episode could not be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum EpisodeBuildError {
    /// The scene file did not load, validate or build into a world.
    #[error("cannot build the episode: {}: {message}", path.display())]
    Scene {
        /// The scene file.
        path: PathBuf,
        /// Why (the scene error, naming the JSON field).
        message: String,
    },
    /// The scene's goals cannot be checked in the built world.
    #[error("cannot build the episode: {}: goal checks: {message}", path.display())]
    GoalChecks {
        /// The scene file.
        path: PathBuf,
        /// Why.
        message: String,
    },
}
