//! Running a benchmark: the manifest first, then every pending unit of this shard, each in
//! two phases — (A) the method's specification and its code, (B) execution in the
//! simulator — with one result line appended per unit as it finishes.
//!
//! Running the same command again resumes: units with a final record are skipped, units
//! whose last record is retryable (transport errors, interruptions) or that have none run
//! again. Demos come from the [`DemoCache`]; each scenario's demo and target scene are
//! loaded once per process and shared by the variants that run on it.
//!
//! Concurrency: `jobs` units run at once; the CPU-bound stages (recording, building and
//! rendering scenes, executing policies) share `cpu_jobs` slots, and model calls share
//! `model_jobs` slots across all units. When a scenario's first unit starts, the next
//! scenario's demo is recorded (or loaded) ahead, so a free slot never waits on one
//! scenario's recording.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use nesy_core::benchmark::Factor;
use nesy_core::format_procedure;
use nesy_pipeline::states::StateSource;
use nesy_pipeline::synth::{CodegenMode, SandboxChecks, SynthError, SynthesisRequest};
use nesy_pipeline::{
    AdaptOptions, DemoInput, DemoKeyframes, TargetInput, derive_setting, execute, output, synth, vlm,
};
use nesy_policy::{Limits, WorkerCommand};
use nesy_reasoner::VlmReasoner;
use nesy_reasoner::codegen::CodeGenerationRequest;
use nesy_sim::tasks::scenario::{self, ConfigFile, Scenario, Side};
use nesy_vlm::CassetteFile;
use nesy_vlm::{
    CassetteMode, CassetteOptions, CassetteTransport, ConfigOverrides, ProcessEnv, Transport, VlmClient,
    VlmConfig,
};
use serde::Serialize;
use tokio::sync::Semaphore;

use crate::demos::{CachedDemo, DemoCache};
use crate::error::BenchError;
use crate::manifest::{MANIFEST_VERSION, Manifest, Provenance, Responder, RunSettings, VariantEntry};
use crate::meter::{CallCounts, Metered};
use crate::methods::{self, Method, MethodFailure, OfflineMeaning, Specification, Specified, UnitInputs};
use crate::record::{Agreement, Effort, Scores, SpecSummary, SubtaskScore, UnitRecord, UnitStatus};
use crate::shard::Shard;
use crate::store::{self, ResultsWriter};
use crate::study::Study;
use crate::unit::{Selection, Unit, UnitKey, units};
use crate::variant::{Variant, config_hash, hex};

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

/// The suite a run uses: the folder's when given, else the complexity-gap suite for a study
/// that runs on it, else the 440.
pub fn run_suite(dir: Option<&Path>, study: Option<Study>) -> Result<Vec<ConfigFile>, BenchError> {
    match (dir, study) {
        (None, Some(s)) if s.uses_gap_suite() => Ok(scenario::generate_gap_suite()),
        _ => load_suite(dir),
    }
}

