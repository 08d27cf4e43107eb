//! The model client: the client and its transports, cassettes and configuration, against
//! an in-process mock server.
//!
//! One test binary per crate: every file here is a module of it, so the crate and its
//! dependencies are linked once. Run one file's tests with
//! `cargo test -p nesy-vlm --test integration <file>::`.

mod cassette;
mod client;
mod fixtures;
mod server_fit;
mod transport;
