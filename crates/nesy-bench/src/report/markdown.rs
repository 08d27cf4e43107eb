//! `report.md`: provenance, the methods, Table 1 (strict and latched), the status of every
//! unit, the time, state-translation and model-call tables, and the figures.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use nesy_core::benchmark::{Complexity, FactorGroup};
use nesy_core::metrics::Tally;

use super::csv::stage_use;
use super::{Aggregate, Tables, is_method, pct};
use crate::manifest::{Manifest, Observation, Responder};
use crate::methods::{self, OfflineMeaning, Role};
use crate::status::UnitStatus;
use crate::unit_record::UnitRecord;

pub(super) fn title_of(variant: &str) -> String {
    let method = variant.split('+').next().unwrap_or(variant);
    let title = methods::find(method).map(|m| m.info().title).unwrap_or(method);
    match variant.split_once('+') {
        Some((_, settings)) => format!("{title} [{}]", settings.replace('+', ", ")),
        None => title.to_owned(),
    }
}

pub(super) fn complexity_title(c: Complexity) -> &'static str {
    match c {
        Complexity::Low => "Low",
        Complexity::Medium => "Medium",
        Complexity::High => "High",
    }
}

/// Table 1's shape: row blocks by factor group, Low/Medium/High × SR/GC/PD and the pooled
/// All column; the best SR and GC of each column within a block in bold (lowest PD).
pub(super) fn table1_markdown(tables: &Tables, latched: bool) -> String {
    let mut md = String::new();
    let (sr_name, gc_name) = if latched {
        ("SR (latched)", "GC (latched)")
    } else {
        ("SR", "GC")
    };
    let _ = write!(md, "| Method |");
    for c in Complexity::ALL {
        let _ = write!(md, " {} {sr_name} | {gc_name} | PD |", complexity_title(c));
    }
    let _ = writeln!(md, " All {sr_name} | {gc_name} | PD | n |");
    let _ = writeln!(md, "|---|{}", "---|".repeat(13));
    let mut columns: Vec<Option<Complexity>> = Complexity::ALL.iter().copied().map(Some).collect();
    columns.push(None);
    for g in FactorGroup::ALL {
        let _ = writeln!(md, "| **{}** |{}", g.title(), " |".repeat(13));
        for v in &tables.variants {
            let _ = write!(md, "| {} |", title_of(v));
            let cells = &tables.cells[v];
            for col in &columns {
                let a = cells.get(&(g, *col)).cloned().unwrap_or_default();
                let (sr, gc) = if latched {
                    (&a.latched_sr, &a.latched_gc)
                } else {
                    (&a.sr, &a.gc)
                };
                // The best method in the column (controls are not ranked).
                let best = |pick: &dyn Fn(&Aggregate) -> &Tally, high: bool| {
                    let mine = pick(&a).mean_se().mean;
                    let ranked: Vec<&String> = tables.variants.iter().filter(|o| is_method(o)).collect();
                    is_method(v)
                        && ranked.len() > 1
                        && pick(&a).n > 0
                        && ranked.iter().all(|o| {
                            let other = tables.cells[o.as_str()]
                                .get(&(g, *col))
                                .map(|x| pick(x).mean_se().mean);
                            other.is_none_or(|m| m.is_nan() || if high { mine >= m } else { mine <= m })
                        })
                };
                let bold = |text: String, b: bool| if b { format!("**{text}**") } else { text };
                let sr_best = best(&|x| if latched { &x.latched_sr } else { &x.sr }, true);
                let gc_best = best(&|x| if latched { &x.latched_gc } else { &x.gc }, true);
                let _ = write!(
                    md,
                    " {} | {} | {} |",
                    bold(pct(sr), sr_best),
                    bold(pct(gc), gc_best),
                    pct(&a.pd_success)
                );
            }
            let n = cells.get(&(g, None)).map_or(0, Aggregate::n);
            let _ = writeln!(md, " {n} |");
        }
    }
    md
}

