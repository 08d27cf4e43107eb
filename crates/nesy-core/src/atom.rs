//! Ground atoms such as `(OnTopOf red_cube floor)` or `(GripperOpen)`.

use std::fmt;
use std::str::FromStr;

use smallvec::SmallVec;

use crate::symbol::Symbol;

/// Argument list of an atom. Up to three arguments live inline (every predicate of the
/// paper has arity ≤ 2); longer PDDL predicates spill to the heap.
pub type Args = SmallVec<[Symbol; 3]>;

/// A ground atom: a predicate applied to object constants.
///
/// `Ord` is by interned id (fast, deterministic within a process); printing code sorts
/// by text where humans read the result.
#[derive(Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Atom {
    pred: Symbol,
    args: Args,
}

impl Atom {
    /// Builds an atom from a predicate name and argument names, interning them.
    pub fn new(pred: &str, args: &[&str]) -> Self {
        Atom {
            pred: Symbol::new(pred),
            args: args.iter().map(|a| Symbol::new(a)).collect(),
        }
    }

    /// Builds an atom from already interned symbols.
    pub fn from_symbols(pred: Symbol, args: impl IntoIterator<Item = Symbol>) -> Self {
        Atom {
            pred,
            args: args.into_iter().collect(),
        }
    }

    /// The predicate.
    pub fn pred(&self) -> Symbol {
        self.pred
    }

    /// The arguments, in order.
    pub fn args(&self) -> &[Symbol] {
        &self.args
    }

    /// Number of arguments.
    pub fn arity(&self) -> usize {
        self.args.len()
    }

    /// True if any argument is `object`.
    pub fn mentions(&self, object: Symbol) -> bool {
        self.args.contains(&object)
    }
}

impl fmt::Display for Atom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}", self.pred)?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        f.write_str(")")
    }
}

impl fmt::Debug for Atom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// Why a string is not a ground atom.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("not a ground atom at column {column}: expected {expected}, found {found:?}")]
pub struct AtomParseError {
    /// 1-based column of the offending character.
    pub column: usize,
    /// What the parser wanted there.
    pub expected: &'static str,
    /// The rest of the input from that column (truncated).
    pub found: String,
}

/// True for characters allowed in names: PDDL-style identifiers with `-`, `_` and `.`.
pub(crate) fn is_name_char(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '_' | '-' | '.')
}

impl FromStr for Atom {
    type Err = AtomParseError;

    /// Parses `(Pred a b)`; whitespace inside is free, the predicate and arguments are
    /// names (letters, digits, `_`, `-`, `.`). Variables (`?x`) are rejected: atoms are
    /// ground.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        use winnow::ascii::multispace0;
        use winnow::combinator::{delimited, preceded, repeat};
        use winnow::prelude::*;
        use winnow::token::take_while;

        fn name<'s>(input: &mut &'s str) -> ModalResult<&'s str> {
            take_while(1.., is_name_char).parse_next(input)
        }

        fn atom(input: &mut &str) -> ModalResult<Atom> {
            let (pred, args): (&str, Vec<&str>) = delimited(
                ('(', multispace0),
                (name, repeat(0.., preceded(multispace0, name))),
                (multispace0, ')'),
            )
            .parse_next(input)?;
            Ok(Atom::new(pred, &args))
        }

        let text = s.trim();
        atom.parse(text).map_err(|e| {
            let offset = e.offset();
            let expected = if offset == 0 {
                "'('"
            } else if text[offset..].starts_with('?') {
                "a ground name (variables are not allowed in ground atoms)"
            } else {
                "a name or ')'"
            };
            AtomParseError {
                column: s.len() - s.trim_start().len() + offset + 1,
                expected,
                found: text[offset..].chars().take(24).collect(),
            }
        })
    }
}

impl serde::Serialize for Atom {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Atom {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = <std::borrow::Cow<'de, str>>::deserialize(deserializer)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_and_parse_round_trip() {
        for text in ["(OnTopOf red_cube floor)", "(GripperOpen)", "(at truck-1 city.2)"] {
            let atom: Atom = text.parse().unwrap();
            assert_eq!(atom.to_string(), text);
        }
        let spaced: Atom = "  ( InsideOf  apple   hinge_body )".parse().unwrap();
        assert_eq!(spaced, Atom::new("InsideOf", &["apple", "hinge_body"]));
    }

    #[test]
    fn rejects_garbage_with_column() {
        let err = "OnTopOf a b)".parse::<Atom>().unwrap_err();
        assert_eq!(err.column, 1);
        let err = "(OnTopOf ?x b)".parse::<Atom>().unwrap_err();
        assert_eq!(err.column, 10);
        assert!(err.expected.contains("variables"));
        assert!("(OnTopOf a".parse::<Atom>().is_err());
        assert!("()".parse::<Atom>().is_err());
    }
}
