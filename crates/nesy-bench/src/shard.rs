//! Sharding for job arrays: `--shard i/n` takes every n-th unit of a fixed-seed permutation
//! of the run's units, so hard units (high complexity, long budgets) spread over the shards
//! instead of piling onto one, and every shard's units are then sorted by scenario, so each
//! scenario's scene is prepared once per shard.

use std::fmt;
use std::str::FromStr;

use nesy_core::rng::SplitMix64;
use serde::{Deserialize, Serialize};

use crate::error::BenchError;
use crate::unit::Unit;

/// The seed of the assignment permutation (fixed: shards must agree on it).
pub(crate) const SHARD_PERMUTATION_SEED: u64 = 42;

/// One shard of a run, 0-based.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, from 0.
    pub index: usize,
    /// The number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole run as one shard.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// The units of this shard, in scenario order.
    pub fn select(self, units: &[Unit]) -> Vec<Unit> {
        let mut order: Vec<usize> = (0..units.len()).collect();
        // Units arrive in their stable order (scenario, variant, repeat); the permutation is
        // a Fisher–Yates shuffle with a fixed seed, the split round-robin.
        let mut rng = SplitMix64::new(SHARD_PERMUTATION_SEED);
        for i in (1..order.len()).rev() {
            let j = rng.below(i + 1);
            order.swap(i, j);
        }
        let mut mine: Vec<usize> = order
            .into_iter()
            .enumerate()
            .filter(|(pos, _)| pos % self.count == self.index)
            .map(|(_, u)| u)
            .collect();
        mine.sort_unstable();
        mine.into_iter().map(|i| units[i].clone()).collect()
    }
}

impl FromStr for Shard {
    type Err = BenchError;

    fn from_str(s: &str) -> Result<Shard, BenchError> {
        let bad = || {
            BenchError::Usage(format!(
                "--shard {s:?}: expected i/n with 0 ≤ i < n, e.g. 0/4 (a Slurm array task: --shard ${{SLURM_ARRAY_TASK_ID}}/4)"
            ))
        };
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count || count > 100_000 {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use super::*;
    use crate::variant::Variant;

    #[test]
    fn shards_partition_the_units_evenly_and_spread_the_high_ones() {
        let files = nesy_sim::tasks::scenario::generate_suite();
        let scenarios = nesy_sim::tasks::scenario::scenarios(&files);
        let variants = [Variant::plain("nesycr"), Variant::plain("imitation")];
        let units = crate::unit::units(&variants, &scenarios, 1, 0);
        let count = 7;
        let mut seen = BTreeSet::new();
        for index in 0..count {
            let mine = Shard { index, count }.select(&units);
            // Round-robin over one permutation: sizes differ by at most one.
            assert!(mine.len().abs_diff(units.len() / count) <= 1, "{}", mine.len());
            let high = mine
                .iter()
                .filter(|u| u.complexity() == nesy_core::benchmark::Complexity::High)
                .count() as f64;
            // 240 of the 880 units are high-complexity; each shard gets roughly its share.
            let share = high / mine.len() as f64;
            assert!((share - 240.0 / 880.0).abs() < 0.1, "shard {index}: {share}");
            for u in mine {
                assert!(seen.insert(u.key.name()), "{} in two shards", u.key.name());
            }
        }
        assert_eq!(seen.len(), units.len(), "every unit in some shard");
        assert_eq!(Shard::WHOLE.select(&units).len(), units.len());
    }

    #[test]
    fn shard_specs_are_checked() {
        assert_eq!("3/4".parse::<Shard>().unwrap(), Shard { index: 3, count: 4 });
        for bad in ["4/4", "1", "a/2", "0/0", "-1/3"] {
            let e = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(e.contains("expected i/n"), "{bad}: {e}");
        }
    }
}
