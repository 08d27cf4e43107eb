//! # nesy-core
//!
//! The symbolic half of NeSyCR: interned symbols, ground atoms and states, and (in the
//! modules built on top of them) formulas, operators, the forward executor, the text
//! formats, patches, a classical planner and the adaptation loop.
//!
//! This crate is pure: no IO, no async runtime, no physics.

pub mod atom;
pub mod state;
pub mod symbol;

pub use atom::Atom;
pub use state::State;
pub use symbol::Symbol;
