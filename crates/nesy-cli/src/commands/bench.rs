//! `nesy bench`: the benchmark harness (`nesy_bench`) from the command line. This module
//! only parses flags, owns the runtime and shows progress.

use std::collections::BTreeMap;
use std::io::IsTerminal as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use anyhow::Context as _;
use nesy_bench::demos::DemoCache;
use nesy_bench::harness::{self, Prepared};
use nesy_bench::harness::{BenchProgress, ResponderSetup, RunConfig, StopSignal};
use nesy_bench::manifest::{Manifest, Observation, RunSettings};
use nesy_bench::methods::{self, OfflineMeaning, Role};
use nesy_bench::studies::Study;
use nesy_bench::{Selection, Shard, UnitRecord, UnitStatus};
use nesy_policy::WorkerCommand;
use nesy_vlm::ConfigOverrides;

use super::OnOff;

/// Arguments of `nesy bench`.
#[derive(Debug, clap::Args)]
pub(crate) struct BenchArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: BenchAction,
}

/// The `nesy bench` subcommands.
#[derive(Debug, clap::Subcommand)]
pub(crate) enum BenchAction {
    /// Run (or resume) a benchmark: every pending unit of a shard, one JSON line each; with
    /// every unit done, the report.
    Run(Box<RunArgs>),
    /// Record every selected scenario's demonstration into the demo cache.
    Demos(DemosArgs),
    /// Print the model calls and images a run would make, per method and cell.
    Plan(Box<RunArgs>),
    /// Summarise a run in progress or finished.
    Status {
        /// The run directory.
        run: PathBuf,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Check that every unit of a (sharded) run has exactly one final record, then write the
    /// report.
    Merge {
        /// The run directory.
        run: PathBuf,
        /// Write a report stamped PARTIAL although units are missing.
        #[arg(long)]
        allow_partial: bool,
    },
    /// Write the report of a run (the same checks as `merge`).
    Report {
        /// The run directory.
        run: PathBuf,
        /// Write a report stamped PARTIAL although units are missing.
        #[arg(long)]
        allow_partial: bool,
    },
    /// Write Slurm job-array files for a run: `run.sbatch` (one task per shard) and
    /// `merge.sbatch`.
    Slurm(SlurmArgs),
    /// Is B better than A? Pairs two runs' units (or two variants of one run) by scenario
    /// and repeat, and prints per cell and overall both success rates with 95 % Wilson
    /// intervals, the difference with McNemar's exact test, and the units that changed.
    Compare(CompareArgs),
    /// List the methods and controls with their classes and settings.
    Methods {
        /// Print them as JSON.
        #[arg(long)]
        json: bool,
    },
}

/// Arguments of `nesy bench run` and `nesy bench plan`.
#[derive(Debug, clap::Args)]
pub(crate) struct RunArgs {
    /// The run directory (default `runs/bench/<date-time>`); running the same command on it
    /// again resumes.
    pub run: Option<PathBuf>,
    /// Methods and variants, comma-separated: `nesycr,imitation,replan`,
    /// `nesycr+verification=off` (`nesy bench methods` lists them). Default `nesycr`, or
    /// the study's variants with `--study`.
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// A study: `ablation` (Table 3's shape) or `robustness` (Table 8's shape), each a set
    /// of NeSyCR variants under one stated error model, on Combination/medium with 3
    /// repeats; `complexity-gap` (Figure 4(b)'s shape), NeSyCR and the controls on the
    /// auxiliary complexity-gap suite with 1 repeat; or `drawers` (Table 2's task) or `hook`
    /// (Figures 1 and 5's task), NeSyCR and the controls on that real-world task's family
    /// with 1 repeat; unless `--scenarios`, `--repeats` and `--suite` say otherwise. Needs
    /// `--vlm oracle`.
    #[arg(long, value_name = "NAME", conflicts_with = "methods")]
    pub study: Option<String>,
    /// Scenarios: `all`, or ids and id prefixes, comma-separated (`comb_medium`). Default
    /// `all`, or the study's cell with `--study`.
    #[arg(long, value_name = "LIST")]
    pub scenarios: Option<String>,
    /// Keep a random sample of this many of the selected scenarios.
    #[arg(long, value_name = "N")]
    pub sample: Option<usize>,
    /// Seed of `--sample`.
    #[arg(long, value_name = "SEED", default_value_t = 0)]
    pub sample_seed: u64,
    /// Spread `--sample` evenly over the table's cells (factor group × complexity).
    #[arg(long, requires = "sample")]
    pub stratify: bool,
    /// Repeats per method and scenario, each with its own seed. Default 1, or 3 with
    /// `--study`.
    #[arg(long, value_name = "N")]
    pub repeats: Option<u32>,
    /// The run seed every unit's seed derives from.
    #[arg(long, value_name = "SEED", default_value_t = 0)]
    pub seed: u64,
    /// Who answers: `oracle` (the offline reference responder), `replay:DIR` (per-unit
    /// cassettes of an earlier run, e.g. runs/bench/X/cassettes), or the URL of an
    /// OpenAI-compatible server. Default: the configured VLM (NESY_VLM_* settings).
    #[arg(long, value_name = "oracle|replay:DIR|URL")]
    pub vlm: Option<String>,
    /// The demo cache.
    #[arg(long, value_name = "DIR", default_value = "runs/demos")]
    pub demos: PathBuf,
    /// Run methods on demonstrations whose final state lacks part of their goal (the authors'
    /// behaviour) instead of recording them as `demo_unusable`.
    #[arg(long)]
    pub keep_gapped_demos: bool,
    /// This process's shard, `i/n` (0-based), e.g. `${SLURM_ARRAY_TASK_ID}/16`.
    #[arg(long, value_name = "i/n", default_value = "0/1")]
    pub shard: String,
    /// Units in flight at once (default: the cores available).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// CPU-bound stages at once (simulation, rendering, recording; default: the cores).
    #[arg(long, value_name = "N")]
    pub cpu_jobs: Option<usize>,
    /// Model calls in flight at once over all units.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub model_jobs: usize,
    /// Stop starting units once the run's cost reaches this many US dollars.
    #[arg(long, value_name = "USD")]
    pub max_cost_usd: Option<f64>,
    /// Stop starting units once more than this fraction of the finished ones (at least 10)
    /// could not reach the model.
    #[arg(long, value_name = "RATE")]
    pub max_error_rate: Option<f64>,
    /// Cap on model calls per unit (the unit ends `method_error` at the cap).
    #[arg(long, value_name = "N")]
    pub max_calls_per_unit: Option<u64>,
    /// Wall-clock budget of one policy in seconds.
    #[arg(long, value_name = "SECS", default_value_t = 300.0)]
    pub policy_timeout: f64,
    /// What every method sees of each scene: `images` (the rendered views) or `state-text`
    /// (each scene's ground-truth state as text in place of its pictures, for text-only
    /// models; NeSyCR reads the ground-truth states).
    #[arg(long, value_enum, default_value_t = Observation::Images)]
    pub observation: Observation,
    /// The robot's protective stop in every scene of the run: `on` (a motion that presses
    /// the arm or what it carries into furniture ends there, and the experts'
    /// demonstrations keep off it) or `off` (the kinematic arm, which passes through
    /// furniture). The manifest records it. Left out, a new run has it on and a resumed run
    /// keeps the setting its manifest records.
    #[arg(long, value_enum)]
    pub protective_stop: Option<OnOff>,
    /// Record the offline responder's calls to per-unit cassettes too (live calls always are).
    #[arg(long)]
    pub record_cassettes: bool,
    /// Record each executed unit's execution (`execution.mcap`, and its first and last
    /// frames for the report's failure gallery).
    #[arg(long)]
    pub record_executions: bool,
    /// Re-execute the stored programs of this earlier run (phase B only: no model call).
    #[arg(long, value_name = "RUN")]
    pub reexecute_from: Option<PathBuf>,
    /// Read the scenario suite from this folder instead of generating it.
    #[arg(long, value_name = "DIR")]
    pub suite: Option<PathBuf>,
    /// One JSON line per finished unit on stdout, and the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// Do not write the report at the end.
    #[arg(long)]
    pub no_report: bool,
    /// VLM settings (also from the environment and `--vlm-config`).
    #[command(flatten)]
    pub vlm_config: ConfigOverrides,
}

/// Arguments of `nesy bench compare`.
#[derive(Debug, clap::Args)]
pub(crate) struct CompareArgs {
    /// Run A (the baseline of the comparison).
    pub run_a: PathBuf,
    /// Run B (default: run A, comparing two of its variants).
    pub run_b: Option<PathBuf>,
    /// The variant of run A (default: its only one).
    #[arg(long, value_name = "VARIANT")]
    pub a: Option<String>,
    /// The variant of run B (default: its only one).
    #[arg(long, value_name = "VARIANT")]
    pub b: Option<String>,
    /// Exit 1 when B's success rate is below A's by more than PP percentage points with
    /// p < 0.05 (McNemar's exact test), so that the comparison can gate a change.
    #[arg(long, value_name = "PP")]
    pub fail_if_worse: Option<f64>,
    /// Print the comparison as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `nesy bench demos`.
#[derive(Debug, clap::Args)]
pub(crate) struct DemosArgs {
    /// Scenarios: `all`, or ids and id prefixes, comma-separated.
    #[arg(long, value_name = "LIST", default_value = "all")]
    pub scenarios: String,
    /// The demo cache.
    #[arg(long, value_name = "DIR", default_value = "runs/demos")]
    pub demos: PathBuf,
    /// Worker threads (default: the cores available).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Read the scenario suite from this folder instead of generating it.
    #[arg(long, value_name = "DIR")]
    pub suite: Option<PathBuf>,
    /// The robot's protective stop in the demonstrations: `on` or `off`, as the run that
    /// will use them sets it (`nesy bench run --protective-stop`).
    #[arg(long, value_enum, default_value_t = OnOff::On)]
    pub protective_stop: OnOff,
}

/// Arguments of `nesy bench slurm`.
#[derive(Debug, clap::Args)]
pub(crate) struct SlurmArgs {
    /// The run directory (on a file system every node sees).
    pub run: PathBuf,
    /// Array tasks (shards).
    #[arg(long, value_name = "N")]
    pub shards: usize,
    /// Cores per task.
    #[arg(long, value_name = "N", default_value_t = 2)]
    pub cpus: usize,
    /// Memory per task.
    #[arg(long, value_name = "SIZE", default_value = "8G")]
    pub mem: String,
    /// Time limit per task.
    #[arg(long, value_name = "HH:MM:SS", default_value = "04:00:00")]
    pub time: String,
    /// Partition.
    #[arg(long)]
    pub partition: Option<String>,
    /// Where the `nesy` binary is on the nodes (default: this binary).
    #[arg(long, value_name = "PATH")]
    pub nesy: Option<PathBuf>,
    /// The arguments of `nesy bench run` besides the run directory and the shard, after `--`.
    #[arg(last = true, value_name = "RUN ARGS")]
    pub run_args: Vec<String>,
}

/// Runs `nesy bench`.
pub(crate) fn run(args: BenchArgs) -> anyhow::Result<ExitCode> {
    match args.action {
        BenchAction::Run(a) => run_bench(*a),
        BenchAction::Demos(a) => demos(a),
        BenchAction::Plan(a) => plan(*a),
        BenchAction::Status { run, json } => status(&run, json),
        BenchAction::Merge { run, allow_partial } | BenchAction::Report { run, allow_partial } => {
            merge(&run, allow_partial)
        }
        BenchAction::Slurm(a) => slurm(a),
        BenchAction::Compare(a) => compare(&a),
        BenchAction::Methods { json } => list_methods(json),
    }
}

fn compare(args: &CompareArgs) -> anyhow::Result<ExitCode> {
    use nesy_bench::compare;
    if let Some(pp) = args.fail_if_worse {
        anyhow::ensure!(
            pp.is_finite() && pp >= 0.0,
            "--fail-if-worse must be a non-negative number of percentage points, got {pp}"
        );
    }
    let run_b = args.run_b.as_deref().unwrap_or(&args.run_a);
    let a = compare::pick_variant(&args.run_a, args.a.as_deref())?;
    let b = compare::pick_variant(run_b, args.b.as_deref())?;
    let result = compare::compare((&args.run_a, &a), (run_b, &b))?;
    let worse = args.fail_if_worse.is_some_and(|pp| result.worse_by_more_than(pp));
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&result)?)?;
    } else {
        outln!("A: {} in {}", result.a.variant, result.a.run)?;
        outln!("B: {} in {}", result.b.variant, result.b.run)?;
        outln!(
            "{:<40}  {:<36}  {:<36}  {:>8}  {:>9}  {:>8}  {:>12}",
            "cell",
            "SR of A",
            "SR of B",
            "B − A",
            "A↑ / B↑",
            "p",
            "units needed"
        )?;
        let rows = result
            .cells
            .iter()
            .map(|(g, c, cell)| (format!("{} / {}", g.title(), c.as_str()), cell))
            .chain(std::iter::once(("overall".to_owned(), &result.overall)));
        for (name, cell) in rows {
            outln!(
                "{:<40}  {:<36}  {:<36}  {:>+7.1}pp  {:>9}  {:>8.4}  {:>12}",
                name,
                cell.a.describe(),
                cell.b.describe(),
                cell.difference_pp(),
                format!("{} / {}", cell.only_a, cell.only_b),
                cell.p_value,
                cell.units_needed.map_or("-".to_owned(), |n| n.to_string())
            )?;
        }
        if result.unpaired > 0 {
            outln!(
                "{} scored unit(s) had no partner and were left out",
                result.unpaired
            )?;
        }
        for c in &result.changed {
            outln!("changed: {}  {} → {}", c.unit, c.a, c.b)?;
        }
        if let Some(pp) = args.fail_if_worse {
            outln!(
                "{}",
                if worse {
                    format!(
                        "WORSE: B is below A by more than {pp} points with p < {}",
                        compare::ALPHA
                    )
                } else {
                    format!("not worse by more than {pp} points at p < {}", compare::ALPHA)
                }
            )?;
        }
    }
    Ok(if worse {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

fn responder(args: &RunArgs) -> anyhow::Result<ResponderSetup> {
    Ok(match args.vlm.as_deref() {
        Some("oracle") => ResponderSetup::Oracle,
        Some(text) if text.starts_with("replay:") => {
            let dir = PathBuf::from(&text["replay:".len()..]);
            anyhow::ensure!(
                dir.is_dir(),
                "--vlm {text}: {} is not a folder of per-unit cassettes (an earlier run's cassettes/)",
                dir.display()
            );
            ResponderSetup::Replay(dir)
        }
        Some(url) if url.starts_with("http://") || url.starts_with("https://") => {
            let mut overrides = args.vlm_config.clone();
            overrides.base_url = Some(url.to_owned());
            if overrides.backend.is_none() && std::env::var_os("NESY_VLM_BACKEND").is_none() {
                overrides.backend = Some(nesy_vlm::BackendKind::Vllm);
            }
            ResponderSetup::Live(Box::new(overrides))
        }
        Some(other) => anyhow::bail!(
            "--vlm {other:?}: expected `oracle`, `replay:DIR` or an http(s):// URL of an OpenAI-compatible server"
        ),
        None => ResponderSetup::Live(Box::new(args.vlm_config.clone())),
    })
}

/// The protective stop a run uses: the one asked for; else, for a run that already has a
/// manifest, the one it records (runs started while the stop was off by default resume
/// unchanged); else on.
fn protective_stop(asked: Option<OnOff>, run_dir: &Path) -> anyhow::Result<bool> {
    Ok(match asked {
        Some(setting) => setting.is_on(),
        None if nesy_bench::manifest::manifest_path(run_dir).exists() => {
            Manifest::read(run_dir)?.settings.protective_stop
        }
        None => true,
    })
}

fn config(args: &RunArgs) -> anyhow::Result<RunConfig> {
    anyhow::ensure!(
        args.policy_timeout.is_finite() && args.policy_timeout > 0.0,
        "--policy-timeout must be a positive number of seconds, got {}",
        args.policy_timeout
    );
    let study = args.study.as_deref().map(Study::parse).transpose()?;
    let repeats = args.repeats.unwrap_or(study.map_or(1, Study::default_repeats));
    anyhow::ensure!(repeats >= 1, "--repeats must be at least 1");
    if let Some(r) = args.max_error_rate {
        anyhow::ensure!(
            (0.0..=1.0).contains(&r),
            "--max-error-rate must be in [0, 1], got {r}"
        );
    }
    if let Some(c) = args.max_cost_usd {
        anyhow::ensure!(
            c.is_finite() && c >= 0.0,
            "--max-cost-usd must be a non-negative number, got {c}"
        );
    }
    let scenarios = args
        .scenarios
        .as_deref()
        .unwrap_or(study.map_or("all", Study::default_scenarios));
    let mut selection = Selection::parse(scenarios);
    selection.sample = args.sample;
    selection.sample_seed = args.sample_seed;
    selection.stratify = args.stratify;
    let run_dir = args
        .run
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs/bench").join(harness::default_run_id()));
    let protective_stop = protective_stop(args.protective_stop, &run_dir)?;
    Ok(RunConfig {
        run_dir,
        variants: match study {
            Some(s) => s.rows().into_iter().map(|r| r.variant).collect(),
            None => nesy_bench::methods::parse_variants(args.methods.as_deref().unwrap_or("nesycr"))?,
        },
        study,
        selection,
        suite_dir: args.suite.clone(),
        repeats,
        run_seed: args.seed,
        responder: responder(args)?,
        demo_cache: args.demos.clone(),
        settings: RunSettings {
            keep_gapped_demos: args.keep_gapped_demos,
            image_size: nesy_sim::perception::render::VIEW_SIZE,
            policy_wall_ms: (args.policy_timeout * 1000.0) as u64,
            max_calls_per_unit: args.max_calls_per_unit,
            observation: args.observation,
            protective_stop,
        },
        shard: args.shard.parse()?,
        jobs: args.jobs.unwrap_or_else(cores).max(1),
        cpu_jobs: args.cpu_jobs.unwrap_or_else(cores).max(1),
        model_jobs: args.model_jobs.max(1),
        max_cost_usd: args.max_cost_usd,
        max_error_rate: args.max_error_rate,
        worker: WorkerCommand::current_exe().context("locating the nesy executable")?,
        record_cassettes: args.record_cassettes,
        record_executions: args.record_executions,
        reexecute: args.reexecute_from.clone(),
    })
}

/// Progress on a terminal: a bar with ETA and a running SR per variant; otherwise one line
/// per unit on stderr; with `--json`, one JSON record per unit on stdout.
struct Progress {
    json: bool,
    bar: Option<indicatif::ProgressBar>,
    tally: Mutex<BTreeMap<String, (usize, usize)>>,
    started: Instant,
}

impl Progress {
    fn new(json: bool) -> Progress {
        let bar = (!json && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::new(0);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "[{elapsed_precise}] {bar:30} {pos}/{len} ETA {eta} {msg}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            bar
        });
        Progress {
            json,
            bar,
            tally: Mutex::new(BTreeMap::new()),
            started: Instant::now(),
        }
    }

    fn running_sr(&self) -> String {
        let t = self.tally.lock().unwrap_or_else(|e| e.into_inner());
        t.iter()
            .map(|(v, (ok, n))| {
                format!(
                    "{v} SR {:.1}% ({ok}/{n})",
                    100.0 * *ok as f64 / (*n).max(1) as f64
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}

impl BenchProgress for Progress {
    fn start(&self, total: usize, pending: usize) {
        match &self.bar {
            Some(bar) => bar.set_length(pending as u64),
            None if !self.json => eprintln!("{pending} of {total} unit(s) of this shard to run"),
            None => {}
        }
    }

    fn unit_done(&self, r: &UnitRecord, done: usize, pending: usize) {
        if r.status.is_scored() {
            let mut t = self.tally.lock().unwrap_or_else(|e| e.into_inner());
            let e = t.entry(r.key.variant.clone()).or_default();
            e.0 += usize::from(r.scores.sr == 1.0);
            e.1 += 1;
        }
        if self.json {
            if let Ok(line) = serde_json::to_string(r) {
                let _ = outln!("{line}");
            }
            return;
        }
        match &self.bar {
            Some(bar) => {
                bar.set_position(done as u64);
                bar.set_message(self.running_sr());
                if !matches!(r.status, UnitStatus::Succeeded) {
                    bar.println(line(r));
                }
            }
            None => {
                let eta = {
                    let elapsed = self.started.elapsed().as_secs_f64();
                    let rate = elapsed / done.max(1) as f64;
                    (pending.saturating_sub(done)) as f64 * rate
                };
                eprintln!("{:>5}/{pending} {} (ETA {:.0} s)", done, line(r), eta);
            }
        }
    }

    fn note(&self, message: &str) {
        match &self.bar {
            Some(bar) => bar.println(message),
            None => eprintln!("{message}"),
        }
    }
}

fn line(r: &UnitRecord) -> String {
    let s = &r.scores;
    let mut text = format!(
        "{} {}: SR {:.0} GC {:.2} PD {:.2}; {} calls, US$ {:.4}, {:.1} s",
        r.key.name(),
        r.status,
        s.sr,
        s.gc,
        s.pd,
        r.effort.calls,
        r.effort.cost_usd,
        r.effort.time.total_s
    );
    if let Some(e) = &r.error {
        text.push_str(" — ");
        text.push_str(e.lines().next().unwrap_or(""));
    }
    text
}

fn run_bench(args: RunArgs) -> anyhow::Result<ExitCode> {
    let config = config(&args)?;
    let run_dir = config.run_dir.clone();
    let whole = config.shard == Shard::WHOLE;
    let progress = Arc::new(Progress::new(args.json));
    let stop = StopSignal::default();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(cores().max(2))
        .enable_all()
        .build()
        .context("starting the async runtime")?;
    let summary = runtime.block_on(async {
        let watcher = stop.clone();
        tokio::spawn(async move {
            if tokio::signal::ctrl_c().await.is_ok() {
                watcher.stop();
            }
        });
        harness::run(config, progress.clone(), stop.clone()).await
    })?;
    if let Some(bar) = &progress.bar {
        bar.finish_and_clear();
    }
    let complete = summary.stopped.is_none();
    let mut report = None;
    if complete && whole && !args.no_report {
        report = Some(nesy_bench::report::write(
            &run_dir,
            &nesy_bench::report::ReportOptions::default(),
        )?);
    }
    if args.json {
        outln!(
            "{}",
            serde_json::to_string(
                &serde_json::json!({"run": run_dir, "summary": summary, "report": report})
            )?
        )?;
    } else {
        eprintln!(
            "{}: ran {} unit(s) ({} already done) in {:.1} s: {}",
            run_dir.display(),
            summary.ran,
            summary.skipped,
            summary.wall_s,
            summary
                .statuses
                .iter()
                .map(|(k, v)| format!("{v} {k}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
        if let Some(r) = &report {
            outln!("{}", r.report.display())?;
        } else if !whole && complete {
            eprintln!(
                "shard {} done; merge the shards with `nesy bench merge {}`",
                args.shard,
                run_dir.display()
            );
        }
    }
    Ok(if complete {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn demos(args: DemosArgs) -> anyhow::Result<ExitCode> {
    let files = harness::load_suite(args.suite.as_deref())?;
    let scenarios = Selection::parse(&args.scenarios).apply(nesy_sim::tasks::scenario::scenarios(&files))?;
    let cache = DemoCache::new(&args.demos, nesy_sim::perception::render::VIEW_SIZE)
        .with_protective_stop(args.protective_stop.is_on());
    let started = Instant::now();
    let total = scenarios.len();
    let results = nesy_bench::pool::run_all(
        &scenarios,
        args.jobs.unwrap_or_else(cores),
        |_, s| cache.ensure(s, 1),
        |i, r| match r {
            Ok(d) => eprintln!(
                "{:>4}/{total} {} {}: {} keyframes{}{}",
                i + 1,
                d.record.scenario,
                if d.recorded_now { "recorded" } else { "cached" },
                d.record.keyframes,
                if d.recorded_now {
                    format!(", {:.1} s", d.record.wall_s)
                } else {
                    String::new()
                },
                d.record
                    .unusable_reason()
                    .map(|w| format!(" — UNUSABLE: {w}"))
                    .unwrap_or_default()
            ),
            Err(e) => eprintln!("{:>4}/{total} error: {e}", i + 1),
        },
    );
    let mut failed = 0;
    let mut unusable = Vec::new();
    let mut recorded = 0;
    for r in &results {
        match r {
            Ok(d) => {
                recorded += usize::from(d.recorded_now);
                if !d.record.usable() {
                    unusable.push(d.record.scenario.clone());
                }
            }
            Err(_) => failed += 1,
        }
    }
    outln!(
        "{} demo(s) in {} ({} recorded now, {} from the cache) in {:.1} s; {} unusable, {} error(s)",
        total,
        args.demos.display(),
        recorded,
        total - recorded - failed,
        started.elapsed().as_secs_f64(),
        unusable.len(),
        failed
    )?;
    if !unusable.is_empty() {
        outln!("unusable: {}", unusable.join(", "))?;
    }
    Ok(if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn plan(args: RunArgs) -> anyhow::Result<ExitCode> {
    let config = config(&args)?;
    let prepared: Prepared = harness::prepare(&config)?;
    let cache = DemoCache::new(&config.demo_cache, config.settings.image_size)
        .with_protective_stop(config.settings.protective_stop);
    let plan = nesy_bench::call_budget::estimate(&prepared, &cache);
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&plan)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    outln!(
        "{:<44} {:<32} {:<7} {:>5} {:>17} {:>19}",
        "variant",
        "group",
        "level",
        "units",
        "calls (min-max)",
        "images (min-max)"
    )?;
    for r in &plan.rows {
        outln!(
            "{:<44} {:<32} {:<7} {:>5} {:>17} {:>19}{}",
            r.variant,
            r.group.title(),
            r.complexity.as_str(),
            r.units,
            format!("{}-{}", r.load.calls_min, r.load.calls_max),
            format!("{}-{}", r.load.images_min, r.load.images_max),
            if r.unrecorded > 0 {
                format!("  ({} demo(s) not recorded: not counted)", r.unrecorded)
            } else {
                String::new()
            }
        )?;
    }
    let t = plan.total;
    outln!(
        "total: {}-{} model calls, {}-{} images over {} units",
        t.calls_min,
        t.calls_max,
        t.images_min,
        t.images_max,
        prepared.units.len()
    )?;
    if plan.unrecorded > 0 {
        outln!(
            "{} unit(s) have no recorded demo yet (`nesy bench demos` records them); their calls are not counted",
            plan.unrecorded
        )?;
    }
    if let ResponderSetup::Live(overrides) = &config.responder
        && let Ok(vc) = nesy_vlm::VlmConfig::resolve(overrides, &nesy_vlm::ProcessEnv)
        && let Some(price) = vc.prices.lookup(&vc.model)
    {
        // An estimate: 255 input tokens per 384² image at high detail, and an assumed 2 000
        // prompt and 800 completion tokens of text per call.
        let cost = |calls: u64, images: u64| {
            let input = images as f64 * 255.0 + calls as f64 * 2000.0;
            let output = calls as f64 * 800.0;
            (input * price.input_per_mtok + output * price.output_per_mtok) / 1e6
        };
        outln!(
            "estimated cost at the price table for {}: US$ {:.2}-{:.2} (255 tokens per image, 2 000 prompt and 800 completion tokens of text per call assumed)",
            vc.model,
            cost(t.calls_min, t.images_min),
            cost(t.calls_max, t.images_max)
        )?;
    }
    Ok(ExitCode::SUCCESS)
}

fn status(run: &Path, json: bool) -> anyhow::Result<ExitCode> {
    let manifest = Manifest::read(run)?;
    let records = harness::final_records(run)?;
    let all = nesy_bench::store::read_all(run)?;
    let retryable = all.iter().filter(|r| !r.status.is_final()).count();
    let mut by: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    let mut sr: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for r in records.values() {
        *by.entry(r.key.variant.clone())
            .or_default()
            .entry(r.status.as_str().into())
            .or_default() += 1;
        if r.status.is_scored() {
            let e = sr.entry(r.key.variant.clone()).or_default();
            e.0 += usize::from(r.scores.sr == 1.0);
            e.1 += 1;
        }
    }
    let missing = harness::missing_units(&manifest, &records).len();
    if json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({
                "units": manifest.units.len(),
                "final": records.len(),
                "missing": missing,
                "retryable_records": retryable,
                "statuses": by,
                "sr": sr.iter().map(|(v, (ok, n))| (v.clone(), serde_json::json!({"succeeded": ok, "scored": n}))).collect::<BTreeMap<_, _>>(),
            }))?
        )?;
        return Ok(ExitCode::SUCCESS);
    }
    outln!(
        "{}: {} of {} unit(s) final, {} to run ({} retryable record(s)); responder: {}",
        run.display(),
        records.len(),
        manifest.units.len(),
        missing,
        retryable,
        manifest.responder.describe()
    )?;
    for (v, statuses) in &by {
        let (ok, n) = sr.get(v).copied().unwrap_or_default();
        outln!(
            "  {v}: SR {:.1}% ({ok}/{n} scored); {}",
            100.0 * ok as f64 / n.max(1) as f64,
            statuses
                .iter()
                .map(|(k, c)| format!("{c} {k}"))
                .collect::<Vec<_>>()
                .join(", ")
        )?;
    }
    Ok(ExitCode::SUCCESS)
}

fn merge(run: &Path, allow_partial: bool) -> anyhow::Result<ExitCode> {
    match nesy_bench::merge::merge(run, allow_partial) {
        Ok(m) => {
            outln!("{}", m.report.report.display())?;
            eprintln!(
                "merged {} results file(s): {} of {} unit(s){}",
                m.files,
                m.units,
                m.expected,
                if m.report.partial { " — PARTIAL" } else { "" }
            );
            Ok(ExitCode::SUCCESS)
        }
        Err(nesy_bench::BenchError::Incomplete {
            message,
            missing,
            duplicates,
        }) => {
            eprintln!("error: {message}");
            for m in &missing {
                eprintln!("missing: {m}");
            }
            for d in &duplicates {
                eprintln!("duplicate: {d}");
            }
            Ok(ExitCode::from(1))
        }
        Err(e) => Err(e.into()),
    }
}

fn slurm(args: SlurmArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(args.shards >= 1, "--shards must be at least 1");
    anyhow::ensure!(
        !args
            .run_args
            .iter()
            .any(|a| a == "--shard" || a.starts_with("--shard=")),
        "the run arguments after -- must not set --shard: each array task sets its own"
    );
    let nesy = match args.nesy {
        Some(p) => p,
        None => std::env::current_exe().context("locating the nesy executable")?,
    };
    let run = std::path::absolute(&args.run).unwrap_or(args.run.clone());
    let job = nesy_bench::slurm::SlurmJob {
        nesy: &nesy,
        run: &run,
        run_args: &args.run_args,
        shards: args.shards,
        cpus: args.cpus.max(1),
        mem: &args.mem,
        time: &args.time,
        partition: args.partition.as_deref(),
    };
    std::fs::create_dir_all(run.join("slurm"))
        .with_context(|| format!("creating {}", run.join("slurm").display()))?;
    let array = run.join("slurm/run.sbatch");
    let merge = run.join("slurm/merge.sbatch");
    std::fs::write(&array, nesy_bench::slurm::array_script(&job))
        .with_context(|| format!("writing {}", array.display()))?;
    std::fs::write(&merge, nesy_bench::slurm::merge_script(&job))
        .with_context(|| format!("writing {}", merge.display()))?;
    outln!("{}", array.display())?;
    outln!("{}", merge.display())?;
    eprintln!(
        "submit with: jid=$(sbatch --parsable {}) && sbatch --dependency=afterok:$jid {}",
        array.display(),
        merge.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn list_methods(json: bool) -> anyhow::Result<ExitCode> {
    let infos: Vec<_> = methods::registry().iter().map(|m| m.info()).collect();
    if json {
        outln!("{}", serde_json::to_string_pretty(&infos)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    outln!(
        "{:<18} {:<8} {:^6} {:^6} {:^6} {:^6} {:^6}  offline",
        "method",
        "role",
        "code",
        "adapt",
        "replan",
        "wm",
        "symbol"
    )?;
    let mark = |b: bool| if b { "✓" } else { "✗" };
    for i in &infos {
        let c = &i.classes;
        outln!(
            "{:<18} {:<8} {:^6} {:^6} {:^6} {:^6} {:^6}  {}",
            i.name,
            match i.role {
                Role::Method => "method",
                Role::Control => "control",
            },
            mark(c.natively_code),
            mark(c.explicit_adapt),
            mark(c.replanning),
            mark(c.world_model),
            mark(c.symbolic_tool),
            match i.offline {
                OfflineMeaning::UpperBound => "oracle gives an upper bound",
                OfflineMeaning::ModelFree => "uses no model",
                OfflineMeaning::NotMeaningful => "needs a live model (refused offline)",
            }
        )?;
        outln!("    {}", i.summary)?;
        for s in i.settings {
            outln!("    +{s}")?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
