//! `report.html`: a run's tables, plots and failure gallery for a browser, self-contained in
//! the run directory. The gallery shows every unit that did not succeed, grouped by method
//! and status: its cause, the first and last frames of its recorded execution (`nesy bench
//! run --record-executions`) or the step where adaptation stopped, and links to its files.

use std::collections::BTreeMap;
use std::path::Path;

use nesy_core::benchmark::FactorGroup;
use nesy_pipeline::output::{ADAPTATION_FILE, ROLLOUT_FIRST_FRAME_FILE, ROLLOUT_LAST_FRAME_FILE};
use nesy_view::{Html, Page};

use super::csv::csv_fields;
use super::{Aggregate, Tables, pct};
use crate::manifest::Manifest;
use crate::stats::units_to_detect_ten_points;
use crate::status::UnitStatus;
use crate::unit_record::UnitRecord;

/// `report.html` in the run directory.
pub const BENCH_HTML_FILE: &str = "report.html";

/// What the page is made of.
pub(super) struct HtmlInputs<'a> {
    pub run: &'a Path,
    pub manifest: &'a Manifest,
    pub tables: &'a Tables,
    pub records: &'a [&'a UnitRecord],
    pub missing: &'a [String],
    pub banner: Option<&'a str>,
    pub study: Option<&'a str>,
    /// The plots written, as paths relative to the run directory.
    pub plots: Vec<String>,
    /// The CSV tables written, relative to the run directory.
    pub csv: Vec<String>,
}

/// The page.
pub(super) fn bench_html(inputs: &HtmlInputs<'_>) -> String {
    let name = inputs
        .run
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| inputs.run.display().to_string());
    let mut page = Page::new(&format!("nesy bench: {name}"));
    page.push(overview(inputs));
    page.section(
        "table1",
        "SR, GC and PD by factor group (Table 1 shape)",
        table1(inputs.tables),
    );
    page.section(
        "wilson",
        "SR as counts, with 95 % Wilson intervals",
        wilson(inputs.tables),
    );
    page.section("statuses", "How the units ended", statuses(inputs.tables));
    if let Some(study) = inputs.study {
        page.section("study", "Study", Html::pre(study));
    }
    page.section("tables", "Every table", csv_tables(inputs));
    page.section("plots", "Plots", plots(inputs));
    page.section("gallery", "Failure gallery", gallery(inputs));
    page.section("files", "Files", files(inputs));
    page.finish()
}

/// What produced the numbers, and what is missing.
fn overview(inputs: &HtmlInputs<'_>) -> Html {
    let m = inputs.manifest;
    let mut parts = Vec::new();
    if let Some(banner) = inputs.banner {
        parts.push(Html::tag("p", "bad", Html::text(banner)));
    }
    if !inputs.missing.is_empty() {
        parts.push(Html::tag(
            "p",
            "bad",
            Html::text(&format!(
                "PARTIAL: {} of {} unit(s) have no final record yet.",
                inputs.missing.len(),
                m.units.len()
            )),
        ));
    }
    parts.push(Html::key_values([
        ("responder".to_owned(), Html::text(&m.responder.describe())),
        (
            "observation".to_owned(),
            Html::text(&format!("{:?}", m.settings.observation)),
        ),
        (
            "units".to_owned(),
            Html::text(&format!(
                "{} ({} variant(s) × {} repeat(s)); {} with a final record",
                m.units.len(),
                m.variants.len(),
                m.repeats,
                inputs.records.len()
            )),
        ),
        ("selection".to_owned(), Html::text(&m.selection.describe())),
        (
            "machine".to_owned(),
            Html::text(&format!(
                "{} ({}), nesy {} ({})",
                m.provenance.machine, m.provenance.host, m.provenance.nesy_version, m.provenance.git_commit
            )),
        ),
        ("started".to_owned(), Html::text(&m.created_at)),
    ]));
    Html::concat(parts)
}

/// SR, GC and PD (mean ± SE, %) per variant and factor group, and pooled.
fn table1(tables: &Tables) -> Html {
    let mut header = vec!["variant".to_owned()];
    for group in FactorGroup::ALL {
        header.push(format!("{group:?} SR / GC / PD"));
    }
    header.push("All SR / GC / PD".to_owned());
    let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let cell = |a: Option<&Aggregate>| match a {
        Some(a) if a.n() > 0 => Html::text(&format!(
            "{} / {} / {}",
            pct(&a.sr),
            pct(&a.gc),
            pct(&a.pd_success)
        )),
        _ => Html::text("–"),
    };
    let rows = tables.variants.iter().map(|v| group_cells(tables, v, &cell));
    Html::concat([
        Html::tag(
            "p",
            "muted",
            Html::text(
                "Mean ± standard error in percent over the scored units; PD over the units that succeeded.",
            ),
        ),
        Html::table(&header_refs, rows),
    ])
}

