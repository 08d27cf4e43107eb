//! Reading a reply's symbols against the task before anything is verified: every predicate
//! an operator uses must be in the run's vocabulary with its arity, and every object
//! constant must be one of the task's objects.
//!
//! Without this a misspelt predicate is not an error but a different claim. A precondition
//! `(forall (?y - thing) (not (OnTop ?y red_cube)))` over a predicate no state ever holds is
//! vacuously true, so the operator verifies and the adapted plan skips a step; a
//! `(gripper_open)` is simply unmet, and the message never says the predicate does not
//! exist. Names are not rewritten to the nearest known one: the reply is refused with the
//! nearest names as suggestions, and the model answers again.

use serde::{Deserialize, Serialize};

use crate::atom::Atom;
use crate::operator::Operator;
use crate::predicates::Vocabulary;
use crate::symbol::Symbol;

/// A name in a reply that the task does not know.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct UnknownSymbol {
    /// What kind of name, and how it is wrong.
    pub kind: SymbolProblem,
    /// The name as the reply wrote it.
    pub name: String,
    /// The nearest known name of the same kind, if one is close.
    pub suggestion: Option<String>,
}

/// How a name is wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "problem", rename_all = "snake_case")]
pub enum SymbolProblem {
    /// Not a predicate of the vocabulary.
    UnknownPredicate,
    /// A known predicate with the wrong number of arguments.
    WrongArity {
        /// Its declared arity.
        expected: usize,
        /// The number of arguments written.
        found: usize,
    },
    /// Not an object of the task.
    UnknownObject,
    /// An object whose declared kind the predicate's parameter does not take.
    WrongKind {
        /// The argument's position, from 1.
        position: usize,
        /// The parameter's kind.
        expected: Symbol,
        /// The object's kind.
        found: Symbol,
    },
}

impl std::fmt::Display for UnknownSymbol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.kind {
            SymbolProblem::UnknownPredicate => write!(f, "`{}` is not a predicate", self.name)?,
            SymbolProblem::WrongArity { expected, found } => {
                write!(f, "`{}` takes {expected} argument(s), not {found}", self.name)?
            }
            SymbolProblem::UnknownObject => write!(f, "`{}` is not an object of this task", self.name)?,
            SymbolProblem::WrongKind {
                position,
                expected,
                found,
            } => write!(
                f,
                "argument {position} of `{}` must be a `{expected}`, but it is a `{found}`",
                self.name
            )?,
        }
        if let Some(s) = &self.suggestion {
            write!(f, "; did you mean `{s}`?")?;
        }
        Ok(())
    }
}

/// The names in `operators` that `vocabulary` and `objects` do not know, each once, in the
/// order they first appear. With `objects` `None`, only predicates are checked.
///
/// ```
/// use nesy_core::adapt::unknown_symbols;
/// use nesy_core::Vocabulary;
/// use nesy_core::text::parse_induction_reply;
/// use nesy_core::Symbol;
///
/// let reply = "* Predicted Action:\nAction Semantic:\n- PickRedCube\nPrecondition:\n- (forall (?y - thing) (not (OnTop ?y red_cube)))\nEffect:\n- (GripperHolding red_cub)\n";
/// let operator = parse_induction_reply(reply).unwrap().operator;
/// let objects = [Symbol::new("red_cube")];
/// let unknown = unknown_symbols(&[&operator], &Vocabulary::new(), Some(&objects));
/// let messages: Vec<String> = unknown.iter().map(|u| u.to_string()).collect();
/// assert_eq!(
///     messages,
///     [
///         "`OnTop` is not a predicate; did you mean `OnTopOf`?",
///         "`red_cub` is not an object of this task; did you mean `red_cube`?",
///     ]
/// );
/// ```
pub fn unknown_symbols(
    operators: &[&Operator],
    vocabulary: &Vocabulary,
    objects: Option<&[Symbol]>,
) -> Vec<UnknownSymbol> {
    let mut names = NameCheck::new(vocabulary, objects);
    for operator in operators {
        for pattern in operator.patterns() {
            names.predicate(pattern.pred, pattern.args.len());
        }
        for constant in operator.constants() {
            names.object(constant);
        }
    }
    names.found
}

/// The names in `atoms` (a state list, such as a state translation's reply) that
/// `vocabulary` and `objects` do not know, each once, in the order they first appear: the
/// same rules as [`unknown_symbols`], applied to ground atoms, and each argument's declared
/// kind checked against its parameter's (only vocabulary files declare kinds).
///
/// ```
/// use nesy_core::adapt::unknown_atom_symbols;
/// use nesy_core::Vocabulary;
/// use nesy_core::text::parse_state_list;
/// use nesy_core::Symbol;
///
/// let atoms = parse_state_list("- (Ontop red_cube floor)\n- (GripperOpen red_cube)").unwrap();
/// let objects = [Symbol::new("red_cube"), Symbol::new("floor")];
/// let unknown = unknown_atom_symbols(atoms.iter(), &Vocabulary::new(), &objects);
/// let messages: Vec<String> = unknown.iter().map(|u| u.to_string()).collect();
/// assert_eq!(
///     messages,
///     [
///         "`Ontop` is not a predicate; did you mean `OnTopOf`?",
///         "`GripperOpen` takes 0 argument(s), not 1",
///     ]
/// );
/// ```
pub fn unknown_atom_symbols<'a>(
    atoms: impl IntoIterator<Item = &'a Atom>,
    vocabulary: &Vocabulary,
    objects: &[Symbol],
) -> Vec<UnknownSymbol> {
    let mut names = NameCheck::new(vocabulary, Some(objects));
    for atom in atoms {
        names.predicate(atom.pred(), atom.args().len());
        for (i, arg) in atom.args().iter().enumerate() {
            names.object(*arg);
            if let Some((expected, found)) = vocabulary.kind_mismatch(atom.pred(), i, arg.as_str()) {
                names.push(UnknownSymbol {
                    kind: SymbolProblem::WrongKind {
                        position: i + 1,
                        expected,
                        found,
                    },
                    name: atom.pred().to_string(),
                    suggestion: None,
                });
            }
        }
    }
    names.found
}

