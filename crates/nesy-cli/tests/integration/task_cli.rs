//! `nesy task new`: a task made from a hand-written pair of scenes, with no scripted expert,
//! and the reasons it refuses one.

use crate::common;

use std::path::Path;

use serde_json::Value;

/// `nesy task new --source S --target T --out OUT --size 64`: exit code, stdout, stderr.
fn task_new(source: &Path, target: &Path, out: &Path) -> (Option<i32>, String, String) {
    let (source, target, out) = (
        source.display().to_string(),
        target.display().to_string(),
        out.display().to_string(),
    );
    common::run(&[
        "task", "new", "--source", &source, "--target", &target, "--out", &out, "--size", "64",
    ])
}

/// The pick-and-place fixture scene with `edit` applied, written to `dir/name`.
fn edited_scene(dir: &Path, name: &str, edit: impl FnOnce(&mut Value)) -> std::path::PathBuf {
    let text =
        std::fs::read_to_string(common::workspace().join("fixtures/scenes/pick_place_finger.json")).unwrap();
    let mut scene: Value = serde_json::from_str(&text).unwrap();
    edit(&mut scene);
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string_pretty(&scene).unwrap()).unwrap();
    path
}

#[test]
fn a_task_from_a_hand_written_scene_pair_is_adapted_offline() {
    let root = common::workspace();
    let dir = common::scratch();
    let out = dir.path().join("cubes-to-suction");
    // The demonstration by the finger robot; the target asks the same of the vacuum robot.
    let (code, stdout, stderr) = task_new(
        &root.join("fixtures/scenes/pick_place_finger.json"),
        &root.join("fixtures/scenes/pick_place_vacuum.json"),
        &out,
    );
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    // The green cube sits on the blue one, so the plan cannot follow the goal's listed order.
    assert!(stdout.contains("pick_place: partial_success"), "{stdout}");
    assert!(stdout.contains("another order than it lists"), "{stdout}");
    for file in [
        "demo.mcap",
        "source.json",
        "target.json",
        "plan.txt",
        "policy.py",
        "task.json",
    ] {
        assert!(out.join(file).is_file(), "{file} missing: {stdout}");
    }
    let task: Value = serde_json::from_str(&std::fs::read_to_string(out.join("task.json")).unwrap()).unwrap();
    assert!(task["keyframes"].as_u64().unwrap() > 6, "{task}");
    assert_eq!(task["name"], "cubes-to-suction");

    // The recorded demo is a demonstration nesy adapts: the offline responder answers from
    // its recorded calls and states, and the adapted policy reaches the target's goal.
    let adapted = dir.path().join("adapted");
    let (code, stdout, stderr) = common::adapt(
        &out.join("demo.mcap"),
        &out.join("target.json"),
        "oracle",
        &adapted,
        &["--execute", "--codegen", "template"],
    );
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(stdout.starts_with("nesy adapt: SUCCEEDED"), "{stdout}");
    assert!(stdout.contains("SR 1"), "{stdout}");
}

#[test]
fn a_scene_without_goals_is_refused() {
    let dir = common::scratch();
    let source = edited_scene(dir.path(), "source.json", |scene| {
        scene["goals"] = Value::Array(Vec::new())
    });
    let target = common::workspace().join("fixtures/scenes/pick_place_finger.json");
    let (code, stdout, stderr) = task_new(&source, &target, &dir.path().join("out"));
    assert_eq!(code, Some(2), "{stdout}{stderr}");
    assert!(stderr.contains("the source scene has no `goals`"), "{stderr}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn a_goal_that_cannot_be_planned_is_refused_with_the_reason() {
    let dir = common::scratch();
    // Nothing in the true domain puts a cube inside another cube.
    let source = edited_scene(dir.path(), "source.json", |scene| {
        scene["goals"][0]["objects"] = serde_json::json!(["red_cube"]);
        scene["goals"][0]["container"] = Value::String("blue_cube".into());
    });
    let target = common::workspace().join("fixtures/scenes/pick_place_finger.json");
    let (code, stdout, stderr) = task_new(&source, &target, &dir.path().join("out"));
    assert_eq!(code, Some(2), "{stdout}{stderr}");
    assert!(
        stderr.contains("the source scene's goal cannot be planned from its initial state"),
        "{stderr}"
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn a_task_between_two_cabinets_is_adapted_to_cabinets_at_right_angles() {
    let root = common::workspace();
    let dir = common::scratch();
    let out = dir.path().join("two-cabinets");
    // The demonstration: two cabinets side by side, a cube for each one's bottom drawer. The
    // target: the cabinets at right angles (their bottom drawers open into each other's
    // way) and the blue cube stacked on the red one.
    let (code, stdout, stderr) = task_new(
        &root.join("fixtures/scenes/drawers_side_by_side_finger.json"),
        &root.join("fixtures/scenes/drawers_perpendicular_stacked_finger.json"),
        &out,
    );
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    let plan = std::fs::read_to_string(out.join("plan.txt")).unwrap();
    assert!(plan.contains("OpenSideBottomDrawer"), "{plan}");
    assert!(
        plan.contains(
            "(not (and (Blocks front_bottom_drawer side_bottom_drawer) (Open front_bottom_drawer)))"
        ),
        "opening one cabinet's drawer needs the other's in its way shut: {plan}"
    );

    let adapted = dir.path().join("adapted");
    let vocabulary = root.join("assets/vocabulary/blocking-drawers.toml");
    let (code, stdout, stderr) = common::adapt(
        &out.join("demo.mcap"),
        &out.join("target.json"),
        "oracle",
        &adapted,
        &[
            "--execute",
            "--codegen",
            "template",
            "--vocabulary",
            vocabulary.to_str().unwrap(),
        ],
    );
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(stdout.contains("MoveToSurroundRedCube: unmet"), "{stdout}");
    assert!(stdout.contains("SR 1"), "{stdout}");
}
