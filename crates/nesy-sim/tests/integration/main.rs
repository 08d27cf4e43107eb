//! The simulator end to end: the world's soundness, kinematics, experts, demos, tasks,
//! the scenario suite, schemas, determinism and refusals.
//!
//! One test binary per crate: every file here is a module of it, so the crate and its
//! dependencies are linked once. Run one file's tests with
//! `cargo test -p nesy-sim --test integration <file>::`.

mod common;

mod codegen_domain;
mod demo;
mod demo_goal;
mod determinism;
mod drawers_family;
mod experts;
mod furniture;
mod hook_family;
mod kinematics;
mod refusals;
mod scenarios;
mod scene_domain;
mod schema;
mod sweep_random;
mod tasks;
mod world_soundness;
