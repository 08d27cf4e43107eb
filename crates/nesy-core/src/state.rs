//! Symbolic states: finite sets of ground atoms under the closed-world assumption.

use std::fmt;

use crate::atom::Atom;
use crate::symbol::Symbol;

/// A set of ground atoms; anything absent is false (closed world).
///
/// Stored as a sorted, de-duplicated vector: membership is a binary search, cloning is a
/// single allocation, and iteration order is deterministic within a process.
#[derive(Clone, Default, PartialEq, Eq, Hash)]
pub struct State {
    atoms: Vec<Atom>,
}

impl State {
    /// The empty state.
    pub fn new() -> Self {
        State::default()
    }

    /// Builds a state from atoms; duplicates collapse.
    pub fn from_atoms(atoms: impl IntoIterator<Item = Atom>) -> Self {
        let mut atoms: Vec<Atom> = atoms.into_iter().collect();
        atoms.sort_unstable();
        atoms.dedup();
        State { atoms }
    }

    /// True if `atom` holds.
    pub fn contains(&self, atom: &Atom) -> bool {
        self.atoms.binary_search(atom).is_ok()
    }

    /// Adds `atom`; returns false if it was already present.
    pub fn insert(&mut self, atom: Atom) -> bool {
        match self.atoms.binary_search(&atom) {
            Ok(_) => false,
            Err(i) => {
                self.atoms.insert(i, atom);
                true
            }
        }
    }

    /// Removes `atom`; returns false if it was absent.
    pub fn remove(&mut self, atom: &Atom) -> bool {
        match self.atoms.binary_search(atom) {
            Ok(i) => {
                self.atoms.remove(i);
                true
            }
            Err(_) => false,
        }
    }

    /// Number of atoms.
    pub fn len(&self) -> usize {
        self.atoms.len()
    }

    /// True if no atom holds.
    pub fn is_empty(&self) -> bool {
        self.atoms.is_empty()
    }

    /// Atoms in storage order (by interned id).
    pub fn iter(&self) -> std::slice::Iter<'_, Atom> {
        self.atoms.iter()
    }

    /// Atoms sorted by their printed text, the order used in every human-facing output.
    pub fn sorted_by_text(&self) -> Vec<&Atom> {
        let mut v: Vec<&Atom> = self.atoms.iter().collect();
        // Texts are distinct (atoms are), so an unstable sort is deterministic; the key is
        // looked up once per atom.
        v.sort_by_cached_key(|a| a.text());
        v
    }

    /// True if every atom of `other` also holds here.
    pub fn is_superset(&self, other: &State) -> bool {
        other.atoms.iter().all(|a| self.contains(a))
    }

    /// The atoms as a slice, in storage order (by interned id).
    pub fn as_slice(&self) -> &[Atom] {
        &self.atoms
    }

    /// The state `(self \ deletes) ∪ adds`, PDDL's effect rule (deletes first, then adds).
    ///
    /// Both inputs must be sorted by [`Atom`]'s `Ord` and free of duplicates; the result is
    /// built in one linear merge.
    pub fn with_changes(&self, deletes: &[Atom], adds: &[Atom]) -> State {
        debug_assert!(deletes.windows(2).all(|w| w[0] < w[1]));
        debug_assert!(adds.windows(2).all(|w| w[0] < w[1]));
        // Changes are few and states are long: find each change by binary search and copy
        // the unchanged runs between them wholesale.
        let src = &self.atoms;
        let mut out = Vec::with_capacity(src.len() + adds.len());
        let (mut pos, mut d, mut a) = (0, 0, 0);
        loop {
            let next = match (deletes.get(d), adds.get(a)) {
                (None, None) => break,
                (Some(&x), None) => x,
                (None, Some(&y)) => y,
                (Some(&x), Some(&y)) => x.min(y),
            };
            let at = pos + src[pos..].partition_point(|s| *s < next);
            out.extend_from_slice(&src[pos..at]);
            pos = at;
            let is_add = adds.get(a) == Some(&next);
            if is_add {
                out.push(next); // added, or deleted and re-added: true afterwards
                a += 1;
            }
            if deletes.get(d) == Some(&next) {
                d += 1;
            }
            if src.get(pos) == Some(&next) {
                pos += 1; // the old copy is consumed either way
            }
        }
        out.extend_from_slice(&src[pos..]);
        State { atoms: out }
    }

    /// Every object constant mentioned by some atom, in id order.
    pub fn objects(&self) -> Vec<Symbol> {
        let mut objs: Vec<Symbol> = self.atoms.iter().flat_map(|a| a.args().iter().copied()).collect();
        objs.sort_unstable();
        objs.dedup();
        objs
    }

    /// What changed from `self` to `next`.
    pub fn diff(&self, next: &State) -> StateDiff {
        // Both sides are sorted by id: one linear merge.
        let (mut added, mut removed) = (Vec::new(), Vec::new());
        let (mut i, mut j) = (0, 0);
        let (a, b) = (&self.atoms, &next.atoms);
        while i < a.len() && j < b.len() {
            match a[i].cmp(&b[j]) {
                std::cmp::Ordering::Less => {
                    removed.push(a[i]);
                    i += 1;
                }
                std::cmp::Ordering::Greater => {
                    added.push(b[j]);
                    j += 1;
                }
                std::cmp::Ordering::Equal => {
                    i += 1;
                    j += 1;
                }
            }
        }
        removed.extend_from_slice(&a[i..]);
        added.extend_from_slice(&b[j..]);
        StateDiff { added, removed }
    }
}

