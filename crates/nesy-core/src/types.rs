//! Object types and the typed universe that quantifiers range over.
//!
//! Every object has a type; `thing` is the root and the default. A [`TypeHierarchy`] holds
//! declared subtypes (`cube - thing`, `red_cube_kind - cube`), and a [`Universe`] is the
//! finite set of typed objects of one scene or problem. `forall`/`exists` over a type range
//! over the objects whose type is that type or one of its subtypes; a quantifier over a
//! type the hierarchy does not know is a [`TypeError::UnknownType`], never vacuous truth.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::symbol::Symbol;

/// The name of the root type.
pub const ROOT_TYPE: &str = "thing";

/// PDDL's name for the root type; accepted as an alias of [`ROOT_TYPE`].
pub const PDDL_ROOT_TYPE: &str = "object";

/// [`ROOT_TYPE`] and [`PDDL_ROOT_TYPE`] interned once: type checks run for every object a
/// quantifier ranges over.
static ROOT_SYMBOLS: std::sync::LazyLock<(Symbol, Symbol)> =
    std::sync::LazyLock::new(|| (Symbol::new(ROOT_TYPE), Symbol::new(PDDL_ROOT_TYPE)));

fn root_symbol() -> Symbol {
    ROOT_SYMBOLS.0
}

/// Errors about types and objects.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum TypeError {
    /// A quantifier, parameter or object names a type that was never declared.
    #[error("unknown type `{name}` (declared types: {known})")]
    UnknownType {
        /// The type name as written.
        name: String,
        /// The declared types, comma-separated.
        known: String,
    },
    /// A type was declared as its own ancestor.
    #[error("type `{name}` is declared as a subtype of itself (cycle through {via})")]
    Cycle {
        /// The type.
        name: String,
        /// The parent that closes the cycle.
        via: String,
    },
    /// An object was given two different types.
    #[error("object `{object}` is declared both as `{first}` and as `{second}`")]
    ConflictingObjectType {
        /// The object.
        object: String,
        /// Its first type.
        first: String,
        /// Its second type.
        second: String,
    },
}

/// Declared types and their parents. `thing` (alias `object`) is always present.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TypeHierarchy {
    /// Each declared type and its parent; the root has none.
    parents: BTreeMap<Symbol, Option<Symbol>>,
}

impl Default for TypeHierarchy {
    fn default() -> Self {
        let mut parents = BTreeMap::new();
        parents.insert(Symbol::new(ROOT_TYPE), None);
        TypeHierarchy { parents }
    }
}

impl TypeHierarchy {
    /// The hierarchy with only the root type.
    pub fn new() -> Self {
        Self::default()
    }

    /// Canonical symbol of a type name: `object` means the root.
    pub fn canonical(name: Symbol) -> Symbol {
        if name == ROOT_SYMBOLS.1 {
            root_symbol()
        } else {
            name
        }
    }

    /// Declares `name` as a subtype of `parent` (declaring the parent as a child of the root
    /// if it is new). Redeclaring a type moves it under the new parent.
    pub fn declare(&mut self, name: Symbol, parent: Symbol) -> Result<(), TypeError> {
        let name = Self::canonical(name);
        let parent = Self::canonical(parent);
        if name.as_str() == ROOT_TYPE {
            return Ok(());
        }
        self.parents
            .entry(parent)
            .or_insert_with(|| Some(Symbol::new(ROOT_TYPE)));
        // Reject cycles: walking up from the parent must not reach `name`.
        let mut cursor = Some(parent);
        while let Some(t) = cursor {
            if t == name {
                return Err(TypeError::Cycle {
                    name: name.to_string(),
                    via: parent.to_string(),
                });
            }
            cursor = self.parents.get(&t).copied().flatten();
        }
        self.parents.insert(name, Some(parent));
        Ok(())
    }

    /// True if the type is declared.
    pub fn contains(&self, name: Symbol) -> bool {
        self.parents.contains_key(&Self::canonical(name))
    }

    /// Checks that a type is declared.
    pub fn check(&self, name: Symbol) -> Result<Symbol, TypeError> {
        let canonical = Self::canonical(name);
        if self.parents.contains_key(&canonical) {
            Ok(canonical)
        } else {
            Err(TypeError::UnknownType {
                name: name.to_string(),
                known: self.known_list(),
            })
        }
    }

