//! `nesy run` on policies that stop making progress: a Python spin and a C-level hang are
//! stopped at the idle limit, long before the wall-clock budget, and reported as a timeout.

use crate::common;

use std::time::{Duration, Instant};

use serde_json::Value;

/// `nesy run` of the policy file `policy` on the pick-and-place scene, with `extra` flags.
fn nesy_run(policy: &str, extra: &[&str]) -> std::process::Output {
    let mut args: Vec<String> = [
        "run",
        "--scene",
        "fixtures/scenes/pick_place_finger.json",
        "--policy",
        policy,
    ]
    .map(String::from)
    .to_vec();
    args.extend(extra.iter().map(|a| a.to_string()));
    common::nesy(&args)
}

/// Writes `source` as a policy file in a scratch directory (kept alive by the returned guard).
fn policy_file(source: &str) -> (tempfile::TempDir, String) {
    let dir = common::scratch();
    let path = dir.path().join("policy_under_test.py");
    std::fs::write(&path, source).unwrap();
    let path = path.display().to_string();
    (dir, path)
}

/// Runs `policy` on the pick-and-place scene with a 1 s idle limit and a 120 s wall clock;
/// returns the JSON result and how long the run took.
fn run_policy(policy: &str) -> (Value, Duration) {
    let (_dir, path) = policy_file(policy);
    let started = Instant::now();
    let output = nesy_run(&path, &["--idle-timeout", "1", "--json"]);
    let took = started.elapsed();
    assert_eq!(
        output.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    (serde_json::from_slice(&output.stdout).expect("JSON result"), took)
}

#[test]
fn a_policy_spinning_in_python_is_stopped_at_the_idle_limit() {
    let (result, took) = run_policy("get_obj_names()\nwhile True: pass\n");
    assert_eq!(result["outcome"]["kind"], "timeout", "{result}");
    assert_eq!(result["outcome"]["limit"], "idle", "{result}");
    assert_eq!(result["trace"].as_array().unwrap().len(), 1, "{result}");
    assert!(took < Duration::from_secs(20), "{took:?}");
}

#[test]
fn a_policy_hanging_in_c_is_killed_at_the_idle_limit() {
    // One big-integer power holds the interpreter lock for minutes; only the parent can stop it.
    let (result, took) = run_policy("get_obj_names()\nx = 7 ** (10 ** 9)\n");
    assert_eq!(result["outcome"]["kind"], "timeout", "{result}");
    assert_eq!(result["outcome"]["limit"], "idle", "{result}");
    // 1 s idle + 3 s grace, far under the 120 s wall clock.
    assert!(took < Duration::from_secs(20), "{took:?}");
}

#[test]
fn the_default_idle_limit_stops_a_spin_within_fifteen_seconds() {
    let limits = nesy_policy::Limits::default();
    assert!(limits.idle_ms + limits.kill_grace_ms <= 15_000, "{limits:?}");
}

#[test]
fn a_bad_idle_limit_names_its_flag() {
    let output = nesy_run(
        "fixtures/scenes/pick_place_finger.json",
        &["--idle-timeout", "NaN"],
    );
    assert_ne!(output.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--idle-timeout must be a positive number"),
        "{stderr}"
    );
}

#[test]
fn a_policy_the_static_checks_reject_is_bad_input() {
    let (_dir, path) = policy_file("import os\n");
    let output = nesy_run(&path, &[]);
    assert_eq!(
        output.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&output.stdout)
    );
    assert!(String::from_utf8_lossy(&output.stdout).contains("outcome: rejected"));
}

#[test]
fn findings_and_tracebacks_name_the_policy_file_as_given() {
    let (_dir, path) = policy_file("x = 1 +\n");
    let output = nesy_run(&path, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(2), "{stdout}");
    assert!(stdout.contains(&format!("{path}:1:")), "{stdout}");
    assert!(!stdout.contains("policy.py"), "{stdout}");

    let (_dir, path) = policy_file("open_gripper()\nraise ValueError('on purpose')\n");
    let output = nesy_run(&path, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains(&format!("File \"{path}\", line 2")), "{stdout}");
    assert!(!stdout.contains("policy.py"), "{stdout}");
}

#[test]
fn a_latin_1_policy_with_its_coding_line_runs() {
    let dir = common::scratch();
    let path = dir.path().join("latin.py");
    std::fs::write(&path, b"# -*- coding: latin-1 -*-\nprint('caf\xe9')\n").unwrap();
    let output = nesy_run(&path.display().to_string(), &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("café"), "{stdout}");
}

#[test]
fn a_policy_that_is_not_utf_8_is_bad_input_with_its_position() {
    let dir = common::scratch();
    let path = dir.path().join("bytes.py");
    std::fs::write(&path, b"open_gripper()\nx = '\xff'\n").unwrap();
    let output = nesy_run(&path.display().to_string(), &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bytes.py"), "{stderr}");
    assert!(stderr.contains("line 2, column 6 (byte offset 20)"), "{stderr}");
}

#[test]
fn a_policy_nested_too_deeply_is_rejected_with_a_message() {
    let (_dir, path) = policy_file(&format!("x = {}1\n", "-".repeat(100_000)));
    let output = nesy_run(&path, &[]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(2), "{stdout}");
    assert!(stdout.contains("nested too deeply"), "{stdout}");
}
