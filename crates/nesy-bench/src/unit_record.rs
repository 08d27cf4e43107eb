//! One JSON line per finished unit: its identity, how it ended, its scores under both
//! scorings, what it cost and where its artifacts are.

use std::collections::BTreeMap;

use nesy_core::benchmark::{Complexity, Factor};
use nesy_core::metrics::{EpisodeResult, SubtaskResult};
use serde::{Deserialize, Serialize};

use nesy_pipeline::TimeBreakdown;

use crate::status::UnitStatus;
use crate::unit::UnitKey;

/// State translation against ground truth, when the states came from the model.
pub(crate) use nesy_pipeline::states::Agreement;

/// One subtask's verdict in a record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SubtaskScore {
    /// `pick_place`, …
    pub subtask: String,
    /// The authors' verdict (latched).
    pub result: SubtaskResult,
    /// Counted objects out of place at the end (the subtask fails the strict scoring).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub displaced: Vec<String>,
}

/// An episode's scores. A unit that never executed scores SR 0 and GC 0 under both
/// scorings and has no PD (its label is kept, its achieved sequence is empty).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// SR, strict scoring (nesy's headline).
    pub sr: f64,
    /// GC, strict scoring.
    pub gc: f64,
    /// SR by the authors' latch.
    pub latched_sr: f64,
    /// GC by the authors' latch.
    pub latched_gc: f64,
    /// PD of the episode (normalised edit distance of the achieved sequence to the label).
    pub pd: f64,
    /// The goal label.
    pub label: Vec<String>,
    /// What was achieved, in time order.
    pub achieved: Vec<String>,
    /// The subtasks.
    pub subtasks: Vec<SubtaskScore>,
}

impl Scores {
    /// The scores of a unit that did not execute: every subtask failed.
    pub fn not_executed(label: Vec<String>, subtasks: &[String]) -> Scores {
        let episode = EpisodeResult {
            subtasks: vec![SubtaskResult::Fail; subtasks.len()],
            label: label.clone(),
            achieved: Vec::new(),
        };
        Scores {
            sr: 0.0,
            gc: 0.0,
            latched_sr: 0.0,
            latched_gc: 0.0,
            pd: episode.procedure_deviation(),
            label,
            achieved: Vec::new(),
            subtasks: subtasks
                .iter()
                .map(|s| SubtaskScore {
                    subtask: s.clone(),
                    result: SubtaskResult::Fail,
                    displaced: Vec::new(),
                })
                .collect(),
        }
    }
}

/// What a unit's specification was.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpecSummary {
    /// `procedure` (symbolic actions), `plan` (natural-language steps) or `none`.
    pub kind: String,
    /// Steps in it.
    pub steps: usize,
    /// Whether the symbolic executor verified it from the target's initial state.
    pub verified: bool,
    /// Refinement rounds used (iterative methods).
    pub iterations: Option<usize>,
    /// The round budget it had.
    pub budget: Option<usize>,
}

/// What a unit spent.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Effort {
    /// Model calls.
    pub calls: u64,
    /// Images sent.
    pub images: u64,
    /// Calls by purpose (`induce`, `patch`, `codegen`, `translate`, `d2c.observe`, …).
    pub calls_by_purpose: BTreeMap<String, u64>,
    /// Estimated cost in US dollars by purpose (empty offline or without a price).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub cost_by_purpose: BTreeMap<String, f64>,
    /// Prompt and completion tokens (0 offline).
    pub tokens: u64,
    /// Cost in US dollars at the configured price table (0 offline).
    pub cost_usd: f64,
    /// Where the unit's time went: the pipeline's own breakdown (model, symbolic, template
    /// compiler, simulator, demo loading), with the unit's wall time as `total_s`.
    #[serde(flatten)]
    pub time: TimeBreakdown,
}

/// One finished unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UnitRecord {
    /// The unit.
    #[serde(flatten)]
    pub key: UnitKey,
    /// The method.
    pub method: String,
    /// The scenario's factor.
    pub factor: Factor,
    /// The scenario's complexity.
    pub complexity: Complexity,
    /// Subtasks the target has beyond the demonstration's, for a scenario of the
    /// complexity-gap suite (absent for the 440).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub added_subtasks: Option<u8>,
    /// The scenario's obstruction change, Σ |target obst − source obst| over its subtasks
    /// (the domain-gap measure of Figure 4(a), taken from the configuration the run used).
    /// Absent in the complexity-gap suite, whose target has subtasks the demonstration
    /// lacks, and in records written before the field was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub obstruction_change: Option<u32>,
    /// The unit's seed.
    pub seed: u64,
    /// Hash of the variant's configuration (a resume refuses records whose hash differs).
    pub config_hash: String,
    /// How it ended.
    pub status: UnitStatus,
    /// Why, when it did not succeed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Scores.
    pub scores: Scores,
    /// The specification.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spec: Option<SpecSummary>,
    /// State translation quality, when states came from the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub states: Option<Agreement>,
    /// Effort.
    pub effort: Effort,
    /// The unit's folder under the run directory.
    pub artifacts: String,
    /// When it finished (RFC 3339, UTC).
    pub finished_at: String,
}
