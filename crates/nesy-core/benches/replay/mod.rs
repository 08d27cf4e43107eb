//! Replays recorded adaptation runs (`tests/adapt_corpus/*.json`, built by
//! `scripts/make_adapt_corpus.py` from `nesy adapt --vlm oracle` run directories) through
//! `adapt::run` with a scripted reasoner that returns the recorded replies in call order, so
//! what is timed is exactly nesy-core's symbolic path: reply parsing, operator verification
//! against the demonstration, identification, patch application and re-verification.
//! Shared by the `adapt` bench, the `adapt_corpus` test and the `adapt_time` example.

#![allow(dead_code)]

use std::collections::VecDeque;
use std::path::PathBuf;
use std::time::Instant;

use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::adapt::{
    AdaptConfig, Demonstration, InductionRequest, PatchRequest, Reasoner, ReasonerError, Target, TaskContext,
};
use nesy_core::{Tier, Vocabulary};
use serde::Deserialize;

/// One recorded run, as stored in the corpus.
#[derive(Debug, Clone, Deserialize)]
pub(super) struct RecordedRun {
    /// The scenario id (`comb_high_00_s0`).
    pub scenario: String,
    instruction: String,
    tier: Tier,
    budget: usize,
    demo_objects: Vec<String>,
    target_objects: Vec<String>,
    demo_states: Vec<State>,
    target_state: State,
    /// Induction replies in call order.
    pub induction_replies: Vec<String>,
    /// Patch replies in call order.
    pub patch_replies: Vec<String>,
    /// What the recorded run ended with.
    pub expected: Expected,
}

/// The recorded run's outcome.
#[derive(Debug, Clone, Deserialize)]
pub(super) struct Expected {
    /// `adapted` or `unresolved`.
    pub outcome: String,
    /// Proposals made.
    pub iterations: usize,
    /// Action names of the adapted (or best) procedure.
    pub procedure: Vec<String>,
}

/// The inputs of `adapt::run` for one recorded run.
pub(super) struct Inputs {
    pub demo: Demonstration,
    pub target: Target,
    pub config: AdaptConfig,
}

impl RecordedRun {
    /// The demonstration, target and configuration the pipeline passed to `adapt::run`.
    pub(super) fn inputs(&self) -> Inputs {
        let task = |objects: &[String]| TaskContext {
            instruction: self.instruction.clone(),
            objects: objects.iter().map(|o| Symbol::new(o)).collect(),
            tier: self.tier,
            vocabulary: Vocabulary::new(),
        };
        Inputs {
            demo: Demonstration {
                states: self.demo_states.clone(),
                task: task(&self.demo_objects),
            },
            target: Target {
                init: self.target_state.clone(),
                task: task(&self.target_objects),
                scene_names: Vec::new(),
                goal: None,
            },
            config: AdaptConfig {
                budget: self.budget,
                ..AdaptConfig::default()
            },
        }
    }

    /// A reasoner that answers with this run's replies, in order.
    pub(super) fn reasoner(&self) -> ScriptedReasoner {
        ScriptedReasoner {
            inductions: self.induction_replies.iter().cloned().collect(),
            patches: self.patch_replies.iter().cloned().collect(),
            first_patch: None,
        }
    }
}

/// Returns recorded replies in call order; running out is a reasoner error.
pub(super) struct ScriptedReasoner {
    inductions: VecDeque<String>,
    patches: VecDeque<String>,
    /// When the first patch was requested: the CLI's split between world-model
    /// construction and adaptation (`nesy-cli/src/pipeline/timing.rs`).
    pub first_patch: Option<Instant>,
}

impl Reasoner for ScriptedReasoner {
    async fn induce_operator(&mut self, request: &InductionRequest) -> Result<String, ReasonerError> {
        self.inductions.pop_front().ok_or_else(|| {
            ReasonerError::exhausted(format!(
                "no recorded induction reply left (step {})",
                request.step
            ))
        })
    }

    async fn propose_patch(&mut self, request: &PatchRequest) -> Result<String, ReasonerError> {
        self.first_patch.get_or_insert_with(Instant::now);
        self.patches.pop_front().ok_or_else(|| {
            ReasonerError::exhausted(format!(
                "no recorded patch reply left (iteration {})",
                request.iteration
            ))
        })
    }
}

/// The corpus directory: `NESY_ADAPT_CORPUS` if set (to time other recorded runs, e.g. a
/// fresh `scripts/make_adapt_corpus.py --out DIR`), else `tests/adapt_corpus`.
pub(super) fn corpus_dir() -> PathBuf {
    match std::env::var_os("NESY_ADAPT_CORPUS") {
        Some(dir) => PathBuf::from(dir),
        None => nesy_testkit::workspace_root().join("tests/adapt_corpus"),
    }
}

/// Every recorded run, sorted by scenario id.
pub(super) fn load_all() -> Vec<RecordedRun> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(corpus_dir())
        .unwrap_or_else(|e| panic!("{}: {e}", corpus_dir().display()))
        .map(|e| e.expect("readable directory entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| {
            let text = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        })
        .collect()
}