/// A variant's row: its name, `cell` of each factor group's pooled units, then of all.
fn group_cells(tables: &Tables, variant: &str, cell: &dyn Fn(Option<&Aggregate>) -> Html) -> Vec<Html> {
    let mut row = vec![Html::text(variant)];
    for group in FactorGroup::ALL {
        row.push(cell(
            tables.cells.get(variant).and_then(|c| c.get(&(group, None))),
        ));
    }
    row.push(cell(tables.all.get(variant)));
    row
}

/// k/n and the Wilson interval per factor group and overall, and the units a 10-point
/// difference would need.
fn wilson(tables: &Tables) -> Html {
    let mut header = vec!["variant".to_owned()];
    for group in FactorGroup::ALL {
        header.push(format!("{group:?}"));
    }
    header.push("All".to_owned());
    header.push("units to detect ±10 pp".to_owned());
    let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let cell = |a: Option<&Aggregate>| match a.map(Aggregate::sr_counts) {
        Some(p) if p.n > 0 => Html::text(&p.describe()),
        _ => Html::text("–"),
    };
    let rows = tables.variants.iter().map(|v| {
        let mut row = group_cells(tables, v, &cell);
        let all = tables.all.get(v);
        let needed = all
            .map(Aggregate::sr_counts)
            .and_then(|p| p.rate())
            .and_then(units_to_detect_ten_points)
            .map(|n| n.to_string())
            .unwrap_or_else(|| "–".into());
        row.push(Html::text(&needed));
        row
    });
    Html::concat([
        Html::tag(
            "p",
            "muted",
            Html::text(
                "Strict successes k/n and the 95 % Wilson score interval. The last column: units per variant that a two-sided test at 5 % with 80 % power needs to tell the overall rate from one 10 points away; compare two runs unit by unit with `nesy bench compare`.",
            ),
        ),
        Html::table(&header_refs, rows),
    ])
}

/// Unit counts by status.
fn statuses(tables: &Tables) -> Html {
    let mut header = vec!["variant"];
    header.extend(UnitStatus::ALL.iter().map(|s| s.as_str()));
    let rows = tables.variants.iter().map(|v| {
        let counts = tables.all.get(v).map(|a| &a.statuses);
        let mut row = vec![Html::text(v)];
        for status in UnitStatus::ALL {
            let n = counts.and_then(|c| c.get(&status)).copied().unwrap_or(0);
            row.push(Html::text(&n.to_string()));
        }
        row
    });
    Html::table(&header, rows)
}

/// Each CSV table the report wrote, shown folded (the units table is left to its file: one
/// row per unit).
fn csv_tables(inputs: &HtmlInputs<'_>) -> Html {
    Html::concat(inputs.csv.iter().map(|relative| {
        if relative.ends_with("units.csv") {
            return Html::tag(
                "p",
                "",
                Html::concat([Html::link(relative, relative), Html::text(": one row per unit")]),
            );
        }
        let text = match std::fs::read_to_string(inputs.run.join(relative)) {
            Ok(text) => text,
            Err(e) => return Html::tag("p", "bad", Html::text(&format!("{relative}: {e}"))),
        };
        let mut lines = text.lines();
        let header = lines.next().map(csv_fields).unwrap_or_default();
        let header_refs: Vec<&str> = header.iter().map(String::as_str).collect();
        let rows = lines.map(|line| csv_fields(line).iter().map(|f| Html::text(f)).collect());
        Html::details(relative, Html::table(&header_refs, rows), false)
    }))
}

/// The plots, embedded.
fn plots(inputs: &HtmlInputs<'_>) -> Html {
    Html::concat(
        inputs
            .plots
            .iter()
            .map(|relative| match std::fs::read(inputs.run.join(relative)) {
                Ok(bytes) => Html::tag("p", "", Html::image(&bytes, "image/png", relative)),
                Err(e) => Html::tag("p", "bad", Html::text(&format!("{relative}: {e}"))),
            }),
    )
}

/// Every unit that did not succeed, by variant and status.
fn gallery(inputs: &HtmlInputs<'_>) -> Html {
    let mut groups: BTreeMap<(usize, UnitStatus), Vec<&UnitRecord>> = BTreeMap::new();
    let order: BTreeMap<&str, usize> = inputs
        .tables
        .variants
        .iter()
        .enumerate()
        .map(|(i, v)| (v.as_str(), i))
        .collect();
    for r in inputs
        .records
        .iter()
        .filter(|r| r.status != UnitStatus::Succeeded)
    {
        let rank = order.get(r.key.variant.as_str()).copied().unwrap_or(usize::MAX);
        groups.entry((rank, r.status)).or_default().push(r);
    }
    if groups.is_empty() {
        return Html::tag("p", "ok", Html::text("Every unit succeeded."));
    }
    let recorded = inputs.records.iter().any(|r| {
        inputs
            .run
            .join(&r.artifacts)
            .join(ROLLOUT_LAST_FRAME_FILE)
            .is_file()
    });
    let mut parts = vec![Html::tag(
        "p",
        "muted",
        Html::text(&format!(
            "{} unit(s) did not succeed.{}",
            inputs
                .records
                .iter()
                .filter(|r| r.status != UnitStatus::Succeeded)
                .count(),
            if recorded {
                " Frames: the recorded execution's first and last keyframes (front view)."
            } else {
                " No execution was recorded in this run (nesy bench run --record-executions records them)."
            }
        )),
    )];
    for ((_, status), units) in groups {
        let variant = &units[0].key.variant;
        parts.push(Html::tag(
            "h3",
            "",
            Html::text(&format!("{variant}: {status} ({})", units.len())),
        ));
        parts.push(Html::tag(
            "div",
            "grid",
            Html::concat(units.iter().map(|r| unit_card(inputs.run, r))),
        ));
    }
    Html::concat(parts)
}

