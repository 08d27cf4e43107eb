//! Noise knobs for the robustness and ablation studies: the oracle's answers degraded on
//! purpose, seeded, so a run with the same seed and requests gives the same answers.
//!
//! Each knob perturbs one kind of answer, so a study can say exactly what its error model
//! is. Rates are Bernoulli probabilities per item unless a knob's doc says it is an exact
//! count.

use std::fmt;
use std::str::FromStr;

use nesy_core::Atom;
use nesy_core::Operator;
use nesy_core::Symbol;
use nesy_core::rng::SplitMix64;
use nesy_core::{Effect, Formula};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use nesy_sim::domain::object_type;

/// Which translated scenes the state knobs perturb.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StateScope {
    /// The demonstration's keyframes only (the paper's Table 8: "applied to all scene graphs
    /// along the demonstration").
    #[default]
    Demo,
    /// The target scene's initial state only.
    Target,
    /// Both.
    Both,
}

impl StateScope {
    /// Whether a translation of `view_set` (`demo/keyframe/3`, `target/initial`) is in scope.
    pub fn covers(self, view_set: &str) -> bool {
        let demo = view_set.starts_with("demo");
        match self {
            StateScope::Demo => demo,
            StateScope::Target => !demo,
            StateScope::Both => true,
        }
    }

    fn as_str(self) -> &'static str {
        match self {
            StateScope::Demo => "demo",
            StateScope::Target => "target",
            StateScope::Both => "both",
        }
    }
}

/// Which atoms of a scene graph count as its relations for the state knobs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Relations {
    /// Binary atoms only (`OnTopOf`, `InsideOf`, `OverOf`): the scene graph's edges.
    #[default]
    Binary,
    /// Every atom, unary (`Open`, `GripperHolding`) and nullary (`GripperOpen`) too.
    All,
}

impl Relations {
    /// Whether `atom` is a relation under this reading.
    pub fn includes(self, atom: &Atom) -> bool {
        match self {
            Relations::Binary => atom.arity() == 2,
            Relations::All => true,
        }
    }

    fn as_str(self) -> &'static str {
        match self {
            Relations::Binary => "binary",
            Relations::All => "all",
        }
    }
}

/// How much noise the oracle adds, knob by knob.
///
/// Operator knobs act on induction replies, state knobs on state translations (so only with
/// `--states vlm`), `bad_patch` on patch replies and `localize_miss` on patch requests made
/// without identification.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct OracleNoise {
    /// Bernoulli rate per literal of an induced operator: the literal is left out (at least
    /// one effect always stays).
    pub op_drop: f64,
    /// Bernoulli rate per literal of an induced operator: the literal is negated (add ↔
    /// delete for effects).
    pub op_flip: f64,
    /// Exact count per scene graph: p·n of its n relation atoms are removed, with p·n
    /// rounded stochastically (down, or up with the fraction's probability), so the
    /// expected share removed is p.
    pub state_drop: f64,
    /// Exact count per scene graph, rounded the same way: p·n false, type-plausible relation
    /// atoms are added (a true relation with one argument swapped for another object of the
    /// same type, never an atom that holds). Injection only adds; it never removes a true
    /// atom.
    pub state_inject: f64,
    /// Bernoulli rate per relation atom kept: its last argument is replaced by another
    /// object (of the same type where there is one), so a true atom becomes a false one.
    pub state_corrupt: f64,
    /// Which scenes the state knobs perturb.
    pub state_scope: StateScope,
    /// Which atoms count as relations.
    pub relations: Relations,
    /// Bernoulli rate per patch reply: its SEARCH block names an action that is not in the
    /// plan, or its inserted actions lose their first one.
    pub bad_patch: f64,
    /// Bernoulli rate per patch request made without identification: instead of finding the
    /// failing step by replaying the procedure, the oracle picks a step at random and patches
    /// it as if it had failed there, offering the first patch it plans for that step without
    /// checking it (when nothing can be planned for the guess, it answers as if it had
    /// localised correctly). A modelling assumption: a model told nothing about where the
    /// procedure fails localises the failure correctly with probability 1 − p.
    pub localize_miss: f64,
}

