//! Execution recordings: `nesy adapt --execute --render-every N` and `nesy run --render-every
//! N --out DIR` replay the policy's calls on a fresh copy of the scene and write
//! `execution.mcap` (a keyframe after every action, in the demo format) and `rollout.mp4`.

use crate::common;

use serde_json::Value;

const DEMO: &str = "fixtures/demos/adapt-realstyle";
const TARGET: &str = "fixtures/demos/adapt-realstyle/target.json";
const CASSETTE: &str = "replay:fixtures/cassettes/adapt-realstyle.json";

/// The frames of a video, as `nesy demo import --keyframes all --json` counts them.
fn video_frames(video: &std::path::Path) -> u64 {
    let out = common::scratch();
    let output = common::nesy(&[
        "demo".into(),
        "import".into(),
        video.display().to_string(),
        "--keyframes".into(),
        "every:1".into(),
        "--instruction".into(),
        "watch".into(),
        "--objects".into(),
        "robot".into(),
        "--json".into(),
        "--out".into(),
        out.path().join("imported").display().to_string(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let report: Value = serde_json::from_slice(&output.stdout).unwrap();
    report["frames"].as_u64().unwrap()
}

#[test]
fn an_executed_adaptation_leaves_its_recording_and_rollout() {
    let out = common::scratch();
    let (code, stdout, stderr) = common::adapt(
        DEMO.as_ref(),
        TARGET.as_ref(),
        CASSETTE,
        out.path(),
        &["--execute", "--render-every", "10"],
    );
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    assert!(stdout.contains("recording"), "{stdout}");
    assert!(!stdout.contains("diverged"), "{stdout}");
    let execution: Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("execution.json")).unwrap()).unwrap();
    let trace = execution["result"]["trace"].as_array().unwrap();
    let actions = trace
        .iter()
        .map(|e| serde_json::from_value::<nesy_sim::api::TraceEntry>(e.clone()).unwrap())
        .filter(|e| e.call.is_action() && e.result.is_ok())
        .count();
    let recording = nesy_sim::demo::read_mcap(&out.path().join("execution.mcap")).unwrap();
    assert_eq!(recording.keyframes.len(), actions + 1);
    assert!(
        recording
            .keyframes
            .iter()
            .skip(1)
            .all(|k| k.action.is_some() && k.state.is_some())
    );
    assert_eq!(recording.metadata.side.as_deref(), Some("execution"));
    // 10 frames a second of simulated time, from the first call to the end of the settle.
    let frames = video_frames(&out.path().join("rollout.mp4"));
    let seconds = recording.keyframes.last().unwrap().time;
    assert!(frames as f64 >= seconds * 10.0, "{frames} frames for {seconds} s");

    // The HTML report shows the demonstration, both procedures with the violation and the
    // patch marked, and the rollout beside it; it loads nothing from elsewhere.
    let html = std::fs::read_to_string(out.path().join("report.html")).unwrap();
    let demo = nesy_sim::demo::read(common::workspace().join(DEMO)).unwrap();
    assert_eq!(
        html.matches("<div class=\"card\"><h3>keyframe ").count(),
        demo.keyframes.len(),
        "one card per keyframe"
    );
    assert_eq!(
        html.matches("src=\"data:image/png;base64,").count(),
        demo.keyframes.len() + 3
    );
    assert!(
        html.contains("<video src=\"rollout.mp4\""),
        "the rollout is shown"
    );
    assert!(html.contains("OpenGripperToDropRedCylinderIntoBottomDrawer  ← first violated precondition"));
    assert!(html.contains("PullBottomDrawerOpen  ← added by a patch"));
    assert!(html.contains("<span class=\"ok\">verified</span>"));
    assert!(!html.contains("<script") && !html.contains("http://") && !html.contains("https://"));
}

#[test]
fn a_recording_needs_an_execution_and_a_whole_frame_rate() {
    let out = common::scratch();
    let (code, _, stderr) = common::adapt(
        DEMO.as_ref(),
        TARGET.as_ref(),
        CASSETTE,
        out.path(),
        &["--render-every", "10"],
    );
    assert_eq!(code, Some(2));
    assert!(
        stderr.contains("--render-every") && stderr.contains("--execute"),
        "{stderr}"
    );
    let (code, _, stderr) = common::adapt(
        DEMO.as_ref(),
        TARGET.as_ref(),
        CASSETTE,
        out.path(),
        &["--execute", "--render-every", "3"],
    );
    assert_eq!(code, Some(2));
    assert!(stderr.contains("must divide"), "{stderr}");
}

#[test]
fn nesy_run_records_into_its_out_folder_and_asks_for_one() {
    let dir = common::scratch();
    let policy = dir.path().join("policy.py");
    std::fs::write(&policy, "move_gripper_to(\"red_cube\")\nclose_gripper()\n").unwrap();
    let run = |extra: &[&str]| {
        let mut args: Vec<String> = [
            "run",
            "--scene",
            "fixtures/scenes/pick_place_finger.json",
            "--policy",
            &policy.display().to_string(),
            "--render-every",
            "20",
        ]
        .map(String::from)
        .to_vec();
        args.extend(extra.iter().map(|a| a.to_string()));
        common::nesy(&args)
    };
    let refused = run(&[]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--out"));
    let out = dir.path().join("recording");
    let recorded = run(&["--out", &out.display().to_string()]);
    let stdout = String::from_utf8_lossy(&recorded.stdout);
    assert!(
        recorded.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&recorded.stderr)
    );
    assert!(stdout.contains("5 fps"), "{stdout}");
    let recording = nesy_sim::demo::read_mcap(&out.join("execution.mcap")).unwrap();
    assert_eq!(recording.keyframes.len(), 3);
    assert!(video_frames(&out.join("rollout.mp4")) > 5);
}
