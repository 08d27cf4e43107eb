//! SEARCH/REPLACE patches over procedures, applied at the action level.
//!
//! A patch replaces a run of consecutive actions (SEARCH) with other actions (REPLACE). The
//! match compares *normalised* actions — name normalised to CamelCase, preconditions and
//! effects compared as sets of their canonical printed form — so whitespace, bullet style,
//! line order inside a section and name spelling (`grasp orange` vs `GraspOrange`) do not
//! matter, but any change of a literal does. If the SEARCH run occurs several times, the
//! occurrence nearest the failing step wins (ties go to the earlier one). If it occurs
//! nowhere, [`PatchError::NoMatch`] names the closest candidate and the first difference.
//! An empty REPLACE removes the matched actions; an empty SEARCH is an error (there is no
//! anchor to insert at).

use std::cell::OnceCell;
use std::fmt;
use std::hash::{Hash, Hasher};

use rustc_hash::FxHasher;
use serde::{Deserialize, Serialize};

use crate::formula::{Effect, Formula};
use crate::operator::{Operator, format_procedure};
use crate::text::normalize_action_name;

/// One SEARCH/REPLACE block.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Patch {
    /// The consecutive actions to find.
    pub search: Vec<Operator>,
    /// What replaces them (empty to remove them).
    pub replace: Vec<Operator>,
}

/// Prints the block the refinement prompt asks for:
///
/// ```text
/// <<<<<<< SEARCH
/// (action blocks)
/// =======
/// (action blocks, or nothing)
/// >>>>>>> REPLACE
/// ```
impl fmt::Display for Patch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "<<<<<<< SEARCH")?;
        writeln!(f, "{}", format_procedure(&self.search))?;
        writeln!(f, "=======")?;
        if !self.replace.is_empty() {
            writeln!(f, "{}", format_procedure(&self.replace))?;
        }
        f.write_str(">>>>>>> REPLACE")
    }
}

/// The comparison key of an action: normalised name, sorted precondition and effect texts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ActionKey {
    name: String,
    pre: Vec<String>,
    eff: Vec<String>,
}

impl ActionKey {
    /// The key of an operator.
    pub fn of(op: &Operator) -> Self {
        let mut pre: Vec<String> = op.pre.iter().map(|f| f.to_string()).collect();
        let mut eff: Vec<String> = op.eff.iter().map(|e| e.to_string()).collect();
        pre.sort();
        pre.dedup();
        eff.sort();
        eff.dedup();
        let mut name = normalize_action_name(&op.name).unwrap_or_else(|| op.name.clone());
        if !op.args.is_empty() {
            name = op.display_name();
        }
        ActionKey { name, pre, eff }
    }

    fn difference(&self, other: &ActionKey) -> Option<String> {
        if self.name != other.name {
            return Some(format!(
                "the name differs (`{}` in SEARCH, `{}` in the procedure)",
                self.name, other.name
            ));
        }
        let section = |what: &str, mine: &[String], theirs: &[String]| -> Option<String> {
            let missing: Vec<&String> = mine.iter().filter(|x| !theirs.contains(x)).collect();
            let extra: Vec<&String> = theirs.iter().filter(|x| !mine.contains(x)).collect();
            if missing.is_empty() && extra.is_empty() {
                return None;
            }
            let mut parts = Vec::new();
            if !missing.is_empty() {
                parts.push(format!("SEARCH has {} which the procedure lacks", join(&missing)));
            }
            if !extra.is_empty() {
                parts.push(format!("the procedure has {} which SEARCH lacks", join(&extra)));
            }
            Some(format!("{what} differ: {}", parts.join("; ")))
        };
        section("preconditions", &self.pre, &other.pre).or_else(|| section("effects", &self.eff, &other.eff))
    }
}

