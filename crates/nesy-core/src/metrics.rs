//! The benchmark's metrics, exactly as `docs/benchmark.md` §7 defines them. This module is
//! their one definition: the simulator's goal checks, the sandbox's reports, the pipeline and
//! the benchmark harness all score episodes with it.
//!
//!
//! - **SR** per episode is 1 iff every subtask ended in `full_success` or
//!   `partial_success` (partial success — everything placed, in another order — counts).
//! - **GC** per episode is the fraction of subtasks that succeeded (full or partial).
//! - **PD** per episode is the Levenshtein distance between the goal-sequence label and
//!   the achieved sequence, over name tokens, divided by `max(|label|, |achieved|, 1)`. By
//!   default PD averages over all episodes; [`PdScope::SuccessfulOnly`] averages over SR = 1
//!   episodes only, as the paper's formula writes it.
//! - Aggregates are mean ± standard error, SE = std(ddof = 1) / √n. With fewer than two
//!   values the SE is NaN (as numpy gives), and the mean of no values is NaN.

use serde::{Deserialize, Serialize};

/// How one subtask ended: the goal checks' verdict, under the authors' names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schemars", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
pub enum SubtaskResult {
    /// Every object placed (and the container closed), in label order.
    FullSuccess,
    /// Every object placed (and the container closed), in another order; counts as success.
    PartialSuccess,
    /// Not achieved by the final call.
    Fail,
}

impl SubtaskResult {
    /// True for full and partial success (both count toward SR).
    pub fn is_success(self) -> bool {
        self != SubtaskResult::Fail
    }

    /// The authors' name: `full_success`, `partial_success` or `fail`.
    pub fn as_str(self) -> &'static str {
        match self {
            SubtaskResult::FullSuccess => "full_success",
            SubtaskResult::PartialSuccess => "partial_success",
            SubtaskResult::Fail => "fail",
        }
    }
}

impl std::fmt::Display for SubtaskResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How a subtask is scored when objects it counted as placed are out of place at the end.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scoring {
    /// nesy's headline: a subtask with a displaced object fails, because the episode's
    /// final state does not show it achieved.
    #[default]
    Strict,
    /// The authors' metric: an object counts once it was placed (latched), whatever happens
    /// to it later.
    Latched,
}

impl Scoring {
    /// The verdict of a subtask under this scoring, given whether any of its counted objects
    /// is out of place at the end.
    pub fn verdict(self, result: SubtaskResult, displaced: bool) -> SubtaskResult {
        match self {
            Scoring::Strict if displaced => SubtaskResult::Fail,
            _ => result,
        }
    }
}

/// Merges per-subtask achievements, each a `(name, control step)` list in time order, into
/// the episode's achieved sequence: time order, ties broken by subtask (config) order and
/// then by the order within the subtask.
///
/// ```
/// use nesy_core::metrics::achieved_in_time_order;
///
/// let drawer = vec![("red_cylinder", 30), ("bottom_drawer", 90)];
/// let cubes = vec![("red_cube", 30), ("blue_cube", 60)];
/// assert_eq!(
///     achieved_in_time_order([drawer, cubes]),
///     ["red_cylinder", "red_cube", "blue_cube", "bottom_drawer"]
/// );
/// ```
pub fn achieved_in_time_order<S, I, A>(per_subtask: I) -> Vec<String>
where
    S: AsRef<str>,
    I: IntoIterator<Item = A>,
    A: IntoIterator<Item = (S, u64)>,
{
    let mut merged: Vec<(u64, String)> = per_subtask
        .into_iter()
        .flat_map(|a| a.into_iter().map(|(name, step)| (step, name.as_ref().to_owned())))
        .collect();
    // Stable: equal steps keep subtask order, then the order within the subtask.
    merged.sort_by_key(|(step, _)| *step);
    merged.into_iter().map(|(_, name)| name).collect()
}

/// What an episode produced.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct EpisodeResult {
    /// One result per subtask.
    pub subtasks: Vec<SubtaskResult>,
    /// The goal-sequence label (expected order of achievements).
    pub label: Vec<String>,
    /// The achieved sequence.
    pub achieved: Vec<String>,
}

