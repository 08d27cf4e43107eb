//! The statistics a success rate needs to be read: a confidence interval that stays inside
//! [0, 1] for small counts (Wilson's), an exact paired test for two methods on the same
//! units (McNemar's, on the discordant pairs), and how many units a difference needs before
//! it can be told from noise.

use serde::Serialize;

/// The normal quantile of a two-sided 95 % interval.
pub const Z_95: f64 = 1.959_963_984_540_054;
/// The normal quantile of 80 % power (one-sided).
const Z_POWER_80: f64 = 0.841_621_233_572_914_3;

/// `k` successes out of `n`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Proportion {
    /// Successes.
    pub k: u64,
    /// Trials.
    pub n: u64,
}

impl Proportion {
    /// The observed rate, or `None` without trials.
    pub fn rate(self) -> Option<f64> {
        (self.n > 0).then(|| self.k as f64 / self.n as f64)
    }

    /// The 95 % Wilson score interval, or `None` without trials.
    ///
    /// ```
    /// use nesy_bench::stats::Proportion;
    /// let (lo, hi) = Proportion { k: 0, n: 12 }.wilson_95().unwrap();
    /// assert!(lo.abs() < 1e-12);
    /// assert!((hi - 0.2425).abs() < 1e-4);
    /// ```
    pub fn wilson_95(self) -> Option<(f64, f64)> {
        let p = self.rate()?;
        let n = self.n as f64;
        let z2 = Z_95 * Z_95;
        let centre = (p + z2 / (2.0 * n)) / (1.0 + z2 / n);
        let half = Z_95 / (1.0 + z2 / n) * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
        Some(((centre - half).max(0.0), (centre + half).min(1.0)))
    }

    /// `k/n (rate %, 95 % CI lo–hi %)`, or `k/n` without trials.
    ///
    /// ```
    /// use nesy_bench::stats::Proportion;
    /// assert_eq!(Proportion { k: 3, n: 4 }.describe(), "3/4 (75.0 %, 95 % CI 30.1–95.4 %)");
    /// ```
    pub fn describe(self) -> String {
        match (self.rate(), self.wilson_95()) {
            (Some(p), Some((lo, hi))) => format!(
                "{}/{} ({:.1} %, 95 % CI {:.1}–{:.1} %)",
                self.k,
                self.n,
                100.0 * p,
                100.0 * lo,
                100.0 * hi
            ),
            _ => format!("{}/{}", self.k, self.n),
        }
    }
}

/// The two-sided p-value of McNemar's exact test: of `b + c` discordant pairs, `b` went one
/// way and `c` the other; under "no difference" each way has probability one half.
///
/// ```
/// use nesy_bench::stats::mcnemar_exact;
/// assert_eq!(mcnemar_exact(0, 0), 1.0);
/// assert!((mcnemar_exact(0, 6) - 0.03125).abs() < 1e-12);
/// assert!((mcnemar_exact(2, 3) - 1.0).abs() < 1e-12);
/// ```
pub fn mcnemar_exact(b: u64, c: u64) -> f64 {
    let n = b + c;
    if n == 0 {
        return 1.0;
    }
    // P(X ≤ min(b, c)) for X ~ Binomial(n, 1/2), summed in log space so large n stays finite.
    let smaller = b.min(c);
    let ln_half_n = n as f64 * 0.5f64.ln();
    let mut ln_choose = 0.0f64;
    let mut tail = 0.0f64;
    for i in 0..=smaller {
        if i > 0 {
            ln_choose += ((n - i + 1) as f64).ln() - (i as f64).ln();
        }
        tail += (ln_choose + ln_half_n).exp();
    }
    (2.0 * tail).min(1.0)
}

/// Units per method needed to tell a success rate of `p1` from one of `p2` with a
/// two-sided test at the 5 % level and 80 % power (the normal approximation for two
/// independent proportions; paired units need no more). `None` when the rates are equal.
///
/// ```
/// use nesy_bench::stats::units_to_detect;
/// assert_eq!(units_to_detect(0.5, 0.6), Some(388));
/// assert_eq!(units_to_detect(0.9, 0.9), None);
/// ```
pub fn units_to_detect(p1: f64, p2: f64) -> Option<u64> {
    let delta = (p1 - p2).abs();
    if delta < 1e-12 {
        return None;
    }
    let mean = (p1 + p2) / 2.0;
    let a = Z_95 * (2.0 * mean * (1.0 - mean)).sqrt();
    let b = Z_POWER_80 * (p1 * (1.0 - p1) + p2 * (1.0 - p2)).sqrt();
    Some(((a + b) * (a + b) / (delta * delta)).ceil() as u64)
}

/// Units per side needed to tell the success rate `rate` from one 10 points lower (or
/// higher, when `rate` is under 10 %), as [`units_to_detect`] counts them: the figure the
/// reports give beside each overall rate.
///
/// ```
/// use nesy_bench::stats::{units_to_detect, units_to_detect_ten_points};
/// assert_eq!(units_to_detect_ten_points(0.5), units_to_detect(0.5, 0.4));
/// assert_eq!(units_to_detect_ten_points(0.05), units_to_detect(0.05, 0.15));
/// ```
pub fn units_to_detect_ten_points(rate: f64) -> Option<u64> {
    let other = if rate >= 0.1 { rate - 0.1 } else { rate + 0.1 };
    units_to_detect(rate, other)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_matches_published_values() {
        // Reference values of the Wilson score interval (z = 1.96).
        let (lo, hi) = Proportion { k: 81, n: 263 }.wilson_95().unwrap();
        assert!(
            (lo - 0.2553).abs() < 5e-4 && (hi - 0.3662).abs() < 5e-4,
            "{lo} {hi}"
        );
        let (lo, hi) = Proportion { k: 12, n: 12 }.wilson_95().unwrap();
        assert!((lo - 0.7575).abs() < 5e-4 && hi == 1.0, "{lo} {hi}");
        assert_eq!(Proportion { k: 0, n: 0 }.wilson_95(), None);
    }

    #[test]
    fn mcnemar_is_symmetric_and_exact() {
        // 1 against 9 discordant pairs: 2 * (1 + 10) / 1024.
        assert!((mcnemar_exact(1, 9) - 22.0 / 1024.0).abs() < 1e-12);
        assert_eq!(mcnemar_exact(9, 1), mcnemar_exact(1, 9));
        // Many pairs stay finite.
        let p = mcnemar_exact(400, 600);
        assert!(p > 0.0 && p < 1e-9, "{p}");
    }
}
