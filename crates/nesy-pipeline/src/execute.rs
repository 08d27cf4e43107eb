//! Execution: the policy runs in the sandboxed worker against the target scene; the goal
//! checks' subtask results give SR, GC and PD (`docs/benchmark.md` §7), scored by
//! `nesy_core::metrics`.

use std::path::{Path, PathBuf};

use nesy_core::metrics::{EpisodeResult, Scoring, SubtaskResult, achieved_in_time_order};
use nesy_policy::{EpisodeSpec, ExecutionResult, Limits, WorkerCommand, run_policy};
use serde::Serialize;

use crate::PipelineError;

/// The execution and its scores.
#[derive(Debug, Clone, Serialize)]
pub struct ExecutionReport {
    /// The scene file the worker ran.
    pub scene_path: PathBuf,
    /// Everything the sandbox reported (outcome, API trace, output, subtasks, final state).
    pub result: ExecutionResult,
    /// SR, GC and PD, when the episode had goal checks.
    pub metrics: Option<EpisodeMetrics>,
}

impl ExecutionReport {
    /// True if every subtask succeeded (full or partial, `docs/benchmark.md` §7).
    pub fn success(&self) -> bool {
        self.metrics.as_ref().is_some_and(|m| m.sr == 1.0)
    }

    /// True if every subtask reached `full_success`.
    pub fn full_success(&self) -> bool {
        self.metrics.as_ref().is_some_and(|m| {
            !m.subtasks.is_empty() && m.subtasks.iter().all(|s| s.status == SubtaskResult::FullSuccess)
        })
    }
}

/// One subtask's verdict.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SubtaskVerdict {
    /// The subtask type.
    pub subtask: String,
    /// Its result by the authors' latch.
    pub status: SubtaskResult,
    /// Counted objects out of place at the end (the subtask fails nesy's headline scoring).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub displaced: Vec<String>,
}

/// The episode's scores (`docs/benchmark.md` §7). The headline SR and GC fail a subtask whose
/// counted objects are out of place at the end; `latched_sr` and `latched_gc` are the
/// authors' scores, which count an object once it was placed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EpisodeMetrics {
    /// The subtask verdicts.
    pub subtasks: Vec<SubtaskVerdict>,
    /// 1 if every subtask succeeded (partial counts) and nothing ended displaced, else 0.
    pub sr: f64,
    /// Fraction of successful subtasks (a subtask with a displaced object fails).
    pub gc: f64,
    /// SR by the authors' latch.
    pub latched_sr: f64,
    /// GC by the authors' latch.
    pub latched_gc: f64,
    /// Normalised Levenshtein distance of the achieved sequence to the goal label, when the
    /// goal checks report the sequences.
    pub pd: Option<f64>,
    /// The goal label (subtask labels in config order).
    pub label: Vec<String>,
    /// What was achieved, in time order.
    pub achieved: Vec<String>,
}

impl EpisodeMetrics {
    /// Scores from the sandbox's subtask results.
    pub fn from_result(result: &ExecutionResult) -> Option<EpisodeMetrics> {
        let subtasks = result.subtasks.as_ref()?;
        let verdicts: Vec<SubtaskVerdict> = subtasks
            .iter()
            .map(|s| SubtaskVerdict {
                subtask: s.subtask.clone(),
                status: s.status,
                displaced: s.displaced.clone(),
            })
            .collect();
        // The goal label is the subtask labels in config order; the achieved sequence merges
        // every subtask's achievements in time order.
        let scored = |scoring: Scoring| EpisodeResult {
            subtasks: verdicts
                .iter()
                .map(|v| scoring.verdict(v.status, !v.displaced.is_empty()))
                .collect(),
            label: subtasks.iter().flat_map(|s| s.label.iter().cloned()).collect(),
            achieved: achieved_in_time_order(
                subtasks
                    .iter()
                    .map(|s| s.achieved.iter().map(|(name, step)| (name.as_str(), *step))),
            ),
        };
        let latched = scored(Scoring::Latched);
        let episode = scored(Scoring::Strict);
        Some(EpisodeMetrics {
            sr: episode.success(),
            gc: episode.goal_condition(),
            latched_sr: latched.success(),
            latched_gc: latched.goal_condition(),
            pd: (!episode.label.is_empty()).then(|| episode.procedure_deviation()),
            label: episode.label,
            achieved: episode.achieved,
            subtasks: verdicts,
        })
    }
}

/// Runs `code` against the scene at `scene_path` in the sandboxed worker.
pub fn execute(
    worker: &WorkerCommand,
    code: &str,
    scene_path: &Path,
    limits: &Limits,
) -> Result<ExecutionReport, PipelineError> {
    let spec = EpisodeSpec::Scene {
        path: std::path::absolute(scene_path).unwrap_or_else(|_| scene_path.to_owned()),
        embodiment: None,
    };
    let result = run_policy(worker, code, &spec, limits).map_err(|e| PipelineError::Execute {
        scene: scene_path.to_owned(),
        message: e.to_string(),
    })?;
    let metrics = EpisodeMetrics::from_result(&result);
    Ok(ExecutionReport {
        scene_path: scene_path.to_owned(),
        result,
        metrics,
    })
}
