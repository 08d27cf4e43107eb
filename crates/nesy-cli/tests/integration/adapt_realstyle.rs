//! The hand-written cassette in real-model style (`fixtures/cassettes/adapt-realstyle.json`):
//! replies with prose, odd bullets, a wrong operator the verifier rejects, a patch whose
//! SEARCH does not match, a code block with an explanation. The pipeline must recover,
//! produce a verified procedure and a policy that succeeds in the simulator.
//!
//! Regenerate (after a prompt or demo-format change) with
//! `cargo test -p nesy-cli --test integration adapt_realstyle:: -- --ignored`.

use crate::common;

use std::sync::Arc;

use nesy_pipeline::vlm::{VlmSetup, VlmSource};
use nesy_pipeline::{self as pipeline, AdaptOptions, DemoInput, NoProgress, TargetInput};
use nesy_policy::WorkerCommand;
use nesy_vlm::{BackendKind, VlmConfig};
use serde_json::Value;

const DEMO_DIR: &str = "fixtures/demos/adapt-realstyle";
const CASSETTE: &str = "fixtures/cassettes/adapt-realstyle.json";

/// The fixture's client: a model in prose, so no reply is held to a JSON schema (the
/// cassette says `constrain: off`, and its replays send none either).
fn unconstrained() -> VlmConfig {
    let mut config = VlmConfig::new(BackendKind::OpenAi, common::realstyle::MODEL);
    config.defaults.constrain = nesy_vlm::ConstrainMode::Off;
    config
}

#[test]
#[ignore = "regenerates the committed demo and cassette"]
fn record_realstyle_fixture() {
    let root = common::workspace();
    let demo_path = root.join(DEMO_DIR).join("demo.mcap");
    common::record_demo(&root.join("fixtures/scenes/drawer_finger.json"), &demo_path, 384);
    let cassette = root.join(CASSETTE);
    let _ = std::fs::remove_file(&cassette);
    let demo = DemoInput::load(&demo_path, &nesy_core::Vocabulary::new()).unwrap();
    let target = TargetInput::load(Some(&root.join(DEMO_DIR).join("target.json")), &demo).unwrap();
    let out = common::scratch();
    let options = AdaptOptions {
        out_dir: out.path().to_owned(),
        worker: Some(WorkerCommand::nesy_binary(env!("CARGO_BIN_EXE_nesy"))),
        execute: true,
        ..AdaptOptions::default()
    };
    let setup = VlmSetup {
        source: VlmSource::Transport {
            config: Box::new(unconstrained()),
            transport: Arc::new(common::realstyle::HandWritten),
        },
        record: Some(cassette),
    };
    let client = pipeline::vlm::build_client(&setup, &demo).unwrap();
    let runtime = tokio::runtime::Runtime::new().unwrap();
    let run = runtime
        .block_on(pipeline::run(
            &demo,
            &target,
            client,
            &options,
            Arc::new(NoProgress),
        ))
        .unwrap();
    pipeline::output::RunDir::create(&run.out_dir)
        .unwrap()
        .write_all(&run, &target)
        .unwrap();
    assert!(run.adapted().is_some(), "{:?}", run.adaptation.outcome);
}

#[test]
fn realstyle_cassette_replays_recovers_and_succeeds() {
    let out = common::scratch();
    let args: Vec<String> = [
        "adapt",
        "--demo",
        DEMO_DIR,
        "--target",
        &format!("{DEMO_DIR}/target.json"),
        "--vlm",
        &format!("replay:{CASSETTE}"),
        "--execute",
        "--json",
        "--out",
        &out.path().display().to_string(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let output = common::nesy(&args);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let summary: Value = serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{e}\n{stdout}\n{stderr}"));

    // World model: the grasp operator that forgot an effect was rejected, then re-predicted.
    let adaptation: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("adaptation.json")).unwrap()).unwrap();
    let inductions = adaptation["inductions"].as_array().unwrap();
    let rejected: Vec<&Value> = inductions.iter().filter(|i| i["verdict"] == "rejected").collect();
    assert_eq!(rejected.len(), 1, "{inductions:#?}");
    assert_eq!(rejected[0]["step"], 1);
    assert!(
        rejected[0]["feedback"]
            .as_str()
            .unwrap()
            .contains("GripperSurrounding red_cylinder"),
        "{}",
        rejected[0]["feedback"]
    );
    let world: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("world_model.json")).unwrap()).unwrap();
    assert_eq!(world["verified"], true);

    // Identification: the drop needs the (closed) bottom drawer open.
    let violations = adaptation["violations"].as_array().unwrap();
    assert_eq!(violations[0]["kind"], "precondition");
    assert_eq!(violations[0]["step"], 3);
    assert_eq!(
        violations[0]["action"],
        "OpenGripperToDropRedCylinderIntoBottomDrawer"
    );
    assert_eq!(
        violations[0]["unmet"],
        serde_json::json!(["(Open bottom_drawer)"])
    );
    // Exploration: the misquoted SEARCH is rejected, the corrected patch accepted.
    let proposals = adaptation["proposals"].as_array().unwrap();
    assert_eq!(proposals.len(), 2);
    assert_eq!(proposals[0]["verdict"], "rejected");
    assert!(
        proposals[0]["feedback"]
            .as_str()
            .unwrap()
            .to_lowercase()
            .contains("match")
    );
    assert_eq!(proposals[1]["verdict"], "accepted");
    assert_eq!(adaptation["status"], "adapted");

    let procedure = std::fs::read_to_string(out.path().join("procedure.txt")).unwrap();
    assert!(
        procedure.contains("# Adapted procedure (12 actions"),
        "{procedure}"
    );
    assert!(procedure.contains("PullBottomDrawerOpen"));

    // The code block was taken from between the prose; the policy succeeded.
    let policy = std::fs::read_to_string(out.path().join("policy.py")).unwrap();
    assert!(policy.starts_with("# The bottom drawer slides out"), "{policy}");
    assert!(!policy.contains("Explanation"));
    assert_eq!(summary["status"], "succeeded", "{stdout}\n{stderr}");
    assert_eq!(output.status.code(), Some(0));
    let execution: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("execution.json")).unwrap()).unwrap();
    assert_eq!(
        execution["metrics"]["subtasks"][0]["status"], "full_success",
        "{execution:#}"
    );
}