fn suite_hash(files: &[ConfigFile]) -> String {
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
            &responder,
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

/// The noise knobs of a variant's `noise` setting (`;` or `,` between knobs).
pub fn noise_of(spec: &str) -> Result<nesy_oracle::OracleNoise, BenchError> {
    spec.replace(';', ",")
        .parse()
        .map_err(|e| BenchError::Usage(format!("noise={spec:?}: {e}")))
}

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
struct ScenarioInputs {
    demo: Arc<DemoInput>,
    keyframes: Arc<DemoKeyframes>,
    target: Arc<TargetInput>,
    cached: CachedDemo,
}

/// A scenario's inputs, filled by the first unit that needs them.
type ScenarioSlot = Arc<tokio::sync::OnceCell<Result<Arc<ScenarioInputs>, String>>>;

/// A unit's client and the counts of its calls.
type UnitClient = (VlmClient, Arc<Mutex<CallCounts>>);

/// What every unit of the run shares.
struct Shared {
    config: RunConfig,
    manifest: Manifest,
    cache: DemoCache,
    cpu: Arc<Semaphore>,
    model: Arc<Semaphore>,
    live: Option<(VlmConfig, Arc<dyn Transport>)>,
    /// Scenario inputs by id; each slot is filled once, under its own lock.
    scenarios: Mutex<HashMap<String, ScenarioSlot>>,
    /// Cost so far (US$).
    cost: Mutex<f64>,
}

/// Runs the pending units of `config.shard`, appending a record per unit.
pub async fn run(
    config: RunConfig,
    progress: Arc<dyn BenchProgress>,
    stop: StopSignal,
) -> Result<RunSummary, BenchError> {
    let started = Instant::now();
    let prepared = prepare(&config)?;
    prepared.manifest.write_or_check(&config.run_dir)?;
    let manifest = Manifest::read(&config.run_dir)?;
    let done = final_records(&config.run_dir)?;
    let hashes: HashMap<&str, &str> = manifest
        .variants
        .iter()
        .map(|v| (v.id.as_str(), v.config_hash.as_str()))
        .collect();
    for r in done.values() {
        if hashes.get(r.key.variant.as_str()) != Some(&r.config_hash.as_str()) {
            return Err(BenchError::Mismatch {
                path: store::results_dir(&config.run_dir),
                message: format!(
                    "unit {} was recorded with another configuration (hash {}); use a new run directory",
                    r.key.name(),
                    r.config_hash
                ),
            });
        }
    }
    let mine = config.shard.select(&prepared.units);
    let pending: Vec<Unit> = mine
        .iter()
        .filter(|u| !done.contains_key(&u.key.name()))
        .cloned()
        .collect();
    progress.start(mine.len(), pending.len());
    let live = match &config.responder {
        ResponderSetup::Live(overrides) => {
            let c = VlmConfig::resolve(overrides, &ProcessEnv)
                .map_err(|e| BenchError::Usage(format!("resolving the VLM configuration: {e}")))?;
            let http = VlmClient::http_transport(&c).map_err(|e| BenchError::Usage(e.to_string()))?;
            Some((c, Arc::new(http) as Arc<dyn Transport>))
        }
        _ => None,
    };
    let shared = Arc::new(Shared {
        cache: DemoCache::new(&config.demo_cache, config.settings.image_size),
        cpu: Arc::new(Semaphore::new(config.cpu_jobs.max(1))),
        model: Arc::new(Semaphore::new(config.model_jobs.max(1))),
        live,
        scenarios: Mutex::new(HashMap::new()),
        cost: Mutex::new(0.0),
        manifest,
        config: config.clone(),
    });
    let mut writer = ResultsWriter::open(&store::shard_file(&config.run_dir, config.shard))?;
    let mut statuses: BTreeMap<String, usize> = BTreeMap::new();
    let mut stopped = None;
    let mut queue: std::collections::VecDeque<Unit> = pending.into();
    let mut set: tokio::task::JoinSet<(UnitKey, UnitRecord)> = tokio::task::JoinSet::new();
    // The next scenario's inputs are prepared while this one's units run: the units of one
    // scenario wait on its single recording, which kept every other core idle in a cold run.
    // Dropped at the end of the run, which aborts what is still pending.
    let mut prefetch: tokio::task::JoinSet<()> = tokio::task::JoinSet::new();
    let mut prefetched: std::collections::HashSet<String> = std::collections::HashSet::new();
    let mut in_flight: HashMap<String, Unit> = HashMap::new();
    let (mut finished, mut errors) = (0usize, 0usize);
    let total_pending = queue.len();
    loop {
        while set.len() < config.jobs.max(1) && stopped.is_none() {
            if stop.is_stopped() {
                stopped = Some("interrupted".to_owned());
                break;
            }
            if let Some(limit) = config.max_cost_usd
                && *shared.cost.lock().unwrap_or_else(|e| e.into_inner()) >= limit
            {
                stopped = Some(format!("the cost guard: US$ {limit} reached (--max-cost-usd)"));
                break;
            }
            if let Some(rate) = config.max_error_rate
                && finished >= 10
                && errors as f64 / finished as f64 > rate
            {
                stopped = Some(format!(
                    "the error guard: {errors} of {finished} finished units failed to reach the model (--max-error-rate {rate})"
                ));
                break;
            }
            let Some(unit) = queue.pop_front() else { break };
            prefetched.insert(unit.scenario.id.clone());
            if let Some(next) = queue.iter().find(|u| u.scenario.id != unit.scenario.id)
                && prefetched.insert(next.scenario.id.clone())
            {
                let (shared, scenario) = (shared.clone(), next.scenario.clone());
                prefetch.spawn(async move {
                    // A failure is stored in the scenario's slot and reported by its units.
                    let _ = scenario_inputs(&shared, &scenario).await;
                });
            }
            let shared = shared.clone();
            in_flight.insert(unit.key.name(), unit.clone());
            set.spawn(async move {
                let key = unit.key.clone();
                let record = run_unit(&shared, &unit).await;
                (key, record)
            });
        }
        if let Some(reason) = &stopped
            && reason == "interrupted"
        {
            // Units in flight are recorded as interrupted and run again on resume.
            set.abort_all();
            for unit in in_flight.values() {
                let record = failed_record(
                    &shared,
                    unit,
                    UnitStatus::Interrupted,
                    "the run was stopped".into(),
                    Effort::default(),
                );
                writer.append(&record)?;
                *statuses.entry(record.status.as_str().into()).or_default() += 1;
            }
            break;
        }
        let Some(joined) = set.join_next().await else {
            break;
        };
        let (key, record) = match joined {
            Ok(pair) => pair,
            Err(e) if e.is_cancelled() => continue,
            Err(e) => {
                return Err(BenchError::Usage(format!("a unit task ended abnormally: {e}")));
            }
        };
        in_flight.remove(&key.name());
        writer.append(&record)?;
        finished += 1;
        if matches!(
            record.status,
            UnitStatus::TransportError | UnitStatus::RequestRefused
        ) {
            errors += 1;
        }
        *shared.cost.lock().unwrap_or_else(|e| e.into_inner()) += record.effort.cost_usd;
        *statuses.entry(record.status.as_str().into()).or_default() += 1;
        progress.unit_done(&record, finished, total_pending);
        if stop.is_stopped() && stopped.is_none() {
            stopped = Some("interrupted".to_owned());
        }
    }
    if let Some(reason) = &stopped {
        progress.note(&format!(
            "stopped by {reason}; run the same command again to resume"
        ));
    }
    Ok(RunSummary {
        shard_units: mine.len(),
        skipped: mine.len() - total_pending,
        ran: finished,
        statuses,
        stopped,
        wall_s: started.elapsed().as_secs_f64(),
    })
}

fn unit_dir(shared: &Shared, unit: &Unit) -> PathBuf {
    shared
        .config
        .run_dir
        .join("units")
        .join(unit.key.folder(&unit.variant))
}

/// `ROOT/<scenario>/<variant>[.r<k>].json`. The suffix is appended, not set: a variant id
/// holds dots (`noise=op-drop=0.1`) and a repeat ends in `.r<k>`, and `set_extension` would
/// replace either, so two units would share one recording.
fn cassette_path(unit: &Unit, root: &Path) -> PathBuf {
    recording_path(&unit.key, &unit.variant, root)
}

fn recording_path(key: &crate::unit::UnitKey, variant: &Variant, root: &Path) -> PathBuf {
    let mut p = root.join(key.folder(variant)).into_os_string();
    p.push(".json");
    PathBuf::from(p)
}

/// The target scene's goal label and subtask names, for units that never executed.
fn target_label(unit: &Unit) -> (Vec<String>, Vec<String>) {
    match unit.scenario.generate(Side::Target) {
        Ok(t) => (
            t.goal_label,
            t.scene
                .goals
                .iter()
                .map(|g| g.kind().as_str().to_owned())
                .collect(),
        ),
        Err(_) => (Vec::new(), Vec::new()),
    }
}

fn failed_record(
    shared: &Shared,
    unit: &Unit,
    status: UnitStatus,
    error: String,
    effort: Effort,
) -> UnitRecord {
    let (label, subtasks) = target_label(unit);
    base_record(
        shared,
        unit,
        status,
        Some(error),
        Scores::not_executed(label, &subtasks),
        effort,
    )
}

fn base_record(
    shared: &Shared,
    unit: &Unit,
    status: UnitStatus,
    error: Option<String>,
    scores: Scores,
    effort: Effort,
) -> UnitRecord {
    UnitRecord {
        key: unit.key.clone(),
        method: unit.variant.method.clone(),
        factor: unit.factor(),
        complexity: unit.complexity(),
        added_subtasks: unit.scenario.added_subtasks,
        obstruction_change: unit.scenario.obstruction_change(),
        seed: unit.seed,
        config_hash: shared
            .manifest
            .variant(&unit.key.variant)
            .map(|v| v.config_hash.clone())
            .unwrap_or_default(),
        status,
        error,
        scores,
        spec: None,
        states: None,
        effort,
        artifacts: Path::new("units")
            .join(unit.key.folder(&unit.variant))
            .to_string_lossy()
            .into_owned(),
        finished_at: nesy_vlm::now_rfc3339(),
    }
}

/// Runs a blocking, CPU-bound closure on the blocking pool under a CPU slot.
async fn cpu<T: Send + 'static>(
    shared: &Shared,
    f: impl FnOnce() -> T + Send + 'static,
) -> Result<T, String> {
    let _slot = shared.cpu.acquire().await.map_err(|e| e.to_string())?;
    tokio::task::spawn_blocking(f).await.map_err(|e| e.to_string())
}

