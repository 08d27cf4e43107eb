//! What the units of a run share: the run's state (configuration, slots, demo cache,
//! results writer), each scenario's inputs loaded once, the CPU slots, a unit's client type,
//! phase A's hand-over to phase B, and reading a run's final records.

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex};

use nesy_pipeline::{DemoInput, DemoKeyframes, TargetInput};
use nesy_sim::tasks::scenario::Scenario;
use nesy_vlm::{Transport, VlmClient, VlmConfig};
use tokio::sync::Semaphore;

use crate::demos::{CachedDemo, DemoCache};
use crate::error::BenchError;
use crate::manifest::Manifest;
use crate::meter::CallCounts;
use crate::status::UnitStatus;
use crate::store::{self};
use crate::unit_record::{Agreement, SpecSummary, UnitRecord};

use super::config::RunConfig;

/// The final records of a run by unit name (the latest when a unit was retried).
pub fn final_records(run: &Path) -> Result<HashMap<String, UnitRecord>, BenchError> {
    let mut out = HashMap::new();
    for (name, mut records) in store::latest_by_unit(store::read_all(run)?) {
        if let Some(r) = records.pop().filter(|r| r.status.is_final()) {
            out.insert(name, r);
        }
    }
    Ok(out)
}

/// One scenario's inputs, loaded once and shared by its units.
pub(super) struct ScenarioInputs {
    /// The predicates the scenario's task is stated in: the built-ins, or a real-world task
    /// family's vocabulary.
    pub(super) vocabulary: Arc<nesy_core::Vocabulary>,
    pub(super) demo: Arc<DemoInput>,
    pub(super) keyframes: Arc<DemoKeyframes>,
    pub(super) target: Arc<TargetInput>,
    pub(super) cached: CachedDemo,
}

/// A scenario's inputs, filled by the first unit that needs them.
pub(super) type ScenarioSlot = Arc<tokio::sync::OnceCell<Result<Arc<ScenarioInputs>, String>>>;

/// A unit's client and the counts of its calls.
pub(super) type UnitClient = (VlmClient, Arc<Mutex<CallCounts>>);

/// What every unit of the run shares.
pub(super) struct Shared {
    pub(super) config: RunConfig,
    pub(super) manifest: Manifest,
    pub(super) cache: DemoCache,
    pub(super) cpu: Arc<Semaphore>,
    pub(super) model: Arc<Semaphore>,
    pub(super) live: Option<(VlmConfig, Arc<dyn Transport>)>,
    /// Scenario inputs by id; each slot is filled once, under its own lock.
    pub(super) scenarios: Mutex<HashMap<String, ScenarioSlot>>,
    /// Cost so far (US$).
    pub(super) cost: Mutex<f64>,
}

/// Runs a blocking, CPU-bound closure on the blocking pool under a CPU slot.
pub(super) async fn cpu<T: Send + 'static>(
    shared: &Shared,
    f: impl FnOnce() -> T + Send + 'static,
) -> Result<T, String> {
    let _slot = shared.cpu.acquire().await.map_err(|e| e.to_string())?;
    tokio::task::spawn_blocking(f).await.map_err(|e| e.to_string())
}

/// The scenario's demo and target, loaded (and the demo recorded) at most once.
pub(super) async fn scenario_inputs(
    shared: &Arc<Shared>,
    scenario: &Scenario,
) -> Result<Arc<ScenarioInputs>, String> {
    let cell = {
        let mut map = shared.scenarios.lock().unwrap_or_else(|e| e.into_inner());
        // Units arrive grouped by scenario: keep a handful of scenarios in memory.
        if map.len() > shared.config.jobs.max(1) * 2 + 2 && !map.contains_key(&scenario.id) {
            map.clear();
        }
        map.entry(scenario.id.clone())
            .or_insert_with(|| Arc::new(tokio::sync::OnceCell::new()))
            .clone()
    };
    cell.get_or_init(|| async {
        let cache = shared.cache.clone();
        let s = scenario.clone();
        cpu(shared, move || -> Result<ScenarioInputs, String> {
            let vocabulary = match s.family {
                Some(family) => family
                    .vocabulary()
                    .map_err(|e| format!("the {family} family's vocabulary: {e}"))?,
                None => nesy_core::Vocabulary::new(),
            };
            let cached = cache.ensure(&s, 1).map_err(|e| e.to_string())?;
            let demo = DemoInput::load(&cached.demo, &vocabulary).map_err(|e| e.to_string())?;
            let target = TargetInput::load(Some(&cached.target), &demo).map_err(|e| e.to_string())?;
            let keyframes = DemoKeyframes::from_demo(&demo).map_err(|e| e.to_string())?;
            Ok(ScenarioInputs {
                vocabulary: Arc::new(vocabulary),
                demo: Arc::new(demo),
                keyframes: Arc::new(keyframes),
                target: Arc::new(target),
                cached,
            })
        })
        .await
        .and_then(|r| r)
        .map(Arc::new)
    })
    .await
    .clone()
}

/// What phase A hands to phase B besides the code.
pub(super) struct PhaseA {
    pub(super) spec: Option<SpecSummary>,
    pub(super) states: Option<Agreement>,
    pub(super) vlm_s: f64,
    pub(super) symbolic_s: (f64, f64),
    pub(super) template_s: f64,
}

/// Why phase A ended without code, and what it measured before it did.
pub(super) struct PhaseAFailure {
    pub(super) status: UnitStatus,
    pub(super) message: String,
    /// Boxed, so that a failed phase stays a small `Err`.
    pub(super) spec: Option<Box<SpecSummary>>,
    /// Symbolic seconds (in all, on the world model) spent before the failure, when the
    /// method got as far as its symbolic stages.
    pub(super) symbolic_s: Option<(f64, f64)>,
}

impl PhaseAFailure {
    /// A failure before anything was measured or specified.
    pub(super) fn new(status: UnitStatus, message: String) -> PhaseAFailure {
        PhaseAFailure {
            status,
            message,
            spec: None,
            symbolic_s: None,
        }
    }
}
