//! `nesy scenarios`: the benchmark's 440 scenarios (generate the configuration files, list
//! the counts, show a scene, run the scripted expert over every scene).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use nesy_sim::tasks::scenario::{self, ConfigFile, CountTable, Family, Scenario, Side};

use super::OnOff;

/// Arguments of `nesy scenarios`.
#[derive(Debug, clap::Args)]
pub(crate) struct ScenariosArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: ScenariosAction,
}

/// The `nesy scenarios` subcommands.
#[derive(Debug, clap::Subcommand)]
pub(crate) enum ScenariosAction {
    /// Write the 15 configuration files (`<factor>_<complexity>.json`), or with `--gap` the
    /// four files of the auxiliary complexity-gap suite (`gap_obst_plus<k>.json`), or with
    /// `--family NAME` a real-world task's family (`family_<name>.json`).
    Generate {
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Write the complexity-gap suite (Figure 4(b); not part of the 440) instead.
        #[arg(long, conflicts_with = "family")]
        gap: bool,
        /// Write a real-world task's family instead: `drawers` (Table 2's task) or `hook`
        /// (Figures 1 and 5's task); neither is part of the 440.
        #[arg(long, value_parser = parse_family)]
        family: Option<Family>,
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
    /// Write one side of a scenario as a PDDL problem over nesy's true domain
    /// (`assets/pddl/nesy-world.pddl`): the objects, the observed initial state and the goal,
    /// for `nesy verify` or any PDDL planner.
    Pddl {
        /// Scenario id, e.g. `comb_high_11_s1`.
        id: String,
        /// Which side.
        #[arg(long, value_enum, default_value = "target")]
        side: SideArg,
        /// Write the problem here instead of printing it.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Also write the domain of this scene here: the domain file's schemas, and each
        /// asset's under its own part names when the scene names them with prefixes (with
        /// the `Blocks` precondition between assets); a planner takes this with the problem.
        #[arg(long, value_name = "FILE")]
        domain_out: Option<PathBuf>,
        /// Read the configurations from this directory instead of generating them.
        #[arg(long)]
        suite: Option<PathBuf>,
    },
    /// Run the scripted expert on the source and target scene of every scenario and report
    /// the success rate, with nothing displaced and by the authors' latch, and each failure
    /// (exit 1 if any scene fails or ends with a displaced object).
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
        /// Only these scenes, `ID:SIDE` comma-separated (`comb_low_09_s1:target`).
        #[arg(long, value_name = "ID:SIDE,...")]
        scenes: Option<String>,
        /// Only the scenes a previous `--report` file lists as not fully successful (or with
        /// displaced objects).
        #[arg(long, value_name = "REPORT")]
        rerun_failures: Option<PathBuf>,
        /// The robot's protective stop: `on` (a motion that presses the arm or what it
        /// carries into furniture ends there, and the experts keep off it; as the benchmark
        /// runs by default) or `off` (the kinematic arm, which passes through furniture).
        #[arg(long, value_enum, default_value_t = OnOff::On)]
        protective_stop: OnOff,
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
pub(crate) fn load_suite(suite: Option<&std::path::Path>) -> anyhow::Result<Vec<ConfigFile>> {
    match suite {
        Some(dir) => Ok(scenario::read_suite(dir)?),
        None => Ok(scenario::generate_suite()),
    }
}

/// The suite that holds scenario `id`: the folder's, or the generated suite its id names
/// (the 440, the complexity-gap suite or a real-world task's family).
pub(crate) fn suite_of(suite: Option<&std::path::Path>, id: &str) -> anyhow::Result<Vec<ConfigFile>> {
    match suite {
        Some(dir) => Ok(scenario::read_suite(dir)?),
        None => Ok(scenario::generated_suite_of(id)),
    }
}

/// A family named on the command line.
fn parse_family(name: &str) -> Result<Family, String> {
    Family::from_name(name).ok_or_else(|| {
        let known: Vec<&str> = Family::ALL.iter().map(|f| f.as_str()).collect();
        format!("expected one of {}", known.join(", "))
    })
}

/// Runs `nesy scenarios`.
pub(crate) fn run(args: ScenariosArgs) -> anyhow::Result<ExitCode> {
    match args.action {
        ScenariosAction::Generate { out, gap, family } => {
            let started = Instant::now();
            let files = match (gap, family) {
                (_, Some(family)) => vec![scenario::generate_family_file(family)],
                (true, None) => scenario::generate_gap_suite(),
                (false, None) => scenario::generate_suite(),
            };
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
            let files = suite_of(suite.as_deref(), &id)?;
            let scenario = scenario::find(&files, &id)?;
            outln!("{}", scenario.generate(side.into())?.scene.to_json_pretty())?;
            Ok(ExitCode::SUCCESS)
        }
        ScenariosAction::Pddl {
            id,
            side,
            out,
            domain_out,
            suite,
        } => {
            let files = suite_of(suite.as_deref(), &id)?;
            let scenario = scenario::find(&files, &id)?;
            let (text, names) = pddl_problem(&scenario, side.into())?;
            if let Some(path) = domain_out {
                let world = nesy_sim::domain::WorldDomain::builtin()?;
                let domain = world.scene_domain(names.iter().map(String::as_str));
                std::fs::write(&path, domain.to_string())
                    .with_context(|| format!("writing {}", path.display()))?;
                eprintln!("{}", path.display());
            }
            match out {
                Some(path) => {
                    std::fs::write(&path, &text).with_context(|| format!("writing {}", path.display()))?;
                    eprintln!("{}", path.display());
                }
                None => out!("{text}")?,
            }
            Ok(ExitCode::SUCCESS)
        }
        ScenariosAction::Sweep {
            suite,
            only,
            side,
            threads,
            report,
            scenes,
            rerun_failures,
            protective_stop,
        } => {
            let filter = SceneFilter {
                only,
                side: side.map(Side::from),
                scenes: scenes.as_deref().map(parse_scenes).transpose()?,
                rerun: rerun_failures.as_deref().map(failed_scenes).transpose()?,
            };
            sweep(suite, filter, threads, report, protective_stop.is_on())
        }
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
    /// How deep the arm and what it carried went into furniture, deepest first.
    furniture_contacts: Vec<nesy_sim::world::FurnitureContact>,
}

/// Which scenes a sweep runs.
struct SceneFilter {
    only: Option<String>,
    side: Option<Side>,
    scenes: Option<Vec<(String, Side)>>,
    rerun: Option<Vec<(String, Side)>>,
}

fn side_named(name: &str) -> anyhow::Result<Side> {
    match name {
        "source" => Ok(Side::Source),
        "target" => Ok(Side::Target),
        other => anyhow::bail!("scene side {other:?}: expected source or target"),
    }
}

/// `ID:SIDE,ID:SIDE`.
fn parse_scenes(text: &str) -> anyhow::Result<Vec<(String, Side)>> {
    text.split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| {
            let (id, side) = s
                .trim()
                .split_once(':')
                .with_context(|| format!("--scenes {s:?}: expected ID:SIDE, e.g. comb_low_09_s1:target"))?;
            Ok((id.to_owned(), side_named(side)?))
        })
        .collect()
}

/// The scenes of a sweep report that were not fully successful or ended with displaced
/// objects.
fn failed_scenes(path: &std::path::Path) -> anyhow::Result<Vec<(String, Side)>> {
    let text = nesy_input::read_text(path, nesy_input::MAX_JSON_BYTES)
        .with_context(|| format!("reading {}", path.display()))?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let v: serde_json::Value = serde_json::from_str(line)
            .with_context(|| format!("{}: line {}: not a sweep report line", path.display(), i + 1))?;
        let field = |k: &str| v.get(k).and_then(|x| x.as_str()).map(str::to_owned);
        let (Some(id), Some(side)) = (field("scenario"), field("side")) else {
            anyhow::bail!(
                "{}: line {}: expected `scenario` and `side`",
                path.display(),
                i + 1
            );
        };
        let ok = v.get("full_success").and_then(|x| x.as_bool()).unwrap_or(false)
            && v.get("displaced")
                .and_then(|x| x.as_array())
                .is_none_or(|d| d.is_empty());
        if !ok {
            out.push((id, side_named(&side)?));
        }
    }
    Ok(out)
}

fn sweep(
    suite: Option<PathBuf>,
    filter: SceneFilter,
    threads: usize,
    report: Option<PathBuf>,
    protective_stop: bool,
) -> anyhow::Result<ExitCode> {
    let files = load_suite(suite.as_deref())?;
    let all = scenario::scenarios(&files);
    let wanted = |id: &str, side: Side| {
        let listed = |list: &Option<Vec<(String, Side)>>| {
            list.as_ref()
                .is_none_or(|l| l.iter().any(|(i, s)| i == id && *s == side))
        };
        filter.only.as_deref().is_none_or(|p| id.starts_with(p))
            && filter.side.is_none_or(|s| s == side)
            && listed(&filter.scenes)
            && listed(&filter.rerun)
    };
    let jobs: Vec<(&Scenario, Side)> = all
        .iter()
        .flat_map(|s| [(s, Side::Source), (s, Side::Target)])
        .filter(|(s, side)| wanted(&s.id, *side))
        .collect();
    anyhow::ensure!(!jobs.is_empty(), "no scene matches the sweep's filters");
    // Lines go out as scenes finish, so a long sweep that is stopped keeps what it did.
    let mut report_file = match &report {
        Some(path) => {
            Some(std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?)
        }
        None => None,
    };
    let started = Instant::now();
    let total = jobs.len();
    let results = nesy_bench::pool::run_all(
        &jobs,
        threads,
        |_, (s, side)| run_one(s, *side, protective_stop),
        |i, result: &SceneResult| {
            eprintln!("{}", sweep_line(i, total, result));
            if let Some(file) = &mut report_file {
                use std::io::Write;
                let json = serde_json::to_string(result).unwrap_or_default();
                if let Err(e) = writeln!(file, "{json}") {
                    eprintln!("warning: writing the report: {e}");
                }
            }
        },
    );
    print_sweep_summary(&results, started.elapsed().as_secs_f64(), threads)
}

/// One scene's line on stderr as it finishes: its position, id, side, verdict, any object
/// left out of place and the expert's error.
fn sweep_line(i: usize, total: usize, result: &SceneResult) -> String {
    format!(
        "{:>4}/{total} {} {:<6} {}{}{}",
        i + 1,
        result.scenario,
        result.side,
        if result.full_success { "ok" } else { "FAIL" },
        if result.displaced.is_empty() {
            String::new()
        } else {
            format!(" (displaced: {})", result.displaced.join(", "))
        },
        result
            .expert_error
            .as_deref()
            .map(|e| format!(": {e}"))
            .unwrap_or_default()
    )
}

/// Groups of furniture contacts the sweep summary lists.
const FURNITURE_GROUPS_SHOWN: usize = 12;

/// The scenes in which the arm or what it carried went deeper into furniture than a touch
/// ([`nesy_sim::world::FURNITURE_TOUCH_DEPTH`]), grouped by what pressed into what during
/// which call (calls without their trace index, carried objects together), the most
/// frequent first. A measurement: the kinematic arm is not stopped by furniture.
fn print_furniture_presses(results: &[SceneResult]) -> anyhow::Result<()> {
    use std::collections::BTreeMap;
    let limit = nesy_sim::world::FURNITURE_TOUCH_DEPTH;
    let pressing = results
        .iter()
        .filter(|r| r.furniture_contacts.iter().any(|c| c.depth > limit))
        .count();
    outln!(
        "arm or carried object deeper than {:.0} mm into furniture: {pressing}/{} scenes",
        limit * 1000.0,
        results.len()
    )?;
    let mut groups: BTreeMap<(String, String, String), (usize, f64)> = BTreeMap::new();
    for contact in results.iter().flat_map(|r| &r.furniture_contacts) {
        if contact.depth <= limit {
            continue;
        }
        let call = contact
            .call
            .split(" #")
            .next()
            .unwrap_or(&contact.call)
            .to_owned();
        let moving = if contact.moving.starts_with("the robot's ") {
            contact.moving.clone()
        } else {
            "a carried object".to_owned()
        };
        let entry = groups
            .entry((moving, contact.obstacle.clone(), call))
            .or_insert((0, 0.0));
        entry.0 += 1;
        entry.1 = entry.1.max(contact.depth);
    }
    let mut groups: Vec<_> = groups.into_iter().collect();
    groups.sort_by_key(|(_, (count, _))| std::cmp::Reverse(*count));
    for ((moving, obstacle, call), (count, deepest)) in groups.iter().take(FURNITURE_GROUPS_SHOWN) {
        outln!(
            "  {count:4} × {moving} into {obstacle} during {call} (deepest {:.1} mm)",
            deepest * 1000.0
        )?;
    }
    if groups.len() > FURNITURE_GROUPS_SHOWN {
        outln!(
            "  … {} more (every contact is in the --report lines)",
            groups.len() - FURNITURE_GROUPS_SHOWN
        )?;
    }
    Ok(())
}

/// The sweep's counts, overall and by side, then the scenes to look at: those that pass only
/// by the authors' latch and those that fail. Exit 1 when there is any.
fn print_sweep_summary(results: &[SceneResult], wall: f64, threads: usize) -> anyhow::Result<ExitCode> {
    let latched = results.iter().filter(|r| r.full_success).count();
    let clean = results
        .iter()
        .filter(|r| r.full_success && r.displaced.is_empty())
        .count();
    let n = results.len();
    outln!(
        "expert full_success with nothing displaced: {clean}/{n} scenes ({:.1}%); by the authors' latch: {latched}/{n} ({:.1}%); {wall:.1} s wall on {threads} thread(s)",
        100.0 * clean as f64 / n as f64,
        100.0 * latched as f64 / n as f64,
    )?;
    for side in ["source", "target"] {
        let of_side: Vec<_> = results.iter().filter(|r| r.side == side).collect();
        let clean = of_side
            .iter()
            .filter(|r| r.full_success && r.displaced.is_empty())
            .count();
        let latched = of_side.iter().filter(|r| r.full_success).count();
        if !of_side.is_empty() {
            outln!(
                "  {side}: {clean}/{} clean, {latched}/{} latched",
                of_side.len(),
                of_side.len()
            )?;
        }
    }
    let displaced: Vec<_> = results
        .iter()
        .filter(|r| r.full_success && !r.displaced.is_empty())
        .collect();
    if !displaced.is_empty() {
        outln!(
            "{} scene(s) pass the authors' latch but end with a latched object out of place (unusable as demos):",
            displaced.len()
        )?;
        for r in &displaced {
            outln!(
                "  {} {} ({}): {}",
                r.scenario,
                r.side,
                r.embodiment,
                r.displaced.join(", ")
            )?;
        }
    }
    print_furniture_presses(results)?;
    let failures: Vec<_> = results.iter().filter(|r| !r.full_success).collect();
    if !failures.is_empty() {
        outln!("failures:")?;
        for r in &failures {
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
    Ok(if failures.is_empty() && displaced.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn run_one(s: &Scenario, side: Side, protective_stop: bool) -> SceneResult {
    let started = Instant::now();
    let task = s.generate(side).map(|mut t| {
        t.scene.protective_stop = protective_stop;
        t
    });
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
            furniture_contacts: run.furniture_contacts,
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
            furniture_contacts: Vec::new(),
        },
    }
}

/// One side of a scenario as a PDDL problem: the scene built and observed, its objects typed
/// for the true domain, its goal with the end effector released; and the scene's object
/// names, which `--domain-out`'s domain is built from too.
fn pddl_problem(scenario: &Scenario, side: Side) -> anyhow::Result<(String, Vec<String>)> {
    use nesy_core::Formula;
    let generated = scenario.generate(side)?;
    let scene = generated.scene;
    let sim =
        nesy_sim::world::Sim::new(&scene).with_context(|| format!("building {} ({side:?})", scenario.id))?;
    let mut init = nesy_sim::perception::observer::observe(&sim);
    // The domain's schemas are split by end effector on this atom.
    init.insert(nesy_core::Atom::new(scene.embodiment.state_predicate(), &[]));
    let goal = Formula::And(scene.symbolic_goal().into_iter().map(Formula::atom).collect());
    let world = nesy_sim::domain::WorldDomain::builtin()?;
    let names = sim.names();
    let name = format!(
        "{}-{}",
        scenario.id,
        if side == Side::Source { "source" } else { "target" }
    );
    let problem = world.problem(&name, names.iter().map(String::as_str), init, goal);
    Ok((problem.to_string(), names))
}