/// The scenario's demo and target, loaded (and the demo recorded) at most once.
async fn scenario_inputs(shared: &Arc<Shared>, scenario: &Scenario) -> Result<Arc<ScenarioInputs>, String> {
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
            let cached = cache.ensure(&s, 1).map_err(|e| e.to_string())?;
            let demo = DemoInput::load(&cached.demo).map_err(|e| e.to_string())?;
            let target = TargetInput::load(Some(&cached.target), &demo).map_err(|e| e.to_string())?;
            let keyframes = DemoKeyframes::from_demo(&demo).map_err(|e| e.to_string())?;
            Ok(ScenarioInputs {
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

/// The unit's client: its responder under the meter. The offline responder is given the
/// demonstration's recorded robot calls.
fn unit_client(shared: &Shared, unit: &Unit, demo: &DemoInput) -> Result<UnitClient, (UnitStatus, String)> {
    let config = &shared.config;
    let (client_config, base): (VlmConfig, Arc<dyn Transport>) = match &config.responder {
        ResponderSetup::Oracle => {
            let noise = unit.variant.option("noise").unwrap_or("").replace(';', ",");
            let transport = vlm::oracle_transport(&noise, unit.seed, demo.recorded_calls())
                .map_err(|e| (UnitStatus::MethodError, e.to_string()))?;
            let transport: Arc<dyn Transport> = if config.record_cassettes {
                let path = cassette_path(unit, &config.run_dir.join("cassettes"));
                record_to(&path, transport, &vlm::oracle_config())?
            } else {
                transport
            };
            (vlm::oracle_config(), transport)
        }
        ResponderSetup::Replay(dir) => {
            let path = cassette_path(unit, dir);
            if !path.is_file() {
                return Err((
                    UnitStatus::TransportError,
                    format!("{}: no recorded cassette for this unit", path.display()),
                ));
            }
            let file = CassetteFile::load(&path).map_err(|e| (UnitStatus::TransportError, e.to_string()))?;
            let c =
                vlm::replay_config(&path, &file).map_err(|e| (UnitStatus::TransportError, e.to_string()))?;
            let options = CassetteOptions {
                allow_playback_repeats: true,
                ..CassetteOptions::default()
            };
            let t = CassetteTransport::open(&path, CassetteMode::None, None, options)
                .map_err(|e| (UnitStatus::TransportError, e.to_string()))?;
            (c, Arc::new(t))
        }
        ResponderSetup::Live(_) => {
            let (c, http) = shared
                .live
                .clone()
                .ok_or_else(|| (UnitStatus::MethodError, "no live client".into()))?;
            let path = cassette_path(unit, &config.run_dir.join("cassettes"));
            let t = record_to(&path, http, &c)?;
            (c, t)
        }
    };
    let metered = Metered::new(base, config.settings.max_calls_per_unit, shared.model.clone());
    let counts = metered.counts();
    Ok((
        VlmClient::with_transport(&client_config, Arc::new(metered)),
        counts,
    ))
}

/// A cassette at `path` recording (new episodes; replaying what it already holds) around
/// `inner`, with the key redacted.
fn record_to(
    path: &Path,
    inner: Arc<dyn Transport>,
    config: &VlmConfig,
) -> Result<Arc<dyn Transport>, (UnitStatus, String)> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .map_err(|e| (UnitStatus::MethodError, format!("{}: {e}", dir.display())))?;
    }
    let t = CassetteTransport::open(
        path,
        CassetteMode::NewEpisodes,
        Some(inner),
        CassetteOptions {
            model: Some(config.model.clone()),
            backend: Some(config.backend.as_str().to_owned()),
            redact: config.api_key.iter().cloned().collect(),
            ..CassetteOptions::default()
        },
    )
    .map_err(|e| (UnitStatus::MethodError, e.to_string()))?;
    Ok(Arc::new(t))
}

/// The code of a specification: the template compiler, or the model's code generation.
async fn make_code(
    client: &VlmClient,
    inputs: &UnitInputs,
    specified: &Specified,
) -> Result<(String, f64, f64), (UnitStatus, String)> {
    let started = Instant::now();
    let target = &inputs.target;
    let mut instruction = target.instruction(&inputs.demo);
    let (procedure, plan) = match &specified.spec {
        Specification::Procedure { procedure, .. } => (procedure.clone(), Vec::new()),
        Specification::Plan {
            steps,
            instruction: rewritten,
        } => {
            if let Some(rewritten) = rewritten {
                instruction = rewritten.clone();
            }
            (Vec::new(), steps.clone())
        }
    };
    match specified.codegen {
        CodegenMode::Template => {
            let request = SynthesisRequest {
                instruction,
                objects: target.objects.clone(),
                procedure,
                source: inputs.setting.source_embodiment,
                target: inputs.setting.target_embodiment,
                scene: &target.scene,
            };
            let reasoner =
                VlmReasoner::new(client.clone()).map_err(|e| (UnitStatus::MethodError, e.to_string()))?;
            let p = synth::synthesize(&reasoner, CodegenMode::Template, &request)
                .await
                .map_err(|e| synth_status(&e))?;
            Ok((p.code, 0.0, started.elapsed().as_secs_f64()))
        }
        CodegenMode::Vlm => {
            let reasoner = VlmReasoner::new(client.clone())
                .map_err(|e| (UnitStatus::MethodError, e.to_string()))?
                .with_embodiments(inputs.setting.source_embodiment, inputs.setting.target_embodiment)
                .with_program_check(Arc::new(SandboxChecks));
            let request = CodeGenerationRequest {
                instruction,
                objects: target.objects.clone(),
                procedure,
                plan,
                embodiment: inputs.setting.target_embodiment,
                // The authors' rule: the extended prompt for the embodiment factors and for
                // Combination (whose scenarios may change the end effector).
                extended: matches!(inputs.setting.factor, Factor::Grip | Factor::Vacu | Factor::Comb)
                    || inputs.setting.source_embodiment != inputs.setting.target_embodiment,
            };
            let source = reasoner.generate_code(&request).await.map_err(|e| {
                let failure = MethodFailure::from_reasoner(e.reasoner_kind(), e.to_string());
                let status = if failure.status == UnitStatus::MethodError {
                    UnitStatus::CodegenFailed
                } else {
                    failure.status
                };
                (status, failure.message)
            })?;
            Ok((source.code, started.elapsed().as_secs_f64(), 0.0))
        }
    }
}

fn synth_status(e: &SynthError) -> (UnitStatus, String) {
    match e {
        SynthError::NoProgram { message, .. } => (UnitStatus::CodegenFailed, message.clone()),
        SynthError::Call { message, failure } => {
            let f = MethodFailure::from_reasoner(*failure, message.clone());
            (f.status, f.message)
        }
    }
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("writing {}: {e}", path.display()))
}

