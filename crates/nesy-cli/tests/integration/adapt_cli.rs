//! `nesy adapt` on bad input and on an unresolved adaptation: clear errors naming the file
//! and field (exit 2), an explicit `unresolved` status with no policy (exit 1).

use crate::common;

use serde_json::Value;

const DEMO: &str = "fixtures/demos/adapt-realstyle";
const TARGET: &str = "fixtures/demos/adapt-realstyle/target.json";
const CASSETTE: &str = "replay:fixtures/cassettes/adapt-realstyle.json";

fn adapt(extra: &[&str], out: &std::path::Path) -> (Option<i32>, String, String) {
    let mut args: Vec<String> = vec!["adapt".into(), "--out".into(), out.display().to_string()];
    args.extend(extra.iter().map(|s| s.to_string()));
    let output = common::nesy(&args);
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn a_missing_demo_is_named() {
    let out = common::scratch();
    let (code, _, stderr) = adapt(
        &[
            "--demo",
            "fixtures/demos/no-such-demo",
            "--target",
            TARGET,
            "--vlm",
            CASSETTE,
        ],
        out.path(),
    );
    assert_eq!(code, Some(2));
    assert!(stderr.contains("fixtures/demos/no-such-demo"), "{stderr}");
}

#[test]
fn a_bad_target_names_the_file_and_the_field() {
    let out = common::scratch();
    let target = out.path().join("bad-target.json");
    let mut scene: Value =
        serde_json::from_str(&std::fs::read_to_string(common::workspace().join(TARGET)).unwrap()).unwrap();
    scene["objects"][1]["kind"] = Value::String("sphere".into());
    std::fs::write(&target, serde_json::to_string_pretty(&scene).unwrap()).unwrap();
    let (code, _, stderr) = adapt(
        &[
            "--demo",
            DEMO,
            "--target",
            &target.display().to_string(),
            "--vlm",
            CASSETTE,
        ],
        out.path(),
    );
    assert_eq!(code, Some(2));
    assert!(stderr.contains("bad-target.json"), "{stderr}");
    assert!(stderr.contains("objects[1].kind"), "{stderr}");
}

#[test]
fn a_missing_cassette_is_named() {
    let out = common::scratch();
    let (code, _, stderr) = adapt(
        &[
            "--demo",
            DEMO,
            "--target",
            TARGET,
            "--vlm",
            "replay:fixtures/cassettes/nothing-here.json",
        ],
        out.path(),
    );
    assert_eq!(code, Some(2));
    assert!(
        stderr.contains("fixtures/cassettes/nothing-here.json"),
        "{stderr}"
    );
    assert!(stderr.contains("cassette not found"), "{stderr}");
}

#[test]
fn a_cassette_miss_names_the_request() {
    // The demo's own scene as the target: no violation, so the code-generation request
    // (other action names) was never recorded.
    let out = common::scratch();
    let (code, _, stderr) = adapt(
        &[
            "--demo",
            DEMO,
            "--target",
            "fixtures/scenes/drawer_finger.json",
            "--vlm",
            CASSETTE,
        ],
        out.path(),
    );
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("cassette miss"), "{stderr}");
    assert!(stderr.contains("purpose codegen"), "{stderr}");
}

#[test]
fn an_exhausted_budget_is_unresolved_and_ships_no_policy() {
    let out = common::scratch();
    let (code, stdout, stderr) = adapt(
        &[
            "--demo",
            DEMO,
            "--target",
            TARGET,
            "--vlm",
            CASSETTE,
            "--budget",
            "1",
            "--execute",
            "--json",
        ],
        out.path(),
    );
    assert_eq!(code, Some(1), "{stdout}\n{stderr}");
    let summary: Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["status"], "unresolved");
    assert!(!out.path().join("policy.py").exists());
    assert!(!out.path().join("execution.json").exists());
    let procedure = std::fs::read_to_string(out.path().join("procedure.txt")).unwrap();
    assert!(
        procedure.contains("# UNRESOLVED after 1 proposal(s)"),
        "{procedure}"
    );
    let adaptation: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("adaptation.json")).unwrap()).unwrap();
    assert_eq!(adaptation["status"], "unresolved");
    assert_eq!(adaptation["proposals"][0]["verdict"], "rejected");
}

#[test]
fn a_replay_writes_the_usage_report_the_environment_asks_for() {
    let out = common::scratch();
    let report = out.path().join("usage.json");
    let args: Vec<String> = [
        "adapt",
        "--out",
        &out.path().join("run").display().to_string(),
        "--demo",
        DEMO,
        "--target",
        TARGET,
        "--vlm",
        CASSETTE,
    ]
    .map(String::from)
    .to_vec();
    let output = common::nesy_with_env(&args, &[("NESY_CASSETTE_USAGE", &report.display().to_string())]);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let usage: Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("usage report")).unwrap();
    assert!(!usage["used"].as_array().unwrap().is_empty(), "{usage}");
    assert!(
        usage["cassette"]
            .as_str()
            .unwrap()
            .ends_with("adapt-realstyle.json"),
        "{usage}"
    );
}

#[test]
fn a_run_that_stops_before_an_outcome_leaves_failure_json() {
    // Another demo's cassette: the first induction request is a miss.
    let out = common::scratch();
    let (code, _, stderr) = adapt(
        &[
            "--demo",
            DEMO,
            "--target",
            TARGET,
            "--vlm",
            "replay:fixtures/cassettes/adapt-composite_medium.json",
        ],
        out.path(),
    );
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("failure.json records why"), "{stderr}");
    let failure: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("failure.json")).unwrap()).unwrap();
    assert_eq!(failure["status"], "failed");
    assert_eq!(failure["failure"], "replay");
    assert!(
        failure["error"]
            .as_str()
            .unwrap()
            .contains("operator induction for transition 1"),
        "{failure}"
    );
    assert!(out.path().join("target_scene.json").is_file());
}