pub(super) fn markdown(
    manifest: &Manifest,
    tables: &Tables,
    records: &[&UnitRecord],
    missing: &[String],
    banner: Option<&str>,
    study: Option<&str>,
) -> String {
    let mut md = String::new();
    write_header(&mut md, manifest, missing, banner);
    write_provenance(&mut md, manifest);
    if let Some(section) = study {
        let _ = writeln!(md);
        md.push_str(section);
    }
    write_methods(&mut md, manifest);
    write_table1(&mut md, tables, records);
    write_statuses(&mut md, tables, records);
    write_time(&mut md, tables);
    write_translation(&mut md, tables, records);
    write_calls(&mut md, tables, records);
    write_figures(&mut md);
    md
}

/// The title, the run's banner and, for a partial run, how many units are missing.
fn write_header(md: &mut String, manifest: &Manifest, missing: &[String], banner: Option<&str>) {
    let partial = if missing.is_empty() { "" } else { " — PARTIAL" };
    let _ = writeln!(md, "# nesy bench report{partial}\n");
    if let Some(b) = banner {
        let _ = writeln!(md, "> **{b}**\n");
    }
    if !missing.is_empty() {
        let _ = writeln!(
            md,
            "> **PARTIAL: {} of {} units have no final record; the cells below count only the units that finished.**\n",
            missing.len(),
            manifest.units.len()
        );
    }
}

/// Who answered, which build, which machine, which scenarios and seeds.
fn write_provenance(md: &mut String, manifest: &Manifest) {
    let p = &manifest.provenance;
    let _ = writeln!(md, "## Provenance\n");
    let _ = writeln!(md, "- responder: {}", manifest.responder.describe());
    let _ = writeln!(
        md,
        "- nesy {} at `{}`; simulator `{}`; prompts `{}`",
        p.nesy_version,
        if p.git_commit.is_empty() {
            "unknown commit"
        } else {
            &p.git_commit
        },
        p.sim_fingerprint,
        &p.prompts_fingerprint[..p.prompts_fingerprint.len().min(16)]
    );
    let _ = writeln!(md, "- machine: {} ({})", p.machine, p.host);
    let _ = writeln!(
        md,
        "- created {}; run seed {}; {} repeat(s); {} units; scenarios: {}",
        manifest.created_at,
        manifest.run_seed,
        manifest.repeats,
        manifest.units.len(),
        if manifest.selection.patterns.is_empty() {
            match manifest.study {
                Some(study) if study.uses_gap_suite() => "all of the complexity-gap suite".to_owned(),
                Some(study) if let Some(family) = study.family() => format!("all of the {family} family"),
                _ => "all 440".to_owned(),
            }
        } else {
            manifest.selection.patterns.join(", ")
        }
    );
    if let Some(k) = manifest.selection.sample {
        let _ = writeln!(
            md,
            "- a {}sample of {k} scenarios, seed {}",
            if manifest.selection.stratify {
                "stratified (factor group × complexity) "
            } else {
                ""
            },
            manifest.selection.sample_seed
        );
    }
    let _ = writeln!(
        md,
        "- observation: {}",
        match manifest.settings.observation {
            Observation::Images => "the rendered views (`images`)",
            Observation::StateText =>
                "each scene's ground-truth state as text in place of its pictures (`state-text`)",
        }
    );
    if let Some(src) = &manifest.reexecutes {
        let _ = writeln!(
            md,
            "- phase B only: re-executes the specifications of `{}`",
            src.display()
        );
    }
    let _ = writeln!(
        md,
        "- demos with a goal gap: {}",
        if manifest.settings.keep_gapped_demos {
            "used anyway (the authors' behaviour)"
        } else {
            "excluded from every method (`demo_unusable`)"
        }
    );
}