/// One failed unit: what it is, why it failed, its frames or where it stopped, its files.
fn unit_card(run: &Path, r: &UnitRecord) -> Html {
    let dir = run.join(&r.artifacts);
    let title = if r.key.repeat > 0 {
        format!("{} (repeat {})", r.key.scenario, r.key.repeat)
    } else {
        r.key.scenario.clone()
    };
    // Linked rather than embedded: a run with many failed units would otherwise make a page
    // of hundreds of megabytes. The files sit in the run directory beside the page.
    let frames: Vec<Html> = [
        (ROLLOUT_FIRST_FRAME_FILE, "first frame"),
        (ROLLOUT_LAST_FRAME_FILE, "last frame"),
    ]
    .iter()
    .filter(|(file, _)| dir.join(file).is_file())
    .map(|(file, label)| Html::image_file(&format!("{}/{file}", r.artifacts), &format!("{title}: {label}")))
    .collect();
    let evidence = if frames.is_empty() {
        Html::tag("p", "", Html::text(&stopped_at(&dir, r)))
    } else {
        Html::tag("div", "frames", Html::concat(frames))
    };
    let cause = r.error.as_deref().unwrap_or("the goal checks failed");
    let subtasks = r
        .scores
        .subtasks
        .iter()
        .map(|s| format!("{} {}", s.subtask, s.result))
        .collect::<Vec<_>>()
        .join(", ");
    let mut files: Vec<(String, String)> = std::fs::read_dir(&dir)
        .map(|read| {
            read.filter_map(Result::ok)
                .filter(|e| e.path().is_file())
                .map(|e| {
                    let name = e.file_name().to_string_lossy().into_owned();
                    (format!("{}/{name}", r.artifacts), name)
                })
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    let links = Html::concat(
        files
            .iter()
            .map(|(href, name)| Html::concat([Html::link(href, name), Html::markup(" ")])),
    );
    Html::tag(
        "div",
        "card",
        Html::concat([
            Html::tag("h3", "", Html::text(&title)),
            Html::tag("p", "bad", Html::text(&r.status.to_string())),
            evidence,
            Html::details(&format!("cause: {}", first_line(cause)), Html::pre(cause), false),
            Html::tag(
                "p",
                "muted",
                Html::text(&format!(
                    "SR {:.0}, GC {:.2}{}; {} model call(s)",
                    r.scores.sr,
                    r.scores.gc,
                    if subtasks.is_empty() {
                        String::new()
                    } else {
                        format!(" ({subtasks})")
                    },
                    r.effort.calls
                )),
            ),
            Html::tag("p", "", links),
        ]),
    )
}

/// Where a unit without a recorded execution stopped: the last violation its adaptation found
/// (from its `adaptation.json`), or its status when it has none.
fn stopped_at(dir: &Path, r: &UnitRecord) -> String {
    let adaptation = std::fs::read_to_string(dir.join(ADAPTATION_FILE))
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok());
    let last = adaptation
        .as_ref()
        .and_then(|a| a.get("violations"))
        .and_then(|v| v.as_array())
        .and_then(|v| v.last());
    match last {
        Some(v) => {
            let unmet: Vec<&str> = v
                .get("unmet")
                .and_then(|u| u.as_array())
                .map(|u| u.iter().filter_map(|x| x.as_str()).collect())
                .unwrap_or_default();
            match v.get("step").and_then(|s| s.as_u64()) {
                Some(step) => format!(
                    "Adaptation stopped at step {} {}: unmet {}.",
                    step + 1,
                    v.get("action").and_then(|a| a.as_str()).unwrap_or("?"),
                    unmet.join(", ")
                ),
                None => format!("Adaptation stopped with the goal unmet: {}.", unmet.join(", ")),
            }
        }
        None if r.status == UnitStatus::ExecutionFailed || r.status == UnitStatus::Succeeded => {
            "The execution was not recorded.".to_owned()
        }
        None => format!("Stopped before execution ({}).", r.status),
    }
}

/// Links to the report's other files.
fn files(inputs: &HtmlInputs<'_>) -> Html {
    let mut links = vec![
        Html::link("report.md", "report.md"),
        Html::link("manifest.json", "manifest.json"),
    ];
    links.extend(inputs.csv.iter().map(|c| Html::link(c, c)));
    Html::list(links)
}

fn first_line(text: &str) -> &str {
    text.lines().next().unwrap_or_default()
}
