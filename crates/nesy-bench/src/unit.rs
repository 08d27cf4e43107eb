//! Units of work. A unit is one (variant, scenario, repeat) and produces exactly one result
//! record. Its seed is derived from the run seed and its identity by SHA-256, never from a
//! randomised hasher, so every machine and every shard draws the same numbers.

use nesy_core::benchmark::{Complexity, Factor};
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
}

impl Selection {
    /// All scenarios.
    pub fn all() -> Selection {
        Selection {
            patterns: Vec::new(),
            sample: None,
            sample_seed: 0,
        }
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
            let mut index: Vec<usize> = (0..chosen.len()).collect();
            for i in 0..k {
                let j = i + rng.below(index.len() - i);
                index.swap(i, j);
            }
            let mut keep = index[..k].to_vec();
            keep.sort_unstable();
            chosen = keep.into_iter().map(|i| chosen[i].clone()).collect();
        }
        Ok(chosen)
    }
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
}
