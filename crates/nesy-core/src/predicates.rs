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

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::symbol::Symbol;
use crate::types::{PDDL_ROOT_TYPE, ROOT_TYPE};

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
    /// The object kind of each parameter, when a vocabulary file declared one (empty: every
    /// parameter takes any object, as the built-ins do).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub kinds: Vec<Symbol>,
}

impl PredicateInfo {
    /// The line a prompt's "predicate definitions" block uses, e.g.
    /// `(OnTopOf ?a ?b): ?a is resting on and supported by ?b.`
    /// A parameter with a declared kind other than the root is written `?x - parts`.
    pub fn definition_line(&self) -> String {
        let mut head = format!("({}", self.name);
        for (i, p) in self.params.iter().enumerate() {
            head.push_str(" ?");
            head.push_str(p);
            if let Some(kind) = self.kind_of_param(i) {
                head.push_str(" - ");
                head.push_str(kind.as_str());
            }
        }
        head.push(')');
        format!("{head}: {}", self.definition)
    }

    /// The declared kind of parameter `index`, unless it is the root kind (any object).
    pub fn kind_of_param(&self, index: usize) -> Option<Symbol> {
        self.kinds
            .get(index)
            .copied()
            .filter(|k| k.as_str() != ROOT_TYPE && k.as_str() != PDDL_ROOT_TYPE)
    }
}

/// An object kind a vocabulary declares, e.g. `parts` under `thing`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct KindInfo {
    /// The kind's name.
    pub name: Symbol,
    /// The kind it refines ([`ROOT_TYPE`] for a top-level kind).
    pub parent: Symbol,
    /// A one-line meaning, for people reading the vocabulary.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub meaning: String,
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
            kinds: Vec::new(),
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
    /// A kind, or a parameter's or an object's kind, names a kind never declared.
    #[error("unknown object kind `{name}` (declared kinds: {known})")]
    UnknownKind {
        /// The kind as written.
        name: String,
        /// The declared kinds, comma-separated.
        known: String,
    },
    /// A kind is declared twice.
    #[error("object kind `{name}` is declared twice")]
    DuplicateKind {
        /// The kind.
        name: String,
    },
    /// An object is given a kind twice, with different kinds.
    #[error("object `{object}` is given kind `{first}` and kind `{second}`")]
    ConflictingObjectKind {
        /// The object.
        object: String,
        /// Its first kind.
        first: String,
        /// Its second kind.
        second: String,
    },
    /// An atom's argument is an object whose declared kind is not the parameter's kind.
    #[error("argument {position} of `{predicate}` must be a `{expected}`, but `{object}` is a `{found}`")]
    WrongKind {
        /// The predicate.
        predicate: String,
        /// The argument's position, from 1.
        position: usize,
        /// The object.
        object: String,
        /// The parameter's kind.
        expected: String,
        /// The object's kind.
        found: String,
    },
}

/// The built-in predicates plus user-declared extras, and the object kinds a vocabulary
/// file declares.
///
/// The lists are shared (`Arc`) and copied on write: every model request carries the task's
/// vocabulary, and cloning it must not copy every definition.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(from = "VocabularyRepr", into = "VocabularyRepr")]
pub struct Vocabulary {
    predicates: Arc<Vec<PredicateInfo>>,
    kinds: Arc<Vec<KindInfo>>,
    object_kinds: Arc<BTreeMap<String, Symbol>>,
}

/// The serialised form of a [`Vocabulary`] (unchanged by the sharing; kinds only when
/// declared).
#[derive(Serialize, Deserialize)]
struct VocabularyRepr {
    predicates: Vec<PredicateInfo>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    kinds: Vec<KindInfo>,
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    object_kinds: BTreeMap<String, Symbol>,
}

impl From<VocabularyRepr> for Vocabulary {
    fn from(repr: VocabularyRepr) -> Self {
        Vocabulary {
            predicates: Arc::new(repr.predicates),
            kinds: Arc::new(repr.kinds),
            object_kinds: Arc::new(repr.object_kinds),
        }
    }
}

impl From<Vocabulary> for VocabularyRepr {
    fn from(v: Vocabulary) -> Self {
        VocabularyRepr {
            predicates: Arc::unwrap_or_clone(v.predicates),
            kinds: Arc::unwrap_or_clone(v.kinds),
            object_kinds: Arc::unwrap_or_clone(v.object_kinds),
        }
    }
}

impl Default for Vocabulary {
    fn default() -> Self {
        Vocabulary {
            predicates: Arc::new(builtin_predicates()),
            kinds: Arc::default(),
            object_kinds: Arc::default(),
        }
    }
}

impl Vocabulary {
    /// The built-in predicate set.
    pub fn new() -> Self {
        Self::default()
    }

    /// A vocabulary with no predicates and no kinds, for a task that declares its own.
    pub fn empty() -> Self {
        Vocabulary {
            predicates: Arc::default(),
            kinds: Arc::default(),
            object_kinds: Arc::default(),
        }
    }

