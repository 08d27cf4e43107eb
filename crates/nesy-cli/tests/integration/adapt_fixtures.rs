//! The fixture demos of `fixtures/demos/`, replayed from cassettes recorded through the real
//! request path with the offline reference responder:
//!
//! ```text
//! nesy adapt --demo fixtures/demos/NAME --target fixtures/demos/NAME/target.json \
//!            --vlm oracle --record fixtures/cassettes/adapt-NAME.json --execute
//! ```
//!
//! Each replay (through the `nesy` binary, with `--execute`) must give a verified world
//! model, the expected first violation, a verified adapted procedure and `full_success` for
//! every subtask in the sandbox.

use crate::common;

use serde_json::{Value, json};

struct Case {
    name: &'static str,
    /// The first violation identification finds: step (0-based), action, unmet literals.
    step: usize,
    action: &'static str,
    unmet: &'static [&'static str],
}

const CASES: &[Case] = &[
    // The target stacks a cube on the red cube: it cannot be approached from above.
    Case {
        name: "pick_place_obst_0to1_finger",
        step: 4,
        action: "MoveToSurroundRedCube",
        unmet: &["(forall (?y - thing) (not (OnTopOf ?y red_cube)))"],
    },
    // The target robot has a vacuum tool: the finger-gripper actions do not apply.
    Case {
        name: "pick_place_grip_finger_to_vacuum",
        step: 0,
        action: "MoveToSurroundPurpleCube",
        unmet: &["(FingerGripper)", "(GripperOpen)"],
    },
    // The target's hinge lid is closed (with a fruit on it): carrying over the box needs it open.
    Case {
        name: "put_in_hinge_obst_0to2_finger",
        step: 2,
        action: "CarryOverHingeBodyLemon",
        unmet: &["(Open hinge_lid)"],
    },
    // Three subtasks; the first violation is the closed bottom drawer (then a stacked cube and a
    // piece in the wrong box follow).
    Case {
        name: "composite_medium",
        step: 2,
        action: "CarryOverBottomDrawerRedCylinder",
        unmet: &["(Open bottom_drawer)"],
    },
];

fn replay(case: &Case) {
    replay_with(case, &[]);
}

fn replay_with(case: &Case, extra: &[&str]) {
    let out = common::scratch();
    let demo = format!("fixtures/demos/{}", case.name);
    let args: Vec<String> = [
        "adapt",
        "--demo",
        &demo,
        "--target",
        &format!("{demo}/target.json"),
        "--vlm",
        &format!("replay:fixtures/cassettes/adapt-{}.json", case.name),
        "--execute",
        "--json",
        "--out",
        &out.path().display().to_string(),
    ]
    .iter()
    .chain(extra)
    .map(|s| s.to_string())
    .collect();
    let output = common::nesy(&args);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}:\n{stdout}\n{stderr}",
        case.name
    );
    let summary: Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["status"], "succeeded");

    let read = |file: &str| -> Value {
        serde_json::from_str(&std::fs::read_to_string(out.path().join(file)).unwrap()).unwrap()
    };
    assert_eq!(read("world_model.json")["verified"], true, "{}", case.name);
    let adaptation = read("adaptation.json");
    assert_eq!(adaptation["status"], "adapted");
    // The adapted procedure verifies from the target's initial state and reaches the goal.
    let report = &adaptation["outcome"]["report"];
    assert!(report["first_failure"].is_null(), "{}: {report}", case.name);
    assert_eq!(report["goal"]["satisfied"], true, "{}", case.name);
    let first = &adaptation["violations"][0];
    assert_eq!(first["kind"], "precondition", "{}", case.name);
    assert_eq!(first["step"], case.step, "{}: {first}", case.name);
    assert_eq!(first["action"], case.action, "{}: {first}", case.name);
    assert_eq!(first["unmet"], json!(case.unmet), "{}: {first}", case.name);

    let execution = read("execution.json");
    let subtasks = execution["metrics"]["subtasks"].as_array().unwrap();
    assert!(!subtasks.is_empty());
    for s in subtasks {
        assert_eq!(s["status"], "full_success", "{}: {s}", case.name);
    }
    assert_eq!(execution["metrics"]["sr"], 1.0);
}

#[test]
fn pick_place_with_a_stacked_cube() {
    replay(&CASES[0]);
}

#[test]
fn finger_gripper_demo_to_a_vacuum_robot() {
    replay(&CASES[1]);
}

#[test]
fn hinge_box_with_a_closed_lid() {
    replay(&CASES[2]);
}

#[test]
fn medium_composite() {
    replay(&CASES[3]);
}

#[test]
fn the_template_compiler_also_reaches_full_success() {
    // The same adaptation, compiled by nesy-sim's template compiler instead of the model's
    // code generation (the recorded code-generation call goes unused).
    replay_with(&CASES[0], &["--codegen", "template"]);
}

#[test]
fn states_translated_by_the_model_from_the_marked_views() {
    // `--states vlm`: every keyframe and the target go through the State Translation prompt
    // (recorded with the oracle, which answers from ground truth, so F1 is 1).
    let out = common::scratch();
    let name = CASES[0].name;
    let demo = format!("fixtures/demos/{name}");
    let args: Vec<String> = [
        "adapt",
        "--demo",
        &demo,
        "--target",
        &format!("{demo}/target.json"),
        "--vlm",
        &format!("replay:fixtures/cassettes/adapt-{name}-states-vlm.json"),
        "--states",
        "vlm",
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
    assert_eq!(
        output.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let summary: Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["states"]["source"], "vlm");
    assert_eq!(summary["states"]["translated"], 14);
    assert_eq!(summary["states"]["agreement"]["f1"], 1.0);
    // The counts behind F1 1.0: every predicted atom true, every expressible atom predicted.
    let counts: Vec<u64> = serde_json::from_value(summary["states"]["agreement"]["counts"].clone()).unwrap();
    assert!(
        counts[0] > 0 && counts.iter().all(|&n| n == counts[0]),
        "{counts:?}"
    );
    assert_eq!(summary["usage"]["by_purpose"]["translate"]["calls"], 14);
    assert_eq!(summary["status"], "succeeded");
}
