//! # nesy-core
//!
//! The symbolic half of NeSyCR: interned symbols, ground atoms and states, typed objects,
//! the predicate vocabulary, formulas and operators, the forward executor Φ, the text
//! formats the VLM and the prompts exchange, SEARCH/REPLACE patches, a classical planner,
//! the adaptation loop (the paper's Algorithm 1) and the benchmark metrics.
//!
//! This crate is pure: no IO, no async runtime, no physics. See `README.md` next to this
//! crate's `Cargo.toml` for the file formats, the design decisions and measured figures.

pub mod adapt;
pub mod atom;
pub mod benchmark;
pub mod embodiment;
pub mod exec;
pub mod formula;
mod indexed;
pub mod metrics;
pub mod operator;
pub mod patch;
pub mod pddl;
pub mod planner;
pub mod predicates;
pub mod rng;
pub mod state;
pub mod symbol;
pub mod text;
pub mod types;

pub use atom::Atom;
pub use embodiment::Embodiment;
pub use exec::{
    ExecError, Report, UnmetPrecondition, Violation, apply, apply_in, verify_procedure, verify_procedure_in,
};
pub use formula::{Effect, Formula, Term, TypedVar};
pub use operator::{CompiledOperator, Operator, format_procedure};
pub use patch::{Patch, PatchError, apply_patch};
pub use predicates::{Category, Tier, Vocabulary};
pub use state::{State, StateDiff};
pub use symbol::Symbol;
pub use text::{ParseError, ParseErrorKind};
pub use types::{TypeHierarchy, Universe};