    /// True if `sub` is `sup` or a (transitive) subtype of it.
    pub fn is_subtype(&self, sub: Symbol, sup: Symbol) -> bool {
        let sup = Self::canonical(sup);
        let mut cursor = Some(Self::canonical(sub));
        while let Some(t) = cursor {
            if t == sup {
                return true;
            }
            cursor = self.parents.get(&t).copied().flatten();
        }
        false
    }

    /// Declared types with their parents, sorted by name.
    pub fn declared(&self) -> Vec<(Symbol, Option<Symbol>)> {
        let mut v: Vec<_> = self.parents.iter().map(|(k, v)| (*k, *v)).collect();
        v.sort_by_key(|(k, _)| k.as_str());
        v
    }

    fn known_list(&self) -> String {
        let mut names: Vec<&str> = self.parents.keys().map(|k| k.as_str()).collect();
        names.sort_unstable();
        names.join(", ")
    }
}

/// A finite set of typed objects: what quantifiers range over.
///
/// Objects keep insertion order, so grounding a quantifier is deterministic.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Universe {
    /// The type hierarchy.
    pub types: TypeHierarchy,
    objects: Vec<(Symbol, Symbol)>,
}

impl Universe {
    /// An empty universe with only the root type.
    pub fn new() -> Self {
        Self::default()
    }

    /// A universe of the given objects, all of type `thing`.
    pub fn of_things(objects: impl IntoIterator<Item = Symbol>) -> Self {
        let mut u = Universe::new();
        for o in objects {
            u.add_thing(o);
        }
        u
    }

    /// Adds an object of type `thing` unless it is already present (with any type).
    pub fn add_thing(&mut self, object: Symbol) {
        if self.type_of(object).is_none() {
            self.objects.push((object, root_symbol()));
        }
    }

    /// Adds a typed object. Adding the same object twice with the same type is a no-op;
    /// with another type it is an error.
    pub fn add(&mut self, object: Symbol, ty: Symbol) -> Result<(), TypeError> {
        let ty = self.types.check(ty)?;
        match self.type_of(object) {
            Some(existing) if existing == ty => Ok(()),
            Some(existing) => Err(TypeError::ConflictingObjectType {
                object: object.to_string(),
                first: existing.to_string(),
                second: ty.to_string(),
            }),
            None => {
                self.objects.push((object, ty));
                Ok(())
            }
        }
    }

    /// The type of an object, if it is in the universe.
    pub fn type_of(&self, object: Symbol) -> Option<Symbol> {
        self.objects.iter().find(|(o, _)| *o == object).map(|(_, t)| *t)
    }

    /// True if the object is present.
    pub fn contains(&self, object: Symbol) -> bool {
        self.type_of(object).is_some()
    }

    /// All objects with their types, in insertion order.
    pub fn objects(&self) -> &[(Symbol, Symbol)] {
        &self.objects
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// True if there are no objects.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// The objects of type `ty` or a subtype, in insertion order. Unknown types are errors.
    pub fn objects_of(&self, ty: Symbol) -> Result<Vec<Symbol>, TypeError> {
        let ty = self.types.check(ty)?;
        Ok(self
            .objects
            .iter()
            .filter(|(_, t)| self.types.is_subtype(*t, ty))
            .map(|(o, _)| *o)
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(x: &str) -> Symbol {
        Symbol::new(x)
    }

    #[test]
    fn hierarchy_and_objects() {
        let mut u = Universe::new();
        u.types.declare(s("fruit"), s("thing")).unwrap();
        u.types.declare(s("citrus"), s("fruit")).unwrap();
        u.add(s("orange"), s("citrus")).unwrap();
        u.add(s("apple"), s("fruit")).unwrap();
        u.add_thing(s("floor"));
        assert_eq!(u.objects_of(s("fruit")).unwrap(), vec![s("orange"), s("apple")]);
        assert_eq!(u.objects_of(s("thing")).unwrap().len(), 3);
        assert_eq!(u.objects_of(s("object")).unwrap().len(), 3);
        assert!(matches!(
            u.objects_of(s("vegetable")),
            Err(TypeError::UnknownType { .. })
        ));
        assert!(u.add(s("orange"), s("fruit")).is_err());
        assert!(u.types.declare(s("fruit"), s("citrus")).is_err());
    }
}