/// Each variant with its role and what its offline rows mean.
fn write_methods(md: &mut String, manifest: &Manifest) {
    let _ = writeln!(md, "\n## Methods\n");
    for v in &manifest.variants {
        if let Ok(m) = methods::find(&v.variant.method) {
            let info = m.info();
            let role = match info.role {
                Role::Method => "method",
                Role::Control => "CONTROL",
            };
            let noisy = v.variant.option("noise").is_some();
            let answered = answered_by(info.offline, &manifest.responder, noisy);
            let _ = writeln!(
                md,
                "- **{}** ({role}; {answered}): {}",
                title_of(&v.id),
                info.summary
            );
        }
    }
}

/// Who gave a method's answers in this run, in words. What an offline row means applies only
/// when the offline responder answered: a live model's rows, and a replay of its calls, are
/// that model's.
fn answered_by(offline: OfflineMeaning, responder: &Responder, noisy: bool) -> &'static str {
    match (offline, responder) {
        (OfflineMeaning::ModelFree, _) => "uses no model",
        (_, Responder::Live { .. }) => "answered by the model",
        (_, Responder::Replay { .. }) => "the recorded run's answers, replayed",
        // Under injected noise the responder is no longer the best case: its rows measure the
        // checks under the stated error model.
        (OfflineMeaning::UpperBound, Responder::Oracle) if noisy => {
            "offline: synthetic, under the stated noise, not an upper bound"
        }
        (OfflineMeaning::UpperBound, Responder::Oracle) => "offline: an upper bound",
        (OfflineMeaning::NotMeaningful, Responder::Oracle) => "needs a live model",
    }
}

/// Table 1, strictly scored and with the authors' latch.
fn write_table1(md: &mut String, tables: &Tables, records: &[&UnitRecord]) {
    let _ = writeln!(
        md,
        "\n## Table 1: SR, GC and PD per factor group and complexity\n"
    );
    let _ = writeln!(
        md,
        "Mean × 100 ± SE (SE = sample standard deviation with ddof = 1 over √n, the two seeds of a configuration counted as independent, as the paper does). SR and GC fail a subtask whose counted objects are out of place at the end; PD averages over successful units only (the all-units PD is in `tables/table1.csv`). A unit that did not execute scores 0. n: scored units per row block.\n"
    );
    md.push_str(&table1_markdown(tables, false));
    if records.iter().any(|r| r.added_subtasks.is_some()) {
        let _ = writeln!(
            md,
            "\nThis run includes scenarios of the auxiliary complexity-gap suite (not part of the 440). They count here under their factor at low complexity, whatever the target's subtask count; the study section gives them by added subtasks."
        );
    }
    write_wilson(md, tables);
    let _ = writeln!(md, "\n### The authors' latched SR and GC\n");
    let _ = writeln!(
        md,
        "The same units scored as the authors score them: an object counts once it was placed, even if it is knocked out again later.\n"
    );
    md.push_str(&table1_markdown(tables, true));
}

/// SR as success counts with 95 % Wilson intervals per factor group and overall, and how
/// many units per method a 10-point difference from each rate would need to be detected.
fn write_wilson(md: &mut String, tables: &Tables) {
    let _ = writeln!(md, "\n### SR as counts, with 95 % Wilson intervals\n");
    let _ = writeln!(
        md,
        "k/n successes (strict) and the Wilson score interval, which stays inside 0–100 % for small n. The last column: units per method that a two-sided test at 5 % with 80 % power would need to tell this overall rate from one 10 points lower (or higher, at 100 %); compare two runs unit by unit with `nesy bench compare`.\n"
    );
    let mut header = String::from("| Method |");
    let mut rule = String::from("|---|");
    for g in FactorGroup::ALL {
        let _ = write!(header, " {} |", g.title());
        rule.push_str("---|");
    }
    header.push_str(" All | units for ±10 pts |");
    rule.push_str("---|---|");
    let _ = writeln!(md, "{header}\n{rule}");
    let cell = |p: crate::stats::Proportion| match p.wilson_95() {
        Some((lo, hi)) => format!("{}/{} [{:.1}, {:.1}]", p.k, p.n, 100.0 * lo, 100.0 * hi),
        None => "–".to_owned(),
    };
    for v in &tables.variants {
        let mut row = format!("| {} |", title_of(v));
        for g in FactorGroup::ALL {
            let p = tables.cells[v]
                .get(&(g, None))
                .map(|a| a.sr_counts())
                .unwrap_or_default();
            let _ = write!(row, " {} |", cell(p));
        }
        let all = tables.all[v].sr_counts();
        let needed = all.rate().and_then(crate::stats::units_to_detect_ten_points);
        let _ = writeln!(
            md,
            "{row} {} | {} |",
            cell(all),
            needed.map_or("–".to_owned(), |n| n.to_string())
        );
    }
}

