//! The policy runtime: the embedded interpreter, the worker's seccomp filter, the paper's
//! worked example policies and the standard-library zip of static builds.
//!
//! One test binary per crate: every file here is a module of it, so the crate and its
//! dependencies are linked once. Run one file's tests with
//! `cargo test -p nesy-policy --test integration <file>::`.

mod runtime;
mod seccomp;
mod stdlib_zip;
mod worked_examples;