/// [`ActionKey`]'s comparison without printing: the normalised name, and the preconditions
/// and effects as sets of the formulas themselves. Printing is injective on formulas (the
/// printed form parses back to the same formula, which `tests/integration/roundtrip.rs`
/// checks), so two formulas are equal exactly when their canonical printed forms are, and
/// `MatchKey`s are equal exactly when the corresponding `ActionKey`s are. Matching a SEARCH block against a
/// procedure compares every action; only the error message needs the printed forms. The
/// formula sets are built on first use: most comparisons are settled by the names.
struct MatchKey<'a> {
    name: String,
    op: &'a Operator,
    pre: OnceCell<Vec<(u64, &'a Formula)>>,
    eff: OnceCell<Vec<(u64, &'a Effect)>>,
}

/// The items with their hashes, duplicates removed (a set).
fn hashed_set<T: Hash + Eq>(items: &[T]) -> Vec<(u64, &T)> {
    let mut out: Vec<(u64, &T)> = Vec::with_capacity(items.len());
    for item in items {
        let mut h = FxHasher::default();
        item.hash(&mut h);
        let h = h.finish();
        if !out.iter().any(|(oh, o)| *oh == h && *o == item) {
            out.push((h, item));
        }
    }
    out
}

/// Set equality of two duplicate-free lists.
fn same_set<T: Eq>(a: &[(u64, &T)], b: &[(u64, &T)]) -> bool {
    a.len() == b.len() && a.iter().all(|(h, x)| b.iter().any(|(g, y)| g == h && y == x))
}

impl<'a> MatchKey<'a> {
    fn of(op: &'a Operator) -> Self {
        let name = if op.args.is_empty() {
            normalize_action_name(&op.name).unwrap_or_else(|| op.name.clone())
        } else {
            op.display_name()
        };
        MatchKey {
            name,
            op,
            pre: OnceCell::new(),
            eff: OnceCell::new(),
        }
    }

    fn pre(&self) -> &[(u64, &'a Formula)] {
        self.pre.get_or_init(|| hashed_set(&self.op.pre))
    }

    fn eff(&self) -> &[(u64, &'a Effect)] {
        self.eff.get_or_init(|| hashed_set(&self.op.eff))
    }
}

impl PartialEq for MatchKey<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name && same_set(self.pre(), other.pre()) && same_set(self.eff(), other.eff())
    }
}

fn join(items: &[&String]) -> String {
    items.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", ")
}

/// The best near-miss for a SEARCH block that matched nowhere.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClosestCandidate {
    /// 0-based index of the first procedure action of the candidate run.
    pub start: usize,
    /// The names of the candidate run's actions.
    pub actions: Vec<String>,
    /// How many SEARCH actions match their counterpart.
    pub matching: usize,
    /// 0-based index in SEARCH of the first mismatching action.
    pub first_mismatch: usize,
    /// What differs there.
    pub difference: String,
}

/// Why a patch could not be applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum PatchError {
    /// The SEARCH block holds no action.
    #[error("the SEARCH block is empty: it must hold the consecutive actions to replace")]
    EmptySearch,
    /// No run of consecutive actions matches the SEARCH block.
    #[error("{}", describe_no_match(*search_len, closest.as_ref()))]
    NoMatch {
        /// Number of actions in SEARCH.
        search_len: usize,
        /// The closest candidate, if the procedure is long enough to hold one.
        closest: Option<ClosestCandidate>,
    },
}

fn describe_no_match(search_len: usize, closest: Option<&ClosestCandidate>) -> String {
    let mut s = format!(
        "the SEARCH block ({search_len} action{}) does not match any consecutive actions of the procedure",
        if search_len == 1 { "" } else { "s" }
    );
    if let Some(c) = closest {
        s.push_str(&format!(
            "; the closest candidate is step {} onwards ({}), where SEARCH action {} `{}`: {}",
            c.start + 1,
            c.actions.join(", "),
            c.first_mismatch + 1,
            c.actions.get(c.first_mismatch).map_or("", |s| s.as_str()),
            c.difference
        ));
    } else {
        s.push_str("; the procedure is shorter than the SEARCH block");
    }
    s
}

/// A successfully applied patch.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct AppliedPatch {
    /// The procedure after the patch.
    pub procedure: Vec<Operator>,
    /// 0-based index where the matched run started.
    pub at: usize,
    /// Number of actions removed.
    pub removed: usize,
    /// Number of actions inserted.
    pub inserted: usize,
    /// Other places the SEARCH block matched (not used).
    pub other_matches: Vec<usize>,
}