/// Why a noise specification was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoiseError {
    /// An item is not `name=value`.
    #[error(
        "noise item {item:?} is not name=value (expected e.g. op-drop=0.1,state-inject=0.1,bad-patch=0.2)"
    )]
    Malformed {
        /// The item.
        item: String,
    },
    /// An unknown knob.
    #[error("unknown noise knob {name:?}; expected one of {KNOBS}{hint}")]
    UnknownKnob {
        /// The name.
        name: String,
        /// Where the knob was split in two, which new knobs replace it.
        hint: String,
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
    /// A choice knob got a value it does not have.
    #[error("noise knob {name}: {value:?}; expected {expected}")]
    BadChoice {
        /// The knob.
        name: String,
        /// The value.
        value: String,
        /// The values it takes.
        expected: &'static str,
    },
}

/// Every knob name, as the error message lists them.
pub(crate) const KNOBS: &str = "op-drop, op-flip, state-drop, state-inject, state-corrupt, state-scope=demo|target|both, relations=binary|all, bad-patch, localize-miss";

impl OracleNoise {
    /// No noise.
    pub const NONE: OracleNoise = OracleNoise {
        op_drop: 0.0,
        op_flip: 0.0,
        state_drop: 0.0,
        state_inject: 0.0,
        state_corrupt: 0.0,
        state_scope: StateScope::Demo,
        relations: Relations::Binary,
        bad_patch: 0.0,
        localize_miss: 0.0,
    };

    /// True when no knob perturbs anything (scope and relations alone change nothing).
    pub fn is_none(&self) -> bool {
        self.rates().iter().all(|(_, v)| *v == 0.0)
    }

    /// True when a state knob is set.
    pub fn perturbs_states(&self) -> bool {
        self.state_drop > 0.0 || self.state_inject > 0.0 || self.state_corrupt > 0.0
    }

    fn rates(&self) -> [(&'static str, f64); 7] {
        [
            ("op-drop", self.op_drop),
            ("op-flip", self.op_flip),
            ("state-drop", self.state_drop),
            ("state-inject", self.state_inject),
            ("state-corrupt", self.state_corrupt),
            ("bad-patch", self.bad_patch),
            ("localize-miss", self.localize_miss),
        ]
    }

    fn rate_mut(&mut self, name: &str) -> Option<&mut f64> {
        Some(match name {
            "op-drop" => &mut self.op_drop,
            "op-flip" => &mut self.op_flip,
            "state-drop" => &mut self.state_drop,
            "state-inject" => &mut self.state_inject,
            "state-corrupt" => &mut self.state_corrupt,
            "bad-patch" => &mut self.bad_patch,
            "localize-miss" => &mut self.localize_miss,
            _ => return None,
        })
    }
}

impl FromStr for OracleNoise {
    type Err = NoiseError;

    /// Parses `op-drop=0.1,state-inject=0.1,state-scope=demo` (any subset, any order;
    /// underscores may stand for hyphens; an empty string or `none` is no noise).
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
            let name = name.trim().replace('_', "-");
            let value = value.trim();
            match name.as_str() {
                "state-scope" => {
                    noise.state_scope = match value {
                        "demo" => StateScope::Demo,
                        "target" => StateScope::Target,
                        "both" => StateScope::Both,
                        _ => return Err(choice(&name, value, "demo, target or both")),
                    };
                    continue;
                }
                "relations" => {
                    noise.relations = match value {
                        "binary" => Relations::Binary,
                        "all" => Relations::All,
                        _ => return Err(choice(&name, value, "binary or all")),
                    };
                    continue;
                }
                _ => {}
            }
            let Some(slot) = noise.rate_mut(&name) else {
                let hint = match name.as_str() {
                    "drop" => " (`drop` is split: op-drop for operators, state-drop for states)",
                    "flip" => " (`flip` is split: op-flip for operators, state-corrupt for states)",
                    _ => "",
                };
                return Err(NoiseError::UnknownKnob {
                    name,
                    hint: hint.into(),
                });
            };
            let v: f64 = value.parse().map_err(|_| NoiseError::NotANumber {
                name: name.clone(),
                value: value.into(),
            })?;
            if !(0.0..=1.0).contains(&v) {
                return Err(NoiseError::OutOfRange { name, value: v });
            }
            *slot = v;
        }
        Ok(noise)
    }
}

fn choice(name: &str, value: &str, expected: &'static str) -> NoiseError {
    NoiseError::BadChoice {
        name: name.into(),
        value: value.into(),
        expected,
    }
}

