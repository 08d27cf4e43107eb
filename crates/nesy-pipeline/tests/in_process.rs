//! The pipeline through its library entry points, in this process: the bundled quick-start
//! demo adapted to its target under the offline reference responder, the policy executed in
//! the sandbox (this binary is its own worker), and the run directory written.
//!
//! A test binary with its own `main` (`harness = false`), since the sandbox re-executes the
//! running binary as its worker: `cargo test -p nesy-pipeline --test in_process`.

use std::process::ExitCode;
use std::sync::Arc;

use nesy_pipeline::vlm::{VlmSetup, VlmSource, build_client};
use nesy_pipeline::{AdaptOptions, DemoInput, NoProgress, RunStatus, TargetInput, output};

fn main() -> ExitCode {
    nesy_testkit::run_tests_or_worker(&[
        (
            "quick_start_demo_adapts_executes_and_writes_its_run_directory",
            quick_start,
        ),
        (
            "an_exhausted_budget_is_unresolved_and_compiles_nothing",
            exhausted_budget,
        ),
    ])
}

fn inputs() -> (DemoInput, TargetInput) {
    let dir = nesy_testkit::workspace_root().join("fixtures/demos/adapt-realstyle");
    let demo = DemoInput::load(&dir, &nesy_core::Vocabulary::new()).expect("the fixture demo loads");
    let target = TargetInput::load(Some(&dir.join("target.json")), &demo).expect("its target loads");
    (demo, target)
}

fn oracle_run(options: &AdaptOptions) -> (nesy_pipeline::AdaptRun, TargetInput) {
    let (demo, target) = inputs();
    let setup = VlmSetup {
        source: VlmSource::Oracle {
            noise: String::new(),
            seed: 0,
        },
        record: None,
    };
    let client = build_client(&setup, &demo).expect("the offline responder needs no network");
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("a runtime");
    let run = runtime
        .block_on(nesy_pipeline::run(
            &demo,
            &target,
            client,
            options,
            Arc::new(NoProgress),
        ))
        .expect("the run reaches an outcome");
    (run, target)
}

fn quick_start() {
    let out = tempfile::tempdir().unwrap();
    let options = AdaptOptions {
        execute: true,
        worker: Some(nesy_testkit::own_worker()),
        out_dir: out.path().to_owned(),
        ..AdaptOptions::default()
    };
    let (run, target) = oracle_run(&options);
    assert_eq!(run.status, RunStatus::Succeeded, "{:?}", run.adaptation.outcome);
    assert_eq!(run.exit_code(), 0);
    // The demonstration drops the cylinder into an open drawer; the target's drawer is
    // closed, so the adapted procedure is longer than the demonstrated one.
    assert!(run.adaptation.outcome.procedure().len() > run.demonstrated().len());
    let execution = run.execution.as_ref().expect("executed");
    let metrics = execution.metrics.as_ref().expect("the scene has goal checks");
    assert_eq!(metrics.sr, 1.0, "{:?}", execution.result.outcome);
    output::RunDir::create(out.path())
        .unwrap()
        .write_all(&run, &target)
        .unwrap();
    for file in [
        "world_model.json",
        "adaptation.json",
        "procedure.txt",
        "policy.py",
        "execution.json",
        "report.md",
    ] {
        assert!(out.path().join(file).is_file(), "{file} written");
    }
}

fn exhausted_budget() {
    let out = tempfile::tempdir().unwrap();
    let options = AdaptOptions {
        budget: Some(0),
        execute: true,
        worker: Some(nesy_testkit::own_worker()),
        out_dir: out.path().to_owned(),
        ..AdaptOptions::default()
    };
    let (run, _) = oracle_run(&options);
    assert_eq!(run.status, RunStatus::Unresolved);
    assert!(run.policy.is_none(), "an unresolved procedure is never compiled");
    assert!(run.execution.is_none(), "nothing runs");
    assert_eq!(run.exit_code(), 1);
}
