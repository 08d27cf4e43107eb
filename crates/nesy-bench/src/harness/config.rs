//! What a run is: who answers (the responder), the run's configuration, progress and
//! stop signals, and preparing a run: the suite, the selected units and the manifest.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use nesy_policy::WorkerCommand;
use nesy_sim::tasks::scenario::{self, ConfigFile};
use nesy_vlm::{ConfigOverrides, ProcessEnv, VlmConfig};
use serde::Serialize;

use crate::error::BenchError;
use crate::manifest::{MANIFEST_VERSION, Manifest, Provenance, Responder, RunSettings, VariantEntry};
use crate::methods::{self, OfflineMeaning};
use crate::shard::Shard;
use crate::studies::Study;
use crate::unit::{Selection, Unit, units};
use crate::unit_record::UnitRecord;
use crate::variant::{Variant, config_hash, noise_of};

/// Who answers the model calls, as configured.
#[derive(Debug, Clone)]
pub enum ResponderSetup {
    /// The offline reference responder (noise per variant, seeded per unit).
    Oracle,
    /// Per-unit cassettes of an earlier run.
    Replay(PathBuf),
    /// A live endpoint (flags > environment > file), recorded per unit.
    Live(Box<ConfigOverrides>),
}

/// Everything a run is asked to do.
#[derive(Debug, Clone)]
pub struct RunConfig {
    /// The run directory.
    pub run_dir: PathBuf,
    /// The variants.
    pub variants: Vec<Variant>,
    /// The study these variants make up, if any (the report adds its table).
    pub study: Option<Study>,
    /// The scenarios.
    pub selection: Selection,
    /// Read the suite from this folder instead of generating it.
    pub suite_dir: Option<PathBuf>,
    /// Repeats per (variant, scenario).
    pub repeats: u32,
    /// The run seed.
    pub run_seed: u64,
    /// Who answers.
    pub responder: ResponderSetup,
    /// The demo cache folder.
    pub demo_cache: PathBuf,
    /// Run-wide settings.
    pub settings: RunSettings,
    /// This process's shard.
    pub shard: Shard,
    /// Units in flight at once.
    pub jobs: usize,
    /// CPU-bound stages at once.
    pub cpu_jobs: usize,
    /// Model calls in flight at once, over all units.
    pub model_jobs: usize,
    /// Stop scheduling units once the run's cost reaches this (US$).
    pub max_cost_usd: Option<f64>,
    /// Stop scheduling units once this fraction of the finished units (at least 10) ended in
    /// a transport error or a refused request.
    pub max_error_rate: Option<f64>,
    /// The `nesy` binary whose `policy-worker` runs policies.
    pub worker: WorkerCommand,
    /// Record the offline responder's calls too (live calls are always recorded).
    pub record_cassettes: bool,
    /// Record every executed unit's execution: `execution.mcap` and its first and last
    /// frames, which the report's failure gallery shows.
    pub record_executions: bool,
    /// Re-execute the specifications of this earlier run (phase B only).
    pub reexecute: Option<PathBuf>,
}

/// Receives the run's progress.
pub trait BenchProgress: Send + Sync {
    /// The run starts: units in this shard, of which `pending` still have to run.
    fn start(&self, total: usize, pending: usize);
    /// A unit finished.
    fn unit_done(&self, record: &UnitRecord, done: usize, pending: usize);
    /// A message (demo recording, a guard stopping the run).
    fn note(&self, message: &str);
}

/// Progress that goes nowhere.
#[derive(Debug, Clone, Copy, Default)]
pub struct Quiet;

impl BenchProgress for Quiet {
    fn start(&self, _total: usize, _pending: usize) {}
    fn unit_done(&self, _record: &UnitRecord, _done: usize, _pending: usize) {}
    fn note(&self, _message: &str) {}
}

/// Set from outside (Ctrl-C) to stop a run: no new unit starts, units in flight are recorded
/// as `interrupted`.
#[derive(Debug, Clone, Default)]
pub struct StopSignal(Arc<AtomicBool>);

impl StopSignal {
    /// Asks the run to stop.
    pub fn stop(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// True once asked.
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// How a run ended.
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    /// Units of this shard.
    pub shard_units: usize,
    /// Units already final before this invocation.
    pub skipped: usize,
    /// Units run now.
    pub ran: usize,
    /// Statuses of the units run now.
    pub statuses: BTreeMap<String, usize>,
    /// Why the run stopped early, if it did.
    pub stopped: Option<String>,
    /// Wall seconds.
    pub wall_s: f64,
}

/// A prepared run: the manifest and the units, before anything runs (also used by
/// `plan`, `status` and `merge`).
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The manifest.
    pub manifest: Manifest,
    /// Every unit of the run.
    pub units: Vec<Unit>,
}