/// How every unit ended, the excluded scenarios and the units that did not succeed.
fn write_statuses(md: &mut String, tables: &Tables, records: &[&UnitRecord]) {
    let _ = writeln!(md, "\n## Status of every unit\n");
    let _ = write!(md, "| Method |");
    for s in UnitStatus::ALL {
        let _ = write!(md, " {} |", s.as_str());
    }
    let _ = writeln!(md, " all |\n|---|{}---|", "---|".repeat(UnitStatus::ALL.len()));
    for v in &tables.variants {
        let a = &tables.all[v];
        let _ = write!(md, "| {} |", title_of(v));
        for s in UnitStatus::ALL {
            let _ = write!(md, " {} |", a.statuses.get(&s).copied().unwrap_or(0));
        }
        let _ = writeln!(md, " {} |", a.statuses.values().sum::<usize>());
    }
    let excluded: BTreeSet<&str> = records
        .iter()
        .filter(|r| r.status == UnitStatus::DemoUnusable)
        .map(|r| r.key.scenario.as_str())
        .collect();
    if !excluded.is_empty() {
        let _ = writeln!(
            md,
            "\nExcluded scenarios (unusable demonstration, {}): {}",
            excluded.len(),
            excluded.iter().copied().collect::<Vec<_>>().join(", ")
        );
    }
    let _ = writeln!(md, "\n### Units that did not succeed\n");
    let mut failures = 0;
    for r in records
        .iter()
        .filter(|r| r.status.is_scored() && r.status != UnitStatus::Succeeded)
    {
        failures += 1;
        if failures <= 200 {
            let _ = writeln!(
                md,
                "- `{}`: {} — {}",
                r.key.name(),
                r.status,
                r.error.as_deref().unwrap_or("").lines().next().unwrap_or("")
            );
        }
    }
    if failures == 0 {
        let _ = writeln!(md, "None.");
    } else if failures > 200 {
        let _ = writeln!(md, "- … and {} more (see `tables/units.csv`)", failures - 200);
    }
}

/// Table 9's shape: model and symbolic time per scored unit.
fn write_time(md: &mut String, tables: &Tables) {
    let _ = writeln!(md, "\n## Table 9: where the time goes\n");
    let _ = writeln!(
        md,
        "Seconds per scored unit, mean ± SE. Model time is the time spent waiting for answers (offline: the responder's own computation); symbolic time is nesy's parsing, verification, identification, patching and planning.\n"
    );
    let _ = writeln!(
        md,
        "| Method | model s | symbolic s | model calls | n |\n|---|---|---|---|---|"
    );
    for v in &tables.variants {
        let a = &tables.all[v];
        let mean = |t: &Tally| {
            let m = t.mean_se();
            if t.n == 0 {
                "–".into()
            } else {
                format!("{:.4}±{:.4}", m.mean, if m.se.is_nan() { 0.0 } else { m.se })
            }
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            title_of(v),
            mean(&a.vlm_s),
            mean(&a.symbolic_s),
            mean(&a.calls),
            a.n()
        );
    }
}