fn write_json(path: &Path, value: &impl Serialize) -> Result<(), String> {
    write(
        path,
        &(serde_json::to_string_pretty(value).unwrap_or_default() + "\n"),
    )
}

fn agreement(states: &Option<StateSource>) -> Option<Agreement> {
    match states {
        Some(StateSource::Vlm {
            agreement: Some(a), ..
        }) => Some(*a),
        _ => None,
    }
}

/// Runs one unit to its record. Never fails: every failure becomes the unit's status.
async fn run_unit(shared: &Arc<Shared>, unit: &Unit) -> UnitRecord {
    let started = Instant::now();
    let mut effort = Effort::default();
    let inputs = match scenario_inputs(shared, &unit.scenario).await {
        Ok(i) => i,
        Err(e) => {
            return failed_record(
                shared,
                unit,
                UnitStatus::MethodError,
                format!("preparing the scenario: {e}"),
                effort,
            );
        }
    };
    if !inputs.cached.record.usable() && !shared.config.settings.keep_gapped_demos {
        let why = inputs.cached.record.unusable_reason().unwrap_or_default();
        return failed_record(shared, unit, UnitStatus::DemoUnusable, why, effort);
    }
    let dir = unit_dir(shared, unit);
    if let Err(e) = std::fs::create_dir_all(&dir) {
        return failed_record(
            shared,
            unit,
            UnitStatus::MethodError,
            format!("{}: {e}", dir.display()),
            effort,
        );
    }
    let setting = derive_setting(&inputs.demo, &inputs.target, &AdaptOptions::default());
    let unit_inputs = UnitInputs {
        demo: inputs.demo.clone(),
        keyframes: inputs.keyframes.clone(),
        target: inputs.target.clone(),
        setting,
        variant: unit.variant.clone(),
        seed: unit.seed,
    };
    let (client, counts) = match unit_client(shared, unit, &inputs.demo) {
        Ok(c) => c,
        Err((status, e)) => return failed_record(shared, unit, status, e, effort),
    };

    // Phase A: the specification and its code (or the earlier run's, when re-executing).
    let phase_a = match &shared.config.reexecute {
        Some(source) => reexecuted(source, unit),
        None => specify_and_code(&client, &unit_inputs, &dir, unit).await,
    };
    let usage = client.finish().ok();
    let c = counts.lock().unwrap_or_else(|e| e.into_inner()).clone();
    effort.calls = c.calls;
    effort.images = c.images;
    effort.calls_by_purpose = c.by_purpose.clone();
    if let Some(u) = &usage {
        effort.tokens = u.total.prompt_tokens + u.total.completion_tokens;
        effort.cost_usd = u.total.cost_usd;
        effort.cost_by_purpose = u
            .by_purpose
            .iter()
            .filter(|(_, t)| t.cost_usd > 0.0)
            .map(|(purpose, t)| (purpose.clone(), t.cost_usd))
            .collect();
    }
    let (code, mut record_base) = match phase_a {
        Ok(a) => a,
        Err((status, message, summary)) => {
            let status = if c.cap_reached {
                UnitStatus::MethodError
            } else {
                status
            };
            effort.wall_s = started.elapsed().as_secs_f64();
            let mut r = failed_record(shared, unit, status, message, effort);
            r.spec = summary;
            return r;
        }
    };
    effort.vlm_s = record_base.vlm_s;
    effort.symbolic_s = record_base.symbolic_s.0;
    effort.symbolic_world_model_s = record_base.symbolic_s.1;
    effort.codegen_template_s = record_base.template_s;

    // Phase B: execution in the sandboxed simulator.
    let target = inputs.target.clone();
    let worker = shared.config.worker.clone();
    let limits = Limits {
        wall_time_ms: shared.config.settings.policy_wall_ms,
        ..Limits::default()
    };
    let exec_dir = dir.clone();
    let executed = cpu(shared, move || {
        let scene = output::prepare_dir(&exec_dir, &target, None).map_err(|e| e.to_string())?;
        write(&exec_dir.join(output::POLICY_FILE), &code)?;
        execute::execute(&worker, &code, &scene, &limits).map_err(|e| e.to_string())
    })
    .await
    .and_then(|r| r);
    effort.sim_s = inputs.target.sim_time.as_secs_f64();
    let report = match executed {
        Ok(r) => r,
        Err(e) => {
            effort.wall_s = started.elapsed().as_secs_f64();
            let mut r = failed_record(shared, unit, UnitStatus::ExecutionFailed, e, effort);
            r.spec = record_base.spec.take();
            return r;
        }
    };
    effort.sim_s += report.result.wall_time_s;
    let _ = write_json(&dir.join(output::EXECUTION_FILE), &report);
    let (label, subtask_names) = target_label(unit);
    let scores = match &report.metrics {
        Some(m) => Scores {
            sr: m.sr,
            gc: m.gc,
            latched_sr: m.latched_sr,
            latched_gc: m.latched_gc,
            pd: m.pd.unwrap_or(0.0),
            label: m.label.clone(),
            achieved: m.achieved.clone(),
            subtasks: m
                .subtasks
                .iter()
                .map(|s| SubtaskScore {
                    subtask: s.subtask.clone(),
                    result: s.status,
                    displaced: s.displaced.clone(),
                })
                .collect(),
        },
        None => Scores::not_executed(label, &subtask_names),
    };
    let (status, error) = if report.success() {
        (UnitStatus::Succeeded, None)
    } else {
        let why = match &report.result.outcome {
            nesy_policy::Outcome::Ok => {
                let failed: Vec<String> = report
                    .metrics
                    .iter()
                    .flat_map(|m| &m.subtasks)
                    .filter(|s| !s.status.is_success() || !s.displaced.is_empty())
                    .map(|s| {
                        if s.displaced.is_empty() {
                            format!("{} {}", s.subtask, s.status)
                        } else {
                            format!("{} displaced {}", s.subtask, s.displaced.join(" "))
                        }
                    })
                    .collect();
                format!("the policy ran to its end; {}", failed.join(", "))
            }
            nesy_policy::Outcome::PythonError(e) => {
                format!(
                    "the policy raised {}: {}{}",
                    e.exception,
                    e.message,
                    e.line
                        .map(|l| format!(" (policy.py line {l})"))
                        .unwrap_or_default()
                )
            }
            other => format!("the policy ended with {}", other.kind()),
        };
        (UnitStatus::ExecutionFailed, Some(why))
    };
    effort.wall_s = started.elapsed().as_secs_f64();
    let mut r = base_record(shared, unit, status, error, scores, effort);
    r.spec = record_base.spec.take();
    r.states = record_base.states;
    r
}

