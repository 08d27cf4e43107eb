//! The PNG figures under `plots/`: SR, GC and PD per cell, against the domain gap and
//! against task complexity.

use nesy_core::benchmark::{Complexity, FactorGroup};
use nesy_core::metrics::Tally;

use super::markdown::{complexity_title, title_of};
use super::plot::{self, Bars, Frame, Lines, Value};
use super::{Aggregate, GAP_LEVELS, Tables, gap_tallies, value};
use crate::unit_record::UnitRecord;

pub(super) fn series_titles(variants: &[String]) -> Vec<String> {
    variants.iter().map(|v| title_of(v)).collect()
}

pub(super) fn plot_cells(tables: &Tables, banner: Option<&str>) -> plot::Canvas {
    let w = 1500usize;
    let series = series_titles(&tables.variants);
    let extra = plot::legend_overflow(w, 70, &series, 1);
    let h = 860 + extra as usize;
    let mut c = plot::canvas_with_header(
        w,
        h,
        "SR, GC and PD per factor group and complexity (mean x 100 +- SE)",
        banner.map(short_banner),
    );
    let mut categories = Vec::new();
    let mut keys = Vec::new();
    for g in FactorGroup::ALL {
        for cx in Complexity::ALL {
            let short = match g {
                FactorGroup::ObstructionAffordance => "O&A",
                FactorGroup::KinematicGripper => "K&G",
                FactorGroup::Combination => "Comb",
            };
            categories.push(format!("{short} {}", complexity_title(cx)));
            keys.push((g, Some(cx)));
        }
    }
    categories.push("All".into());
    let metric = |pick: &dyn Fn(&Aggregate) -> &Tally| -> Vec<Vec<Option<Value>>> {
        tables
            .variants
            .iter()
            .map(|v| {
                let mut col: Vec<Option<Value>> = keys
                    .iter()
                    .map(|k| tables.cells[v].get(k).and_then(|a| value(pick(a))))
                    .collect();
                col.push(value(pick(&tables.all[v])));
                col
            })
            .collect()
    };
    let panels: [(&str, Vec<Vec<Option<Value>>>); 3] = [
        ("SR (%)", metric(&|a| &a.sr)),
        ("GC (%)", metric(&|a| &a.gc)),
        ("PD (%, successful units)", metric(&|a| &a.pd_success)),
    ];
    for (i, (title, values)) in panels.iter().enumerate() {
        plot::draw_bars(
            &mut c,
            Frame {
                x: 0,
                y: 44 + i as i64 * 265,
                w: w as i64,
                h: 265,
            },
            &Bars {
                title,
                y_label: "%",
                y_max: 100.0,
                categories: &categories,
                series: &series,
                values,
            },
        );
    }
    plot::legend(&mut c, 70, h as i64 - 22 - extra, &series);
    c
}

pub(super) fn short_banner(b: &str) -> &str {
    b.split(". ").next().unwrap_or(b)
}

/// A figure of SR and PD side by side against one axis.
pub(super) struct SrPd<'a> {
    pub(super) header: &'a str,
    pub(super) x_label: &'a str,
    pub(super) categories: &'a [String],
    pub(super) series: &'a [String],
    pub(super) sr: &'a [Vec<Option<Value>>],
    pub(super) pd: &'a [Vec<Option<Value>>],
    pub(super) note: &'a str,
}

pub(super) fn two_panel_lines(f: SrPd, banner: Option<&str>) -> plot::Canvas {
    let SrPd {
        header,
        x_label,
        categories,
        series,
        sr,
        pd,
        note,
    } = f;
    let w = 1100usize;
    // Room for every legend line: a run's variant names can be long.
    let extra = plot::legend_overflow(w, 70, series, 1);
    let h = 560 + extra as usize;
    let mut c = plot::canvas_with_header(w, h, header, banner.map(short_banner));
    for (i, (title, values)) in [("SR (%)", sr), ("PD (%, successful units)", pd)]
        .into_iter()
        .enumerate()
    {
        plot::draw_lines(
            &mut c,
            Frame {
                x: i as i64 * 550,
                y: 48,
                w: 550,
                h: 440,
            },
            &Lines {
                title,
                x_label,
                y_label: "%",
                y_max: 100.0,
                categories,
                series,
                values,
            },
        );
    }
    plot::legend(&mut c, 70, h as i64 - 52 - extra, series);
    plot::footnote(&mut c, h as i64 - 24, note);
    c
}

pub(super) fn plot_gap(variants: &[String], records: &[&UnitRecord], banner: Option<&str>) -> plot::Canvas {
    let tallies = gap_tallies(variants, records);
    let categories: Vec<String> = GAP_LEVELS.iter().map(|s| s.to_string()).collect();
    let pick = |f: &dyn Fn(&Aggregate) -> &Tally| -> Vec<Vec<Option<Value>>> {
        variants
            .iter()
            .map(|v| tallies[v].iter().map(|a| value(f(a))).collect())
            .collect()
    };
    two_panel_lines(
        SrPd {
            header: "SR and PD against the domain gap (Figure 4(a) shape)",
            x_label: "domain-gap level",
            categories: &categories,
            series: &series_titles(variants),
            sr: &pick(&|a| &a.sr),
            pd: &pick(&|a| &a.pd_success),
            note: "level: sum over subtasks of |target obst - source obst| (obst, affo, comb): Low 1-2, Moderate 3-4, High >= 5",
        },
        banner,
    )
}

pub(super) fn plot_complexity(tables: &Tables, banner: Option<&str>) -> plot::Canvas {
    let categories: Vec<String> = Complexity::ALL
        .iter()
        .map(|c| complexity_title(*c).to_owned())
        .collect();
    let pick = |f: &dyn Fn(&Aggregate) -> &Tally| -> Vec<Vec<Option<Value>>> {
        tables
            .variants
            .iter()
            .map(|v| {
                Complexity::ALL
                    .iter()
                    .map(|c| tables.by_complexity[v].get(c).and_then(|a| value(f(a))))
                    .collect()
            })
            .collect()
    };
    two_panel_lines(
        SrPd {
            header: "SR and PD against task complexity (all factors)",
            x_label: "complexity",
            categories: &categories,
            series: &series_titles(&tables.variants),
            sr: &pick(&|a| &a.sr),
            pd: &pick(&|a| &a.pd_success),
            note: "not Figure 4(b)'s complexity gap: source and target of the 440 scenarios have the same subtasks",
        },
        banner,
    )
}
