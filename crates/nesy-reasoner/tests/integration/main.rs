//! The reasoner: the prompts rendered against snapshots, the few-shot examples replayed in
//! the simulator, the fixtures, and `VlmReasoner` against scripted transports and a mock
//! server.
//!
//! One test binary per crate: every file here is a module of it, so the crate and its
//! dependencies are linked once. Run one file's tests with
//! `cargo test -p nesy-reasoner --test integration <file>::`.

mod scenario;

mod examples;

mod prompts;
mod reasoner;
