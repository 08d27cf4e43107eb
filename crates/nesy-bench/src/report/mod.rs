//! The report of a run: `report.md`, `tables/*.csv` and `plots/*.png` in the run directory.
//!
//! Every cell comes from the units' records through [`nesy_core::metrics::Tally`]: cells are
//! tallied once and the row blocks and the pooled "All" column merge cells, so the pooled
//! figures are scenario-weighted means over every scored unit, as the paper's "on average"
//! figures are. SR and GC count a unit that never executed as 0; PD averages over successful
//! units by default (the paper's tables), with the all-units PD in the CSV. Units with an
//! unusable demonstration are excluded from every method alike and listed.

mod csv;
mod figures;
mod html;
mod markdown;
pub mod plot;
mod study_tables;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use nesy_core::benchmark::{Complexity, Factor, FactorGroup};
use nesy_core::metrics::Tally;
use serde::Serialize;

use crate::error::BenchError;
use crate::harness::final_records;
use crate::manifest::{Manifest, Responder};
use crate::methods::{self, Role};
use crate::status::UnitStatus;
use crate::store;
use crate::unit_record::UnitRecord;
use csv::{csv_field, stages_csv, status_csv, table1_csv, time_csv, units_csv};
use figures::{plot_cells, plot_complexity, plot_gap};
use markdown::markdown;

pub use html::BENCH_HTML_FILE;
use plot::Value;

/// Tallies of one group of units.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Aggregate {
    /// SR (strict), 0/1 per scored unit.
    pub sr: Tally,
    /// GC (strict).
    pub gc: Tally,
    /// SR by the authors' latch.
    pub latched_sr: Tally,
    /// GC by the authors' latch.
    pub latched_gc: Tally,
    /// PD over the units that succeeded (strict).
    pub pd_success: Tally,
    /// PD over every scored unit.
    pub pd_all: Tally,
    /// Seconds in model calls per scored unit.
    pub vlm_s: Tally,
    /// Seconds of symbolic work per scored unit.
    pub symbolic_s: Tally,
    /// Model calls per scored unit.
    pub calls: Tally,
    /// Statuses of every unit (scored or not).
    pub statuses: BTreeMap<UnitStatus, usize>,
}

impl Aggregate {
    /// Adds a unit.
    pub fn push(&mut self, r: &UnitRecord) {
        *self.statuses.entry(r.status).or_default() += 1;
        if !r.status.is_scored() {
            return;
        }
        let s = &r.scores;
        self.sr.push(s.sr);
        self.gc.push(s.gc);
        self.latched_sr.push(s.latched_sr);
        self.latched_gc.push(s.latched_gc);
        self.pd_all.push(s.pd);
        if s.sr == 1.0 {
            self.pd_success.push(s.pd);
        }
        self.vlm_s.push(r.effort.time.vlm_s);
        self.symbolic_s.push(r.effort.time.symbolic_s);
        self.calls.push(r.effort.calls as f64);
    }

    /// Both groups' units together.
    pub fn merged(&self, other: &Aggregate) -> Aggregate {
        let mut statuses = self.statuses.clone();
        for (k, v) in &other.statuses {
            *statuses.entry(*k).or_default() += v;
        }
        Aggregate {
            sr: self.sr.merged(&other.sr),
            gc: self.gc.merged(&other.gc),
            latched_sr: self.latched_sr.merged(&other.latched_sr),
            latched_gc: self.latched_gc.merged(&other.latched_gc),
            pd_success: self.pd_success.merged(&other.pd_success),
            pd_all: self.pd_all.merged(&other.pd_all),
            vlm_s: self.vlm_s.merged(&other.vlm_s),
            symbolic_s: self.symbolic_s.merged(&other.symbolic_s),
            calls: self.calls.merged(&other.calls),
            statuses,
        }
    }

    /// Scored units.
    pub fn n(&self) -> usize {
        self.sr.n
    }

    /// Strict successes out of the scored units.
    pub fn sr_counts(&self) -> crate::stats::Proportion {
        crate::stats::Proportion {
            // SR is 0 or 1 per unit, so its sum counts the successes.
            k: self.sr.sum.round() as u64,
            n: self.sr.n as u64,
        }
    }
}