/// Applies a patch to a procedure, choosing the match nearest `near` (the failing step).
pub fn apply_patch(procedure: &[Operator], patch: &Patch, near: usize) -> Result<AppliedPatch, PatchError> {
    let k = patch.search.len();
    if k == 0 {
        return Err(PatchError::EmptySearch);
    }
    let search: Vec<MatchKey<'_>> = patch.search.iter().map(MatchKey::of).collect();
    let keys: Vec<MatchKey<'_>> = procedure.iter().map(MatchKey::of).collect();
    if keys.len() < k {
        return Err(PatchError::NoMatch {
            search_len: k,
            closest: None,
        });
    }
    let starts = 0..=keys.len() - k;
    let matches: Vec<usize> = starts.clone().filter(|&i| keys[i..i + k] == search[..]).collect();
    let distance = |i: usize| {
        if (i..i + k).contains(&near) {
            0
        } else if near < i {
            i - near
        } else {
            near - (i + k - 1)
        }
    };
    let Some(&at) = matches.iter().min_by_key(|&&i| (distance(i), i)) else {
        let best = starts
            .map(|i| {
                let matching = (0..k).filter(|&j| keys[i + j] == search[j]).count();
                let names = (0..k).filter(|&j| keys[i + j].name == search[j].name).count();
                (matching, names, std::cmp::Reverse(distance(i)), i)
            })
            .max()
            .map(|(_, _, _, i)| i);
        let closest = best.map(|start| {
            let first_mismatch = (0..k).find(|&j| keys[start + j] != search[j]).unwrap_or(0);
            ClosestCandidate {
                start,
                actions: procedure[start..start + k]
                    .iter()
                    .map(|o| o.display_name())
                    .collect(),
                matching: (0..k).filter(|&j| keys[start + j] == search[j]).count(),
                first_mismatch,
                difference: ActionKey::of(&patch.search[first_mismatch])
                    .difference(&ActionKey::of(&procedure[start + first_mismatch]))
                    .unwrap_or_else(|| "they differ".to_string()),
            }
        });
        return Err(PatchError::NoMatch {
            search_len: k,
            closest,
        });
    };
    let mut out = Vec::with_capacity(procedure.len() - k + patch.replace.len());
    out.extend_from_slice(&procedure[..at]);
    out.extend(patch.replace.iter().cloned());
    out.extend_from_slice(&procedure[at + k..]);
    Ok(AppliedPatch {
        procedure: out,
        at,
        removed: k,
        inserted: patch.replace.len(),
        other_matches: matches.into_iter().filter(|&i| i != at).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::parse_procedure;

    fn ops(text: &str) -> Vec<Operator> {
        parse_procedure(text).unwrap()
    }

    fn block(name: &str, pre: &str, eff: &str) -> String {
        format!("{name}\n- Preconditions:\n\t{pre}\n- Effects:\n\t{eff}")
    }

    #[test]
    fn nearest_match_and_removal() {
        let a = block("A", "(P)", "(Q)");
        let b = block("B", "(Q)", "(R)");
        let proc_ = ops(&[a.clone(), b.clone(), a.clone(), b.clone()].join("\n\n"));
        let patch = Patch {
            search: ops(&a),
            replace: vec![],
        };
        let applied = apply_patch(&proc_, &patch, 3).unwrap();
        assert_eq!(applied.at, 2);
        assert_eq!(applied.other_matches, vec![0]);
        assert_eq!(applied.procedure.len(), 3);
        let applied = apply_patch(&proc_, &patch, 0).unwrap();
        assert_eq!(applied.at, 0);
    }

    #[test]
    fn normalised_comparison_and_no_match() {
        let proc_ = ops(&block("GraspOrange", "(GripperOpen)", "(GripperHolding orange)"));
        let search =
            ops("grasp orange\n- Preconditions:\n  - (GripperOpen)\n- Effects:\n  * (GripperHolding orange)");
        let patch = Patch {
            search,
            replace: ops(&block("X", "(A)", "(B)")),
        };
        assert_eq!(apply_patch(&proc_, &patch, 0).unwrap().procedure[0].name, "X");
        let wrong = Patch {
            search: ops(&block(
                "GraspOrange",
                "(GripperClosed)",
                "(GripperHolding orange)",
            )),
            replace: vec![],
        };
        let err = apply_patch(&proc_, &wrong, 0).unwrap_err();
        let PatchError::NoMatch { closest: Some(c), .. } = &err else {
            panic!("{err:?}")
        };
        assert_eq!(c.start, 0);
        assert!(c.difference.contains("(GripperClosed)"), "{}", c.difference);
        assert!(err.to_string().contains("closest candidate"));
        assert_eq!(
            apply_patch(
                &proc_,
                &Patch {
                    search: vec![],
                    replace: vec![]
                },
                0
            )
            .unwrap_err(),
            PatchError::EmptySearch
        );
    }
}
