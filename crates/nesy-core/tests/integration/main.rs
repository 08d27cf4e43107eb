//! The symbolic core against its corpora: reference semantics, replayed adaptations,
//! malformed replies, the paper's worked examples, the planner and format round trips.
//!
//! One test binary per crate: every file here is a module of it, so the crate and its
//! dependencies are linked once. Run one file's tests with
//! `cargo test -p nesy-core --test integration <file>::`.

mod common;

mod adapt_corpus;
mod corpus;
mod garbage;
mod paper_examples;
mod planner_world;
mod reference;
mod roundtrip;