/// A cell of Table 1: a factor group at a complexity, or pooled over complexities (`None`).
pub type CellKey = (FactorGroup, Option<Complexity>);

/// Every variant's cells, rows and the pooled column.
#[derive(Debug, Clone, Default)]
pub struct Tables {
    /// Variant ids in manifest order.
    pub variants: Vec<String>,
    /// `cells[variant][(group, complexity)]`; `(group, None)` pools the group's row, and the
    /// pooled "All" column is in `all`.
    pub cells: BTreeMap<String, BTreeMap<CellKey, Aggregate>>,
    /// Per variant and complexity, pooled over every factor: the "All" column by complexity.
    pub by_complexity: BTreeMap<String, BTreeMap<Complexity, Aggregate>>,
    /// Per variant, everything.
    pub all: BTreeMap<String, Aggregate>,
}

impl Tables {
    /// Tallies `records` of the listed variants.
    pub fn build(variants: &[String], records: &[&UnitRecord]) -> Tables {
        let mut t = Tables {
            variants: variants.to_vec(),
            ..Tables::default()
        };
        for v in variants {
            let mut cells: BTreeMap<CellKey, Aggregate> = BTreeMap::new();
            let mut by_c: BTreeMap<Complexity, Aggregate> = BTreeMap::new();
            for r in records.iter().filter(|r| &r.key.variant == v) {
                let g = r.factor.group();
                cells.entry((g, Some(r.complexity))).or_default().push(r);
                by_c.entry(r.complexity).or_default().push(r);
            }
            let mut all = Aggregate::default();
            for g in FactorGroup::ALL {
                let mut row = Aggregate::default();
                for c in Complexity::ALL {
                    if let Some(a) = cells.get(&(g, Some(c))) {
                        row = row.merged(a);
                    }
                }
                all = all.merged(&row);
                cells.insert((g, None), row);
            }
            t.cells.insert(v.clone(), cells);
            t.by_complexity.insert(v.clone(), by_c);
            t.all.insert(v.clone(), all);
        }
        t
    }
}

/// Mean ± SE in percent, `–` without values.
pub fn pct(t: &Tally) -> String {
    let m = t.mean_se().percent();
    if t.n == 0 {
        "–".into()
    } else if m.se.is_nan() {
        format!("{:.2}", m.mean)
    } else {
        format!("{:.2}±{:.2}", m.mean, m.se)
    }
}

fn value(t: &Tally) -> Option<Value> {
    (t.n > 0).then(|| {
        let m = t.mean_se().percent();
        Value {
            mean: m.mean,
            se: m.se,
        }
    })
}

/// The report's options.
#[derive(Debug, Clone, Default)]
pub struct ReportOptions {
    /// Write a report although units are missing (stamped PARTIAL).
    pub allow_partial: bool,
}

/// What the report wrote.
#[derive(Debug, Clone, Serialize)]
pub struct ReportFiles {
    /// `report.md`.
    pub report: PathBuf,
    /// `report.html`: the tables, the plots and the failure gallery.
    pub html: PathBuf,
    /// The CSV tables.
    pub tables: Vec<PathBuf>,
    /// The PNG plots.
    pub plots: Vec<PathBuf>,
    /// True if units were missing.
    pub partial: bool,
}

/// The banner of a run: what its numbers are and are not (who answered; for a live model, the
/// model, the observation setting and the sample its figures describe).
pub fn banner(manifest: &Manifest) -> Option<String> {
    let noisy: Vec<String> = manifest
        .variants
        .iter()
        .filter_map(|v| v.variant.option("noise").map(|n| format!("`{n}`")))
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    let base = base_banner(manifest)?;
    Some(if noisy.is_empty() {
        base
    } else {
        format!(
            "{base} SYNTHETIC: variants with `noise` degrade the responder's answers on purpose under the stated error model ({}); their rows are not upper bounds either.",
            noisy.join(", ")
        )
    })
}

