//! Ground atoms such as `(OnTopOf red_cube floor)` or `(GripperOpen)`.
//!
//! Atoms are hash-consed: every distinct `(predicate, arguments)` pair is stored once in a
//! process-wide table and an [`Atom`] is just its dense `u32` id. Atoms are therefore
//! `Copy`, four bytes wide, compare and hash without touching memory, and a
//! [`crate::State`] of two hundred atoms clones with one 800-byte `memcpy`. The predicate
//! and arguments are found through a lock-free, append-only slot table. The table only
//! grows; its size is bounded by the number of distinct atoms a process ever builds.

use std::fmt;
use std::str::FromStr;
use std::sync::{LazyLock, OnceLock, RwLock};

use rustc_hash::FxHashMap;
use smallvec::SmallVec;

use crate::symbol::Symbol;

/// Argument list of an atom. Up to three arguments live inline (every predicate of the
/// paper has arity ≤ 2); longer PDDL predicates spill to the heap.
pub type Args = SmallVec<[Symbol; 3]>;

/// The interned data behind an atom.
#[derive(Debug)]
struct AtomData {
    pred: Symbol,
    args: Args,
    /// The printed form, `(Pred a b)`, built once at interning: printing, and sorting by
    /// text (every human-facing output), then never allocate or resolve symbols.
    text: Box<str>,
}

type AtomKey = (Symbol, Args);

/// Key → id; taken for writing only when a new atom is created.
static ATOMS: LazyLock<RwLock<FxHashMap<AtomKey, u32>>> = LazyLock::new(|| RwLock::new(FxHashMap::default()));

/// Id → data, in segments of doubling size (segment k holds `64 << k` slots), so that
/// reading never takes a lock and no slot ever moves.
const SEGMENTS: usize = 27;
type Segment = Box<[OnceLock<&'static AtomData>]>;
static SLOTS: [OnceLock<Segment>; SEGMENTS] = [const { OnceLock::new() }; SEGMENTS];

/// Segment and offset of an id in a table of segments of doubling size (`64 << k`).
pub(crate) fn locate(id: u32) -> (usize, usize) {
    let n = u64::from(id) / 64 + 1;
    let k = 63 - n.leading_zeros() as usize;
    let start = 64 * ((1u64 << k) - 1);
    (k, (u64::from(id) - start) as usize)
}

/// Slots of the per-thread memo in front of the shared table (a power of two).
const MEMO_SLOTS: usize = 4096;

/// One memo slot: predicate and up to three argument indices, the arity plus one (0 marks
/// an empty slot) and the atom's id.
#[derive(Clone, Copy)]
struct MemoSlot {
    key: [u32; 4],
    arity: u32,
    id: u32,
}

thread_local! {
    /// Grounding interns the same atoms over and over (every quantifier instance, every
    /// verification); a direct-mapped memo answers those without the shared table's lock
    /// and hash probe. Ids never change once handed out, so a slot can never be stale.
    static MEMO: std::cell::RefCell<Box<[MemoSlot]>> = std::cell::RefCell::new(
        vec![MemoSlot { key: [0; 4], arity: 0, id: 0 }; MEMO_SLOTS].into_boxed_slice()
    );
}

fn intern(pred: Symbol, args: Args) -> u32 {
    intern_slice(pred, &args)
}

/// [`intern`] from borrowed arguments: the argument list is copied only when the shared
/// table has to be consulted.
fn intern_slice(pred: Symbol, args: &[Symbol]) -> u32 {
    if args.len() > 3 {
        return intern_shared(pred, args.iter().copied().collect());
    }
    let mut key = [pred.index(), 0, 0, 0];
    for (k, a) in key[1..].iter_mut().zip(args) {
        *k = a.index();
    }
    let arity = args.len() as u32 + 1;
    let hash = key.iter().chain(std::iter::once(&arity)).fold(0u64, |h, &x| {
        (h.rotate_left(5) ^ u64::from(x)).wrapping_mul(0x517c_c1b7_2722_0a95)
    });
    let slot = (hash >> 52) as usize % MEMO_SLOTS;
    MEMO.with_borrow_mut(|memo| {
        let entry = &mut memo[slot];
        if entry.arity == arity && entry.key == key {
            return entry.id;
        }
        let id = intern_shared(pred, args.iter().copied().collect());
        *entry = MemoSlot { key, arity, id };
        id
    })
}

/// Looks up or creates the id of `(pred, args)` in the process-wide table.
fn intern_shared(pred: Symbol, args: Args) -> u32 {
    let key = (pred, args);
    if let Some(&id) = ATOMS.read().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return id;
    }
    let mut table = ATOMS.write().unwrap_or_else(|e| e.into_inner());
    if let Some(&id) = table.get(&key) {
        return id;
    }
    let id = u32::try_from(table.len()).expect("more than 2^32 distinct atoms");
    // Leaked on purpose: the table lives for the whole process and hands out `'static`
    // references.
    let mut text = String::with_capacity(32);
    text.push('(');
    text.push_str(key.0.as_str());
    for a in &key.1 {
        text.push(' ');
        text.push_str(a.as_str());
    }
    text.push(')');
    let data: &'static AtomData = Box::leak(Box::new(AtomData {
        pred: key.0,
        args: key.1.clone(),
        text: text.into_boxed_str(),
    }));
    let (k, offset) = locate(id);
    let segment = SLOTS[k].get_or_init(|| (0..(64usize << k)).map(|_| OnceLock::new()).collect());
    // Ids are handed out once, under the write lock, so the slot is still empty.
    let _ = segment[offset].set(data);
    table.insert(key, id);
    id
}

