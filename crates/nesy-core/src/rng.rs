//! SplitMix64: the small deterministic generator every part of nesy draws its seeded
//! randomness from (IK restarts, oracle noise, seeding larger generators, test layouts), so
//! a run depends only on its seeds, never on global state or a platform's hasher.
//!
//! ```
//! use nesy_core::rng::SplitMix64;
//!
//! let mut a = SplitMix64::new(7);
//! let mut b = SplitMix64::new(7);
//! assert_eq!(a.next_u64(), b.next_u64());
//! let u = a.unit();
//! assert!((0.0..1.0).contains(&u));
//! assert!(a.below(10) < 10);
//! ```

/// A SplitMix64 generator (Steele, Lea and Flood's 64-bit mixer on a Weyl sequence).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator whose state starts at `seed`.
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform value in [0, 1) with 53 random bits.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A value below `n` (`n` of 0 counts as 1), by remainder: uniform enough for the small
    /// `n` nesy draws from.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// True with probability `p` (never for `p ≤ 0`).
    pub fn chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.unit() <= p
    }
}