/// What phase A hands to phase B besides the code.
struct PhaseA {
    spec: Option<SpecSummary>,
    states: Option<Agreement>,
    vlm_s: f64,
    symbolic_s: (f64, f64),
    template_s: f64,
}

type PhaseAFailure = (UnitStatus, String, Option<SpecSummary>);

async fn specify_and_code(
    client: &VlmClient,
    inputs: &UnitInputs,
    dir: &Path,
    unit: &Unit,
) -> Result<(String, PhaseA), PhaseAFailure> {
    let method: Arc<dyn Method> =
        methods::find(&unit.variant.method).map_err(|e| (UnitStatus::MethodError, e.to_string(), None))?;
    let specified = match method.specify(inputs, client).await {
        Ok(s) => s,
        Err(f) => {
            if let Some(a) = &f.adaptation {
                let _ = write_json(&dir.join(output::ADAPTATION_FILE), a.as_ref());
            }
            let summary = f.iterations.map(|(iterations, budget)| SpecSummary {
                kind: "none".into(),
                steps: 0,
                verified: false,
                iterations: Some(iterations),
                budget: Some(budget),
            });
            return Err((f.status, f.message, summary));
        }
    };
    let summary = SpecSummary {
        kind: specified.spec.kind().into(),
        steps: specified.spec.len(),
        verified: matches!(specified.spec, Specification::Procedure { verified: true, .. }),
        iterations: specified.iterations.map(|i| i.0),
        budget: specified.iterations.map(|i| i.1),
    };
    let spec_text = match &specified.spec {
        Specification::Procedure { procedure, .. } => format_procedure(procedure),
        Specification::Plan { steps, .. } => steps
            .iter()
            .enumerate()
            .map(|(i, s)| format!("{}. {s}", i + 1))
            .collect::<Vec<_>>()
            .join("\n"),
    };
    let _ = write_json(
        &dir.join("spec.json"),
        &serde_json::json!({
            "summary": summary,
            "text": spec_text,
            "notes": specified.notes,
        }),
    );
    if let Some(a) = &specified.adaptation {
        let _ = write_json(&dir.join(output::ADAPTATION_FILE), a);
    }
    let (code, vlm_code_s, template_s) = make_code(client, inputs, &specified)
        .await
        .map_err(|(s, m)| (s, m, Some(summary.clone())))?;
    Ok((
        code,
        PhaseA {
            spec: Some(summary),
            states: agreement(&specified.states),
            vlm_s: specified.vlm_s + vlm_code_s,
            symbolic_s: specified.symbolic_s,
            template_s,
        },
    ))
}

