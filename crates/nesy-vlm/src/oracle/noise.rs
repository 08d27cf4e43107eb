//! Noise knobs for the robustness study: the oracle's answers degraded on purpose, seeded,
//! so a run with the same seed and requests gives the same answers.

use std::fmt;
use std::str::FromStr;

use nesy_core::formula::{Effect, Formula};
use nesy_core::operator::Operator;
use nesy_core::rng::SplitMix64;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// How much noise the oracle adds. Each value is a probability in [0, 1].
///
/// - `drop`: each literal of an induced operator (and each atom of a translated state) is
///   left out;
/// - `flip`: each literal of an induced operator is negated (add ↔ delete for effects), and
///   each translated atom is replaced by a wrong relation (another object in its last
///   place);
/// - `bad_patch`: a patch reply is corrupted: its SEARCH block names an action that is not
///   in the plan, or its inserted actions lose their first one.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct OracleNoise {
    /// Probability of leaving out a literal or atom.
    pub drop: f64,
    /// Probability of negating a literal or corrupting an atom.
    pub flip: f64,
    /// Probability of corrupting a patch.
    pub bad_patch: f64,
}

/// Why a noise specification was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoiseError {
    /// An item is not `name=value`.
    #[error("noise item {item:?} is not name=value (expected e.g. drop=0.1,flip=0.1,bad-patch=0.2)")]
    Malformed {
        /// The item.
        item: String,
    },
    /// An unknown knob.
    #[error("unknown noise knob {name:?}; expected drop, flip or bad-patch")]
    UnknownKnob {
        /// The name.
        name: String,
    },
    /// The value is not a number.
    #[error("noise knob {name}: {value:?} is not a number")]
    NotANumber {
        /// The knob.
        name: String,
        /// The value.
        value: String,
    },
    /// The value is not a probability.
    #[error("noise knob {name}: {value} is outside [0, 1]")]
    OutOfRange {
        /// The knob.
        name: String,
        /// The value.
        value: f64,
    },
}

impl OracleNoise {
    /// No noise.
    pub const NONE: OracleNoise = OracleNoise {
        drop: 0.0,
        flip: 0.0,
        bad_patch: 0.0,
    };

    /// True when every knob is zero.
    pub fn is_none(&self) -> bool {
        *self == OracleNoise::NONE
    }
}

impl FromStr for OracleNoise {
    type Err = NoiseError;

    /// Parses `drop=0.1,flip=0.1,bad-patch=0.2` (any subset, any order; `bad_patch` is
    /// accepted too; an empty string or `none` is no noise).
    fn from_str(s: &str) -> Result<Self, NoiseError> {
        let mut noise = OracleNoise::NONE;
        let s = s.trim();
        if s.is_empty() || s.eq_ignore_ascii_case("none") {
            return Ok(noise);
        }
        for item in s.split(',') {
            let item = item.trim();
            let Some((name, value)) = item.split_once('=') else {
                return Err(NoiseError::Malformed { item: item.into() });
            };
            let (name, value) = (name.trim(), value.trim());
            let v: f64 = value.parse().map_err(|_| NoiseError::NotANumber {
                name: name.into(),
                value: value.into(),
            })?;
            if !(0.0..=1.0).contains(&v) {
                return Err(NoiseError::OutOfRange {
                    name: name.into(),
                    value: v,
                });
            }
            match name {
                "drop" => noise.drop = v,
                "flip" => noise.flip = v,
                "bad-patch" | "bad_patch" => noise.bad_patch = v,
                other => return Err(NoiseError::UnknownKnob { name: other.into() }),
            }
        }
        Ok(noise)
    }
}

impl fmt::Display for OracleNoise {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "drop={},flip={},bad-patch={}",
            self.drop, self.flip, self.bad_patch
        )
    }
}

/// A small deterministic generator (SplitMix64) seeded per request.
#[derive(Debug, Clone)]
pub struct NoiseRng(SplitMix64);