fn base_banner(manifest: &Manifest) -> Option<String> {
    match &manifest.responder {
        Responder::Live {
            backend,
            model,
            constrain,
            ..
        } => Some(format!(
            // The first sentence is what a figure shows: short enough for the narrowest one.
            "REAL MODEL — {model} ({backend}, constraints {constrain}), observation {}, {}. These numbers describe this model in this setting only; none is comparable with the paper's tables.",
            manifest.settings.observation.as_str(),
            sample_words(manifest)
        )),
        Responder::Oracle => Some(
            "OFFLINE — no model answered. NeSyCR rows are the reference responder's upper bound (ground-truth answers, every one checked by the symbolic executor); control rows use no model. No number here is a method's performance, and none is comparable with the paper's tables.".into(),
        ),
        Responder::Replay { cassettes } => Some(format!(
            "REPLAYED — the model calls are replayed from {}; the numbers are those of the recorded run.",
            cassettes.display()
        )),
    }
}

/// The run's scenarios in words: how many, and how they were drawn when sampled.
fn sample_words(manifest: &Manifest) -> String {
    let scenarios = manifest
        .units
        .iter()
        .map(|u| u.scenario.as_str())
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    match manifest.selection.sample {
        Some(_) => format!(
            "{scenarios} scenarios ({}sample, seed {})",
            if manifest.selection.stratify {
                "stratified "
            } else {
                ""
            },
            manifest.selection.sample_seed
        ),
        None => format!("{scenarios} scenarios"),
    }
}

/// Writes `report.md`, the CSV tables and the plots of a run. Units without a final record
/// are an error unless `allow_partial`; two final records of one unit always are.
pub fn write(run: &Path, options: &ReportOptions) -> Result<ReportFiles, BenchError> {
    let manifest = Manifest::read(run)?;
    let grouped = store::latest_by_unit(store::read_all(run)?);
    let duplicates: Vec<String> = grouped
        .iter()
        .filter(|(_, rs)| rs.iter().filter(|r| r.status.is_final()).count() > 1)
        .map(|(n, _)| n.clone())
        .collect();
    if !duplicates.is_empty() {
        return Err(BenchError::Incomplete {
            message: format!(
                "{} unit(s) have more than one final record (shards overlapping?): {}",
                duplicates.len(),
                sample(&duplicates)
            ),
            missing: Vec::new(),
            duplicates,
        });
    }
    let records = final_records(run)?;
    let missing = crate::harness::missing_units(&manifest, &records);
    if !missing.is_empty() && !options.allow_partial {
        return Err(BenchError::Incomplete {
            message: format!(
                "{} of {} unit(s) have no final record: {} (resume the run, or --allow-partial for a report stamped PARTIAL)",
                missing.len(),
                manifest.units.len(),
                sample(&missing)
            ),
            missing,
            duplicates: Vec::new(),
        });
    }
    let mut ordered: Vec<&UnitRecord> = records.values().collect();
    ordered.sort_by(|a, b| a.key.cmp(&b.key));
    let variants: Vec<String> = manifest.variants.iter().map(|v| v.id.clone()).collect();
    let tables = Tables::build(&variants, &ordered);
    std::fs::create_dir_all(run.join("tables")).map_err(|e| BenchError::io(run.join("tables"), e))?;
    std::fs::create_dir_all(run.join("plots")).map_err(|e| BenchError::io(run.join("plots"), e))?;
    let mut files = ReportFiles {
        report: run.join("report.md"),
        html: run.join(BENCH_HTML_FILE),
        tables: Vec::new(),
        plots: Vec::new(),
        partial: !missing.is_empty(),
    };
    for (name, text) in [
        ("table1.csv", table1_csv(&tables)),
        ("units.csv", units_csv(&ordered)),
        ("status.csv", status_csv(&tables)),
        ("time.csv", time_csv(&tables)),
        ("domain_gap.csv", gap_csv(&variants, &ordered)),
        ("stages.csv", stages_csv(&variants, &ordered)),
    ] {
        let path = run.join("tables").join(name);
        std::fs::write(&path, text).map_err(|e| BenchError::io(&path, e))?;
        files.tables.push(path);
    }
    let banner = banner(&manifest);
    for (name, canvas) in [
        ("sr_gc_pd.png", plot_cells(&tables, banner.as_deref())),
        ("domain_gap.png", plot_gap(&variants, &ordered, banner.as_deref())),
        ("complexity.png", plot_complexity(&tables, banner.as_deref())),
    ] {
        let path = run.join("plots").join(name);
        canvas.save(&path)?;
        files.plots.push(path);
    }
    let study = manifest
        .study
        .map(|s| study_tables::StudyTable::build(s, &ordered));
    if let Some(table) = &study {
        let path = run.join("tables").join("study.csv");
        std::fs::write(&path, table.csv()).map_err(|e| BenchError::io(&path, e))?;
        files.tables.push(path);
        let path = run.join("plots").join("study.png");
        table.plot().save(&path)?;
        files.plots.push(path);
        if let (Some(csv), Some(canvas)) = (table.added_csv(), table.added_plot()) {
            let path = run.join("tables").join("complexity_gap.csv");
            std::fs::write(&path, csv).map_err(|e| BenchError::io(&path, e))?;
            files.tables.push(path);
            let path = run.join("plots").join("complexity_gap.png");
            canvas.save(&path)?;
            files.plots.push(path);
        }
    }
    let study_md = study.as_ref().map(study_tables::StudyTable::markdown);
    let md = markdown(
        &manifest,
        &tables,
        &ordered,
        &missing,
        banner.as_deref(),
        study_md.as_deref(),
    );
    std::fs::write(&files.report, md).map_err(|e| BenchError::io(&files.report, e))?;
    let relative = |paths: &[PathBuf]| -> Vec<String> {
        paths
            .iter()
            .map(|p| p.strip_prefix(run).unwrap_or(p).display().to_string())
            .collect()
    };
    let page = html::bench_html(&html::HtmlInputs {
        run,
        manifest: &manifest,
        tables: &tables,
        records: &ordered,
        missing: &missing,
        banner: banner.as_deref(),
        study: study_md.as_deref(),
        plots: relative(&files.plots),
        csv: relative(&files.tables),
    });
    std::fs::write(&files.html, page).map_err(|e| BenchError::io(&files.html, e))?;
    Ok(files)
}