/// Phase A of an earlier run: its stored program, or its failure carried over.
fn reexecuted(source: &Path, unit: &Unit) -> Result<(String, PhaseA), PhaseAFailure> {
    let records = final_records(source).map_err(|e| (UnitStatus::MethodError, e.to_string(), None))?;
    let old = records.get(&unit.key.name()).ok_or_else(|| {
        (
            UnitStatus::MethodError,
            format!(
                "{}: has no final record of this unit to re-execute",
                source.display()
            ),
            None,
        )
    })?;
    let policy = source.join(&old.artifacts).join(output::POLICY_FILE);
    match std::fs::read_to_string(&policy) {
        Ok(code)
            if !matches!(
                old.status,
                UnitStatus::Unresolved
                    | UnitStatus::CodegenFailed
                    | UnitStatus::MethodError
                    | UnitStatus::DemoUnusable
                    | UnitStatus::RequestRefused
            ) =>
        {
            Ok((
                code,
                PhaseA {
                    spec: old.spec.clone(),
                    states: old.states,
                    vlm_s: old.effort.vlm_s,
                    symbolic_s: (old.effort.symbolic_s, old.effort.symbolic_world_model_s),
                    template_s: old.effort.codegen_template_s,
                },
            ))
        }
        _ => Err((
            old.status,
            old.error
                .clone()
                .unwrap_or_else(|| "no program in the re-executed run".into()),
            old.spec.clone(),
        )),
    }
}

