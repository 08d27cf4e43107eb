//! Is B better than A, or is it noise? Two runs' (or one run's two variants') final records
//! paired by scenario and repeat; per cell of the table and overall, both success rates with
//! Wilson intervals, the difference, McNemar's exact test on the pairs whose outcome
//! differs, and the units that changed.

use std::collections::BTreeMap;
use std::path::Path;

use nesy_core::benchmark::{Complexity, FactorGroup};
use serde::Serialize;

use crate::error::BenchError;
use crate::harness::final_records;
use crate::stats::{Proportion, mcnemar_exact, units_to_detect};
use crate::unit_record::UnitRecord;

/// The significance level `--fail-if-worse` tests at.
pub const ALPHA: f64 = 0.05;

/// One side of a comparison: a run and the variant of it compared.
#[derive(Debug, Clone, Serialize)]
pub struct Side {
    /// The run directory.
    pub run: String,
    /// The variant.
    pub variant: String,
}

/// The paired outcome of one cell (or of every unit).
#[derive(Debug, Clone, Default, Serialize)]
pub struct PairedCell {
    /// Successes of A over the pairs.
    pub a: Proportion,
    /// Successes of B over the pairs.
    pub b: Proportion,
    /// Pairs A succeeded on and B did not.
    pub only_a: u64,
    /// Pairs B succeeded on and A did not.
    pub only_b: u64,
    /// McNemar's exact two-sided p-value.
    pub p_value: f64,
    /// Units per side a test would need to detect the observed difference (5 %, 80 %
    /// power), when there is one.
    pub units_needed: Option<u64>,
}

impl PairedCell {
    fn push(&mut self, a: bool, b: bool) {
        self.a.n += 1;
        self.b.n += 1;
        self.a.k += u64::from(a);
        self.b.k += u64::from(b);
        self.only_a += u64::from(a && !b);
        self.only_b += u64::from(b && !a);
    }

    fn finish(&mut self) {
        self.p_value = mcnemar_exact(self.only_a, self.only_b);
        self.units_needed = match (self.a.rate(), self.b.rate()) {
            (Some(a), Some(b)) => units_to_detect(a, b),
            _ => None,
        };
    }

    /// B's success rate minus A's, in percentage points.
    pub fn difference_pp(&self) -> f64 {
        match (self.a.rate(), self.b.rate()) {
            (Some(a), Some(b)) => 100.0 * (b - a),
            _ => 0.0,
        }
    }
}

/// A unit whose outcome differs between the two sides.
#[derive(Debug, Clone, Serialize)]
pub struct Changed {
    /// `scenario/r<repeat>`.
    pub unit: String,
    /// A's status.
    pub a: String,
    /// B's status.
    pub b: String,
}

/// The comparison.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// Side A.
    pub a: Side,
    /// Side B.
    pub b: Side,
    /// Per cell of the table (factor group and complexity).
    pub cells: Vec<(FactorGroup, Complexity, PairedCell)>,
    /// Over every pair.
    pub overall: PairedCell,
    /// Units scored on one side only (left out of every pair).
    pub unpaired: usize,
    /// The pairs whose success differs, A's successes first.
    pub changed: Vec<Changed>,
}

impl Comparison {
    /// True when B is worse than A by more than `pp` percentage points overall and the
    /// difference is significant at [`ALPHA`].
    pub fn worse_by_more_than(&self, pp: f64) -> bool {
        self.overall.difference_pp() < -pp && self.overall.p_value < ALPHA
    }
}

/// A run's scored records of `variant`, by `scenario/r<repeat>`.
fn scored(run: &Path, variant: &str) -> Result<BTreeMap<String, UnitRecord>, BenchError> {
    Ok(final_records(run)?
        .into_values()
        .filter(|r| r.key.variant == variant && r.status.is_scored())
        .map(|r| (format!("{}/r{}", r.key.scenario, r.key.repeat), r))
        .collect())
}

/// The variants a run has final records of.
pub fn variants(run: &Path) -> Result<Vec<String>, BenchError> {
    let mut names: Vec<String> = final_records(run)?.into_values().map(|r| r.key.variant).collect();
    names.sort();
    names.dedup();
    Ok(names)
}

/// The variant of `run` to compare: `given`, or the run's only one.
pub fn pick_variant(run: &Path, given: Option<&str>) -> Result<String, BenchError> {
    if let Some(v) = given {
        return Ok(v.to_owned());
    }
    match variants(run)?.as_slice() {
        [one] => Ok(one.clone()),
        many => Err(BenchError::Usage(format!(
            "{} holds {} variants ({}); name the one to compare",
            run.display(),
            many.len(),
            many.join(", ")
        ))),
    }
}