impl EpisodeResult {
    /// SR of this episode: 1 if every subtask succeeded, else 0.
    pub fn success(&self) -> f64 {
        if !self.subtasks.is_empty() && self.subtasks.iter().all(|s| s.is_success()) {
            1.0
        } else {
            0.0
        }
    }

    /// GC of this episode: the fraction of subtasks that succeeded (0 for no subtasks).
    pub fn goal_condition(&self) -> f64 {
        if self.subtasks.is_empty() {
            return 0.0;
        }
        self.subtasks.iter().filter(|s| s.is_success()).count() as f64 / self.subtasks.len() as f64
    }

    /// PD of this episode: normalised edit distance between label and achieved sequence.
    pub fn procedure_deviation(&self) -> f64 {
        let denom = self.label.len().max(self.achieved.len()).max(1);
        levenshtein(&self.label, &self.achieved) as f64 / denom as f64
    }
}

/// Edit distance (insertions, deletions, substitutions) between two token sequences.
pub fn levenshtein<T: PartialEq>(a: &[T], b: &[T]) -> usize {
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, x) in a.iter().enumerate() {
        cur[0] = i + 1;
        for (j, y) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(x != y);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// A mean with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanSe {
    /// The mean.
    pub mean: f64,
    /// Standard error: sample standard deviation (ddof 1) over √n.
    pub se: f64,
    /// Number of values.
    pub n: usize,
}

impl MeanSe {
    /// Mean and SE of `values`.
    pub fn of(values: &[f64]) -> Self {
        let mut tally = Tally::default();
        values.iter().for_each(|v| tally.push(*v));
        tally.mean_se()
    }

    /// Scaled to percent (mean × 100 ± SE × 100), as the tables report.
    pub fn percent(self) -> MeanSe {
        MeanSe {
            mean: self.mean * 100.0,
            se: self.se * 100.0,
            n: self.n,
        }
    }
}

impl std::fmt::Display for MeanSe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:.2}±{:.2}", self.mean, self.se)
    }
}

/// Running sums of a metric over episodes: cells of a table are tallied once, and rows and
/// the pooled "All" column merge the cells' tallies, so every mean ± SE in a report comes from
/// the same arithmetic over the same episodes.
///
/// ```
/// use nesy_core::metrics::{MeanSe, Tally};
///
/// let (mut a, mut b) = (Tally::default(), Tally::default());
/// [1.0, 0.0, 1.0].iter().for_each(|v| a.push(*v));
/// [1.0, 1.0].iter().for_each(|v| b.push(*v));
/// let pooled = a.merged(&b).mean_se();
/// assert_eq!(pooled.n, 5);
/// assert!((pooled.mean - 0.8).abs() < 1e-12);
/// assert!((pooled.se - MeanSe::of(&[1.0, 0.0, 1.0, 1.0, 1.0]).se).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Tally {
    /// Number of values.
    pub n: usize,
    /// Their sum.
    pub sum: f64,
    /// The sum of their squares.
    pub sum_sq: f64,
}

impl Tally {
    /// Adds one value.
    pub fn push(&mut self, value: f64) {
        self.n += 1;
        self.sum += value;
        self.sum_sq += value * value;
    }

    /// Both tallies' values together.
    pub fn merged(&self, other: &Tally) -> Tally {
        Tally {
            n: self.n + other.n,
            sum: self.sum + other.sum,
            sum_sq: self.sum_sq + other.sum_sq,
        }
    }

    /// Mean and standard error, SE = sample standard deviation (ddof 1) / √n. With fewer
    /// than two values the SE is NaN, and the mean of no values is NaN.
    pub fn mean_se(&self) -> MeanSe {
        let n = self.n;
        if n == 0 {
            return MeanSe {
                mean: f64::NAN,
                se: f64::NAN,
                n,
            };
        }
        let mean = self.sum / n as f64;
        let se = if n < 2 {
            f64::NAN
        } else {
            // Clamped: rounding can leave a tiny negative for values that are all equal.
            let var = ((self.sum_sq - self.sum * mean) / (n - 1) as f64).max(0.0);
            var.sqrt() / (n as f64).sqrt()
        };
        MeanSe { mean, se, n }
    }
}

