//! Where a run's time goes, as in the paper's Table 9: VLM time (model calls, prompt
//! rendering included), symbolic time (parsing, verification, patching: everything the
//! adaptation loop does outside model calls), and simulation time (building, observing and
//! rendering the target, and executing the policy).

use std::sync::Arc;
use std::time::{Duration, Instant};

use nesy_core::adapt::{InductionRequest, PatchRequest, Reasoner, ReasonerError};
use serde::Serialize;

use super::progress::Progress;

/// Seconds spent per kind of work in one run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct TimeBreakdown {
    /// Reading the demo.
    pub load_s: f64,
    /// Model calls: state translation, induction, proposals, code generation.
    pub vlm_s: f64,
    /// The adaptation loop outside model calls (and the template compiler).
    pub symbolic_s: f64,
    /// The part of `symbolic_s` spent building the world model (parsing and verifying the
    /// induced operators against the demonstration, Eq. 3).
    pub symbolic_world_model_s: f64,
    /// The part of `symbolic_s` spent on counterfactual adaptation (identification,
    /// patching and re-verification, Eq. 6–8).
    pub symbolic_adaptation_s: f64,
    /// The target scene (build, observe, render) and the policy's execution.
    pub sim_s: f64,
    /// Wall time of `nesy_core::adapt::run` (VLM + symbolic parts of it).
    pub adapt_wall_s: f64,
    /// The whole run.
    pub total_s: f64,
}

/// A [`Reasoner`] that measures the time spent inside the wrapped reasoner and reports
/// each call as progress.
pub struct TimedReasoner<R> {
    inner: R,
    vlm: Duration,
    progress: Arc<dyn Progress>,
    transitions: usize,
    budget: usize,
    calls: usize,
    first_patch: Option<(Instant, Duration)>,
}

impl<R: Reasoner> TimedReasoner<R> {
    /// Wraps `inner`; `transitions` and `budget` only shape the progress messages.
    pub fn new(inner: R, progress: Arc<dyn Progress>, transitions: usize, budget: usize) -> Self {
        TimedReasoner {
            inner,
            vlm: Duration::ZERO,
            progress,
            transitions,
            budget,
            calls: 0,
            first_patch: None,
        }
    }

    /// Time spent inside the wrapped reasoner so far.
    pub fn vlm_time(&self) -> Duration {
        self.vlm
    }

    /// When the first patch was requested and the model time spent before it (the end of
    /// world-model construction and the first identification), if any was requested.
    pub fn first_patch(&self) -> Option<(Instant, Duration)> {
        self.first_patch
    }

    /// Calls made so far.
    pub fn calls(&self) -> usize {
        self.calls
    }

    /// The wrapped reasoner.
    pub fn into_inner(self) -> R {
        self.inner
    }
}

impl<R: Reasoner + Send> Reasoner for TimedReasoner<R> {
    async fn induce_operator(&mut self, request: &InductionRequest) -> Result<String, ReasonerError> {
        self.progress.detail(&format!(
            "inducing operator {}/{} (attempt {})",
            request.step + 1,
            self.transitions,
            request.attempt + 1
        ));
        let started = Instant::now();
        let reply = self.inner.induce_operator(request).await;
        self.vlm += started.elapsed();
        self.calls += 1;
        reply
    }

    async fn propose_patch(&mut self, request: &PatchRequest) -> Result<String, ReasonerError> {
        let what = match (&request.erroneous, request.failing_step) {
            (Some(op), Some(step)) => format!("step {} {}", step + 1, op.display_name()),
            _ => "goal".to_owned(),
        };
        if self.first_patch.is_none() {
            self.first_patch = Some((Instant::now(), self.vlm));
        }
        self.progress.detail(&format!(
            "patch proposal {}/{} for {what}",
            request.iteration + 1,
            self.budget
        ));
        let started = Instant::now();
        let reply = self.inner.propose_patch(request).await;
        self.vlm += started.elapsed();
        self.calls += 1;
        reply
    }
}
