//! Units of work. A unit is one (variant, scenario, repeat) and produces exactly one result
//! record. Its seed is derived from the run seed and its identity by SHA-256, never from a
//! randomised hasher, so every machine and every shard draws the same numbers.

use nesy_core::benchmark::{Complexity, Factor, FactorGroup};
use nesy_core::rng::SplitMix64;
use nesy_sim::tasks::scenario::Scenario;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::error::BenchError;
use crate::variant::Variant;

/// The identity of a unit.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct UnitKey {
    /// The scenario id, e.g. `comb_medium_03_s1`.
    pub scenario: String,
    /// The variant id.
    pub variant: String,
    /// The repeat, from 0.
    pub repeat: u32,
}

impl UnitKey {
    /// `scenario/variant/r<repeat>`: the unit's name in records and messages.
    pub fn name(&self) -> String {
        format!("{}/{}/r{}", self.scenario, self.variant, self.repeat)
    }

    /// The unit's folder under the run's `units/`: `<scenario>/<variant>` for repeat 0,
    /// `<scenario>/<variant>.r<k>` otherwise.
    pub fn folder(&self, variant: &Variant) -> std::path::PathBuf {
        let leaf = if self.repeat == 0 {
            variant.file_name()
        } else {
            format!("{}.r{}", variant.file_name(), self.repeat)
        };
        std::path::Path::new(&self.scenario).join(leaf)
    }

    /// The unit's seed: the first 8 bytes (little-endian) of SHA-256 over the run seed, the
    /// variant, the scenario and the repeat.
    pub fn seed(&self, run_seed: u64) -> u64 {
        let mut h = Sha256::new();
        h.update(run_seed.to_le_bytes());
        for part in [self.variant.as_bytes(), self.scenario.as_bytes()] {
            h.update((part.len() as u64).to_le_bytes());
            h.update(part);
        }
        h.update(self.repeat.to_le_bytes());
        let digest = h.finalize();
        let mut bytes = [0u8; 8];
        bytes.copy_from_slice(&digest[..8]);
        u64::from_le_bytes(bytes)
    }
}

/// Which scenarios a run covers.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Selection {
    /// Ids or id prefixes (`comb_medium`, `obst_low_03_s0`); empty means all 440.
    pub patterns: Vec<String>,
    /// Keep a random sample of this many of the matching scenarios.
    pub sample: Option<usize>,
    /// Seed of the sample.
    pub sample_seed: u64,
    /// Spread the sample over the table's cells (factor group × complexity): each cell
    /// present gets an equal share, and the remainder goes to cells drawn with the same seed.
    /// Left out of the manifest when false, so earlier runs keep their hashes.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub stratify: bool,
}

impl Selection {
    /// All scenarios.
    pub fn all() -> Selection {
        Selection {
            patterns: Vec::new(),
            sample: None,
            sample_seed: 0,
            stratify: false,
        }
    }

    /// One line: the patterns (or all 440) and the sample, if any.
    pub fn describe(&self) -> String {
        let mut text = if self.patterns.is_empty() {
            "all 440 scenarios".to_owned()
        } else {
            self.patterns.join(", ")
        };
        if let Some(k) = self.sample {
            text.push_str(&format!(
                "; a {}sample of {k}, seed {}",
                if self.stratify { "stratified " } else { "" },
                self.sample_seed
            ));
        }
        text
    }

    /// Parses `all` or a comma-separated list of ids and prefixes.
    pub fn parse(text: &str) -> Selection {
        let patterns = if text.trim() == "all" {
            Vec::new()
        } else {
            text.split(',')
                .map(|s| s.trim().to_owned())
                .filter(|s| !s.is_empty())
                .collect()
        };
        Selection {
            patterns,
            ..Selection::all()
        }
    }

    /// The selected scenarios, in suite order. A pattern matching nothing is an error (a
    /// typo must not shrink a run silently). A sample is drawn without replacement by a
    /// seeded partial shuffle and returned in suite order.
    pub fn apply(&self, scenarios: Vec<Scenario>) -> Result<Vec<Scenario>, BenchError> {
        for p in &self.patterns {
            if !scenarios.iter().any(|s| s.id.starts_with(p.as_str())) {
                return Err(BenchError::Usage(format!(
                    "--scenarios: no scenario id starts with {p:?} (ids look like obst_low_00_s0; `nesy scenarios list --ids`)"
                )));
            }
        }
        let mut chosen: Vec<Scenario> = scenarios
            .into_iter()
            .filter(|s| {
                self.patterns.is_empty() || self.patterns.iter().any(|p| s.id.starts_with(p.as_str()))
            })
            .collect();
        if let Some(k) = self.sample {
            if k > chosen.len() {
                return Err(BenchError::Usage(format!(
                    "--sample {k}: only {} scenarios match",
                    chosen.len()
                )));
            }
            let mut rng = SplitMix64::new(self.sample_seed);
            let mut keep = if self.stratify {
                stratified_sample(&chosen, k, &mut rng)?
            } else {
                partial_shuffle((0..chosen.len()).collect(), k, &mut rng)
            };
            keep.sort_unstable();
            chosen = keep.into_iter().map(|i| chosen[i].clone()).collect();
        }
        Ok(chosen)
    }
}

/// The first `k` of `index` after a seeded partial shuffle.
fn partial_shuffle(mut index: Vec<usize>, k: usize, rng: &mut SplitMix64) -> Vec<usize> {
    for i in 0..k {
        let j = i + rng.below(index.len() - i);
        index.swap(i, j);
    }
    index.truncate(k);
    index
}