/// Pairs `a`'s and `b`'s scored units by scenario and repeat and compares their success.
pub fn compare(a: (&Path, &str), b: (&Path, &str)) -> Result<Comparison, BenchError> {
    let left = scored(a.0, a.1)?;
    let right = scored(b.0, b.1)?;
    let mut cells: BTreeMap<(FactorGroup, Complexity), PairedCell> = BTreeMap::new();
    let mut overall = PairedCell::default();
    let mut changed = Vec::new();
    let mut paired = 0;
    for (unit, ra) in &left {
        let Some(rb) = right.get(unit) else {
            continue;
        };
        paired += 1;
        let (sa, sb) = (ra.scores.sr == 1.0, rb.scores.sr == 1.0);
        cells
            .entry((ra.factor.group(), ra.complexity))
            .or_default()
            .push(sa, sb);
        overall.push(sa, sb);
        if sa != sb {
            changed.push(Changed {
                unit: unit.clone(),
                a: ra.status.as_str().to_owned(),
                b: rb.status.as_str().to_owned(),
            });
        }
    }
    if paired == 0 {
        return Err(BenchError::Usage(format!(
            "no scored unit of {} in {} has a partner of {} in {} (same scenario and repeat)",
            a.1,
            a.0.display(),
            b.1,
            b.0.display()
        )));
    }
    overall.finish();
    let cells = cells
        .into_iter()
        .map(|((group, complexity), mut cell)| {
            cell.finish();
            (group, complexity, cell)
        })
        .collect();
    // A's successes that B lost first, then B's gains.
    changed.sort_by(|x, y| (x.a != "succeeded", &x.unit).cmp(&(y.a != "succeeded", &y.unit)));
    Ok(Comparison {
        a: Side {
            run: a.0.display().to_string(),
            variant: a.1.to_owned(),
        },
        b: Side {
            run: b.0.display().to_string(),
            variant: b.1.to_owned(),
        },
        cells,
        overall,
        unpaired: left.len() + right.len() - 2 * paired,
        changed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shard::Shard;
    use crate::status::UnitStatus;
    use crate::store::{ResultsWriter, shard_file, tests::record};

    /// A run of `variant` whose unit `i` of `n` succeeds when `succeeds(i)`.
    fn run(dir: &Path, variant: &str, n: usize, succeeds: impl Fn(usize) -> bool) {
        let mut writer = ResultsWriter::open(&shard_file(dir, Shard::WHOLE)).unwrap();
        for i in 0..n {
            let ok = succeeds(i);
            let status = if ok {
                UnitStatus::Succeeded
            } else {
                UnitStatus::ExecutionFailed
            };
            writer
                .append(&record(
                    &format!("obst_low_{i:02}_s0"),
                    variant,
                    status,
                    f64::from(u8::from(ok)),
                ))
                .unwrap();
        }
    }

    #[test]
    fn identical_runs_differ_in_nothing() {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        run(a.path(), "nesycr", 30, |i| i % 3 != 0);
        run(b.path(), "nesycr", 30, |i| i % 3 != 0);
        let c = compare((a.path(), "nesycr"), (b.path(), "nesycr")).unwrap();
        assert_eq!(
            (c.overall.a, c.overall.b),
            (Proportion { k: 20, n: 30 }, Proportion { k: 20, n: 30 })
        );
        assert_eq!(
            (c.overall.only_a, c.overall.only_b, c.overall.p_value),
            (0, 0, 1.0)
        );
        assert!(c.changed.is_empty() && c.overall.units_needed.is_none());
        assert!(!c.worse_by_more_than(0.0));
    }

    #[test]
    fn a_strictly_better_run_is_significant_and_the_reverse_fails_the_gate() {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        run(a.path(), "nesycr+verification=off", 30, |i| i < 10);
        run(b.path(), "nesycr", 30, |_| true);
        let c = compare((a.path(), "nesycr+verification=off"), (b.path(), "nesycr")).unwrap();
        assert_eq!((c.overall.only_a, c.overall.only_b), (0, 20));
        assert!((c.overall.p_value - 2.0 * 0.5f64.powi(20)).abs() < 1e-15);
        assert!((c.overall.difference_pp() - 200.0 / 3.0).abs() < 1e-9);
        assert_eq!(c.changed.len(), 20);
        assert!(!c.worse_by_more_than(5.0));
        let reverse = compare((b.path(), "nesycr"), (a.path(), "nesycr+verification=off")).unwrap();
        assert!(reverse.worse_by_more_than(5.0));
        assert!(!reverse.worse_by_more_than(70.0));
    }

    #[test]
    fn a_difference_inside_the_noise_does_not_fail_the_gate() {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        // 15 against 13 of 30: three units lost, one gained.
        run(a.path(), "nesycr", 30, |i| i < 15);
        run(b.path(), "nesycr", 30, |i| (i < 12) || i == 20);
        let c = compare((a.path(), "nesycr"), (b.path(), "nesycr")).unwrap();
        assert_eq!((c.overall.only_a, c.overall.only_b), (3, 1));
        assert!((c.overall.p_value - 0.625).abs() < 1e-12);
        assert!(c.overall.difference_pp() < -5.0);
        assert!(!c.worse_by_more_than(5.0));
        // Lost units come first.
        assert_eq!(c.changed[0].a, "succeeded");
        assert_eq!(c.changed.last().unwrap().unit, "obst_low_20_s0/r0");
        assert!(c.overall.units_needed.unwrap() > 500);
    }

    #[test]
    fn runs_without_common_units_are_refused_and_partners_are_counted() {
        let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        run(a.path(), "nesycr", 4, |_| true);
        run(b.path(), "replan", 2, |_| true);
        assert!(compare((a.path(), "nesycr"), (b.path(), "nesycr")).is_err());
        let c = compare((a.path(), "nesycr"), (b.path(), "replan")).unwrap();
        assert_eq!((c.overall.a.n, c.unpaired), (2, 2));
        assert!(pick_variant(a.path(), None).unwrap() == "nesycr");
    }
}