fn sample(names: &[String]) -> String {
    let shown: Vec<&str> = names.iter().take(8).map(String::as_str).collect();
    let more = names.len().saturating_sub(shown.len());
    if more > 0 {
        format!("{} and {more} more", shown.join(", "))
    } else {
        shown.join(", ")
    }
}

fn is_method(variant: &str) -> bool {
    let method = variant.split('+').next().unwrap_or(variant);
    methods::find(method).is_ok_and(|m| m.info().role == Role::Method)
}

/// The domain-gap level of a unit: its obstruction change binned, for the obst, affo and
/// comb factors (`None` for the others and for complexity-gap scenarios). The change is the
/// one the record carries, so a run over an edited `--suite` is binned by its own
/// configurations; a record written before records carried it is looked up in `fallback`.
pub fn gap_level(record: &UnitRecord, fallback: &[nesy_sim::tasks::scenario::Scenario]) -> Option<usize> {
    if !matches!(record.factor, Factor::Obst | Factor::Affo | Factor::Comb) || record.added_subtasks.is_some()
    {
        return None;
    }
    let change = match record.obstruction_change {
        Some(change) => change,
        None => fallback
            .iter()
            .find(|s| s.id == record.key.scenario)?
            .obstruction_change()?,
    };
    Some(match change {
        0..=2 => 0,
        3..=4 => 1,
        _ => 2,
    })
}

const GAP_LEVELS: [&str; 3] = ["Low", "Moderate", "High"];

fn gap_tallies(variants: &[String], records: &[&UnitRecord]) -> BTreeMap<String, [Aggregate; 3]> {
    // Only records from before the change was recorded need the generated suite.
    let fallback = if records
        .iter()
        .any(|r| r.obstruction_change.is_none() && r.added_subtasks.is_none())
    {
        nesy_sim::tasks::scenario::scenarios(&nesy_sim::tasks::scenario::generate_suite())
    } else {
        Vec::new()
    };
    let mut out: BTreeMap<String, [Aggregate; 3]> = BTreeMap::new();
    for v in variants {
        out.insert(v.clone(), Default::default());
    }
    for r in records {
        if let (Some(level), Some(slot)) = (gap_level(r, &fallback), out.get_mut(&r.key.variant)) {
            slot[level].push(r);
        }
    }
    out
}