/// Indices of `k` of `scenarios` spread over the table's cells (factor group × complexity,
/// in table order): `k / cells` from each, and one more from each of `k % cells` cells drawn
/// by `rng`. A cell too small for its share is an error rather than a lopsided sample.
fn stratified_sample(
    scenarios: &[Scenario],
    k: usize,
    rng: &mut SplitMix64,
) -> Result<Vec<usize>, BenchError> {
    let mut cells: std::collections::BTreeMap<(FactorGroup, Complexity), Vec<usize>> = Default::default();
    for (i, s) in scenarios.iter().enumerate() {
        cells.entry((s.factor.group(), s.complexity)).or_default().push(i);
    }
    let cells: Vec<((FactorGroup, Complexity), Vec<usize>)> = cells.into_iter().collect();
    let mut shares = vec![k / cells.len(); cells.len()];
    for c in partial_shuffle((0..cells.len()).collect(), k % cells.len(), rng) {
        shares[c] += 1;
    }
    let mut keep = Vec::with_capacity(k);
    for (((group, complexity), members), share) in cells.into_iter().zip(shares) {
        if share > members.len() {
            return Err(BenchError::Usage(format!(
                "--sample {k} --stratify: the cell {} / {} has {} scenario(s), fewer than its share of {share}",
                group.title(),
                complexity.as_str(),
                members.len()
            )));
        }
        keep.extend(partial_shuffle(members, share, rng));
    }
    Ok(keep)
}

/// A unit with what the harness needs to run it.
#[derive(Debug, Clone)]
pub struct Unit {
    /// Its identity.
    pub key: UnitKey,
    /// Its variant.
    pub variant: Variant,
    /// Its scenario.
    pub scenario: Scenario,
    /// Its seed.
    pub seed: u64,
}

impl Unit {
    /// The scenario's factor.
    pub fn factor(&self) -> Factor {
        self.scenario.factor
    }

    /// The scenario's complexity.
    pub fn complexity(&self) -> Complexity {
        self.scenario.complexity
    }
}

/// Every unit of a run: variants × scenarios × repeats, ordered by scenario, then variant,
/// then repeat (so a worker that takes units in order builds each scenario's scene once).
pub(crate) fn units(variants: &[Variant], scenarios: &[Scenario], repeats: u32, run_seed: u64) -> Vec<Unit> {
    let mut out = Vec::new();
    for scenario in scenarios {
        for variant in variants {
            for repeat in 0..repeats {
                let key = UnitKey {
                    scenario: scenario.id.clone(),
                    variant: variant.id(),
                    repeat,
                };
                let seed = key.seed(run_seed);
                out.push(Unit {
                    key,
                    variant: variant.clone(),
                    scenario: scenario.clone(),
                    seed,
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_depend_on_every_part() {
        let k = UnitKey {
            scenario: "obst_low_00_s0".into(),
            variant: "nesycr".into(),
            repeat: 0,
        };
        let base = k.seed(1);
        assert_eq!(base, k.seed(1));
        assert_ne!(base, k.seed(2));
        assert_ne!(
            base,
            UnitKey {
                repeat: 1,
                ..k.clone()
            }
            .seed(1)
        );
        assert_ne!(
            base,
            UnitKey {
                variant: "imitation".into(),
                ..k.clone()
            }
            .seed(1)
        );
        assert_eq!(k.name(), "obst_low_00_s0/nesycr/r0");
    }

    #[test]
    fn selection_filters_samples_and_rejects_typos() {
        let files = nesy_sim::tasks::scenario::generate_suite();
        let all = nesy_sim::tasks::scenario::scenarios(&files);
        assert_eq!(Selection::all().apply(all.clone()).unwrap().len(), 440);
        let comb = Selection::parse("comb_medium").apply(all.clone()).unwrap();
        assert_eq!(comb.len(), 40);
        assert!(Selection::parse("comb_mediun").apply(all.clone()).is_err());
        let sample = Selection {
            sample: Some(60),
            sample_seed: 7,
            ..Selection::all()
        };
        let a = sample.apply(all.clone()).unwrap();
        let b = sample.apply(all).unwrap();
        assert_eq!(a.len(), 60);
        assert_eq!(
            a.iter().map(|s| &s.id).collect::<Vec<_>>(),
            b.iter().map(|s| &s.id).collect::<Vec<_>>()
        );
    }

    #[test]
    fn a_stratified_sample_covers_every_cell_evenly() {
        let files = nesy_sim::tasks::scenario::generate_suite();
        let all = nesy_sim::tasks::scenario::scenarios(&files);
        let stratified = |k: usize, seed: u64| Selection {
            sample: Some(k),
            sample_seed: seed,
            stratify: true,
            ..Selection::all()
        };
        for seed in 0..5 {
            let chosen = stratified(12, seed).apply(all.clone()).unwrap();
            assert_eq!(chosen.len(), 12);
            let mut per_cell: std::collections::BTreeMap<_, usize> = Default::default();
            for s in &chosen {
                *per_cell.entry((s.factor.group(), s.complexity)).or_default() += 1;
            }
            // Nine cells: one each, and three of them a second.
            assert_eq!(per_cell.len(), 9, "seed {seed}: {per_cell:?}");
            assert_eq!(per_cell.values().filter(|n| **n == 2).count(), 3);
            let ids = |v: &[Scenario]| v.iter().map(|s| s.id.clone()).collect::<Vec<_>>();
            assert_eq!(
                ids(&chosen),
                ids(&stratified(12, seed).apply(all.clone()).unwrap())
            );
        }
        // Within one cell the draw is the plain sample of that cell.
        let comb = Selection {
            patterns: vec!["comb_low".into()],
            ..stratified(3, 1)
        };
        assert_eq!(comb.apply(all.clone()).unwrap().len(), 3);
        assert!(
            Selection {
                patterns: vec!["comb_low".into()],
                ..stratified(41, 1)
            }
            .apply(all)
            .is_err()
        );
    }
}