impl NoiseRng {
    /// A generator for one request: the run's seed and the request body decide it, so a
    /// re-asked request (with feedback appended) draws anew while a replayed run repeats.
    pub fn for_request(seed: u64, body: &serde_json::Value) -> NoiseRng {
        let mut h = Sha256::new();
        h.update(seed.to_le_bytes());
        h.update(body.to_string().as_bytes());
        let digest = h.finalize();
        let mut bytes = [0u8; 8];
        bytes.copy_from_slice(&digest[..8]);
        NoiseRng(SplitMix64::new(u64::from_le_bytes(bytes)))
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.0.chance(p)
    }

    /// A uniform index below `n` (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        self.0.below(n)
    }
}

/// Drops and negates literals of an induced operator; at least one effect stays. Returns
/// how many literals were changed.
pub fn perturb_operator(op: &mut Operator, noise: &OracleNoise, rng: &mut NoiseRng) -> usize {
    let mut changed = 0;
    let mut pre = Vec::new();
    for f in op.pre.iter().cloned() {
        if rng.chance(noise.drop) {
            changed += 1;
        } else if rng.chance(noise.flip) {
            changed += 1;
            pre.push(match f {
                Formula::Not(inner) => *inner,
                other => Formula::negate(other),
            });
        } else {
            pre.push(f);
        }
    }
    op.pre = pre.into();
    let total = op.eff.len();
    let mut eff = Vec::new();
    for (k, e) in op.eff.iter().cloned().enumerate() {
        let last_chance = eff.is_empty() && k + 1 == total;
        if !last_chance && rng.chance(noise.drop) {
            changed += 1;
        } else if rng.chance(noise.flip) {
            changed += 1;
            eff.push(match e {
                Effect::Add(p) => Effect::Del(p),
                Effect::Del(p) => Effect::Add(p),
                other => other,
            });
        } else {
            eff.push(e);
        }
    }
    op.eff = eff.into();
    changed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_cli_form() {
        let n: OracleNoise = "drop=0.1,flip=0.1,bad-patch=0.2".parse().unwrap();
        assert_eq!(
            n,
            OracleNoise {
                drop: 0.1,
                flip: 0.1,
                bad_patch: 0.2
            }
        );
        assert_eq!(n.to_string().parse::<OracleNoise>().unwrap(), n);
        assert!("".parse::<OracleNoise>().unwrap().is_none());
        assert!("none".parse::<OracleNoise>().unwrap().is_none());
        assert_eq!(" bad_patch = 1 ".parse::<OracleNoise>().unwrap().bad_patch, 1.0);
    }

    #[test]
    fn refuses_bad_input_with_typed_errors() {
        assert!(matches!(
            "drop".parse::<OracleNoise>(),
            Err(NoiseError::Malformed { .. })
        ));
        assert!(matches!(
            "noise=0.1".parse::<OracleNoise>(),
            Err(NoiseError::UnknownKnob { .. })
        ));
        assert!(matches!(
            "flip=lots".parse::<OracleNoise>(),
            Err(NoiseError::NotANumber { .. })
        ));
        assert!(matches!(
            "drop=1.5".parse::<OracleNoise>(),
            Err(NoiseError::OutOfRange { .. })
        ));
        let e = "bad-patch=-0.1".parse::<OracleNoise>().unwrap_err().to_string();
        assert!(e.contains("bad-patch") && e.contains("[0, 1]"), "{e}");
    }

    #[test]
    fn draws_are_seeded_by_request() {
        let body = serde_json::json!({"messages": ["a"]});
        let mut a = NoiseRng::for_request(7, &body);
        let mut b = NoiseRng::for_request(7, &body);
        let mut c = NoiseRng::for_request(8, &body);
        let xs: Vec<usize> = (0..4).map(|_| a.below(1 << 30)).collect();
        assert_eq!(xs, (0..4).map(|_| b.below(1 << 30)).collect::<Vec<_>>());
        assert_ne!(xs, (0..4).map(|_| c.below(1 << 30)).collect::<Vec<_>>());
        let hits = (0..10_000).filter(|_| a.chance(0.2)).count();
        assert!((1_700..2_300).contains(&hits), "{hits}");
        assert!(!a.chance(0.0));
    }
}
