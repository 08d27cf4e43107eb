//! The `nesy` binary driven as a user would: adapt, run, bench, scenarios and verify,
//! on the bundled fixtures, cassettes and a local mock server.
//!
//! One test binary per crate: every file here is a module of it, so the crate and its
//! dependencies are linked once. Run one file's tests with
//! `cargo test -p nesy-cli --test integration <file>::`.

mod common;

mod adapt_cli;
mod adapt_drift;
mod adapt_fixtures;
mod adapt_live;
mod adapt_realstyle;
mod adapt_task_files;
mod bench_baselines;
mod bench_cli;
mod camera_target;
mod cassette_cli;
mod demo_import;
mod execution_recording;
mod real_model;
mod robot_bridge;
mod run_cli;
mod scenarios_cli;
mod serve_cli;
mod task_cli;
mod verify;
