//! The simulator as an [`Episode`]: nesy-sim's [`Sim`] runs the robot API; after the policy
//! it settles for the post-run steps of `docs/benchmark.md` §7 and reports the goal checks' subtask results
//! (for scenes with goals) and the observed symbolic state.

use nesy_sim::perception::observer::observe;
use nesy_sim::tasks::goal::{GoalMonitor, POST_RUN_SETTLE_STEPS, SubtaskOutcome};
use nesy_sim::world::Sim;

use crate::episode::{Episode, EpisodeBuildError, EpisodeEnd, EpisodeFactory, EpisodeSpec};
use crate::result::SubtaskReport;
use crate::testing::RecordingRobot;

impl Episode for Sim {
    fn finish(&mut self) -> EpisodeEnd {
        // With goal checks attached (scenes with goals), the goal monitor runs the post-run
        // settle: 100 steps, and 100 more with the final check if something is undecided.
        // Without goals the world settles for the first phase only.
        match nesy_sim::tasks::goal::finish_episode(self) {
            Some(outcome) => EpisodeEnd {
                subtasks: Some(outcome.subtasks.iter().map(subtask_result).collect()),
                final_state: Some(observe(self)),
            },
            None => {
                self.step_idle(POST_RUN_SETTLE_STEPS);
                EpisodeEnd {
                    subtasks: None,
                    final_state: Some(observe(self)),
                }
            }
        }
    }

    fn tool_position(&self) -> Option<[f64; 3]> {
        let tip = self.tool_pose().translation.vector;
        Some([tip.x, tip.y, tip.z])
    }
}

fn subtask_result(outcome: &SubtaskOutcome) -> SubtaskReport {
    SubtaskReport {
        subtask: outcome.subtask.as_str().to_owned(),
        status: outcome.result,
        label: outcome.label.clone(),
        achieved: outcome
            .achieved
            .iter()
            .map(|a| (a.name.clone(), a.step))
            .collect(),
        displaced: outcome.displaced.clone(),
    }
}

/// Builds episodes from scene files with nesy-sim, and the recording test double.
#[derive(Clone, Copy, Debug, Default)]
pub struct SimEpisodes;

impl EpisodeFactory for SimEpisodes {
    fn build(&self, spec: &EpisodeSpec) -> Result<Box<dyn Episode>, EpisodeBuildError> {
        match spec {
            EpisodeSpec::Scene { path, embodiment } => {
                let mut scene =
                    nesy_sim::scene::SceneSpec::from_file(path).map_err(|e| scene_error(path, e))?;
                if let Some(embodiment) = embodiment {
                    scene.embodiment = *embodiment;
                }
                let mut sim = Sim::new(&scene).map_err(|e| scene_error(path, e))?;
                if !scene.goals.is_empty() {
                    GoalMonitor::attach(&mut sim).map_err(|e| EpisodeBuildError::GoalChecks {
                        path: path.clone(),
                        message: e.to_string(),
                    })?;
                }
                Ok(Box::new(sim))
            }
            EpisodeSpec::RecordingDouble { embodiment } => Ok(Box::new(RecordingRobot::new(*embodiment))),
        }
    }
}

fn scene_error(path: &std::path::Path, error: nesy_sim::scene::SceneError) -> EpisodeBuildError {
    EpisodeBuildError::Scene {
        path: path.to_owned(),
        message: error.to_string(),
    }
}