    /// Declares a predicate in full ([`PredicateInfo`], with parameter kinds). Redeclaring
    /// with the same arity replaces the definition and kinds (a built-in keeps its tiers);
    /// another arity is an error, and so is a parameter kind never declared.
    pub fn declare_predicate(&mut self, mut info: PredicateInfo) -> Result<(), VocabularyError> {
        for kind in &info.kinds {
            self.check_kind(*kind)?;
        }
        let predicates = Arc::make_mut(&mut self.predicates);
        if let Some(existing) = predicates.iter_mut().find(|p| p.name == info.name) {
            if existing.arity != info.arity {
                return Err(VocabularyError::ArityConflict {
                    name: info.name.to_string(),
                    existing: existing.arity,
                    declared: info.arity,
                });
            }
            info.tiers = existing.tiers.clone();
            *existing = info;
            return Ok(());
        }
        predicates.push(info);
        Ok(())
    }

    /// Declares an object kind under `parent` (the root, [`ROOT_TYPE`], or a kind declared
    /// before). Kinds form a tree, so a parameter of kind `container` accepts a `box`
    /// declared under it.
    pub fn declare_kind(&mut self, name: &str, parent: &str, meaning: &str) -> Result<(), VocabularyError> {
        let name = Symbol::new(name);
        if self.is_kind(name) {
            return Err(VocabularyError::DuplicateKind {
                name: name.to_string(),
            });
        }
        let parent = self.check_kind(Symbol::new(parent))?;
        Arc::make_mut(&mut self.kinds).push(KindInfo {
            name,
            parent,
            meaning: meaning.to_string(),
        });
        Ok(())
    }

    /// Gives `object` a declared kind; its atoms are then checked against the parameters'
    /// kinds. Objects without one take any parameter (free-form object lists).
    pub fn assign_kind(&mut self, object: &str, kind: &str) -> Result<(), VocabularyError> {
        let kind = self.check_kind(Symbol::new(kind))?;
        let map = Arc::make_mut(&mut self.object_kinds);
        if let Some(first) = map.get(object).filter(|k| **k != kind) {
            return Err(VocabularyError::ConflictingObjectKind {
                object: object.to_string(),
                first: first.to_string(),
                second: kind.to_string(),
            });
        }
        map.insert(object.to_string(), kind);
        Ok(())
    }

    /// The declared object kinds, in declaration order.
    pub fn kinds(&self) -> &[KindInfo] {
        &self.kinds
    }

    /// The declared kind of `object`, if it has one.
    pub fn kind_of(&self, object: &str) -> Option<Symbol> {
        self.object_kinds.get(object).copied()
    }

    fn is_kind(&self, name: Symbol) -> bool {
        matches!(name.as_str(), ROOT_TYPE | PDDL_ROOT_TYPE) || self.kinds.iter().any(|k| k.name == name)
    }

    /// `name` if it is the root or a declared kind.
    pub(crate) fn check_kind(&self, name: Symbol) -> Result<Symbol, VocabularyError> {
        if self.is_kind(name) {
            return Ok(name);
        }
        let mut known = vec![ROOT_TYPE.to_string()];
        known.extend(self.kinds.iter().map(|k| k.name.to_string()));
        Err(VocabularyError::UnknownKind {
            name: name.to_string(),
            known: known.join(", "),
        })
    }

    /// Whether `kind` is `of` or declared under it. Parents are declared before their
    /// children, so the walk up ends at the root, which no declaration names.
    fn is_subkind(&self, mut kind: Symbol, of: Symbol) -> bool {
        loop {
            if kind == of {
                return true;
            }
            match self.kinds.iter().find(|k| k.name == kind) {
                Some(declared) => kind = declared.parent,
                None => return false,
            }
        }
    }

    /// The parameter kind an argument of `predicate` at `index` fails, as (expected, found),
    /// when `object` has a declared kind that is not the parameter's or one under it.
    pub fn kind_mismatch(&self, predicate: Symbol, index: usize, object: &str) -> Option<(Symbol, Symbol)> {
        let expected = self.get(predicate)?.kind_of_param(index)?;
        let found = self.kind_of(object)?;
        (!self.is_subkind(found, expected)).then_some((expected, found))
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
        self.declare_predicate(PredicateInfo {
            name: Symbol::new(name),
            arity: params.len(),
            category,
            params: params.iter().map(|p| p.to_string()).collect(),
            definition: definition.to_string(),
            tiers: Vec::new(),
            kinds: Vec::new(),
        })
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

    /// Checks a ground atom against the declarations: its predicate and arity, and each
    /// argument's kind where both the parameter and the object have one.
    pub fn check_atom(&self, atom: &crate::Atom) -> Result<(), VocabularyError> {
        self.check_use(atom.pred(), atom.args().len())?;
        for (i, arg) in atom.args().iter().enumerate() {
            if let Some((expected, found)) = self.kind_mismatch(atom.pred(), i, arg.as_str()) {
                return Err(VocabularyError::WrongKind {
                    predicate: atom.pred().to_string(),
                    position: i + 1,
                    object: arg.to_string(),
                    expected: expected.to_string(),
                    found: found.to_string(),
                });
            }
        }
        Ok(())
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