/// Collects the unknown names of a reply, each once.
struct NameCheck<'a> {
    vocabulary: &'a Vocabulary,
    predicate_names: Vec<&'a str>,
    /// `None`: objects are not checked.
    objects: Option<&'a [Symbol]>,
    found: Vec<UnknownSymbol>,
}

impl<'a> NameCheck<'a> {
    fn new(vocabulary: &'a Vocabulary, objects: Option<&'a [Symbol]>) -> Self {
        NameCheck {
            vocabulary,
            predicate_names: vocabulary.predicates().iter().map(|p| p.name.as_str()).collect(),
            objects,
            found: Vec::new(),
        }
    }

    fn push(&mut self, symbol: UnknownSymbol) {
        if !self
            .found
            .iter()
            .any(|f| f.name == symbol.name && f.kind == symbol.kind)
        {
            self.found.push(symbol);
        }
    }

    /// A use of predicate `pred` with `arguments` arguments.
    fn predicate(&mut self, pred: Symbol, arguments: usize) {
        let name = pred.as_str();
        match self.vocabulary.get(pred) {
            None => {
                let suggestion = nearest(name, &self.predicate_names);
                self.push(UnknownSymbol {
                    kind: SymbolProblem::UnknownPredicate,
                    name: name.to_string(),
                    suggestion,
                });
            }
            Some(p) if p.arity != arguments => {
                let expected = p.arity;
                self.push(UnknownSymbol {
                    kind: SymbolProblem::WrongArity {
                        expected,
                        found: arguments,
                    },
                    name: name.to_string(),
                    suggestion: None,
                });
            }
            Some(_) => {}
        }
    }

    /// A use of object constant `object`.
    fn object(&mut self, object: Symbol) {
        let Some(objects) = self.objects else { return };
        if objects.contains(&object) {
            return;
        }
        let object_names: Vec<&str> = objects.iter().map(|o| o.as_str()).collect();
        let suggestion = nearest(object.as_str(), &object_names);
        self.push(UnknownSymbol {
            kind: SymbolProblem::UnknownObject,
            name: object.to_string(),
            suggestion,
        });
    }
}

/// The prose for a reply whose names the task does not know (induction and patches alike).
pub(super) fn describe_unknown(unknown: &[UnknownSymbol]) -> String {
    let list: Vec<String> = unknown.iter().map(|u| format!("- {u}")).collect();
    format!(
        "The reply could not be read: it uses names this task does not have.\n{}\nUse only the predicates defined above, with their arguments, and the listed objects.",
        list.join("\n")
    )
}

/// The object names a reply may use: the task's objects and every name its states mention
/// (fixtures and parts such as `floor`, `hinge_lid` or a drawer handle are in the states but
/// not always in the object list), plus `extra` (the constants of the procedure a patch
/// edits), each once.
pub fn known_objects<'a>(
    objects: &[Symbol],
    states: impl IntoIterator<Item = &'a crate::state::State>,
    extra: impl IntoIterator<Item = Symbol>,
) -> Vec<Symbol> {
    let mut known: Vec<Symbol> = objects.to_vec();
    let mut add = |name: Symbol| {
        if !known.contains(&name) {
            known.push(name);
        }
    };
    for state in states {
        for atom in state.iter() {
            atom.args().iter().for_each(|a| add(*a));
        }
    }
    extra.into_iter().for_each(&mut add);
    known
}

/// The known name closest to `name`: one that differs only in case, `_` or `-` first, else
/// the one fewest edits away if that is at most a third of the name's length (at least 2).
fn nearest(name: &str, known: &[&str]) -> Option<String> {
    let fold = |s: &str| -> String {
        s.chars()
            .filter(|c| *c != '_' && *c != '-')
            .flat_map(char::to_lowercase)
            .collect()
    };
    let folded = fold(name);
    if let Some(same) = known.iter().find(|k| fold(k) == folded) {
        return Some((*same).to_string());
    }
    let limit = (name.chars().count() / 3).max(2);
    known
        .iter()
        .map(|k| (edit_distance(&folded, &fold(k)), *k))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, k)| k.to_string())
}

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = if ca == *cb {
                diagonal
            } else {
                1 + diagonal.min(above).min(row[j])
            };
            diagonal = above;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn case_and_snake_case_variants_point_at_the_known_name() {
        let known = ["GripperOpen", "OnTopOf", "InsideOf"];
        assert_eq!(nearest("gripper_open", &known).as_deref(), Some("GripperOpen"));
        assert_eq!(nearest("GRIPPEROPEN", &known).as_deref(), Some("GripperOpen"));
        assert_eq!(nearest("OnTop", &known).as_deref(), Some("OnTopOf"));
        assert_eq!(nearest("Levitating", &known), None);
    }

    #[test]
    fn edit_distance_counts_single_character_edits() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
    }
}