impl FromIterator<Atom> for State {
    fn from_iter<I: IntoIterator<Item = Atom>>(iter: I) -> Self {
        State::from_atoms(iter)
    }
}

impl<'a> IntoIterator for &'a State {
    type Item = &'a Atom;
    type IntoIter = std::slice::Iter<'a, Atom>;
    fn into_iter(self) -> Self::IntoIter {
        self.atoms.iter()
    }
}

/// Prints the paper's state list: one `- (Atom ...)` line per atom, sorted by text, or
/// `None` for the empty state.
impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.atoms.is_empty() {
            return f.write_str("None");
        }
        for (i, atom) in self.sorted_by_text().into_iter().enumerate() {
            if i > 0 {
                f.write_str("\n")?;
            }
            write!(f, "- {atom}")?;
        }
        Ok(())
    }
}

impl fmt::Debug for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.sorted_by_text()).finish()
    }
}

/// Serialised as a JSON array of atom strings sorted by text, e.g. `["(GripperOpen)"]`.
impl serde::Serialize for State {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.sorted_by_text())
    }
}

impl<'de> serde::Deserialize<'de> for State {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let atoms = Vec::<Atom>::deserialize(deserializer)?;
        Ok(State::from_atoms(atoms))
    }
}

/// The change between two states: atoms that became true and atoms that became false.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct StateDiff {
    /// Atoms true after but not before.
    pub added: Vec<Atom>,
    /// Atoms true before but not after.
    pub removed: Vec<Atom>,
}

impl StateDiff {
    /// True if nothing changed.
    pub fn is_empty(&self) -> bool {
        self.added.is_empty() && self.removed.is_empty()
    }
}

/// Prints the authors' diff form: `(+) (Atom)` lines, then `(-) (Atom)` lines, each
/// group sorted by text; `None` when nothing changed.
impl fmt::Display for StateDiff {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("None");
        }
        let mut lines: Vec<String> = Vec::new();
        let mut added: Vec<String> = self.added.iter().map(|a| a.to_string()).collect();
        let mut removed: Vec<String> = self.removed.iter().map(|a| a.to_string()).collect();
        added.sort();
        removed.sort();
        lines.extend(added.into_iter().map(|a| format!("(+) {a}")));
        lines.extend(removed.into_iter().map(|a| format!("(-) {a}")));
        f.write_str(&lines.join("\n"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn atom(s: &str) -> Atom {
        s.parse().unwrap()
    }

    #[test]
    fn set_semantics() {
        let mut s = State::from_atoms([
            atom("(GripperOpen)"),
            atom("(OnTopOf a b)"),
            atom("(GripperOpen)"),
        ]);
        assert_eq!(s.len(), 2);
        assert!(s.contains(&atom("(OnTopOf a b)")));
        assert!(!s.insert(atom("(GripperOpen)")));
        assert!(s.remove(&atom("(GripperOpen)")));
        assert!(!s.contains(&atom("(GripperOpen)")));
        assert!(!s.remove(&atom("(GripperOpen)")));
    }

    #[test]
    fn prints_paper_format_sorted() {
        let s = State::from_atoms([
            atom("(OnTopOf b floor)"),
            atom("(Closed hinge_lid)"),
            atom("(GripperOpen)"),
        ]);
        assert_eq!(
            s.to_string(),
            "- (Closed hinge_lid)\n- (GripperOpen)\n- (OnTopOf b floor)"
        );
        assert_eq!(State::new().to_string(), "None");
    }

    #[test]
    fn with_changes_deletes_then_adds() {
        let s = State::from_atoms([atom("(A)"), atom("(B)"), atom("(C)")]);
        let mut dels = vec![atom("(B)"), atom("(C)")];
        let mut adds = vec![atom("(C)"), atom("(D)")];
        dels.sort();
        adds.sort();
        let next = s.with_changes(&dels, &adds);
        assert_eq!(next, State::from_atoms([atom("(A)"), atom("(C)"), atom("(D)")]));
    }

    #[test]
    fn diff_and_json() {
        let a = State::from_atoms([atom("(GripperOpen)"), atom("(GripperSurrounding x)")]);
        let b = State::from_atoms([atom("(GripperClosed)"), atom("(GripperHolding x)")]);
        let d = a.diff(&b);
        assert_eq!(
            d.to_string(),
            "(+) (GripperClosed)\n(+) (GripperHolding x)\n(-) (GripperOpen)\n(-) (GripperSurrounding x)"
        );
        let json = serde_json::to_string(&a).unwrap();
        assert_eq!(json, r#"["(GripperOpen)","(GripperSurrounding x)"]"#);
        assert_eq!(serde_json::from_str::<State>(&json).unwrap(), a);
    }
}
