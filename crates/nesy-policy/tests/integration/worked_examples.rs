//! The worked examples of `policies/` run in the embedded interpreter against the real
//! simulator (nesy-sim) on both embodiments, and move the robot: the observed symbolic state
//! after the post-run settle shows the task done.

use std::path::PathBuf;

use nesy_core::Embodiment;
use nesy_policy::{EpisodeFactory, EpisodeSpec, Limits, Outcome, SimEpisodes, run_in_process};

fn root() -> PathBuf {
    nesy_testkit::workspace_root()
}

fn run_example(policy: &str, scene: &str, embodiment: Embodiment, expected: &[&str]) {
    let source = std::fs::read_to_string(root().join("crates/nesy-policy/policies").join(policy)).unwrap();
    let spec = EpisodeSpec::Scene {
        path: root().join("fixtures/scenes").join(scene),
        embodiment: Some(embodiment),
    };
    let episode = SimEpisodes.build(&spec).unwrap();
    let result = run_in_process(&source, episode, &Limits::default(), None).unwrap();
    assert_eq!(
        result.outcome,
        Outcome::Ok,
        "{policy} on {embodiment}: {:#?}\n{}",
        result.outcome,
        result.stdout.text
    );
    assert!(
        result.trace.iter().all(|e| e.result.is_ok()),
        "{policy} on {embodiment}: a call was refused"
    );
    let state = result.final_state.expect("the simulator reports its state");
    let text = state.to_string();
    for atom in expected {
        assert!(
            text.contains(atom),
            "{policy} on {embodiment}: missing {atom} in\n{text}"
        );
    }
}

#[test]
fn pick_place_finger() {
    run_example(
        "pick_place.py",
        "pick_place_finger.json",
        Embodiment::Finger,
        &[
            "(InsideOf green_cube toy_box)",
            "(InsideOf red_cube toy_box)",
            "(InsideOf blue_cube toy_box)",
        ],
    );
}

#[test]
fn pick_place_vacuum() {
    run_example(
        "pick_place.py",
        "pick_place_vacuum.json",
        Embodiment::Vacuum,
        &[
            "(InsideOf green_cube toy_box)",
            "(InsideOf red_cube toy_box)",
            "(InsideOf blue_cube toy_box)",
        ],
    );
}

#[test]
fn drawer_finger() {
    run_example(
        "drawer.py",
        "drawer_finger.json",
        Embodiment::Finger,
        &["(Closed bottom_drawer)", "(InsideOf red_cylinder bottom_drawer)"],
    );
}

#[test]
fn drawer_vacuum() {
    run_example(
        "drawer.py",
        "drawer_vacuum.json",
        Embodiment::Vacuum,
        &["(Closed bottom_drawer)", "(InsideOf red_cylinder bottom_drawer)"],
    );
}

#[test]
fn hinge_finger() {
    run_example(
        "hinge.py",
        "hinge_finger.json",
        Embodiment::Finger,
        &["(Closed hinge_lid)", "(InsideOf apple hinge_body)"],
    );
}

#[test]
fn hinge_vacuum() {
    run_example(
        "hinge.py",
        "hinge_vacuum.json",
        Embodiment::Vacuum,
        &["(Closed hinge_lid)", "(InsideOf apple hinge_body)"],
    );
}

#[test]
fn sweep_finger() {
    run_example(
        "sweep.py",
        "sweep_finger.json",
        Embodiment::Finger,
        &[
            "(InsideOf white_rook left_chess_box)",
            "(InsideOf black_bishop right_chess_box)",
        ],
    );
}

#[test]
fn sweep_vacuum() {
    run_example(
        "sweep.py",
        "sweep_vacuum.json",
        Embodiment::Vacuum,
        &[
            "(InsideOf white_rook left_chess_box)",
            "(InsideOf black_bishop right_chess_box)",
        ],
    );
}
