//! The VLM layer: the client and transports, cassettes, prompts, the reasoner, the
//! fixtures and the offline reference responder on simulated scenes.
//!
//! One test binary per crate: every file here is a module of it, so the crate and its
//! dependencies are linked once. Run one file's tests with
//! `cargo test -p nesy-vlm --test integration <file>::`.

mod common;
mod oracle_common;

mod cassette;
mod client;
mod examples;
mod fixtures;
mod oracle_adapt;
mod oracle_codegen;
mod oracle_domain;
mod prompts;
mod reasoner;
mod transport;
