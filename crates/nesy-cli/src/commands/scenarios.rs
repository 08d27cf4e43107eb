//! `nesy scenarios`: the benchmark's 440 scenarios (generate the configuration files, list
//! the counts, show a scene, run the scripted expert over every scene).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::Context;
use nesy_sim::tasks::scenario::{self, ConfigFile, CountTable, Scenario, Side};

/// Arguments of `nesy scenarios`.
#[derive(Debug, clap::Args)]
pub struct ScenariosArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: ScenariosAction,
}

/// The `nesy scenarios` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum ScenariosAction {
    /// Write the 15 configuration files (`<factor>_<complexity>.json`).
    Generate {
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
    },
    /// Print the table of scenario counts (the paper's Table 6).
    List {
        /// Read the configurations from this directory instead of generating them.
        #[arg(long)]
        suite: Option<PathBuf>,
        /// Print every scenario id instead of the table.
        #[arg(long)]
        ids: bool,
    },
    /// Print one side of a scenario as `scene.json`.
    Show {
        /// Scenario id, e.g. `obst_low_00_s0`.
        id: String,
        /// Which side.
        #[arg(long, value_enum, default_value = "target")]
        side: SideArg,
        /// Read the configurations from this directory instead of generating them.
        #[arg(long)]
        suite: Option<PathBuf>,
    },
    /// Run the scripted expert on the source and target scene of every scenario and report
    /// the success rate and each failure (exit 1 if any scene fails).
    Sweep {
        /// Read the configurations from this directory instead of generating them.
        #[arg(long)]
        suite: Option<PathBuf>,
        /// Only scenarios whose id starts with this.
        #[arg(long)]
        only: Option<String>,
        /// Only this side of each scenario (default: both).
        #[arg(long, value_enum)]
        side: Option<SideArg>,
        /// Worker threads (one simulator each).
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Also write every result as JSON lines here, one line as each scene finishes.
        #[arg(long)]
        report: Option<PathBuf>,
    },
}

/// A scenario side on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SideArg {
    /// The demonstration.
    Source,
    /// The deployment.
    Target,
}

impl From<SideArg> for Side {
    fn from(s: SideArg) -> Side {
        match s {
            SideArg::Source => Side::Source,
            SideArg::Target => Side::Target,
        }
    }
}

/// The configurations: from `suite` if given, else generated.
pub fn load_suite(suite: Option<&std::path::Path>) -> anyhow::Result<Vec<ConfigFile>> {
    match suite {
        Some(dir) => Ok(scenario::read_suite(dir)?),
        None => Ok(scenario::generate_suite()),
    }
}

/// Runs `nesy scenarios`.
pub fn run(args: ScenariosArgs) -> anyhow::Result<ExitCode> {
    match args.action {
        ScenariosAction::Generate { out } => {
            let started = Instant::now();
            let files = scenario::generate_suite();
            let all = scenario::scenarios(&files);
            // Generating every scene checks that the whole suite is usable.
            for s in &all {
                s.scenes()?;
            }
            let written = scenario::write_suite(&files, &out)?;
            for path in &written {
                outln!("{}", path.display())?;
            }
            eprintln!(
                "{} files, {} configurations, {} scenarios ({} scenes generated) in {:.1} ms",
                written.len(),
                files.iter().map(|f| f.episodes.len()).sum::<usize>(),
                all.len(),
                2 * all.len(),
                started.elapsed().as_secs_f64() * 1e3
            );
            Ok(ExitCode::SUCCESS)
        }
        ScenariosAction::List { suite, ids } => {
            let files = load_suite(suite.as_deref())?;
            let all = scenario::scenarios(&files);
            if ids {
                for s in &all {
                    outln!("{}", s.id)?;
                }
            } else {
                out!("{}", CountTable::of(&all).render())?;
            }
            Ok(ExitCode::SUCCESS)
        }
        ScenariosAction::Show { id, side, suite } => {
            let files = load_suite(suite.as_deref())?;
            let scenario = scenario::find(&files, &id)?;
            outln!("{}", scenario.generate(side.into())?.scene.to_json_pretty())?;
            Ok(ExitCode::SUCCESS)
        }
        ScenariosAction::Sweep {
            suite,
            only,
            side,
            threads,
            report,
        } => sweep(suite, only, side.map(Side::from), threads, report),
    }
}

/// One scene's result in the sweep.
#[derive(Debug, serde::Serialize)]
struct SceneResult {
    scenario: String,
    side: &'static str,
    embodiment: &'static str,
    full_success: bool,
    results: Vec<&'static str>,
    expert_error: Option<String>,
    /// Latched objects out of place at the end: the scene passes the authors' latch, but a
    /// demo recorded from it does not show its goal (`nesy record` refuses it).
    displaced: Vec<String>,
    actions: usize,
    sim_seconds: f64,
    wall_seconds: f64,
}