/// The scenario suite: generated, or read from a folder.
pub fn load_suite(dir: Option<&Path>) -> Result<Vec<ConfigFile>, BenchError> {
    Ok(match dir {
        Some(d) => scenario::read_suite(d)?,
        None => scenario::generate_suite(),
    })
}

/// The suite a run uses: the folder's when given, else the complexity-gap suite or a
/// real-world task's family for a study that runs on it, else the 440.
pub fn run_suite(dir: Option<&Path>, study: Option<Study>) -> Result<Vec<ConfigFile>, BenchError> {
    match (dir, study) {
        (None, Some(s)) if s.uses_gap_suite() => Ok(scenario::generate_gap_suite()),
        (None, Some(s)) if let Some(family) = s.family() => Ok(vec![scenario::generate_family_file(family)]),
        _ => load_suite(dir),
    }
}

pub(super) fn suite_hash(files: &[ConfigFile]) -> String {
    config_hash(&files.iter().map(ConfigFile::to_json_pretty).collect::<Vec<_>>())
}

/// The responder as the manifest records it.
pub fn describe_responder(setup: &ResponderSetup) -> Result<Responder, BenchError> {
    Ok(match setup {
        ResponderSetup::Oracle => Responder::Oracle,
        ResponderSetup::Replay(dir) => Responder::Replay {
            cassettes: dir.clone(),
        },
        ResponderSetup::Live(overrides) => {
            let config = VlmConfig::resolve(overrides, &ProcessEnv)
                .map_err(|e| BenchError::Usage(format!("resolving the VLM configuration: {e}")))?;
            Responder::Live {
                backend: config.backend.as_str().to_owned(),
                model: config.model.clone(),
                base_url: config.base_url.clone(),
                constrain: config.defaults.constrain,
            }
        }
    })
}

/// Builds the manifest and the unit list, validating every variant; nothing is written.
pub fn prepare(config: &RunConfig) -> Result<Prepared, BenchError> {
    if config.variants.is_empty() {
        return Err(BenchError::Usage("no methods given".into()));
    }
    let responder = describe_responder(&config.responder)?;
    let mut entries = Vec::new();
    for v in &config.variants {
        let method = methods::find(&v.method)?;
        method.validate(v)?;
        if method.info().offline == OfflineMeaning::NotMeaningful && responder == Responder::Oracle {
            return Err(BenchError::Usage(format!(
                "{}: its model calls are global (a perfect answer is the planner's plan), so the offline responder cannot answer them honestly; run it with a live model or replay a live run's cassettes",
                v.method
            )));
        }
        if let Some(noise) = v.option("noise") {
            let knobs = noise_of(noise)?;
            if knobs.perturbs_states() && v.option("states") != Some("vlm") {
                return Err(BenchError::Usage(format!(
                    "variant {v}: the state knobs perturb state translation, which only runs with states=vlm; add +states=vlm"
                )));
            }
            if responder != Responder::Oracle {
                return Err(BenchError::Usage(format!(
                    "variant {v}: `noise` perturbs the offline responder's answers and needs --vlm oracle"
                )));
            }
        }
        if entries.iter().any(|e: &VariantEntry| e.id == v.id()) {
            return Err(BenchError::Usage(format!("variant {v} is given twice")));
        }
        entries.push(VariantEntry {
            variant: v.clone(),
            id: v.id(),
            config_hash: String::new(),
            deviations: method.deviations(v),
        });
    }
    let files = run_suite(config.suite_dir.as_deref(), config.study)?;
    let scenarios = config.selection.apply(scenario::scenarios(&files))?;
    let units = units(
        &config.variants,
        &scenarios,
        config.repeats.max(1),
        config.run_seed,
    );
    let provenance = Provenance::current();
    for e in &mut entries {
        e.config_hash = config_hash(&(
            &e.variant,
            &responder.identity(),
            &config.settings,
            &provenance.sim_fingerprint,
            &provenance.prompts_fingerprint,
            &config.reexecute,
        ));
    }
    let mut manifest = Manifest {
        schema_version: MANIFEST_VERSION,
        created_at: nesy_vlm::now_rfc3339(),
        provenance,
        suite_hash: suite_hash(&files),
        responder,
        run_seed: config.run_seed,
        repeats: config.repeats.max(1),
        selection: config.selection.clone(),
        settings: config.settings.clone(),
        variants: entries,
        study: config.study,
        units: units.iter().map(|u| u.key.clone()).collect(),
        reexecutes: config.reexecute.clone(),
        config_hash: String::new(),
    };
    manifest.config_hash = manifest.compute_hash();
    Ok(Prepared { manifest, units })
}

/// A short id for a run directory from the clock: `YYYYMMDD-HHMMSS`.
pub fn default_run_id() -> String {
    nesy_vlm::now_rfc3339()
        .replace(['-', ':'], "")
        .replace('T', "-")
        .trim_end_matches('Z')
        .to_owned()
}
