//! The benchmark harness through its library entry points, in this process: one scenario
//! with NeSyCR under the offline reference responder and the two model-free controls,
//! resumed, and reported. Policies run in the sandbox, and this binary is its own worker.
//!
//! A test binary with its own `main` (`harness = false`), since the sandbox re-executes the
//! running binary as its worker: `cargo test -p nesy-bench --test in_process`.

use std::path::Path;
use std::process::ExitCode;
use std::sync::Arc;

use nesy_bench::harness::{Quiet, ResponderSetup, RunConfig, RunSummary, StopSignal, final_records};
use nesy_bench::manifest::{Observation, RunSettings};
use nesy_bench::methods::parse_variants;
use nesy_bench::report::{ReportOptions, write};
use nesy_bench::{Selection, UnitStatus};

fn main() -> ExitCode {
    nesy_testkit::run_tests_or_worker(&[
        (
            "a_run_records_every_unit_resumes_with_nothing_left_and_reports",
            run_resume_report,
        ),
        (
            "an_unresolved_unit_keeps_its_symbolic_seconds",
            unresolved_symbolic_seconds,
        ),
    ])
}

/// The scenario: a pick-and-place with one obstruction at low complexity, which NeSyCR
/// adapts under the offline responder.
const SCENARIO: &str = "obst_low_00_s0";

fn config(run_dir: &Path, demos: &Path) -> RunConfig {
    RunConfig {
        run_dir: run_dir.to_owned(),
        variants: parse_variants("nesycr,imitation,replan").unwrap(),
        study: None,
        selection: Selection::parse(SCENARIO),
        suite_dir: None,
        repeats: 1,
        run_seed: 0,
        responder: ResponderSetup::Oracle,
        demo_cache: demos.to_owned(),
        settings: RunSettings {
            keep_gapped_demos: false,
            image_size: 64,
            policy_wall_ms: 120_000,
            max_calls_per_unit: None,
            observation: Observation::Images,
            protective_stop: false,
        },
        shard: "0/1".parse().unwrap(),
        jobs: 2,
        cpu_jobs: 2,
        model_jobs: 8,
        max_cost_usd: None,
        max_error_rate: None,
        worker: nesy_testkit::own_worker(),
        record_cassettes: false,
        record_executions: false,
        reexecute: None,
    }
}

fn run(config: RunConfig) -> RunSummary {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap()
        .block_on(nesy_bench::harness::run(
            config,
            Arc::new(Quiet),
            StopSignal::default(),
        ))
        .expect("the run completes")
}

fn run_resume_report() {
    let dir = tempfile::tempdir().unwrap();
    let (run_dir, demos) = (dir.path().join("run"), dir.path().join("demos"));

    let first = run(config(&run_dir, &demos));
    assert_eq!(
        (first.shard_units, first.ran, first.skipped),
        (3, 3, 0),
        "{first:?}"
    );
    let records = final_records(&run_dir).unwrap();
    assert_eq!(records.len(), 3);
    let nesycr = records
        .values()
        .find(|r| r.key.variant == "nesycr")
        .expect("NeSyCR's unit");
    assert_eq!(nesycr.status, UnitStatus::Succeeded, "{nesycr:?}");
    assert!(records.values().all(|r| r.status.is_final()));

    // Running the same configuration again finds every unit final and runs none.
    let again = run(config(&run_dir, &demos));
    assert_eq!((again.ran, again.skipped), (0, 3), "{again:?}");

    let files = write(&run_dir, &ReportOptions::default()).unwrap();
    let report = std::fs::read_to_string(&files.report).unwrap();
    assert!(report.contains("NeSyCR"), "{report}");
    assert!(run_dir.join("tables/table1.csv").is_file());
}

/// NeSyCR with one refinement round on a scenario that needs two ends unresolved; its
/// record still carries the symbolic time its world model and identification took.
fn unresolved_symbolic_seconds() {
    let dir = tempfile::tempdir().unwrap();
    let (run_dir, demos) = (dir.path().join("run"), dir.path().join("demos"));
    let mut unresolved = config(&run_dir, &demos);
    unresolved.variants = parse_variants("nesycr+budget=1").unwrap();
    run(unresolved);
    let records = final_records(&run_dir).unwrap();
    let record = records.values().next().expect("the unit's record");
    assert_eq!(record.status, UnitStatus::Unresolved, "{record:?}");
    let time = &record.effort.time;
    assert!(time.symbolic_s > 0.0, "{time:?}");
    assert!(time.symbolic_world_model_s > 0.0, "{time:?}");
    assert!(time.symbolic_world_model_s <= time.symbolic_s, "{time:?}");
}
