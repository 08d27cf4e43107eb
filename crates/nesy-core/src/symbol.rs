//! Interned symbols: object, predicate, type and action names.
//!
//! Every name is interned once in a process-wide table, so symbols are `Copy`, compare
//! and hash as a `u32`, and resolve back to a `&'static str` without locking.

use std::fmt;
use std::sync::{LazyLock, OnceLock};

use lasso::{Key, Spur, ThreadedRodeo};

/// Fx hashing: names are short and trusted enough that SipHash's DoS resistance buys
/// nothing here, while interning sits on every parser's hot path.
type Interner = ThreadedRodeo<Spur, rustc_hash::FxBuildHasher>;

static INTERNER: LazyLock<Interner> = LazyLock::new(|| ThreadedRodeo::with_hasher(rustc_hash::FxBuildHasher));

/// Key index → resolved text, filled on first resolution. `ThreadedRodeo::resolve` looks the
/// key up in a sharded, locked map; printing and sorting resolve names in hot loops, so the
/// answer is kept in an append-only slot table (segments of doubling size, as for atoms)
/// that is read without locking.
const TEXT_SEGMENTS: usize = 27;

/// At most this many names are remembered per thread (the interner itself is unbounded).
const RECENT_CAPACITY: usize = 1 << 16;

thread_local! {
    static RECENT: std::cell::RefCell<rustc_hash::FxHashMap<&'static str, Symbol>> =
        std::cell::RefCell::new(rustc_hash::FxHashMap::default());
}
type TextSegment = Box<[OnceLock<&'static str>]>;
static TEXTS: [OnceLock<TextSegment>; TEXT_SEGMENTS] = [const { OnceLock::new() }; TEXT_SEGMENTS];

/// An interned name.
///
/// `Ord` follows interning order, which is cheap and deterministic within a process but
/// not alphabetical; use [`Symbol::as_str`] when a human-facing order is needed.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Symbol(Spur);

impl Symbol {
    /// Interns `name` (or finds it if it was interned before).
    pub fn new(name: &str) -> Self {
        // Parsers intern every name they read; a per-thread map in front of the shared
        // interner answers repeated names without touching its locks.
        RECENT.with_borrow_mut(|recent| {
            if let Some(&sym) = recent.get(name) {
                return sym;
            }
            let sym = Symbol(INTERNER.get_or_intern(name));
            if recent.len() < RECENT_CAPACITY {
                recent.insert(sym.as_str(), sym);
            }
            sym
        })
    }

    /// The dense interned index (stable for the life of the process).
    pub(crate) fn index(self) -> u32 {
        self.0.into_usize() as u32
    }

    /// Returns the symbol for `name` only if it has been interned already.
    pub fn lookup(name: &str) -> Option<Self> {
        INTERNER.get(name).map(Symbol)
    }

    /// The interned text.
    pub fn as_str(self) -> &'static str {
        // The interner is a never-dropped static, so its strings live for the whole
        // process; `resolve` ties them to the borrow of the static, which is 'static.
        let rodeo: &'static Interner = &INTERNER;
        let (k, offset) = crate::atom::locate(self.0.into_usize() as u32);
        let segment = TEXTS[k].get_or_init(|| (0..(64usize << k)).map(|_| OnceLock::new()).collect());
        segment[offset].get_or_init(|| rodeo.resolve(&self.0))
    }
}

impl fmt::Display for Symbol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl fmt::Debug for Symbol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.as_str())
    }
}

impl From<&str> for Symbol {
    fn from(name: &str) -> Self {
        Symbol::new(name)
    }
}

impl serde::Serialize for Symbol {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

impl<'de> serde::Deserialize<'de> for Symbol {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = <std::borrow::Cow<'de, str>>::deserialize(deserializer)?;
        Ok(Symbol::new(&name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interning_is_idempotent_and_resolves() {
        let a = Symbol::new("red_cube");
        let b = Symbol::new("red_cube");
        assert_eq!(a, b);
        assert_eq!(a.as_str(), "red_cube");
        assert_ne!(a, Symbol::new("red_cube2"));
        assert_eq!(Symbol::lookup("red_cube"), Some(a));
    }

    #[test]
    fn serde_round_trip() {
        let s = Symbol::new("hinge_lid");
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(json, "\"hinge_lid\"");
        let back: Symbol = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);
    }
}