fn sweep(
    suite: Option<PathBuf>,
    only: Option<String>,
    side: Option<Side>,
    threads: usize,
    report: Option<PathBuf>,
) -> anyhow::Result<ExitCode> {
    let files = load_suite(suite.as_deref())?;
    let selected: Vec<Scenario> = scenario::scenarios(&files)
        .into_iter()
        .filter(|s| only.as_deref().is_none_or(|p| s.id.starts_with(p)))
        .collect();
    anyhow::ensure!(
        !selected.is_empty(),
        "no scenario id starts with {:?}",
        only.unwrap_or_default()
    );
    let jobs: Vec<(&Scenario, Side)> = selected
        .iter()
        .flat_map(|s| [(s, Side::Source), (s, Side::Target)])
        .filter(|(_, sd)| side.is_none_or(|want| want == *sd))
        .collect();
    // Lines go out as scenes finish, so a long sweep that is stopped keeps what it did.
    let report_file = match &report {
        Some(path) => Some(Mutex::new(
            std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?,
        )),
        None => None,
    };
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(usize, SceneResult)>> = Mutex::new(Vec::new());
    let started = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&(s, side)) = jobs.get(i) else { break };
                    let result = run_one(s, side);
                    let line = format!(
                        "{:>4}/{} {} {:<6} {}{}",
                        i + 1,
                        jobs.len(),
                        result.scenario,
                        result.side,
                        if result.full_success { "ok" } else { "FAIL" },
                        result
                            .expert_error
                            .as_deref()
                            .map(|e| format!(": {e}"))
                            .unwrap_or_default()
                    );
                    eprintln!("{line}");
                    if let Some(file) = &report_file {
                        use std::io::Write;
                        let json = serde_json::to_string(&result).unwrap_or_default();
                        let mut file = file.lock().unwrap_or_else(|e| e.into_inner());
                        if let Err(e) = writeln!(file, "{json}") {
                            eprintln!("warning: writing the report: {e}");
                        }
                    }
                    results
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push((i, result));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    results.sort_by_key(|(i, _)| *i);
    let wall = started.elapsed().as_secs_f64();
    let ok = results.iter().filter(|(_, r)| r.full_success).count();
    outln!(
        "expert full_success: {ok}/{} scenes ({:.1}%) in {wall:.1} s wall on {threads} thread(s)",
        results.len(),
        100.0 * ok as f64 / results.len() as f64
    )?;
    for side in ["source", "target"] {
        let of_side: Vec<_> = results.iter().filter(|(_, r)| r.side == side).collect();
        let ok = of_side.iter().filter(|(_, r)| r.full_success).count();
        outln!("  {side}: {ok}/{}", of_side.len())?;
    }
    let displaced: Vec<_> = results
        .iter()
        .filter(|(_, r)| r.full_success && !r.displaced.is_empty())
        .collect();
    if !displaced.is_empty() {
        outln!(
            "of the full_success scenes, {} end with a latched object out of place (unusable as demos):",
            displaced.len()
        )?;
        for (_, r) in &displaced {
            outln!(
                "  {} {} ({}): {}",
                r.scenario,
                r.side,
                r.embodiment,
                r.displaced.join(", ")
            )?;
        }
    }
    let failures: Vec<_> = results.iter().filter(|(_, r)| !r.full_success).collect();
    if !failures.is_empty() {
        outln!("failures:")?;
        for (_, r) in &failures {
            outln!(
                "  {} {} ({}): results {:?}{}",
                r.scenario,
                r.side,
                r.embodiment,
                r.results,
                r.expert_error
                    .as_deref()
                    .map(|e| format!("; expert: {e}"))
                    .unwrap_or_default()
            )?;
        }
    }
    Ok(if failures.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn run_one(s: &Scenario, side: Side) -> SceneResult {
    let started = Instant::now();
    let task = s.generate(side);
    let (embodiment, outcome) = match &task {
        Ok(t) => (
            t.scene.embodiment.as_str(),
            nesy_sim::demo::run_expert(&t.scene).map_err(|e| e.to_string()),
        ),
        Err(e) => ("?", Err(e.to_string())),
    };
    match outcome {
        Ok(run) => SceneResult {
            scenario: s.id.clone(),
            side: side.as_str(),
            embodiment,
            full_success: run.full_success(),
            results: run.outcome.subtasks.iter().map(|o| o.result.as_str()).collect(),
            expert_error: run.expert_error.map(|e| e.to_string()),
            displaced: run.outcome.displaced.clone(),
            actions: run.actions,
            sim_seconds: run.sim_seconds,
            wall_seconds: started.elapsed().as_secs_f64(),
        },
        Err(message) => SceneResult {
            scenario: s.id.clone(),
            side: side.as_str(),
            embodiment,
            full_success: false,
            results: Vec::new(),
            expert_error: Some(message),
            displaced: Vec::new(),
            actions: 0,
            sim_seconds: 0.0,
            wall_seconds: started.elapsed().as_secs_f64(),
        },
    }
}