/// Table 7's shape, when the states came from the model: translation against ground truth.
fn write_translation(md: &mut String, tables: &Tables, records: &[&UnitRecord]) {
    let translated: Vec<&&UnitRecord> = records.iter().filter(|r| r.states.is_some()).collect();
    if !translated.is_empty() {
        let _ = writeln!(md, "\n## Table 7: state translation against ground truth\n");
        let _ = writeln!(
            md,
            "| Method | precision | recall | F1 | units |\n|---|---|---|---|---|"
        );
        for v in &tables.variants {
            let mut p = Tally::default();
            let mut r_ = Tally::default();
            let mut f = Tally::default();
            for r in translated.iter().filter(|r| &r.key.variant == v) {
                if let Some(a) = r.states {
                    p.push(a.precision);
                    r_.push(a.recall);
                    f.push(a.f1);
                }
            }
            if p.n > 0 {
                let _ = writeln!(
                    md,
                    "| {} | {:.3} | {:.3} | {:.3} | {} |",
                    title_of(v),
                    p.mean_se().mean,
                    r_.mean_se().mean,
                    f.mean_se().mean,
                    p.n
                );
            }
        }
    }
}

/// Model calls per method and stage, with their cost.
fn write_calls(md: &mut String, tables: &Tables, records: &[&UnitRecord]) {
    let stages = stage_use(&tables.variants, records);
    if !stages.is_empty() {
        let _ = writeln!(md, "\n## Model calls per method and stage\n");
        let _ = writeln!(
            md,
            "| Method | stage | calls | per unit | cost (USD) |\n|---|---|---|---|---|"
        );
        for (v, stage, u) in &stages {
            let _ = writeln!(
                md,
                "| {} | `{stage}` | {} | {:.1} | {:.4} |",
                title_of(v),
                u.calls,
                u.calls as f64 / u.units.max(1) as f64,
                u.cost_usd
            );
        }
    }
}

/// The three figures and what their axes mean.
fn write_figures(md: &mut String) {
    let _ = writeln!(md, "\n## Figures\n");
    let _ = writeln!(md, "![SR, GC and PD per cell](plots/sr_gc_pd.png)\n");
    let _ = writeln!(
        md,
        "![SR and PD against the domain gap](plots/domain_gap.png)\n\nDomain-gap level (Figure 4(a)'s axis, which the paper does not define): the obstruction change summed over a scenario's subtasks, Σ|target obst − source obst|, on the obst, affo and comb scenarios; Low 1–2, Moderate 3–4, High ≥ 5. Embodiment-only scenarios (grip, vacu) have no obstruction change and are left out.\n"
    );
    let _ = writeln!(
        md,
        "![SR and PD against task complexity](plots/complexity.png)\n\nAgainst task complexity, not Figure 4(b)'s complexity gap: in the 440 suite the source and the target always have the same subtasks.\n"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A live model's NeSyCR rows are never called an upper bound, nor are their replays.
    #[test]
    fn only_the_offline_responder_gives_an_upper_bound() {
        let live = Responder::Live {
            backend: "llamacpp".to_owned(),
            model: "gemma3-270m-q4_k_m".to_owned(),
            base_url: "http://127.0.0.1:8080/v1".to_owned(),
            constrain: Default::default(),
        };
        let replay = Responder::Replay {
            cassettes: "run/cassettes".into(),
        };
        let upper = OfflineMeaning::UpperBound;
        assert_eq!(
            answered_by(upper, &Responder::Oracle, false),
            "offline: an upper bound"
        );
        assert!(answered_by(upper, &Responder::Oracle, true).contains("not an upper bound"));
        assert_eq!(answered_by(upper, &live, false), "answered by the model");
        assert_eq!(
            answered_by(OfflineMeaning::NotMeaningful, &live, false),
            "answered by the model"
        );
        assert_eq!(
            answered_by(upper, &replay, false),
            "the recorded run's answers, replayed"
        );
        for responder in [&Responder::Oracle, &live, &replay] {
            assert_eq!(
                answered_by(OfflineMeaning::ModelFree, responder, false),
                "uses no model"
            );
        }
    }
}
