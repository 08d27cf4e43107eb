//! A study's table (Table 3's or Table 8's shape), its CSV and its figure.
//!
//! SR and GC are averaged per scenario over its repeats first, and the mean ± SE is taken
//! over scenarios, so the noise seeds of one scenario are not counted as independent
//! episodes. PD is over the successful units, as in the paper.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use nesy_core::metrics::{MeanSe, Tally};

use super::csv_field;
use super::plot::{self, Bars, Frame, Value};
use crate::status::UnitStatus;
use crate::studies::{Study, StudyRow};
use crate::unit_record::UnitRecord;

/// One row's figures.
#[derive(Debug, Clone)]
pub(super) struct RowStats {
    row: StudyRow,
    id: String,
    /// Scenarios with at least one scored unit.
    scenarios: usize,
    /// Scored units.
    units: usize,
    sr: MeanSe,
    gc: MeanSe,
    pd: MeanSe,
    calls: MeanSe,
    statuses: BTreeMap<UnitStatus, usize>,
    /// Mean precision and recall of the translated states (demo keyframes and target
    /// pooled per unit), where states were translated.
    agreement: Option<(f64, f64)>,
    /// Per added-subtask count (complexity-gap scenarios only): SR pooled as the row's,
    /// and PD over the successful units.
    by_added: BTreeMap<u8, AddedStats>,
}

/// One row's figures at one added-subtask count.
#[derive(Debug, Clone)]
pub(super) struct AddedStats {
    scenarios: usize,
    sr: MeanSe,
    pd: MeanSe,
}

/// `pick` averaged per scenario over its repeats, then mean × 100 ± SE over scenarios; and
/// how many scenarios that is.
fn per_scenario(records: &[&UnitRecord], pick: impl Fn(&UnitRecord) -> f64) -> (usize, MeanSe) {
    let mut by_scenario: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    for r in records {
        by_scenario
            .entry(r.key.scenario.as_str())
            .or_default()
            .push(pick(r));
    }
    let mean = tally(
        by_scenario
            .values()
            .map(|v| v.iter().sum::<f64>() / v.len() as f64),
    )
    .percent();
    (by_scenario.len(), mean)
}

/// PD × 100 ± SE over the units that succeeded, as the paper reports it.
fn success_pd(records: &[&UnitRecord]) -> MeanSe {
    tally(records.iter().filter(|r| r.scores.sr == 1.0).map(|r| r.scores.pd)).percent()
}

/// A figure's point for a mean ± SE: none without units, no whisker for a single one.
fn plotted(m: &MeanSe) -> Option<Value> {
    (m.n > 0).then_some(Value {
        mean: m.mean,
        se: if m.n > 1 { m.se } else { f64::NAN },
    })
}

/// The study's rows, in the study's order.
#[derive(Debug, Clone)]
pub(super) struct StudyTable {
    study: Study,
    rows: Vec<RowStats>,
}

/// `mean±SE`, or the mean alone with its n when there is no SE to give.
fn shown(m: &MeanSe) -> String {
    match m.n {
        0 => "—".to_owned(),
        1 => format!("{:.2} (n=1)", m.mean),
        _ => m.to_string(),
    }
}

fn tally(values: impl IntoIterator<Item = f64>) -> MeanSe {
    let mut t = Tally::default();
    values.into_iter().for_each(|v| t.push(v));
    t.mean_se()
}

impl StudyTable {
    /// Tallies the records of every row of `study`.
    pub(super) fn build(study: Study, records: &[&UnitRecord]) -> StudyTable {
        let rows = study
            .rows()
            .into_iter()
            .map(|row| {
                let id = row.variant.id();
                let mine: Vec<&UnitRecord> =
                    records.iter().copied().filter(|r| r.key.variant == id).collect();
                let mut statuses = BTreeMap::new();
                for r in &mine {
                    *statuses.entry(r.status).or_default() += 1;
                }
                let scored: Vec<&UnitRecord> =
                    mine.iter().copied().filter(|r| r.status.is_scored()).collect();
                let (scenarios, sr) = per_scenario(&scored, |r| r.scores.sr);
                let (_, gc) = per_scenario(&scored, |r| r.scores.gc);
                let translated: Vec<_> = scored.iter().filter_map(|r| r.states.as_ref()).collect();
                let agreement = (!translated.is_empty()).then(|| {
                    let n = translated.len() as f64;
                    (
                        translated.iter().map(|a| a.precision).sum::<f64>() / n,
                        translated.iter().map(|a| a.recall).sum::<f64>() / n,
                    )
                });
                let mut by_added: BTreeMap<u8, Vec<&UnitRecord>> = BTreeMap::new();
                for r in &scored {
                    if let Some(k) = r.added_subtasks {
                        by_added.entry(k).or_default().push(r);
                    }
                }
                let by_added = by_added
                    .into_iter()
                    .map(|(k, rs)| {
                        let (scenarios, sr) = per_scenario(&rs, |r| r.scores.sr);
                        let pd = success_pd(&rs);
                        (k, AddedStats { scenarios, sr, pd })
                    })
                    .collect();
                RowStats {
                    by_added,
                    id,
                    scenarios,
                    units: scored.len(),
                    sr,
                    gc,
                    pd: success_pd(&scored),
                    calls: tally(scored.iter().map(|r| r.effort.calls as f64)),
                    statuses,
                    agreement,
                    row,
                }
            })
            .collect();
        StudyTable { study, rows }
    }

