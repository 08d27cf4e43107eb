//! `nesy scenarios` and `nesy record` through the binary: the paper's Table 6 counts, the
//! written suite read back, the complexity-gap suite listed apart, a scene shown from either
//! source, a recorded demo read back, bad input named with its file, and a reader that closes
//! the pipe early.

use crate::common;

use std::io::Read;
use std::process::{Command, Stdio};

use nesy_sim::scene::SceneSpec;

/// The numbers of the table row that starts with `label`.
fn row(table: &str, label: &str) -> Vec<u32> {
    let line = table
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no row {label:?} in\n{table}"));
    line[label.len()..]
        .split_whitespace()
        .map(|n| n.parse().expect("a count"))
        .collect()
}

#[test]
fn list_prints_the_papers_table_6() {
    let (code, stdout, stderr) = common::run(&["scenarios", "list"]);
    assert_eq!(code, Some(0), "{stderr}");
    for factor in ["obst", "affo", "grip", "vacu"] {
        assert_eq!(row(&stdout, factor), [30, 30, 20, 80], "{factor}");
    }
    assert_eq!(row(&stdout, "comb"), [40, 40, 40, 120]);
    assert_eq!(row(&stdout, "Total scenarios"), [160, 160, 120, 440]);
}

#[test]
fn a_generated_suite_reads_back_to_the_same_scenarios() {
    let dir = common::scratch();
    let suite = dir.path().join("suite");
    let suite_arg = suite.to_str().unwrap();
    let (code, stdout, stderr) = common::run(&["scenarios", "generate", "--out", suite_arg]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(stdout.lines().count(), 15, "{stdout}");
    assert_eq!(std::fs::read_dir(&suite).unwrap().count(), 15);

    let (_, generated, _) = common::run(&["scenarios", "list", "--ids"]);
    let (code, read_back, stderr) = common::run(&["scenarios", "list", "--ids", "--suite", suite_arg]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(read_back, generated);
    assert_eq!(read_back.lines().count(), 440);

    for side in ["source", "target"] {
        let (code, shown, stderr) = common::run(&["scenarios", "show", "grip_medium_03_s1", "--side", side]);
        assert_eq!(code, Some(0), "{stderr}");
        let (_, from_suite, _) = common::run(&[
            "scenarios",
            "show",
            "grip_medium_03_s1",
            "--side",
            side,
            "--suite",
            suite_arg,
        ]);
        assert_eq!(shown, from_suite, "{side}");
        let scene = SceneSpec::from_json_str(&shown, side).expect("a valid scene.json");
        assert!(!scene.goals.is_empty(), "{side}: the scene carries its goals");
    }
}

/// A folder of complexity-gap files lists its 80 scenarios by added subtasks, labelled as
/// outside the 440, and none of them under a Table 6 row; their ids read back.
#[test]
fn a_gap_suite_lists_by_added_subtasks_not_under_table_6() {
    let dir = common::scratch();
    let suite = dir.path().join("gap");
    let suite_arg = suite.to_str().unwrap();
    let (code, stdout, stderr) = common::run(&["scenarios", "generate", "--gap", "--out", suite_arg]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(stdout.lines().count(), 4, "{stdout}");
    let (code, table, stderr) = common::run(&["scenarios", "list", "--suite", suite_arg]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(table.contains("not part of the 440"), "{table}");
    for added in 0..4 {
        assert_eq!(row(&table, &format!("+{added} ")), [20], "{table}");
    }
    assert_eq!(row(&table, "Total gap scenarios"), [80]);
    assert!(
        !table.contains("Total scenarios") && !table.contains("obst "),
        "{table}"
    );
    let (code, ids, stderr) = common::run(&["scenarios", "list", "--ids", "--suite", suite_arg]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(ids.lines().count(), 80);
    assert!(ids.lines().all(|id| id.starts_with("gap_obst_plus")), "{ids}");
}

#[test]
fn bad_input_names_the_file_or_the_id() {
    let dir = common::scratch();
    let suite = dir.path().join("suite");
    let suite_arg = suite.to_str().unwrap();
    assert_eq!(
        common::run(&["scenarios", "generate", "--out", suite_arg]).0,
        Some(0)
    );
    let broken = suite.join("obst_low.json");
    std::fs::write(&broken, "{\n  \"factor\": \"obst\",\n  \"complexity\": \n}\n").unwrap();
    let (code, _, stderr) = common::run(&["scenarios", "list", "--suite", suite_arg]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("obst_low.json") && stderr.contains("line 4"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");

    let (code, _, stderr) = common::run(&["scenarios", "show", "obst_low_99_s7"]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("obst_low_99_s7"), "{stderr}");
    let (code, _, stderr) = common::run(&["record", "--scenario", "nope", "--out", suite_arg]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("\"nope\""), "{stderr}");
}

#[test]
fn record_writes_a_demo_that_reads_back_and_the_target_scene() {
    let dir = common::scratch();
    let out = dir.path().join("demo");
    let id = "obst_low_00_s0";
    let (code, _, stderr) = common::run(&[
        "record",
        "--scenario",
        id,
        "--out",
        out.to_str().unwrap(),
        "--size",
        "32",
        "--threads",
        "1",
    ]);
    assert_eq!(code, Some(0), "the expert completes the source side: {stderr}");
    let demo = nesy_sim::demo::read(out.join("demo.mcap")).expect("the recorded demo reads back");
    assert_eq!(demo.metadata.scenario_id.as_deref(), Some(id));
    assert!(demo.keyframes.len() > 2, "{} keyframes", demo.keyframes.len());
    assert!(demo.keyframes[0].action.is_none());
    for keyframe in &demo.keyframes[1..] {
        let action = keyframe
            .action
            .as_ref()
            .expect("every later keyframe follows an action");
        assert!(action.call.is_action() && action.result.is_ok());
        assert!(keyframe.state.is_some());
    }

    let (_, shown, _) = common::run(&["scenarios", "show", id, "--side", "target"]);
    let written = std::fs::read_to_string(out.join("target.json")).unwrap();
    assert_eq!(
        SceneSpec::from_json_str(&written, "target.json").unwrap(),
        SceneSpec::from_json_str(&shown, "shown").unwrap()
    );
}

/// The real-world tasks' families are found by id without a suite folder: `nesy record`
/// demonstrates one with the scripted expert and `scenarios show` prints its scenes.
#[test]
fn a_family_scenario_is_recorded_and_shown_by_its_id() {
    let dir = common::scratch();
    let out = dir.path().join("demo");
    let id = "family_drawers_01_s1";
    let (code, stdout, stderr) = common::run(&[
        "record",
        "--scenario",
        id,
        "--out",
        out.to_str().unwrap(),
        "--size",
        "32",
        "--threads",
        "1",
    ]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    let said = format!("{stdout}{stderr}");
    assert!(
        said.contains("put_in_prismatic: full_success, put_in_prismatic: full_success"),
        "{said}"
    );
    let demo = nesy_sim::demo::read(out.join("demo.mcap")).unwrap();
    assert_eq!(demo.metadata.scenario_id.as_deref(), Some(id));
    let (code, shown, stderr) = common::run(&["scenarios", "show", id, "--side", "target"]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(shown.contains("side_drawer_body"), "{shown}");
    let (code, _, stderr) = common::run(&["scenarios", "show", "family_nope_00_s0"]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("family_<name>_<NN>_s<seed>"), "{stderr}");
}

#[test]
fn a_reader_that_stops_early_ends_the_command_quietly() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_nesy"))
        .args(["scenarios", "list", "--ids"])
        .current_dir(common::workspace())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Closing the read end before the 440 ids are written makes the writes fail.
    drop(child.stdout.take());
    let mut stderr = String::new();
    child.stderr.take().unwrap().read_to_string(&mut stderr).unwrap();
    let status = child.wait().unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        matches!(status.code(), Some(0) | Some(141)),
        "{status:?}: {stderr}"
    );
}