impl fmt::Display for OracleNoise {
    /// The knobs that are set, in a fixed order (`none` when none is); scope and relations
    /// are written when a state knob is set. Parsing the text gives the same noise back.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts: Vec<String> = self
            .rates()
            .iter()
            .filter(|(_, v)| *v > 0.0)
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        if self.perturbs_states() {
            parts.push(format!("state-scope={}", self.state_scope.as_str()));
            parts.push(format!("relations={}", self.relations.as_str()));
        }
        if parts.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&parts.join(","))
        }
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

    /// `p·n` rounded stochastically: down, or up with the probability of the fraction, so
    /// the expectation is exactly `p·n`.
    pub fn count(&mut self, p: f64, n: usize) -> usize {
        let x = p * n as f64;
        let floor = x.floor();
        floor as usize + usize::from(self.0.unit() < x - floor)
    }
}

/// Drops and negates literals of an induced operator (`op_drop`, `op_flip`); at least one
/// effect stays. Returns how many literals were changed.
pub(crate) fn perturb_operator(op: &mut Operator, noise: &OracleNoise, rng: &mut NoiseRng) -> usize {
    let mut changed = 0;
    let mut pre = Vec::new();
    for f in op.pre.iter().cloned() {
        if rng.chance(noise.op_drop) {
            changed += 1;
        } else if rng.chance(noise.op_flip) {
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
        if !last_chance && rng.chance(noise.op_drop) {
            changed += 1;
        } else if rng.chance(noise.op_flip) {
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

/// What [`perturb_state`] did to one scene graph.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct StatePerturbation {
    /// The relation atoms the scene had.
    pub relations: usize,
    /// Relation atoms removed.
    pub dropped: usize,
    /// Relation atoms whose last argument was replaced.
    pub corrupted: usize,
    /// False atoms added.
    pub injected: usize,
}

impl StatePerturbation {
    /// Every change.
    pub(crate) fn changed(&self) -> usize {
        self.dropped + self.corrupted + self.injected
    }
}

/// How many tries [`perturb_state`] makes per atom to inject before giving up on it (a scene
/// with one object of each type has few false relations to offer).
const INJECT_TRIES: usize = 32;

/// Applies the state knobs to one translated scene: `atoms` are the true atoms the oracle
/// would answer, `objects` the scene's objects. Drops first, then corrupts what is left,
/// then injects, each counted against the relations the true scene had. The scope is the
/// caller's to check. The result is sorted and free of duplicates.
pub(crate) fn perturb_state(
    atoms: &[Atom],
    objects: &[Symbol],
    noise: &OracleNoise,
    rng: &mut NoiseRng,
) -> (Vec<Atom>, StatePerturbation) {
    let mut report = StatePerturbation::default();
    let is_relation = |a: &Atom| noise.relations.includes(a);
    let relations: Vec<usize> = (0..atoms.len()).filter(|&i| is_relation(&atoms[i])).collect();
    report.relations = relations.len();

    // Drop an exact number of distinct relations, chosen uniformly (a partial shuffle).
    let mut order = relations.clone();
    let drops = rng.count(noise.state_drop, relations.len()).min(order.len());
    for k in 0..drops {
        let j = k + rng.below(order.len() - k);
        order.swap(k, j);
    }
    let dropped: std::collections::BTreeSet<usize> = order[..drops].iter().copied().collect();
    report.dropped = drops;

    let truth: std::collections::BTreeSet<Atom> = atoms.iter().copied().collect();
    let mut out: Vec<Atom> = Vec::with_capacity(atoms.len());
    for (i, atom) in atoms.iter().enumerate() {
        if dropped.contains(&i) {
            continue;
        }
        if is_relation(atom) && !atom.args().is_empty() && rng.chance(noise.state_corrupt) {
            let mut args = atom.args().to_vec();
            let last = args.len() - 1;
            if let Some(other) = other_object(objects, args[last], &args, false, rng) {
                args[last] = other;
                out.push(Atom::from_symbols(atom.pred(), args));
                report.corrupted += 1;
                continue;
            }
        }
        out.push(*atom);
    }

    // Inject false relations modelled on true ones: one argument swapped for another object
    // of its type, never an atom that holds, never a repeated argument.
    let templates: Vec<Atom> = relations
        .iter()
        .map(|&i| atoms[i])
        .filter(|a| !a.args().is_empty())
        .collect();
    let wanted = rng.count(noise.state_inject, relations.len());
    let mut injected = std::collections::BTreeSet::new();
    if !templates.is_empty() {
        let mut tries = 0;
        while injected.len() < wanted && tries < wanted * INJECT_TRIES {
            tries += 1;
            let template = templates[rng.below(templates.len())];
            let mut args = template.args().to_vec();
            let k = rng.below(args.len());
            let Some(other) = other_object(objects, args[k], &args, true, rng) else {
                continue;
            };
            args[k] = other;
            let candidate = Atom::from_symbols(template.pred(), args);
            if !truth.contains(&candidate) && !out.contains(&candidate) {
                injected.insert(candidate);
            }
        }
    }
    report.injected = injected.len();
    out.extend(injected);
    out.sort_by_key(|a| a.to_string());
    out.dedup();
    (out, report)
}

/// Another object than every one in `avoid`, of the type of `like`; when the scene has none
/// of that type, any other object unless `same_type_only`.
fn other_object(
    objects: &[Symbol],
    like: Symbol,
    avoid: &[Symbol],
    same_type_only: bool,
    rng: &mut NoiseRng,
) -> Option<Symbol> {
    let kind = object_type(like.as_str());
    let free: Vec<Symbol> = objects.iter().copied().filter(|o| !avoid.contains(o)).collect();
    let typed: Vec<Symbol> = free
        .iter()
        .copied()
        .filter(|o| object_type(o.as_str()) == kind)
        .collect();
    let pool = if typed.is_empty() && !same_type_only {
        free
    } else {
        typed
    };
    (!pool.is_empty()).then(|| pool[rng.below(pool.len())])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_cli_form_and_prints_it_back() {
        let n: OracleNoise = "op-drop=0.1,op_flip=0.05,state-inject=0.1,state-scope=both,relations=all,bad-patch=0.2,localize-miss=0.5"
            .parse()
            .unwrap();
        assert_eq!(
            n,
            OracleNoise {
                op_drop: 0.1,
                op_flip: 0.05,
                state_inject: 0.1,
                state_scope: StateScope::Both,
                relations: Relations::All,
                bad_patch: 0.2,
                localize_miss: 0.5,
                ..OracleNoise::NONE
            }
        );
        assert_eq!(n.to_string().parse::<OracleNoise>().unwrap(), n);
        assert!("".parse::<OracleNoise>().unwrap().is_none());
        assert!("none".parse::<OracleNoise>().unwrap().is_none());
        assert_eq!(OracleNoise::NONE.to_string(), "none");
        // Scope alone perturbs nothing.
        assert!("state-scope=target".parse::<OracleNoise>().unwrap().is_none());
        assert_eq!(" bad_patch = 1 ".parse::<OracleNoise>().unwrap().bad_patch, 1.0);
    }

    #[test]
    fn refuses_bad_input_with_typed_errors() {
        assert!(matches!(
            "op-drop".parse::<OracleNoise>(),
            Err(NoiseError::Malformed { .. })
        ));
        assert!(matches!(
            "noise=0.1".parse::<OracleNoise>(),
            Err(NoiseError::UnknownKnob { .. })
        ));
        let split = "drop=0.1".parse::<OracleNoise>().unwrap_err().to_string();
        assert!(
            split.contains("op-drop") && split.contains("state-drop"),
            "{split}"
        );
        assert!(matches!(
            "op-flip=lots".parse::<OracleNoise>(),
            Err(NoiseError::NotANumber { .. })
        ));
        assert!(matches!(
            "state-drop=1.5".parse::<OracleNoise>(),
            Err(NoiseError::OutOfRange { .. })
        ));
        assert!(matches!(
            "state-scope=everywhere".parse::<OracleNoise>(),
            Err(NoiseError::BadChoice { .. })
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

    #[test]
    fn stochastic_rounding_keeps_the_expected_count() {
        let mut rng = NoiseRng::for_request(1, &serde_json::json!(1));
        assert_eq!(rng.count(0.5, 10), 5);
        assert_eq!(rng.count(0.0, 10), 0);
        let total: usize = (0..10_000).map(|_| rng.count(0.1, 7)).sum();
        // E = 0.7 per draw.
        assert!((6_700..7_300).contains(&total), "{total}");
    }

    fn scene() -> (Vec<Atom>, Vec<Symbol>) {
        let atoms = [
            "(OnTopOf red_cube floor)",
            "(OnTopOf green_cube red_cube)",
            "(OnTopOf blue_cube floor)",
            "(InsideOf apple toy_box)",
            "(OnTopOf toy_box floor)",
            "(Open hinge_lid)",
            "(GripperOpen)",
            "(FingerGripper)",
        ];
        let mut atoms: Vec<Atom> = atoms.iter().map(|a| a.parse().unwrap()).collect();
        atoms.sort_by_key(|a| a.to_string());
        let objects = [
            "red_cube",
            "green_cube",
            "blue_cube",
            "apple",
            "toy_box",
            "floor",
            "hinge_lid",
        ]
        .iter()
        .map(|o| Symbol::new(o))
        .collect();
        (atoms, objects)
    }

    fn draw(noise: &str, seed: u64) -> (Vec<Atom>, StatePerturbation) {
        let (atoms, objects) = scene();
        let noise: OracleNoise = noise.parse().unwrap();
        let mut rng = NoiseRng::for_request(seed, &serde_json::json!(seed));
        perturb_state(&atoms, &objects, &noise, &mut rng)
    }

    #[test]
    fn state_inject_adds_false_atoms_and_never_removes_one() {
        let (truth, _) = scene();
        for seed in 0..200 {
            let (out, report) = draw("state-inject=0.4", seed);
            assert!(truth.iter().all(|a| out.contains(a)), "seed {seed}: {out:?}");
            let added: Vec<&Atom> = out.iter().filter(|a| !truth.contains(a)).collect();
            assert_eq!(added.len(), report.injected);
            // 0.4 of the 5 binary relations is exactly 2.
            assert_eq!(report.injected, 2, "seed {seed}");
            for a in added {
                assert_eq!(a.arity(), 2, "binary relations only by default: {a}");
                assert_ne!(a.args()[0], a.args()[1], "{a}");
                // Type-plausible: the same predicate as a true relation, each argument of
                // the type some true atom of that predicate has in that place.
                assert!(
                    truth.iter().any(|t| t.pred() == a.pred()
                        && t.args()
                            .iter()
                            .zip(a.args())
                            .all(|(x, y)| object_type(x.as_str()) == object_type(y.as_str()))),
                    "{a}"
                );
            }
        }
    }

    #[test]
    fn state_drop_removes_an_exact_share_of_relations_only() {
        let (truth, _) = scene();
        for seed in 0..100 {
            let (out, report) = draw("state-drop=0.4", seed);
            assert_eq!(report.relations, 5);
            assert_eq!(report.dropped, 2);
            assert_eq!(out.len(), truth.len() - 2);
            assert!(out.iter().all(|a| truth.contains(a)));
            // Unary and nullary atoms are not relations under `binary`.
            for kept in ["(Open hinge_lid)", "(GripperOpen)", "(FingerGripper)"] {
                assert!(out.contains(&kept.parse().unwrap()), "{kept}");
            }
        }
        let (_, all) = draw("state-drop=0.5,relations=all", 3);
        assert_eq!((all.relations, all.dropped), (8, 4));
    }

    #[test]
    fn state_corrupt_replaces_atoms_one_for_one() {
        let (truth, _) = scene();
        let (out, report) = draw("state-corrupt=1", 0);
        assert_eq!(report.corrupted, 5);
        assert_eq!(out.len(), truth.len());
        assert_eq!(out.iter().filter(|a| !truth.contains(a)).count(), 5);
    }

    #[test]
    fn scope_decides_which_translations_are_touched() {
        assert!(StateScope::Demo.covers("demo/keyframe/3"));
        assert!(!StateScope::Demo.covers("target/initial"));
        assert!(StateScope::Target.covers("target/initial"));
        assert!(!StateScope::Target.covers("demo/keyframe/0"));
        assert!(StateScope::Both.covers("target/initial") && StateScope::Both.covers("demo/keyframe/1"));
    }

    #[test]
    fn op_knobs_leave_states_alone_and_state_knobs_leave_operators_alone() {
        let (truth, _) = scene();
        let (out, report) = draw("op-drop=1,op-flip=1,bad-patch=1", 5);
        assert_eq!((out, report.changed()), (truth, 0));
        let atom = |s: &str| nesy_core::AtomPattern::ground(s.parse().unwrap());
        let mut op = Operator::new(
            "a",
            vec![Formula::Atom(atom("(P x)"))],
            vec![Effect::Add(atom("(Q x)")), Effect::Del(atom("(P x)"))],
        );
        let before = op.clone();
        let noise: OracleNoise = "state-drop=1,state-inject=1,state-corrupt=1".parse().unwrap();
        let mut rng = NoiseRng::for_request(0, &serde_json::json!(0));
        assert_eq!(perturb_operator(&mut op, &noise, &mut rng), 0);
        assert_eq!(op, before);
    }
}
