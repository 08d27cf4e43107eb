//! Scheduling a run: the pending units of this shard, the CPU and model slots they share,
//! each scenario's inputs loaded once, and one result line per finished unit.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use nesy_vlm::{ProcessEnv, Transport, VlmClient, VlmConfig};
use tokio::sync::Semaphore;

use crate::demos::DemoCache;
use crate::error::BenchError;
use crate::manifest::Manifest;
use crate::status::UnitStatus;
use crate::store::{self, ResultsWriter};
use crate::unit::{Unit, UnitKey};
use crate::unit_record::{Effort, UnitRecord};

use super::config::{BenchProgress, ResponderSetup, RunConfig, RunSummary, StopSignal, prepare};
use super::shared::{Shared, final_records, scenario_inputs};
use super::unit::{failed_record, run_unit};

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
    check_configurations(&config.run_dir, &manifest, &done)?;
    let mine = config.shard.select(&prepared.units);
    let pending: Vec<Unit> = mine
        .iter()
        .filter(|u| !done.contains_key(&u.key.name()))
        .cloned()
        .collect();
    progress.start(mine.len(), pending.len());
    let live = live_transport(&config.responder)?;
    let shared = Arc::new(Shared {
        cache: DemoCache::new(&config.demo_cache, config.settings.image_size)
            .with_protective_stop(config.settings.protective_stop),
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
    let mut prefetch = Prefetch::default();
    let mut in_flight: HashMap<String, Unit> = HashMap::new();
    let (mut finished, mut errors) = (0usize, 0usize);
    let total_pending = queue.len();
    loop {
        while set.len() < config.jobs.max(1) && stopped.is_none() {
            if let Some(reason) = stop_reason(&config, &stop, &shared, finished, errors) {
                stopped = Some(reason);
                break;
            }
            let Some(unit) = queue.pop_front() else { break };
            prefetch.next_scenario(&shared, &unit, &queue);
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
            record_interrupted(&shared, in_flight.values(), &mut writer, &mut statuses)?;
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
        errors += usize::from(reached_no_model(record.status));
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

/// Whether a unit ended without reaching the model (what the error guard counts).
fn reached_no_model(status: UnitStatus) -> bool {
    matches!(status, UnitStatus::TransportError | UnitStatus::RequestRefused)
}

/// The next scenario's inputs, prepared while this one's units run.
#[derive(Default)]
struct Prefetch {
    /// Dropped at the end of the run, which aborts what is still pending.
    tasks: tokio::task::JoinSet<()>,
    /// Scenarios already started or prefetched.
    seen: std::collections::HashSet<String>,
}

impl Prefetch {
    /// Starts preparing the first scenario after `unit`'s in the queue, once.
    fn next_scenario(&mut self, shared: &Arc<Shared>, unit: &Unit, queue: &std::collections::VecDeque<Unit>) {
        self.seen.insert(unit.scenario.id.clone());
        if let Some(next) = queue.iter().find(|u| u.scenario.id != unit.scenario.id)
            && self.seen.insert(next.scenario.id.clone())
        {
            let (shared, scenario) = (shared.clone(), next.scenario.clone());
            self.tasks.spawn(async move {
                // A failure is stored in the scenario's slot and reported by its units.
                let _ = scenario_inputs(&shared, &scenario).await;
            });
        }
    }
}

/// Refuses a run directory whose recorded units were made under another configuration of
/// their variant: mixing them would score two configurations as one.
fn check_configurations(
    run_dir: &Path,
    manifest: &Manifest,
    done: &HashMap<String, UnitRecord>,
) -> Result<(), BenchError> {
    let hashes: HashMap<&str, &str> = manifest
        .variants
        .iter()
        .map(|v| (v.id.as_str(), v.config_hash.as_str()))
        .collect();
    for r in done.values() {
        if hashes.get(r.key.variant.as_str()) != Some(&r.config_hash.as_str()) {
            return Err(BenchError::Mismatch {
                path: store::results_dir(run_dir),
                message: format!(
                    "unit {} was recorded with another configuration (hash {}); use a new run directory",
                    r.key.name(),
                    r.config_hash
                ),
            });
        }
    }
    Ok(())
}

/// The configuration and the HTTP transport every unit shares, for a live responder.
type LiveTransport = (VlmConfig, Arc<dyn Transport>);

/// The HTTP transport every unit shares, for a live responder.
fn live_transport(responder: &ResponderSetup) -> Result<Option<LiveTransport>, BenchError> {
    Ok(match responder {
        ResponderSetup::Live(overrides) => {
            let c = VlmConfig::resolve(overrides, &ProcessEnv)
                .map_err(|e| BenchError::Usage(format!("resolving the VLM configuration: {e}")))?;
            let http = VlmClient::http_transport(&c).map_err(|e| BenchError::Usage(e.to_string()))?;
            Some((c, Arc::new(http) as Arc<dyn Transport>))
        }
        _ => None,
    })
}

/// Why no further unit may start: the run was stopped, the cost guard or the error guard
/// was reached.
fn stop_reason(
    config: &RunConfig,
    stop: &StopSignal,
    shared: &Shared,
    finished: usize,
    errors: usize,
) -> Option<String> {
    if stop.is_stopped() {
        return Some("interrupted".to_owned());
    }
    if let Some(limit) = config.max_cost_usd
        && *shared.cost.lock().unwrap_or_else(|e| e.into_inner()) >= limit
    {
        return Some(format!("the cost guard: US$ {limit} reached (--max-cost-usd)"));
    }
    if let Some(rate) = config.max_error_rate
        && finished >= 10
        && errors as f64 / finished as f64 > rate
    {
        return Some(format!(
            "the error guard: {errors} of {finished} finished units failed to reach the model (--max-error-rate {rate})"
        ));
    }
    None
}

/// Records the units in flight when the run was stopped as interrupted, to run again on
/// resume.
fn record_interrupted<'a>(
    shared: &Shared,
    in_flight: impl Iterator<Item = &'a Unit>,
    writer: &mut ResultsWriter,
    statuses: &mut BTreeMap<String, usize>,
) -> Result<(), BenchError> {
    for unit in in_flight {
        let record = failed_record(
            shared,
            unit,
            UnitStatus::Interrupted,
            "the run was stopped".into(),
            Effort::default(),
        );
        writer.append(&record)?;
        *statuses.entry(record.status.as_str().into()).or_default() += 1;
    }
    Ok(())
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
