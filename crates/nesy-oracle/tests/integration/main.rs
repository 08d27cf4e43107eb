//! The offline reference responder on simulated scenes: every expert transition induced
//! from the true domain, the template compiler's programs, and whole adaptations through
//! the real client and reasoner, executed in the sandbox.
//!
//! One test binary per crate: every file here is a module of it. Run one file's tests with
//! `cargo test -p nesy-oracle --test integration <file>::`.

mod common;

mod adapt;
mod codegen;
mod domain;
