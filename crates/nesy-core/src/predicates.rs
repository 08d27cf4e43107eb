//! The predicate vocabulary: the paper's built-in predicate set, its prompt tiers, and
//! user-declared extras.
//!
//! The built-in set follows the paper's predicate figure: five physics-related predicates
//! (`OverOf`, `OnTopOf`, `InsideOf`, `Open`, `Closed`) and ten embodiment-specific ones
//! (gripper and vacuum). Tiers select what a prompt shows (`docs/benchmark.md` §9):
//!
//! | tier | predicates |
//! |---|---|
//! | `partial` | OverOf, OnTopOf, InsideOf, GripperSurrounding, GripperHolding |
//! | `full` | partial + Open, Closed, GripperOpen, GripperClosed |
//! | `extended` | full + FingerGripper, VacuumSuction, VacuumAligned, VacuumAttached, VacuumActive, VacuumInactive |
//! | `end_effector` | FingerGripper, VacuumSuction, GripperOpen, GripperClosed, VacuumActive, VacuumInactive |
//!
//! A [`Vocabulary`] is the built-in set plus extras such as `Finegrained/1` and
//! `Gathered/1` from the paper's real-world task. Extras are physics-related unless
//! declared otherwise, which matters for goal derivation (embodiment-specific atoms never
//! enter a goal).

use std::fmt;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::symbol::Symbol;

/// Whether a predicate describes the world or the robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Category {
    /// Spatial relations and articulation states: part of what a task must achieve.
    Physics,
    /// The robot's end effector and its state: depends on the embodiment, never a goal.
    Embodiment,
}

/// A prompt tier: which predicates a prompt defines (`docs/benchmark.md` §9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Tier {
    /// Spatial relations plus gripper surrounding/holding.
    Partial,
    /// Partial plus open/closed for containers and the gripper.
    Full,
    /// Full plus the embodiment markers and the vacuum predicates.
    Extended,
    /// Only the end-effector predicates.
    EndEffector,
}

impl Tier {
    /// All tiers.
    pub const ALL: [Tier; 4] = [Tier::Partial, Tier::Full, Tier::Extended, Tier::EndEffector];

    /// The tier's name as used in configuration files.
    pub fn name(self) -> &'static str {
        match self {
            Tier::Partial => "partial",
            Tier::Full => "full",
            Tier::Extended => "extended",
            Tier::EndEffector => "end_effector",
        }
    }
}

impl fmt::Display for Tier {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Tier {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Tier::ALL
            .into_iter()
            .find(|t| t.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                format!("unknown predicate tier `{s}` (expected partial, full, extended or end_effector)")
            })
    }
}

/// One predicate: its name, arity, category, parameter names and a one-line definition.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PredicateInfo {
    /// The predicate's name, e.g. `OnTopOf`.
    pub name: Symbol,
    /// Number of arguments.
    pub arity: usize,
    /// Physics-related or embodiment-specific.
    pub category: Category,
    /// Parameter names used in the definition, e.g. `["a", "b"]`.
    pub params: Vec<String>,
    /// One-line definition referring to the parameters as `?a`, `?b`.
    pub definition: String,
    /// Tiers that include this predicate (empty for user-declared extras, which every
    /// tier includes).
    pub tiers: Vec<Tier>,
}

impl PredicateInfo {
    /// The line a prompt's "predicate definitions" block uses, e.g.
    /// `(OnTopOf ?a ?b): ?a is resting on and supported by ?b.`
    pub fn definition_line(&self) -> String {
        let mut head = format!("({}", self.name);
        for p in &self.params {
            head.push_str(" ?");
            head.push_str(p);
        }
        head.push(')');
        format!("{head}: {}", self.definition)
    }
}

struct Builtin {
    name: &'static str,
    params: &'static [&'static str],
    category: Category,
    definition: &'static str,
    tiers: &'static [Tier],
}

use Category::{Embodiment, Physics};
use Tier::{EndEffector, Extended, Full, Partial};

