//! # nesy-core
//!
//! The symbolic half of NeSyCR: interned symbols, ground atoms and states, typed objects,
//! the predicate vocabulary, formulas and operators, the forward executor Φ, the text
//! formats the VLM and the prompts exchange, SEARCH/REPLACE patches, a classical planner,
//! the adaptation loop (the paper's Algorithm 1) and the benchmark metrics.
//!
//! This crate is pure: no IO, no async runtime, no physics. See `README.md` next to this
//! crate's `Cargo.toml` for the file formats, the design decisions and measured figures.
//!
//! A state in the paper's list format, an operator in its action-block format, and the
//! executor checking the operator's preconditions before applying its effects:
//!
//! ```
//! use nesy_core::text::{parse_action_block, parse_state_list};
//!
//! let state = parse_state_list("- (OnTopOf red_cube floor)\n- (GripperOpen)").unwrap();
//! let grasp = parse_action_block(
//!     "GraspRedCube\n- Preconditions:\n\t(GripperOpen)\n- Effects:\n\t(GripperHolding red_cube)\n\t(not (GripperOpen))",
//! )
//! .unwrap();
//! let after = nesy_core::apply(&state, &grasp).unwrap();
//! assert!(after.to_string().contains("(GripperHolding red_cube)"));
//! assert!(!after.to_string().contains("(GripperOpen)"));
//! // Applied again, the precondition no longer holds: the executor says which literal.
//! assert!(nesy_core::apply(&after, &grasp).is_err());
//! ```

pub mod adapt;
mod atom;
pub mod benchmark;
mod embodiment;
mod exec;
mod formula;
mod indexed;
pub mod metrics;
mod operator;
mod patch;
pub mod pddl;
pub mod planner;
mod predicates;
pub mod rng;
mod state;
mod symbol;
pub mod text;
mod types;
mod vocabulary_file;

pub use atom::{Args, Atom, AtomParseError};
pub use embodiment::Embodiment;
pub use exec::{
    CompiledProcedure, ExecError, GoalCheck, Report, StepOutcome, StepStatus, UnmetPrecondition, Violation,
    apply, apply_in, check_goal, format_unmet, implicit_universe, verify_procedure, verify_procedure_in,
};
pub use formula::{
    AtomPattern, AtomTruth, Bindings, ConditionalEffect, Effect, Formula, Ground, GroundEffects, GroundError,
    Term, TypedVar, fmt_typed_vars,
};
pub use operator::{CompiledOperator, Operator, format_procedure};
pub use patch::{ActionKey, AppliedPatch, ClosestCandidate, Patch, PatchError, apply_patch};
pub use predicates::{
    Category, KindInfo, PredicateInfo, Tier, Vocabulary, VocabularyError, builtin_predicates,
};
pub use state::{State, StateDiff};
pub use symbol::Symbol;
pub use types::{PDDL_ROOT_TYPE, ROOT_TYPE, TypeError, TypeHierarchy, Universe};
pub use vocabulary_file::{
    MAX_PREDICATE_ARITY, VOCABULARY_FORMAT_VERSION, VocabularyFileError, parse_vocabulary_file,
};
