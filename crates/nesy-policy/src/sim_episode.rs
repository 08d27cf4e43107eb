//! The simulator as an [`Episode`]: nesy-sim's [`Sim`] runs the robot API; after the policy
//! it settles for the post-run steps of spec §7 and reports the goal checks' subtask results
//! (for scenes with goals) and the observed symbolic state.

use nesy_sim::goal::{GoalMonitor, SubtaskOutcome, SubtaskResult as GoalResult};
use nesy_sim::{Sim, observe};

use crate::episode::{Episode, EpisodeBuildError, EpisodeEnd, EpisodeFactory, EpisodeSpec};
use crate::result::{SubtaskResult, SubtaskStatus};
use crate::testing::RecordingRobot;

/// Control steps the world settles after the policy ends before the goal check (spec §7:
/// `check_result` first steps 100 times; the second 100 steps, with the final check, run
/// only while the result is undecided, which needs the goal checks of nesy-sim).
pub const SETTLE_STEPS: u32 = 100;

impl Episode for Sim {
    fn finish(&mut self) -> EpisodeEnd {
        // With goal checks attached (scenes with goals), the goal monitor runs spec §7's
        // settle: 100 steps, and 100 more with the final check if something is undecided.
        match nesy_sim::goal::finish_episode(self) {
            Some(outcome) => EpisodeEnd {
                subtasks: Some(outcome.subtasks.iter().map(subtask_result).collect()),
                final_state: Some(observe(self)),
            },
            None => {
                self.step_idle(SETTLE_STEPS);
                EpisodeEnd {
                    subtasks: None,
                    final_state: Some(observe(self)),
                }
            }
        }
    }
}

fn subtask_result(outcome: &SubtaskOutcome) -> SubtaskResult {
    SubtaskResult {
        subtask: outcome.subtask.as_str().to_owned(),
        status: match outcome.result {
            GoalResult::FullSuccess => SubtaskStatus::FullSuccess,
            GoalResult::PartialSuccess => SubtaskStatus::PartialSuccess,
            GoalResult::Fail => SubtaskStatus::Failure,
        },
        label: outcome.label.clone(),
        achieved: outcome
            .achieved
            .iter()
            .map(|a| (a.name.clone(), a.step))
            .collect(),
    }
}

/// Builds episodes from scene files with nesy-sim, and the recording test double.
#[derive(Clone, Copy, Debug, Default)]
pub struct SimEpisodes;

impl EpisodeFactory for SimEpisodes {
    fn build(&self, spec: &EpisodeSpec) -> Result<Box<dyn Episode>, EpisodeBuildError> {
        match spec {
            EpisodeSpec::Scene {
                path,
                embodiment,
                render_every,
            } => {
                if *render_every != 0 {
                    return Err(EpisodeBuildError(
                        "rendering during a policy run (--render-every) is not implemented yet".to_owned(),
                    ));
                }
                let mut scene = nesy_sim::SceneSpec::from_file(path)
                    .map_err(|e| EpisodeBuildError(format!("{}: {e}", path.display())))?;
                if let Some(embodiment) = embodiment {
                    scene.embodiment = *embodiment;
                }
                let mut sim =
                    Sim::new(&scene).map_err(|e| EpisodeBuildError(format!("{}: {e}", path.display())))?;
                if !scene.goals.is_empty() {
                    GoalMonitor::attach(&mut sim)
                        .map_err(|e| EpisodeBuildError(format!("{}: goal checks: {e}", path.display())))?;
                }
                Ok(Box::new(sim))
            }
            EpisodeSpec::RecordingDouble { embodiment } => Ok(Box::new(RecordingRobot::new(*embodiment))),
        }
    }
}