const BUILTINS: &[Builtin] = &[
    Builtin {
        name: "OverOf",
        params: &["a", "b"],
        category: Physics,
        definition: "?a is held directly above ?b without touching it.",
        tiers: &[Partial, Full, Extended],
    },
    Builtin {
        name: "OnTopOf",
        params: &["a", "b"],
        category: Physics,
        definition: "?a is resting on and supported by ?b.",
        tiers: &[Partial, Full, Extended],
    },
    Builtin {
        name: "InsideOf",
        params: &["a", "b"],
        category: Physics,
        definition: "?a is contained within ?b.",
        tiers: &[Partial, Full, Extended],
    },
    Builtin {
        name: "Open",
        params: &["x"],
        category: Physics,
        definition: "container or lid ?x is fully opened.",
        tiers: &[Full, Extended],
    },
    Builtin {
        name: "Closed",
        params: &["x"],
        category: Physics,
        definition: "container or lid ?x is fully closed.",
        tiers: &[Full, Extended],
    },
    Builtin {
        name: "FingerGripper",
        params: &[],
        category: Embodiment,
        definition: "the robot's end effector is a two-finger gripper; a precondition of every finger action.",
        tiers: &[Extended, EndEffector],
    },
    Builtin {
        name: "VacuumSuction",
        params: &[],
        category: Embodiment,
        definition: "the robot's end effector is a vacuum suction tool; a precondition of every suction action.",
        tiers: &[Extended, EndEffector],
    },
    Builtin {
        name: "GripperSurrounding",
        params: &["x"],
        category: Embodiment,
        definition: "?x is between the open fingertips, not yet grasped.",
        tiers: &[Partial, Full, Extended],
    },
    Builtin {
        name: "GripperHolding",
        params: &["x"],
        category: Embodiment,
        definition: "the gripper is closed and holds ?x.",
        tiers: &[Partial, Full, Extended],
    },
    Builtin {
        name: "GripperOpen",
        params: &[],
        category: Embodiment,
        definition: "the gripper fingers are open.",
        tiers: &[Full, Extended, EndEffector],
    },
    Builtin {
        name: "GripperClosed",
        params: &[],
        category: Embodiment,
        definition: "the gripper fingers are closed.",
        tiers: &[Full, Extended, EndEffector],
    },
    Builtin {
        name: "VacuumAligned",
        params: &["x"],
        category: Embodiment,
        definition: "the suction cup touches ?x but suction is off (the vacuum analogue of GripperSurrounding).",
        tiers: &[Extended],
    },
    Builtin {
        name: "VacuumAttached",
        params: &["x"],
        category: Embodiment,
        definition: "suction is on and ?x is attached to the cup (the vacuum analogue of GripperHolding).",
        tiers: &[Extended],
    },
    Builtin {
        name: "VacuumActive",
        params: &[],
        category: Embodiment,
        definition: "suction is on (the vacuum analogue of GripperClosed).",
        tiers: &[Extended, EndEffector],
    },
    Builtin {
        name: "VacuumInactive",
        params: &[],
        category: Embodiment,
        definition: "suction is off (the vacuum analogue of GripperOpen).",
        tiers: &[Extended, EndEffector],
    },
];

/// The paper's fifteen predicates, in the order of its predicate figure.
pub fn builtin_predicates() -> Vec<PredicateInfo> {
    BUILTINS
        .iter()
        .map(|b| PredicateInfo {
            name: Symbol::new(b.name),
            arity: b.params.len(),
            category: b.category,
            params: b.params.iter().map(|p| p.to_string()).collect(),
            definition: b.definition.to_string(),
            tiers: b.tiers.to_vec(),
        })
        .collect()
}

/// Why a predicate declaration or use is not accepted.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum VocabularyError {
    /// A declared predicate already exists with another arity.
    #[error(
        "predicate `{name}` already exists with arity {existing}, cannot redeclare it with arity {declared}"
    )]
    ArityConflict {
        /// The predicate.
        name: String,
        /// Its arity so far.
        existing: usize,
        /// The arity in the new declaration.
        declared: usize,
    },
    /// An atom uses a predicate the vocabulary does not define.
    #[error("unknown predicate `{name}`")]
    Unknown {
        /// The predicate.
        name: String,
    },
    /// An atom uses a predicate with the wrong number of arguments.
    #[error("predicate `{name}` takes {expected} argument(s), found {found}")]
    WrongArity {
        /// The predicate.
        name: String,
        /// Its declared arity.
        expected: usize,
        /// The number of arguments used.
        found: usize,
    },
}

/// The built-in predicates plus user-declared extras.
///
/// The list is shared (`Arc`) and copied on write: every model request carries the task's
/// vocabulary, and cloning it must not copy every definition.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(from = "VocabularyRepr", into = "VocabularyRepr")]
pub struct Vocabulary {
    predicates: Arc<Vec<PredicateInfo>>,
}

/// The serialised form of a [`Vocabulary`] (unchanged by the sharing).
#[derive(Serialize, Deserialize)]
struct VocabularyRepr {
    predicates: Vec<PredicateInfo>,
}

impl From<VocabularyRepr> for Vocabulary {
    fn from(repr: VocabularyRepr) -> Self {
        Vocabulary {
            predicates: Arc::new(repr.predicates),
        }
    }
}

impl From<Vocabulary> for VocabularyRepr {
    fn from(v: Vocabulary) -> Self {
        VocabularyRepr {
            predicates: Arc::unwrap_or_clone(v.predicates),
        }
    }
}

impl Default for Vocabulary {
    fn default() -> Self {
        Vocabulary {
            predicates: Arc::new(builtin_predicates()),
        }
    }
}

