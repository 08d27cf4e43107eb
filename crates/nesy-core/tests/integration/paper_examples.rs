//! The paper's appendix examples parse and verify as the paper describes.

use nesy_core::text::{parse_action_block, parse_procedure, parse_state_list};
use nesy_core::{Atom, ExecError, State, apply};
use nesy_core::{StepStatus, verify_procedure};

fn atom(s: &str) -> Atom {
    s.parse().unwrap()
}

/// Identification example: the orange cannot be dropped into the hinge body while the lid
/// is closed; the violated precondition is `(not (Closed hinge_lid))`.
#[test]
fn orange_hinge_lid_identification() {
    let text = std::fs::read_to_string(
        nesy_testkit::workspace_root().join("fixtures/responses/procedure-hinge.txt"),
    )
    .unwrap();
    let procedure = parse_procedure(&text).unwrap();
    let counterfactual = parse_state_list(
        "- (Closed bottom_drawer)\n- (Closed hinge_lid)\n- (GripperOpen)\n- (OnTopOf orange floor)",
    )
    .unwrap();
    let report = verify_procedure(&counterfactual, &procedure, None);
    assert_eq!(report.first_failure, Some(3));
    let StepStatus::Failed { violation } = &report.steps[3].status else {
        panic!("{report:?}")
    };
    assert_eq!(violation.action, "OpenGripperToDropOrangeIntoHingeBody");
    assert_eq!(violation.to_string(), "- (not (Closed hinge_lid))");
    assert_eq!(violation.unmet[0].atoms.len(), 1);
    assert_eq!(violation.unmet[0].atoms[0].atom, atom("(Closed hinge_lid)"));
    assert!(violation.unmet[0].atoms[0].holds);
    // The state when the error occurred still has the lid closed and the orange held.
    let at_error = report.failing_state.as_ref().unwrap();
    assert!(
        at_error.contains(&atom("(GripperHolding orange)")) && at_error.contains(&atom("(Closed hinge_lid)"))
    );
}

/// The action operator example, written as the paper's figure writes it.
#[test]
fn move_gripper_to_surround_orange_with_forall() {
    let figure = "Name:\nMoveGripperToSurroundOrange\n\nPreconditions:\n- (GripperSurrounding orange)\n- (GripperOpen)\n- (forall (?y - thing)\n    (not (GripperHolding ?y))\n  )\n\nEffects:\n- (GripperClosed)\n- (GripperHolding orange)\n- (not (GripperOpen))\n- (not (GripperSurrounding orange))\n";
    let op = parse_action_block(figure).unwrap();
    assert_eq!(op.name, "MoveGripperToSurroundOrange");
    assert_eq!(
        op.pre[2].to_string(),
        "(forall (?y - thing) (not (GripperHolding ?y)))"
    );
    let s = State::from_atoms([
        atom("(GripperSurrounding orange)"),
        atom("(GripperOpen)"),
        atom("(OnTopOf orange floor)"),
    ]);
    let next = apply(&s, &op).unwrap();
    assert_eq!(
        next,
        State::from_atoms([
            atom("(GripperClosed)"),
            atom("(GripperHolding orange)"),
            atom("(OnTopOf orange floor)")
        ])
    );
    // Holding something else violates the forall; the atom that broke it is named.
    let holding = State::from_atoms([
        atom("(GripperSurrounding orange)"),
        atom("(GripperOpen)"),
        atom("(GripperHolding apple)"),
    ]);
    let Err(ExecError::Violation(v)) = apply(&holding, &op) else {
        panic!()
    };
    assert_eq!(v.to_string(), "- (forall (?y - thing) (not (GripperHolding ?y)))");
    assert_eq!(v.unmet[0].atoms.len(), 1);
    assert_eq!(v.unmet[0].atoms[0].atom, atom("(GripperHolding apple)"));
}

/// The real-world drawer example: nested not/and preconditions with the extra predicates
/// Finegrained and Gathered.
#[test]
fn magnetic_hook_nested_preconditions() {
    let grasp_screws = parse_action_block(
        "Grasp Black Screws\n- Preconditions:\n\t(GripperOpen)\n\t(not (and (Finegrained black_screws) (not (Gathered black_screws))))\n- Effects:\n\t(GripperHolding black_screws)\n\t(not (GripperOpen))",
    )
    .unwrap();
    assert_eq!(grasp_screws.name, "GraspBlackScrews");
    let scattered = State::from_atoms([atom("(GripperOpen)"), atom("(Finegrained black_screws)")]);
    let Err(ExecError::Violation(v)) = apply(&scattered, &grasp_screws) else {
        panic!()
    };
    assert_eq!(
        v.to_string(),
        "- (not (and (Finegrained black_screws) (not (Gathered black_screws))))"
    );
    let truths: Vec<(String, bool)> = v.unmet[0]
        .atoms
        .iter()
        .map(|t| (t.atom.to_string(), t.holds))
        .collect();
    assert_eq!(
        truths,
        vec![
            ("(Finegrained black_screws)".into(), true),
            ("(Gathered black_screws)".into(), false)
        ]
    );
    let gathered = State::from_atoms([
        atom("(GripperOpen)"),
        atom("(Finegrained black_screws)"),
        atom("(Gathered black_screws)"),
    ]);
    assert!(apply(&gathered, &grasp_screws).is_ok());

    let grasp_hook = parse_action_block(
        "GraspMagneticHook\n- Preconditions:\n  - (GripperOpen)\n  - (not (and (OnTopOf silver_screws magnetic_hook) (not (OnTopOf gold_screws bottom_drawer)) (not (OnTopOf bracket bottom_drawer))))\n- Effects:\n  - (GripperHolding magnetic_hook)",
    )
    .unwrap();
    let stacked = State::from_atoms([
        atom("(GripperOpen)"),
        atom("(OnTopOf silver_screws magnetic_hook)"),
    ]);
    let Err(ExecError::Violation(v)) = apply(&stacked, &grasp_hook) else {
        panic!()
    };
    assert_eq!(v.unmet.len(), 1);
    assert_eq!(v.unmet[0].atoms.len(), 3);

    let release = parse_action_block(
        "ReleaseMagneticHookIntoBottomDrawer\n- Preconditions:\n\t(GripperHolding magnetic_hook)\n\t(not (InsideOf magnetic_hook bottom_drawer))\n- Effects:\n\t(InsideOf magnetic_hook bottom_drawer)",
    )
    .unwrap();
    let already = State::from_atoms([
        atom("(GripperHolding magnetic_hook)"),
        atom("(InsideOf magnetic_hook bottom_drawer)"),
    ]);
    let Err(ExecError::Violation(v)) = apply(&already, &release) else {
        panic!()
    };
    assert_eq!(v.to_string(), "- (not (InsideOf magnetic_hook bottom_drawer))");
}

/// A quantifier over a type the universe does not know is an error, not vacuous truth.
#[test]
fn unknown_type_is_an_error() {
    let op = parse_action_block(
        "A\n- Preconditions:\n\t(forall (?f - fruit) (not (GripperHolding ?f)))\n- Effects:\n\t(B)",
    )
    .unwrap();
    assert!(matches!(apply(&State::new(), &op), Err(ExecError::Ground(_))));
}