/// Which episodes PD averages over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PdScope {
    /// Every episode (the authors' aggregation script's default).
    #[default]
    AllEpisodes,
    /// Only episodes with SR = 1 (the paper's formula; `--pd_success`).
    SuccessfulOnly,
}

/// SR, GC and PD over a set of episodes, in percent.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Success rate.
    pub sr: MeanSe,
    /// Goal condition.
    pub gc: MeanSe,
    /// Procedure deviation.
    pub pd: MeanSe,
}

/// Aggregates episodes into SR, GC and PD (percent, mean ± SE).
pub fn summarize(episodes: &[EpisodeResult], pd_scope: PdScope) -> Summary {
    let sr: Vec<f64> = episodes.iter().map(|e| e.success()).collect();
    let gc: Vec<f64> = episodes.iter().map(|e| e.goal_condition()).collect();
    let pd: Vec<f64> = episodes
        .iter()
        .filter(|e| pd_scope == PdScope::AllEpisodes || e.success() == 1.0)
        .map(|e| e.procedure_deviation())
        .collect();
    Summary {
        sr: MeanSe::of(&sr).percent(),
        gc: MeanSe::of(&gc).percent(),
        pd: MeanSe::of(&pd).percent(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use SubtaskResult::*;

    fn ep(subtasks: &[SubtaskResult], label: &[&str], achieved: &[&str]) -> EpisodeResult {
        EpisodeResult {
            subtasks: subtasks.to_vec(),
            label: label.iter().map(|s| s.to_string()).collect(),
            achieved: achieved.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn per_episode_values() {
        let partial = ep(
            &[FullSuccess, PartialSuccess],
            &["a", "b", "hinge"],
            &["b", "a", "hinge"],
        );
        assert_eq!(partial.success(), 1.0);
        assert_eq!(partial.goal_condition(), 1.0);
        // b a hinge vs a b hinge: two substitutions over max length 3.
        assert!((partial.procedure_deviation() - 2.0 / 3.0).abs() < 1e-12);
        let failed = ep(&[FullSuccess, Fail, Fail, FullSuccess], &["a", "b"], &[]);
        assert_eq!(failed.success(), 0.0);
        assert_eq!(failed.goal_condition(), 0.5);
        assert_eq!(failed.procedure_deviation(), 1.0);
        assert_eq!(ep(&[], &[], &[]).procedure_deviation(), 0.0);
        assert_eq!(
            levenshtein(
                &["k", "i", "t", "t", "e", "n"],
                &["s", "i", "t", "t", "i", "n", "g"]
            ),
            3
        );
    }

    #[test]
    fn aggregates_by_hand() {
        let episodes = vec![
            ep(&[FullSuccess, FullSuccess], &["a", "b"], &["a", "b"]),
            ep(&[FullSuccess, Fail], &["a", "b"], &["a"]),
            ep(&[PartialSuccess, FullSuccess], &["a", "b"], &["b", "a"]),
            ep(&[Fail, Fail], &["a", "b"], &[]),
        ];
        let s = summarize(&episodes, PdScope::AllEpisodes);
        // SR values 1,0,1,0: mean .5, sd = sqrt(1/3), se = sd/2.
        assert!((s.sr.mean - 50.0).abs() < 1e-9);
        assert!((s.sr.se - 100.0 * (1.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-9);
        // GC values 1, .5, 1, 0: mean .625.
        assert!((s.gc.mean - 62.5).abs() < 1e-9);
        // PD values 0, .5, 1, 1: mean .625.
        assert!((s.pd.mean - 62.5).abs() < 1e-9);
        let s = summarize(&episodes, PdScope::SuccessfulOnly);
        // PD over episodes 1 and 3: 0 and 1.
        assert!((s.pd.mean - 50.0).abs() < 1e-9);
        assert_eq!(s.pd.n, 2);
        assert!(MeanSe::of(&[0.3]).se.is_nan());
        assert!(MeanSe::of(&[]).mean.is_nan());
    }
}