/// A ground atom: a predicate applied to object constants.
///
/// `Ord` is by interned id (fast, deterministic for a given interning order); printing code
/// sorts by text where humans read the result.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Atom(u32);

impl Atom {
    /// Builds an atom from a predicate name and argument names, interning them.
    pub fn new(pred: &str, args: &[&str]) -> Self {
        Atom(intern(
            Symbol::new(pred),
            args.iter().map(|a| Symbol::new(a)).collect(),
        ))
    }

    /// Builds an atom from already interned symbols.
    pub fn from_symbols(pred: Symbol, args: impl IntoIterator<Item = Symbol>) -> Self {
        Atom(intern(pred, args.into_iter().collect()))
    }

    /// [`Atom::from_symbols`] from a slice (grounding's hot path: no argument list is built
    /// when the atom is already known to this thread).
    pub(crate) fn from_slice(pred: Symbol, args: &[Symbol]) -> Self {
        Atom(intern_slice(pred, args))
    }

    fn data(self) -> &'static AtomData {
        let (k, offset) = locate(self.0);
        SLOTS[k]
            .get()
            .and_then(|segment| segment[offset].get().copied())
            .expect("an Atom's id always comes from the table, which filled its slot first")
    }

    /// The predicate.
    pub fn pred(&self) -> Symbol {
        self.data().pred
    }

    /// The arguments, in order.
    pub fn args(&self) -> &[Symbol] {
        &self.data().args
    }

    /// Number of arguments.
    pub fn arity(&self) -> usize {
        self.data().args.len()
    }

    /// True if any argument is `object`.
    pub fn mentions(&self, object: Symbol) -> bool {
        self.data().args.contains(&object)
    }

    /// The printed form, `(Pred a b)` (what `Display` writes), without allocating.
    pub fn text(&self) -> &'static str {
        &self.data().text
    }

    /// The dense interned id (stable for the life of the process).
    pub fn id(&self) -> u32 {
        self.0
    }
}

impl fmt::Display for Atom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.text())
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
                column: s.len() - s.trim_start().len() + text[..offset].chars().count() + 1,
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
    fn slot_layout_covers_ids_without_gaps() {
        let (mut segment, mut offset) = (0, 0);
        for id in 0..100_000u32 {
            assert_eq!(locate(id), (segment, offset), "id {id}");
            offset += 1;
            if offset == 64 << segment {
                segment += 1;
                offset = 0;
            }
        }
        let (k, offset) = locate(u32::MAX);
        assert!(k < SEGMENTS && offset < 64 << k);
    }

    #[test]
    fn interning_gives_identity() {
        let a = Atom::new("OnTopOf", &["x", "y"]);
        let b = Atom::from_symbols(Symbol::new("OnTopOf"), [Symbol::new("x"), Symbol::new("y")]);
        assert_eq!(a, b);
        assert_eq!(a.id(), b.id());
        assert_ne!(a, Atom::new("OnTopOf", &["y", "x"]));
        assert_eq!(a.arity(), 2);
        assert!(a.mentions(Symbol::new("y")));
    }

    #[test]
    fn memo_collisions_keep_identity() {
        // Far more atoms than memo slots, of every arity the memo covers and one it does
        // not, interned twice in different orders and from another thread.
        let keys: Vec<(String, Vec<String>)> = (0..12_000)
            .map(|i| {
                let args = (0..i % 5).map(|j| format!("memo_o{}", (i + j) % 97)).collect();
                (format!("MemoP{}", i % 41), args)
            })
            .collect();
        let build = |(p, args): &(String, Vec<String>)| {
            Atom::new(p, &args.iter().map(String::as_str).collect::<Vec<_>>())
        };
        let first: Vec<Atom> = keys.iter().map(build).collect();
        for (key, atom) in keys.iter().zip(&first).rev() {
            assert_eq!(build(key), *atom);
            assert_eq!(atom.pred().as_str(), key.0);
            assert_eq!(atom.args().len(), key.1.len());
        }
        let again = std::thread::scope(|s| s.spawn(|| keys.iter().map(build).collect::<Vec<_>>()).join());
        assert_eq!(again.unwrap(), first);
        assert_ne!(first[0], first[41]);
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