impl Vocabulary {
    /// The built-in predicate set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Declares an extra predicate, e.g. `declare("Gathered", &["x"], Category::Physics,
    /// "the fine-grained parts ?x lie together in one pile.")`. Redeclaring with the same
    /// arity replaces the definition; another arity is an error.
    pub fn declare(
        &mut self,
        name: &str,
        params: &[&str],
        category: Category,
        definition: &str,
    ) -> Result<(), VocabularyError> {
        let info = PredicateInfo {
            name: Symbol::new(name),
            arity: params.len(),
            category,
            params: params.iter().map(|p| p.to_string()).collect(),
            definition: definition.to_string(),
            tiers: Vec::new(),
        };
        let predicates = Arc::make_mut(&mut self.predicates);
        if let Some(existing) = predicates.iter_mut().find(|p| p.name == info.name) {
            if existing.arity != info.arity {
                return Err(VocabularyError::ArityConflict {
                    name: name.to_string(),
                    existing: existing.arity,
                    declared: info.arity,
                });
            }
            *existing = PredicateInfo {
                tiers: existing.tiers.clone(),
                ..info
            };
            return Ok(());
        }
        predicates.push(info);
        Ok(())
    }

    /// Looks a predicate up by name.
    pub fn get(&self, name: Symbol) -> Option<&PredicateInfo> {
        self.predicates.iter().find(|p| p.name == name)
    }

    /// All predicates: built-ins in the paper's order, then extras in declaration order.
    pub fn predicates(&self) -> &[PredicateInfo] {
        &self.predicates
    }

    /// True for predicates that describe the world rather than the robot. Unknown
    /// predicates count as physics-related (a world model may use names the vocabulary
    /// never saw; only the known embodiment predicates are excluded from goals).
    pub fn is_physics(&self, name: Symbol) -> bool {
        self.get(name).is_none_or(|p| p.category == Category::Physics)
    }

    /// Checks that an atom-shaped use of a predicate matches its declaration.
    pub fn check_use(&self, name: Symbol, arity: usize) -> Result<(), VocabularyError> {
        match self.get(name) {
            None => Err(VocabularyError::Unknown {
                name: name.to_string(),
            }),
            Some(p) if p.arity != arity => Err(VocabularyError::WrongArity {
                name: name.to_string(),
                expected: p.arity,
                found: arity,
            }),
            Some(_) => Ok(()),
        }
    }

    /// The predicates a tier shows: the built-ins of the tier, then every extra.
    pub fn tier(&self, tier: Tier) -> Vec<&PredicateInfo> {
        self.predicates
            .iter()
            .filter(|p| p.tiers.is_empty() || p.tiers.contains(&tier))
            .collect()
    }

    /// The "predicate definitions" block a prompt embeds: one
    /// `(Name ?a ?b): definition` line per predicate of the tier.
    pub fn render_definitions(&self, tier: Tier) -> String {
        self.tier(tier)
            .iter()
            .map(|p| p.definition_line())
            .collect::<Vec<_>>()
            .join("\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiers_match_the_spec() {
        let v = Vocabulary::new();
        let names = |t| v.tier(t).iter().map(|p| p.name.as_str()).collect::<Vec<_>>();
        assert_eq!(
            names(Tier::Partial),
            [
                "OverOf",
                "OnTopOf",
                "InsideOf",
                "GripperSurrounding",
                "GripperHolding"
            ]
        );
        assert_eq!(names(Tier::Full).len(), 9);
        assert_eq!(names(Tier::Extended).len(), 15);
        assert_eq!(
            names(Tier::EndEffector),
            [
                "FingerGripper",
                "VacuumSuction",
                "GripperOpen",
                "GripperClosed",
                "VacuumActive",
                "VacuumInactive"
            ]
        );
    }

    #[test]
    fn extras_and_rendering() {
        let mut v = Vocabulary::new();
        v.declare(
            "Finegrained",
            &["x"],
            Category::Physics,
            "?x consists of many small loose parts.",
        )
        .unwrap();
        v.declare(
            "Gathered",
            &["x"],
            Category::Physics,
            "the parts of ?x lie together in one pile.",
        )
        .unwrap();
        assert!(v.declare("Gathered", &["x", "y"], Category::Physics, "").is_err());
        let block = v.render_definitions(Tier::Partial);
        assert!(block.starts_with("(OverOf ?a ?b): "));
        assert!(block.contains("(OnTopOf ?a ?b): ?a is resting on and supported by ?b."));
        assert!(block.ends_with("(Gathered ?x): the parts of ?x lie together in one pile."));
        assert!(v.is_physics(Symbol::new("Gathered")));
        assert!(!v.is_physics(Symbol::new("GripperHolding")));
        assert!(v.check_use(Symbol::new("OnTopOf"), 1).is_err());
        assert_eq!("end_effector".parse::<Tier>().unwrap(), Tier::EndEffector);
    }
}