    /// The markdown section: banner, table, comparison with the full method, readings.
    pub(super) fn markdown(&self) -> String {
        let mut md = String::new();
        let study = self.study;
        let _ = writeln!(md, "## {}\n", study.title());
        let _ = writeln!(
            md,
            "> **SYNTHETIC — no model answered. Error model: {}** These rows say what nesy's symbolic checks do with a literal responder under this error model; they are not NeSyCR's or any ablation's performance, and they are not comparable with the paper's table, whose numbers come from a real model on the authors' scenes.\n",
            study.error_model()
        );
        let translated = self.rows.iter().any(|r| r.agreement.is_some());
        let _ = write!(
            md,
            "| row | scenarios | units | SR | GC | PD (successful units) | ΔSR vs full | \\|ΔSR\\| > SE | model calls / unit |"
        );
        if translated {
            let _ = write!(md, " state P / R |");
        }
        let _ = writeln!(md);
        let _ = write!(md, "|---|---|---|---|---|---|---|---|---|");
        if translated {
            let _ = write!(md, "---|");
        }
        let _ = writeln!(md);
        let full = self.rows.first();
        for (k, r) in self.rows.iter().enumerate() {
            let (delta, exceeds) = match full {
                Some(f) if k > 0 && r.scenarios > 0 && f.scenarios > 0 => {
                    let d = r.sr.mean - f.sr.mean;
                    let se = r.sr.se.max(f.sr.se);
                    (format!("{d:+.2}"), if d.abs() > se { "yes" } else { "no" })
                }
                _ => ("—".to_owned(), "—"),
            };
            let _ = write!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {:.1} |",
                r.row.label,
                r.scenarios,
                r.units,
                shown(&r.sr),
                shown(&r.gc),
                shown(&r.pd),
                delta,
                exceeds,
                r.calls.mean
            );
            if translated {
                match r.agreement {
                    Some((p, rc)) => {
                        let _ = write!(md, " {p:.3} / {rc:.3} |");
                    }
                    None => {
                        let _ = write!(md, " — |");
                    }
                }
            }
            let _ = writeln!(md);
        }
        let _ = writeln!(
            md,
            "\nSR and GC: mean × 100 ± SE over scenarios, each scenario's repeats (noise seeds) averaged first. PD: mean × 100 ± SE over the units that succeeded. ΔSR is against the first row; \"|ΔSR| > SE\" compares it with the larger of the two rows' SEs.{}\n",
            if translated {
                " State P / R: the translated states' precision and recall against the ground truth the prompt's predicate tier can express, demo keyframes and target pooled per unit, then averaged over units; a demo-only perturbation therefore shows diluted by the unperturbed target."
            } else {
                ""
            }
        );
        let added: Vec<u8> = self.added_counts();
        if !added.is_empty() {
            self.write_by_added(&mut md, &added);
        }
        let _ = writeln!(md, "How the units ended:\n");
        for r in &self.rows {
            let parts: Vec<String> = r.statuses.iter().map(|(s, n)| format!("{s} {n}")).collect();
            let _ = writeln!(md, "- {}: {}", r.row.label, parts.join(", "));
        }
        let _ = writeln!(md, "\nWhat each row runs:\n");
        for r in &self.rows {
            let _ = writeln!(md, "- **{}** (`{}`): {}.", r.row.label, r.id, r.row.reading);
        }
        let _ = writeln!(md);
        md
    }

    /// The complexity gap's table: each row's SR and PD by the number of subtasks the target
    /// adds to the demonstration's, and its figure.
    fn write_by_added(&self, md: &mut String, added: &[u8]) {
        let _ = writeln!(
            md,
            "By added subtasks (the target's subtasks beyond the demonstration's one): SR as above, PD over the successful units, n = scenarios.\n"
        );
        let _ = write!(md, "| row |");
        for k in added {
            let _ = write!(md, " +{k} SR | +{k} PD |");
        }
        let _ = writeln!(md);
        let _ = writeln!(md, "|---|{}", "---|---|".repeat(added.len()));
        for r in &self.rows {
            let _ = write!(md, "| {} |", r.row.label);
            for k in added {
                match r.by_added.get(k) {
                    Some(a) => {
                        let _ = write!(md, " {} (n={}) | {} |", shown(&a.sr), a.scenarios, shown(&a.pd));
                    }
                    None => {
                        let _ = write!(md, " — | — |");
                    }
                }
            }
            let _ = writeln!(md);
        }
        let _ = writeln!(
            md,
            "\n![SR and PD against the added subtasks](plots/complexity_gap.png)\n"
        );
    }

    /// The added-subtask counts any row has records for, ascending.
    fn added_counts(&self) -> Vec<u8> {
        let mut added: Vec<u8> = self
            .rows
            .iter()
            .flat_map(|r| r.by_added.keys().copied())
            .collect();
        added.sort_unstable();
        added.dedup();
        added
    }

    /// One CSV line per row and added-subtask count, when the records are of the
    /// complexity-gap suite.
    pub(super) fn added_csv(&self) -> Option<String> {
        let added = self.added_counts();
        if added.is_empty() {
            return None;
        }
        let mut out = String::from(
            "study,row,variant,added_subtasks,scenarios,sr_mean,sr_se,pd_success_mean,pd_success_se,pd_success_n\n",
        );
        for r in &self.rows {
            for (k, a) in &r.by_added {
                let _ = writeln!(
                    out,
                    "{},{},{},{k},{},{:.4},{:.4},{:.4},{:.4},{}",
                    self.study.name(),
                    csv_field(r.row.label),
                    csv_field(&r.id),
                    a.scenarios,
                    a.sr.mean,
                    a.sr.se,
                    a.pd.mean,
                    a.pd.se,
                    a.pd.n
                );
            }
        }
        Some(out)
    }

    /// SR and PD against the added subtasks, one line per row, when the records are of the
    /// complexity-gap suite.
    pub(super) fn added_plot(&self) -> Option<plot::Canvas> {
        let added = self.added_counts();
        if added.is_empty() {
            return None;
        }
        let categories: Vec<String> = added.iter().map(|k| format!("+{k}")).collect();
        let series: Vec<String> = self.rows.iter().map(|r| r.row.label.to_owned()).collect();
        let pick = |f: &dyn Fn(&AddedStats) -> &MeanSe| -> Vec<Vec<Option<Value>>> {
            self.rows
                .iter()
                .map(|r| {
                    added
                        .iter()
                        .map(|k| r.by_added.get(k).map(f).and_then(plotted))
                        .collect()
                })
                .collect()
        };
        Some(super::figures::two_panel_lines(
            super::figures::SrPd {
                header: "SR and PD against the complexity gap (auxiliary suite)",
                x_label: "subtasks added to the demonstrated one",
                categories: &categories,
                series: &series,
                sr: &pick(&|a| &a.sr),
                pd: &pick(&|a| &a.pd),
                note: "OFFLINE: the reference responder plans what the demo does not show; not the paper's Figure 4(b)",
            },
            Some("OFFLINE - no model answered; report.md states what the rows mean"),
        ))
    }

    /// One CSV line per row.
    pub(super) fn csv(&self) -> String {
        let mut out = String::from(
            "study,row,variant,scenarios,units,sr_mean,sr_se,gc_mean,gc_se,pd_success_mean,pd_success_se,pd_success_n,calls_mean,state_precision,state_recall\n",
        );
        for r in &self.rows {
            let (p, rc) = r.agreement.map_or((String::new(), String::new()), |(p, rc)| {
                (format!("{p:.4}"), format!("{rc:.4}"))
            });
            let _ = writeln!(
                out,
                "{},{},{},{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{},{:.2},{p},{rc}",
                self.study.name(),
                csv_field(r.row.label),
                csv_field(&r.id),
                r.scenarios,
                r.units,
                r.sr.mean,
                r.sr.se,
                r.gc.mean,
                r.gc.se,
                r.pd.mean,
                r.pd.se,
                r.pd.n,
                r.calls.mean
            );
        }
        out
    }

    /// SR, GC and PD per row as grouped bars with SE whiskers.
    pub(super) fn plot(&self) -> plot::Canvas {
        let w = 1200usize;
        let series: Vec<String> = self.rows.iter().map(|r| r.row.label.to_owned()).collect();
        // The layout leaves room for two legend lines; more lengthen the canvas.
        let extra = plot::legend_overflow(w, 70, &series, 2);
        let h = 560 + extra as usize;
        let header = format!("{} - SYNTHETIC", self.study.title());
        let mut c = plot::canvas_with_header(
            w,
            h,
            &header,
            Some("SYNTHETIC - no model answered; report.md states the error model"),
        );
        let categories = vec![
            "SR (%)".to_owned(),
            "GC (%)".to_owned(),
            "PD (%, successful)".to_owned(),
        ];
        let values: Vec<Vec<Option<Value>>> = self
            .rows
            .iter()
            .map(|r| vec![plotted(&r.sr), plotted(&r.gc), plotted(&r.pd)])
            .collect();
        plot::draw_bars(
            &mut c,
            Frame {
                x: 0,
                y: 44,
                w: w as i64,
                h: 440,
            },
            &Bars {
                title: "mean x 100 +- SE",
                y_label: "%",
                y_max: 100.0,
                categories: &categories,
                series: &series,
                values: &values,
            },
        );
        plot::legend(&mut c, 70, h as i64 - 72 - extra, &series);
        plot::footnote(
            &mut c,
            h as i64 - 24,
            "SR, GC: SE over scenarios (repeats averaged first); PD: SE over successful units",
        );
        c
    }
}
