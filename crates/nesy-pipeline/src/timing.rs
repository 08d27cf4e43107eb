//! Where a run's time goes, as in the paper's Table 9: VLM time (model calls, prompt
//! rendering included), symbolic time (parsing, verification, patching: everything the
//! adaptation loop does outside model calls and progress reporting), and simulation time
//! (building, observing and rendering the target, and executing the policy). The template
//! compiler (`--codegen template`) is code synthesis without a model and is reported on its
//! own, not as symbolic time.

use std::sync::Arc;
use std::time::{Duration, Instant};

use nesy_core::adapt::{InductionRequest, PatchRequest, Reasoner, ReasonerError};
use serde::{Deserialize, Serialize};

use super::progress::Progress;

/// Seconds spent per kind of work in one run: one `nesy adapt` run, or one benchmark unit
/// (whose rows carry it). A field a run did not measure is 0.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TimeBreakdown {
    /// Reading the demo.
    pub load_s: f64,
    /// Model calls: state translation, induction, proposals, code generation.
    pub vlm_s: f64,
    /// The adaptation loop (`nesy_core::adapt::run`) outside model calls and progress
    /// reporting: reply parsing, verification, identification, patching, trace recording.
    pub symbolic_s: f64,
    /// The part of `symbolic_s` spent building the world model (parsing and verifying the
    /// induced operators against the demonstration, Eq. 3).
    pub symbolic_world_model_s: f64,
    /// The part of `symbolic_s` spent on counterfactual adaptation (identification,
    /// patching and re-verification, Eq. 6–8).
    pub symbolic_adaptation_s: f64,
    /// The target scene (build, observe, render) and the policy's execution.
    pub sim_s: f64,
    /// The template compiler (`--codegen template`; 0 otherwise): code synthesis from the
    /// verified procedure without a model.
    pub codegen_template_s: f64,
    /// Wall time of `nesy_core::adapt::run`: its VLM and symbolic parts plus progress
    /// reporting.
    pub adapt_wall_s: f64,
    /// The whole run (a benchmark unit's wall time, once recorded as `wall_s`).
    #[serde(alias = "wall_s")]
    pub total_s: f64,
}

impl TimeBreakdown {
    /// Sets the symbolic time from its total and its world-model part (in seconds); the
    /// adaptation part is the rest.
    ///
    /// ```
    /// use nesy_pipeline::TimeBreakdown;
    ///
    /// let mut t = TimeBreakdown::default();
    /// t.set_symbolic((0.5, 0.25));
    /// assert_eq!((t.symbolic_s, t.symbolic_world_model_s, t.symbolic_adaptation_s), (0.5, 0.25, 0.25));
    /// ```
    pub fn set_symbolic(&mut self, (total_s, world_model_s): (f64, f64)) {
        self.symbolic_s = total_s;
        self.symbolic_world_model_s = world_model_s;
        self.symbolic_adaptation_s = (total_s - world_model_s).max(0.0);
    }
}

/// A [`Reasoner`] that measures the time spent inside the wrapped reasoner and reports
/// each call as progress.
pub(crate) struct TimedReasoner<R> {
    inner: R,
    vlm: Duration,
    reporting: Duration,
    progress: Arc<dyn Progress>,
    transitions: usize,
    budget: usize,
    calls: usize,
    first_patch: Option<FirstPatch>,
}

/// When the first patch was requested, and the time spent outside symbolic work before it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FirstPatch {
    /// When the request arrived.
    pub at: Instant,
    /// Model time before it.
    pub vlm_before: Duration,
    /// Progress-reporting time before it.
    pub reporting_before: Duration,
}

impl<R: Reasoner> TimedReasoner<R> {
    /// Wraps `inner`; `transitions` and `budget` only shape the progress messages.
    pub(crate) fn new(inner: R, progress: Arc<dyn Progress>, transitions: usize, budget: usize) -> Self {
        TimedReasoner {
            inner,
            vlm: Duration::ZERO,
            reporting: Duration::ZERO,
            progress,
            transitions,
            budget,
            calls: 0,
            first_patch: None,
        }
    }

    /// Time spent inside the wrapped reasoner so far.
    pub(crate) fn vlm_time(&self) -> Duration {
        self.vlm
    }

    /// Time spent reporting progress (formatting and emitting the messages) so far.
    pub(crate) fn reporting_time(&self) -> Duration {
        self.reporting
    }

    /// When the first patch was requested (the end of world-model construction and the
    /// first identification), if any was requested.
    pub(crate) fn first_patch(&self) -> Option<FirstPatch> {
        self.first_patch
    }

    /// Calls made so far.
    pub(crate) fn calls(&self) -> usize {
        self.calls
    }

    /// The wrapped reasoner.
    pub(crate) fn into_inner(self) -> R {
        self.inner
    }
}

impl<R: Reasoner + Send> Reasoner for TimedReasoner<R> {
    async fn induce_operator(&mut self, request: &InductionRequest) -> Result<String, ReasonerError> {
        let reporting = Instant::now();
        self.progress.detail(&format!(
            "inducing operator {}/{} (attempt {})",
            request.step + 1,
            self.transitions,
            request.attempt + 1
        ));
        self.reporting += reporting.elapsed();
        let started = Instant::now();
        let reply = self.inner.induce_operator(request).await;
        self.vlm += started.elapsed();
        self.calls += 1;
        reply
    }

    async fn propose_patch(&mut self, request: &PatchRequest) -> Result<String, ReasonerError> {
        let reporting = Instant::now();
        if self.first_patch.is_none() {
            self.first_patch = Some(FirstPatch {
                at: reporting,
                vlm_before: self.vlm,
                reporting_before: self.reporting,
            });
        }
        let what = match (&request.erroneous, request.failing_step) {
            (Some(op), Some(step)) => format!("step {} {}", step + 1, op.display_name()),
            _ => "goal".to_owned(),
        };
        self.progress.detail(&format!(
            "patch proposal {}/{} for {what}",
            request.iteration + 1,
            self.budget
        ));
        self.reporting += reporting.elapsed();
        let started = Instant::now();
        let reply = self.inner.propose_patch(request).await;
        self.vlm += started.elapsed();
        self.calls += 1;
        reply
    }
}