fn gap_csv(variants: &[String], records: &[&UnitRecord]) -> String {
    let mut out = String::from("variant,gap_level,n,sr_mean,sr_se,pd_success_mean,pd_success_se\n");
    for (v, levels) in gap_tallies(variants, records) {
        for (k, a) in levels.iter().enumerate() {
            let (sr, pd) = (a.sr.mean_se().percent(), a.pd_success.mean_se().percent());
            let _ = writeln!(
                out,
                "{},{},{},{:.4},{:.4},{:.4},{:.4}",
                csv_field(&v),
                GAP_LEVELS[k],
                a.n(),
                sr.mean,
                sr.se,
                pd.mean,
                pd.se
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use nesy_core::metrics::Tally;

    use super::*;

    fn tally(mean_pct: f64, n: usize) -> Tally {
        Tally {
            n,
            sum: mean_pct / 100.0 * n as f64,
            sum_sq: 0.0,
        }
    }

    /// The paper's Table 1 cells (O&A, K&G, Comb × Low, Medium, High) for one metric.
    type Cells = [[f64; 3]; 3];
    const N: [[usize; 3]; 3] = [[60, 60, 40], [60, 60, 40], [40, 40, 40]];

    fn pooled(cells: &Cells) -> f64 {
        let mut all = Tally::default();
        for (g, row) in cells.iter().enumerate() {
            for (c, mean) in row.iter().enumerate() {
                all = all.merged(&tally(*mean, N[g][c]));
            }
        }
        all.mean_se().percent().mean
    }

    /// PD pooled over successful episodes: each cell weighs by its number of successes.
    fn pooled_pd(pd: &Cells, sr: &Cells) -> f64 {
        let mut all = Tally::default();
        for g in 0..3 {
            for c in 0..3 {
                let successes = (sr[g][c] / 100.0 * N[g][c] as f64).round() as usize;
                all = all.merged(&tally(pd[g][c], successes));
            }
        }
        all.mean_se().percent().mean
    }

    const NESYCR_SR: Cells = [
        [86.67, 75.00, 60.00],
        [93.33, 78.33, 52.50],
        [80.00, 65.00, 47.50],
    ];
    const NESYCR_GC: Cells = [
        [92.50, 90.56, 83.12],
        [96.67, 85.00, 78.12],
        [88.75, 83.33, 75.00],
    ];
    const NESYCR_PD: Cells = [[1.92, 10.57, 12.50], [0.00, 5.11, 10.12], [2.81, 6.60, 17.11]];
    const GPT4V_SR: Cells = [
        [71.67, 41.67, 20.00],
        [60.00, 56.67, 30.00],
        [55.00, 35.00, 15.00],
    ];
    const GPT4V_GC: Cells = [
        [82.50, 68.89, 57.50],
        [68.33, 81.67, 76.88],
        [70.00, 69.17, 63.12],
    ];
    const STATLER_SR: Cells = [[61.67, 41.67, 5.00], [68.33, 50.00, 42.50], [67.50, 52.50, 32.50]];
    const STATLER_GC: Cells = [
        [75.83, 71.67, 60.62],
        [74.17, 70.56, 74.38],
        [81.25, 82.50, 73.12],
    ];
    const D2C_SR: Cells = [[26.67, 25.00, 22.50], [33.33, 25.00, 20.00], [30.00, 20.00, 7.50]];
    const D2C_PD: Cells = [[5.00, 10.67, 6.94], [0.00, 0.00, 7.81], [0.00, 5.56, 12.50]];

    #[test]
    fn pooling_reproduces_the_papers_averages() {
        let sr = pooled(&NESYCR_SR);
        assert!(
            (sr - pooled(&GPT4V_SR) - 27.73).abs() < 0.005,
            "{}",
            sr - pooled(&GPT4V_SR)
        );
        assert!((sr - pooled(&STATLER_SR) - 24.77).abs() < 0.005);
        assert!((sr - pooled(&D2C_SR) - 49.09).abs() < 0.005);
        let gc = pooled(&NESYCR_GC);
        // The paper says 15.16; its rounded cells give 15.15.
        assert!((gc - pooled(&GPT4V_GC) - 15.16).abs() < 0.015);
        assert!((gc - pooled(&STATLER_GC) - 13.20).abs() < 0.005);
        // "Only a 1.73 average increase" in PD over Demo2Code, pooled over successes.
        let gap = pooled_pd(&NESYCR_PD, &NESYCR_SR) - pooled_pd(&D2C_PD, &D2C_SR);
        assert!((gap - 1.73).abs() < 0.01, "{gap}");
    }

    #[test]
    fn failures_count_as_zero_and_unusable_demos_are_excluded() {
        use crate::store::tests::record;
        let records = [
            record("a", "m", UnitStatus::Succeeded, 1.0),
            record("b", "m", UnitStatus::MethodError, 0.0),
            record("c", "m", UnitStatus::ExecutionFailed, 0.0),
            record("d", "m", UnitStatus::DemoUnusable, 0.0),
        ];
        let refs: Vec<&UnitRecord> = records.iter().collect();
        let t = Tables::build(&["m".to_owned()], &refs);
        let all = &t.all["m"];
        assert_eq!(all.n(), 3, "the unusable demo is not scored");
        assert!((all.sr.mean_se().mean - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(all.pd_success.n, 1, "PD by default over successful units only");
        assert_eq!(all.pd_all.n, 3);
        assert_eq!(all.statuses[&UnitStatus::DemoUnusable], 1);
        assert_eq!(
            all.statuses.values().sum::<usize>(),
            4,
            "every unit is accounted for"
        );
    }

    /// A live run's banner, on every figure and atop the report, names the model, the
    /// observation setting and the sample (the published real-model run's manifest).
    #[test]
    fn a_live_run_is_labelled_with_its_model_setting_and_sample() {
        let text = include_str!("../../../../bench/runs/2026-12-06-gemma3-270m/manifest.json");
        let manifest = Manifest::parse(Path::new("manifest.json"), text).unwrap();
        let banner = banner(&manifest).expect("a live run has a banner");
        assert_eq!(
            banner,
            "REAL MODEL — gemma3-270m-q4_k_m (llamacpp, constraints auto), observation state-text, 12 scenarios (stratified sample, seed 0). These numbers describe this model in this setting only; none is comparable with the paper's tables."
        );
        // What the figures show fits the narrowest of them (1,100 pixels of 8-pixel glyphs).
        assert!(figures::short_banner(&banner).chars().count() <= 1100 / 8);
    }

    #[test]
    fn se_uses_ddof_one() {
        let mut t = Tally::default();
        for v in [1.0, 0.0, 1.0, 0.0] {
            t.push(v);
        }
        let m = t.mean_se();
        assert!((m.se - (1.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-12);
        assert_eq!(pct(&Tally::default()), "–");
    }

    /// The level follows the change a record carries, so an edited suite is binned by its
    /// own configurations; a record without one is looked up in the generated suite; the
    /// complexity-gap suite and the embodiment factors have no level.
    #[test]
    fn gap_levels_follow_the_recorded_obstruction_change() {
        use crate::store::tests::record;
        let suite = nesy_sim::tasks::scenario::scenarios(&nesy_sim::tasks::scenario::generate_suite());
        let real = &suite.iter().find(|s| s.id == "obst_high_03_s0").unwrap();
        let change = real.obstruction_change().unwrap();
        assert!(change >= 4, "4 obstructed subtasks: {change}");
        let mut r = record("obst_high_03_s0", "m", UnitStatus::Succeeded, 1.0);
        let looked_up = gap_level(&r, &suite);
        assert_eq!(looked_up, Some(if change <= 4 { 1 } else { 2 }));
        for (recorded, level) in [(1, 0), (2, 0), (3, 1), (4, 1), (5, 2), (9, 2)] {
            r.obstruction_change = Some(recorded);
            assert_eq!(gap_level(&r, &suite), Some(level), "change {recorded}");
            assert_eq!(gap_level(&r, &[]), Some(level), "no suite needed");
        }
        r.factor = Factor::Grip;
        assert_eq!(gap_level(&r, &suite), None);
        r.factor = Factor::Obst;
        r.added_subtasks = Some(2);
        assert_eq!(gap_level(&r, &suite), None);
        let gap = nesy_sim::tasks::scenario::scenarios(&nesy_sim::tasks::scenario::generate_gap_suite());
        assert!(gap.iter().all(|s| s.obstruction_change().is_none()));
    }
}