/// Units of a run that have no final record yet, by name.
pub fn missing_units(manifest: &Manifest, records: &HashMap<String, UnitRecord>) -> Vec<String> {
    manifest
        .units
        .iter()
        .map(UnitKey::name)
        .filter(|n| !records.contains_key(n))
        .collect()
}

/// A short id for a run directory from the clock: `YYYYMMDD-HHMMSS`.
pub fn default_run_id() -> String {
    nesy_vlm::now_rfc3339()
        .replace(['-', ':'], "")
        .replace('T', "-")
        .trim_end_matches('Z')
        .to_owned()
}

/// A digest of a file's bytes, for artifacts named in reports.
pub fn file_digest(path: &Path) -> Option<String> {
    use sha2::Digest as _;
    std::fs::read(path).ok().map(|b| hex(&sha2::Sha256::digest(&b)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::unit::UnitKey;

    #[test]
    fn every_unit_has_its_own_recording() {
        let root = Path::new("/c");
        let path = |variant: &str, repeat: u32| {
            let v = Variant::parse(variant).unwrap();
            let key = UnitKey {
                scenario: "obst_low_00_s0".to_owned(),
                variant: v.id(),
                repeat,
            };
            recording_path(&key, &v, root)
        };
        let paths = [
            path("nesycr", 0),
            path("nesycr", 1),
            path("nesycr", 2),
            path("nesycr+noise=op-drop=0.1", 0),
            path("nesycr+noise=op-drop=0.2", 0),
        ];
        for (i, a) in paths.iter().enumerate() {
            assert_eq!(a.extension().and_then(|e| e.to_str()), Some("json"), "{a:?}");
            for b in &paths[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }
}
