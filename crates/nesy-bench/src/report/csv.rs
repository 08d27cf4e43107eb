//! The CSV tables under `tables/`: Table 1, every unit, statuses, stages, time and the
//! domain gap.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use nesy_core::metrics::Tally;

use super::{Aggregate, Tables};
use crate::status::UnitStatus;
use crate::unit_record::UnitRecord;

pub(super) fn table1_csv(tables: &Tables) -> String {
    let mut out = String::from(
        "variant,group,complexity,n,sr_mean,sr_se,gc_mean,gc_se,pd_success_mean,pd_success_se,pd_success_n,pd_all_mean,pd_all_se,latched_sr_mean,latched_sr_se,latched_gc_mean,latched_gc_se,sr_k,sr_wilson95_lo,sr_wilson95_hi\n",
    );
    let num = |x: f64| {
        if x.is_nan() {
            String::new()
        } else {
            format!("{x:.4}")
        }
    };
    let mut row = |v: &str, group: &str, complexity: &str, a: &Aggregate| {
        let f = |t: &Tally| {
            let m = t.mean_se().percent();
            format!("{},{}", num(m.mean), num(m.se))
        };
        let counts = a.sr_counts();
        let (lo, hi) = counts.wilson_95().unwrap_or((f64::NAN, f64::NAN));
        let _ = writeln!(
            out,
            "{v},{group},{complexity},{},{},{},{},{},{},{},{},{},{},{}",
            a.n(),
            f(&a.sr),
            f(&a.gc),
            f(&a.pd_success),
            a.pd_success.n,
            f(&a.pd_all),
            f(&a.latched_sr),
            f(&a.latched_gc),
            counts.k,
            num(100.0 * lo),
            num(100.0 * hi)
        );
    };
    for v in &tables.variants {
        for ((g, c), a) in &tables.cells[v] {
            row(v, g.title(), c.map_or("all", |c| c.as_str()), a);
        }
        for (c, a) in &tables.by_complexity[v] {
            row(v, "all", c.as_str(), a);
        }
        row(v, "all", "all", &tables.all[v]);
    }
    out
}

pub(super) fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\"").replace('\n', " "))
    } else {
        s.to_owned()
    }
}

/// The fields of one line written with [`csv_field`]: commas split, double quotes group and
/// a doubled quote inside them stands for one.
pub(super) fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                field.push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field)),
            (c, _) => field.push(c),
        }
    }
    fields.push(field);
    fields
}

pub(super) fn units_csv(records: &[&UnitRecord]) -> String {
    let mut out = String::from(
        "scenario,variant,repeat,method,factor,complexity,seed,status,sr,gc,pd,latched_sr,latched_gc,calls,images,vlm_s,symbolic_s,sim_s,wall_s,error\n",
    );
    for r in records {
        let s = &r.scores;
        let e = &r.effort;
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{:.4},{:.4},{},{:.4},{},{},{:.4},{:.6},{:.3},{:.3},{}",
            r.key.scenario,
            csv_field(&r.key.variant),
            r.key.repeat,
            r.method,
            r.factor,
            r.complexity,
            r.seed,
            r.status,
            s.sr,
            s.gc,
            s.pd,
            s.latched_sr,
            s.latched_gc,
            e.calls,
            e.images,
            e.time.vlm_s,
            e.time.symbolic_s,
            e.time.sim_s,
            e.time.total_s,
            csv_field(r.error.as_deref().unwrap_or(""))
        );
    }
    out
}

pub(super) fn status_csv(tables: &Tables) -> String {
    let mut out = String::from("variant");
    for s in UnitStatus::ALL {
        out.push(',');
        out.push_str(s.as_str());
    }
    out.push('\n');
    for v in &tables.variants {
        out.push_str(&csv_field(v));
        for s in UnitStatus::ALL {
            let _ = write!(out, ",{}", tables.all[v].statuses.get(&s).copied().unwrap_or(0));
        }
        out.push('\n');
    }
    out
}

/// Calls and cost per variant and stage (purpose label), over the variant's final records.
pub(super) struct StageUse {
    pub(super) calls: u64,
    pub(super) cost_usd: f64,
    pub(super) units: usize,
}

pub(super) fn stage_use(variants: &[String], records: &[&UnitRecord]) -> Vec<(String, String, StageUse)> {
    let mut rows = Vec::new();
    for v in variants {
        let mine: Vec<&&UnitRecord> = records.iter().filter(|r| &r.key.variant == v).collect();
        let mut by_stage: BTreeMap<String, StageUse> = BTreeMap::new();
        for r in &mine {
            for (purpose, calls) in &r.effort.calls_by_purpose {
                let entry = by_stage.entry(purpose.clone()).or_insert(StageUse {
                    calls: 0,
                    cost_usd: 0.0,
                    units: mine.len(),
                });
                entry.calls += calls;
                entry.cost_usd += r.effort.cost_by_purpose.get(purpose).copied().unwrap_or(0.0);
            }
        }
        rows.extend(by_stage.into_iter().map(|(stage, u)| (v.clone(), stage, u)));
    }
    rows
}

pub(super) fn stages_csv(variants: &[String], records: &[&UnitRecord]) -> String {
    let mut out = String::from("variant,stage,units,calls,calls_per_unit,cost_usd\n");
    for (v, stage, u) in stage_use(variants, records) {
        let _ = writeln!(
            out,
            "{},{},{},{},{:.3},{:.6}",
            csv_field(&v),
            csv_field(&stage),
            u.units,
            u.calls,
            u.calls as f64 / u.units.max(1) as f64,
            u.cost_usd
        );
    }
    out
}

pub(super) fn time_csv(tables: &Tables) -> String {
    let mut out =
        String::from("variant,n,model_s_mean,model_s_se,symbolic_s_mean,symbolic_s_se,calls_mean\n");
    for v in &tables.variants {
        let a = &tables.all[v];
        let (m, s, c) = (a.vlm_s.mean_se(), a.symbolic_s.mean_se(), a.calls.mean_se());
        let _ = writeln!(
            out,
            "{},{},{:.6},{:.6},{:.6},{:.6},{:.3}",
            csv_field(v),
            a.n(),
            m.mean,
            m.se,
            s.mean,
            s.se,
            c.mean
        );
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn fields_read_back_as_written() {
        let written = ["plain", "a, b", "say \"hi\"", ""]
            .map(super::csv_field)
            .join(",");
        assert_eq!(super::csv_fields(&written), ["plain", "a, b", "say \"hi\"", ""]);
    }
}
