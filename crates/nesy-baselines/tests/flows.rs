//! Each baseline's whole flow against a scripted responder that answers by purpose: every
//! stage is called with the inputs the authors give it, the plan comes out of the last
//! reply, and a reply without its answer is a typed failure (authors) or re-asked (repaired).

use std::sync::Arc;

use nesy_baselines::{
    BaselineError, BaselineInputs, Fidelity, Keyframe, SceneObservation, SceneViews, critic, demo2code,
    gpt4v, llmdm, morevqa, statler,
};
use nesy_core::State;
use nesy_core::Vocabulary;
use nesy_reasoner::Views;
use nesy_testkit::{Scripted, TRUNCATED};
use nesy_vlm::{BackendKind, Image, VlmClient, VlmConfig, VlmError, WireRequest};
use serde_json::Value;

fn client(transport: Arc<Scripted>, max_images: Option<usize>) -> VlmClient {
    let mut config = VlmConfig::new(BackendKind::OpenAi, "gpt-5");
    config.base_url = "http://127.0.0.1:9".into();
    config.max_images_per_request = max_images;
    // One call at a time, so replies are taken in keyframe order.
    config.max_concurrency = 1;
    VlmClient::with_transport(&config, transport)
}

fn png(seed: u8) -> Image {
    Image::png(nesy_testkit::png(2, u64::from(seed))).unwrap()
}

fn six(seed: u8) -> SceneViews {
    let views = |s: u8| Views::new([("top", png(s)), ("front", png(s + 1)), ("back", png(s + 2))]);
    SceneViews {
        raw: views(seed),
        marked: views(seed + 3),
    }
}

fn state(atoms: &[&str]) -> State {
    State::from_atoms(atoms.iter().map(|a| a.parse().unwrap()))
}

/// A three-keyframe pick-and-place demo; the target has a cube stacked on the red one.
fn inputs(fidelity: Fidelity) -> BaselineInputs {
    BaselineInputs {
        instruction: "Put the red cube in the box.".into(),
        source_objects: vec!["red_cube".into(), "box".into(), "floor".into()],
        keyframes: vec![
            Keyframe {
                state: state(&["(GripperOpen)", "(OnTopOf red_cube floor)"]),
                observation: SceneObservation::Images(six(1)),
            },
            Keyframe {
                state: state(&["(GripperClosed)", "(GripperHolding red_cube)"]),
                observation: SceneObservation::Images(six(10)),
            },
            Keyframe {
                state: state(&["(GripperOpen)", "(InsideOf red_cube box)"]),
                observation: SceneObservation::Images(six(20)),
            },
        ],
        target_objects: vec![
            "red_cube".into(),
            "blue_cube".into(),
            "box".into(),
            "floor".into(),
        ],
        target_state: state(&[
            "(GripperOpen)",
            "(OnTopOf red_cube floor)",
            "(OnTopOf blue_cube red_cube)",
        ]),
        target_observation: SceneObservation::Images(six(40)),
        vocabulary: Vocabulary::new(),
        end_effector_in_state: false,
        budget: 10,
        fidelity,
    }
}

fn messages(request: &WireRequest) -> &Vec<Value> {
    request.body["messages"].as_array().unwrap()
}

fn text_of(message: &Value) -> String {
    match &message["content"] {
        Value::String(s) => s.clone(),
        Value::Array(parts) => parts
            .iter()
            .filter_map(|p| p["text"].as_str())
            .collect::<Vec<_>>()
            .join("\n"),
        _ => String::new(),
    }
}

fn images(message: &Value) -> usize {
    message["content"].as_array().map_or(0, |parts| {
        parts.iter().filter(|p| p["type"] == "image_url").count()
    })
}

const OBSERVATIONS: [&str; 3] = [
    "The cube rests on the table.\n- The open gripper is empty; the red cube lies on the table.",
    "**Observation:**\n\u{2022} The gripper holds the red cube.",
    "- The red cube is in the box and the gripper is open.\n- (a second line is not used)",
];

const PLAN: &str = "The blue cube covers the red one, so it goes first.\n\n1. **Grasp** the blue cube.\n2. Put the blue cube on the table.\n3. Grasp the red cube.\n4. Drop the red cube into the box.\n\nThis keeps to the demonstration otherwise.";

#[test]
fn demo2code_observes_every_keyframe_then_plans_for_the_target() {
    let transport = Scripted::with(&[(demo2code::OBSERVE, &OBSERVATIONS), (demo2code::ACTIONS, &[PLAN])]);
    let plan = pollster::block_on(demo2code::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap();
    assert_eq!(
        plan.steps,
        [
            "Grasp the blue cube.",
            "Put the blue cube on the table.",
            "Grasp the red cube.",
            "Drop the red cube into the box."
        ]
    );
    assert!(plan.deviations.is_empty());
    let purposes: Vec<&str> = plan.stages.iter().map(|s| s.purpose.as_str()).collect();
    assert_eq!(
        purposes,
        ["d2c.observe", "d2c.observe", "d2c.observe", "d2c.actions"]
    );
    // Each observation call sees its keyframe's state and six captioned images.
    let observe = transport.requests(demo2code::OBSERVE);
    assert_eq!(observe.len(), 3);
    let user = text_of(&messages(&observe[1])[1]);
    assert!(user.contains("- (GripperHolding red_cube)"), "{user}");
    assert!(user.contains("scene front (with object labels)"), "{user}");
    assert!(observe.iter().all(|r| images(&messages(r)[1]) == 6));
    // The planning call sees the numbered observations, the target's state and objects,
    // the full tier's predicates and the target's six images; the physical constraints are
    // NeSyCR's.
    let actions = transport.requests(demo2code::ACTIONS);
    let user = text_of(&messages(&actions[0])[1]);
    assert!(
        user.contains(
            "1. The open gripper is empty; the red cube lies on the table.\n2. The gripper holds the red cube.\n3. The red cube is in the box and the gripper is open."
        ),
        "{user}"
    );
    assert!(user.contains("- (OnTopOf blue_cube red_cube)"), "{user}");
    assert!(user.contains("- blue_cube"), "{user}");
    assert!(user.contains("(Closed ?x)"), "{user}");
    assert!(!user.contains("VacuumAttached"), "{user}");
    assert_eq!(images(&messages(&actions[0])[1]), 6);
    let system = text_of(&messages(&actions[0])[0]);
    assert!(
        system.contains(
            nesy_reasoner::prompts::PHYSICAL_CONSTRAINTS
                .lines()
                .next()
                .unwrap()
        )
    );
    assert!(
        actions
            .iter()
            .chain(&observe)
            .all(|r| r.body["reasoning_effort"] == "low")
    );
}

/// The same episode in the text-observation setting: each scene's ground-truth state in place
/// of its pictures.
fn state_text_inputs(fidelity: Fidelity) -> BaselineInputs {
    let mut inputs = inputs(fidelity);
    for keyframe in &mut inputs.keyframes {
        keyframe.observation = SceneObservation::StateText(keyframe.state.clone());
    }
    inputs.target_observation = SceneObservation::StateText(inputs.target_state.clone());
    inputs
}

#[test]
fn in_the_text_observation_setting_no_request_carries_a_picture() {
    let transport = Scripted::with(&[(demo2code::OBSERVE, &OBSERVATIONS), (demo2code::ACTIONS, &[PLAN])]);
    pollster::block_on(demo2code::run(
        &client(transport.clone(), None),
        &state_text_inputs(Fidelity::Authors),
    ))
    .unwrap();
    let observe = transport.requests(demo2code::OBSERVE);
    let actions = transport.requests(demo2code::ACTIONS);
    assert_eq!((observe.len(), actions.len()), (3, 1));
    for request in observe.iter().chain(&actions) {
        assert!(messages(request).iter().all(|m| images(m) == 0));
        for message in messages(request) {
            let text = text_of(message);
            assert!(
                !text.contains("image"),
                "a request without pictures announces some:\n{text}"
            );
        }
    }
    let user = text_of(&messages(&observe[1])[1]);
    assert!(
        user.contains("scene, as its ground-truth state (no pictures in this setting):\n- (GripperClosed)\n- (GripperHolding red_cube)"),
        "{user}"
    );
    let user = text_of(&messages(&actions[0])[1]);
    assert!(user.contains("scene, as its ground-truth state"), "{user}");
    assert!(!user.contains("scene front"), "{user}");
}

/// A reply of Gemma 3 270M (Q4_K_M, pretrained) to Demo2Code's observation prompt in the
/// text-observation setting, recorded against a local llama.cpp server: it never stops and is
/// cut off at the 256-token cap.
const RECORDED_RUNAWAY: &str = "<length>You may give a code at this point to the system.\nYou may give an answer to the system:\n\nThe model has been placed on top of a box and is held by a gripper.\nThis is a 3-state scenario (a 2-state scenario is also possible, but it's not needed here).\n- The robot is holding the box firmly with its mouth open and the gripper is grasping it from the floor.\n- The robot's gripper is working on the box, holding the box firmly with its mouth open.\n- The robot has opened the box and is holding the floor with its mouth closed.\n- The robot has lifted the box from the floor and is in a position to carry the object.\n\nAnswer:\n- The model has been placed on top of a box and is held by a gripper.\n- The robot ";

/// Every observation runs away, as the recorded model's did; the flow fails on the first
/// keyframe's, but only after every keyframe's observation has ended, so the calls made do
/// not depend on timing and a replay makes the same ones (with a fast server the others used
/// to be cancelled at the first failure, with a slow one most had already been made).
#[test]
fn a_failed_observation_still_lets_every_keyframe_be_observed() {
    let transport = Scripted::with(&[(demo2code::OBSERVE, &[RECORDED_RUNAWAY; 6])]);
    let error = pollster::block_on(demo2code::run(
        &client(transport.clone(), None),
        &state_text_inputs(Fidelity::Authors),
    ))
    .unwrap_err();
    assert!(
        matches!(&error, BaselineError::Unreadable { purpose, attempts: 2, .. } if purpose == "d2c.observe"),
        "{error:?}"
    );
    assert!(error.to_string().contains("cut off at the token cap"), "{error}");
    // Each of the three keyframes asked twice (the re-ask of a cut-off reply).
    assert_eq!(transport.requests(demo2code::OBSERVE).len(), 6);
}

#[test]
fn an_observation_without_its_line_fails_as_the_authors_parser_does_or_is_re_asked() {
    let prose = "I see a robot and a cube.";
    // Authors: no re-ask; the unit fails with the reply kept.
    let transport = Scripted::with(&[(demo2code::OBSERVE, &[OBSERVATIONS[0], prose, OBSERVATIONS[2]])]);
    let error = pollster::block_on(demo2code::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap_err();
    match &error {
        BaselineError::Unreadable {
            purpose,
            reply,
            attempts,
            problem,
        } => {
            assert_eq!(purpose, "d2c.observe");
            assert_eq!(reply, prose);
            assert_eq!(*attempts, 1);
            assert!(problem.contains("no line starting with"), "{problem}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(error.reasoner_kind(), nesy_core::adapt::ReasonerErrorKind::Reply);
    assert!(transport.requests(demo2code::ACTIONS).is_empty());

    // Repaired: the reply goes back with the reason, the corrected one is used.
    let transport = Scripted::with(&[
        (
            demo2code::OBSERVE,
            &[OBSERVATIONS[0], prose, OBSERVATIONS[1], OBSERVATIONS[2]],
        ),
        (demo2code::ACTIONS, &[PLAN]),
    ]);
    let plan = pollster::block_on(demo2code::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Repaired),
    ))
    .unwrap();
    assert_eq!(plan.steps.len(), 4);
    assert_eq!(plan.stages[1].reasked.len(), 1);
    assert!(!plan.deviations.is_empty());
    let observe = transport.requests(demo2code::OBSERVE);
    let reask = messages(&observe[2]);
    assert_eq!(reask.len(), 4);
    assert_eq!(text_of(&reask[2]), prose);
    assert!(
        text_of(&reask[3]).contains("could not be read: it has no line starting with"),
        "{}",
        text_of(&reask[3])
    );
}

#[test]
fn a_plan_cut_off_at_the_token_cap_is_re_asked_in_either_mode() {
    let cut = format!("{TRUNCATED}The blue cube covers the red one.\n1. Grasp the bl");
    let transport = Scripted::with(&[
        (demo2code::OBSERVE, &OBSERVATIONS),
        (demo2code::ACTIONS, &[&cut, PLAN]),
    ]);
    let plan = pollster::block_on(demo2code::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap();
    assert_eq!(plan.steps.len(), 4);
    let actions = &plan.stages[3];
    assert_eq!(actions.reasked.len(), 1);
    assert!(
        actions.reasked[0].contains("cut off at the token cap"),
        "{:?}",
        actions.reasked
    );
}

const DESCRIPTION: &str = "Here is the analysis.\n\n```\nTask: put the red cube in the box.\nActions:\n1. Grasp the red cube.\n2. Drop it into the box.\n```\n";

#[test]
fn gpt4v_describes_the_whole_demonstration_in_one_request_then_plans() {
    let transport = Scripted::with(&[(gpt4v::DESCRIBE, &[DESCRIPTION]), (gpt4v::PLAN, &[PLAN])]);
    let mut inputs = inputs(Fidelity::Authors);
    inputs.target_state = state(&["(GripperOpen)", "(OnTopOf blue_cube red_cube)", "(FingerGripper)"]);
    let plan = pollster::block_on(gpt4v::run(&client(transport.clone(), None), &inputs)).unwrap();
    assert_eq!(plan.steps.len(), 4);
    let describe = transport.requests(gpt4v::DESCRIBE);
    assert_eq!(describe.len(), 1);
    let user = &messages(&describe[0])[1];
    assert_eq!(images(user), 3 * 6);
    let text = text_of(user);
    assert!(
        text.contains("2. (GripperClosed), (GripperHolding red_cube)"),
        "{text}"
    );
    assert!(
        text.contains("demo keyframe 3 back (with object labels)"),
        "{text}"
    );
    // The plan sees the description's block, only the end-effector predicates and atoms,
    // and the target's six images.
    let plan_request = transport.requests(gpt4v::PLAN);
    let user = &messages(&plan_request[0])[1];
    assert_eq!(images(user), 6);
    let text = text_of(user);
    assert!(
        text.contains("Demonstrated domain:\nTask: put the red cube in the box."),
        "{text}"
    );
    assert!(!text.contains("Here is the analysis"), "{text}");
    assert!(
        text.contains("- (GripperOpen)\n- (FingerGripper)")
            || text.contains("- (FingerGripper)\n- (GripperOpen)"),
        "{text}"
    );
    assert!(!text.contains("(OnTopOf blue_cube red_cube)"), "{text}");
    assert!(!text.contains("(OnTopOf ?a ?b)"), "{text}");
}

#[test]
fn a_description_over_the_endpoints_image_limit_is_refused_before_sending() {
    let transport = Scripted::with(&[(gpt4v::DESCRIBE, &[DESCRIPTION]), (gpt4v::PLAN, &[PLAN])]);
    let error = pollster::block_on(gpt4v::run(
        &client(transport.clone(), Some(12)),
        &inputs(Fidelity::Authors),
    ))
    .unwrap_err();
    match &error {
        BaselineError::Call {
            purpose,
            error:
                VlmError::TooManyImages {
                    images: 18,
                    limit: 12,
                },
        } => assert_eq!(purpose, "gpt4v.describe"),
        other => panic!("{other:?}"),
    }
    assert_eq!(
        error.reasoner_kind(),
        nesy_core::adapt::ReasonerErrorKind::Refused
    );
    assert!(transport.requests(gpt4v::DESCRIBE).is_empty());
    assert_eq!(gpt4v::shape(3).largest_request_images, 18);
    // A description without its block fails as the authors' reader does.
    let transport = Scripted::with(&[(gpt4v::DESCRIBE, &["The robot picks the cube."])]);
    let error =
        pollster::block_on(gpt4v::run(&client(transport, None), &inputs(Fidelity::Authors))).unwrap_err();
    assert!(error.to_string().contains("has no fenced block"), "{error}");
}

const SOURCE_PLAN: &str = "Three transitions.\n1. Move the gripper around the red cube.\n2. Close the gripper to grasp the red cube.\n3. Drop the red cube into the box.";

const FEEDBACK_BLOCKED: &str =
    "The blue cube sits on the red cube.\n- The red cube is covered by the blue cube, so step 1 fails.";

/// A correction in the style of the prompt's example: numbered SEARCH and REPLACE lines.
const CORRECTION_NUMBERED: &str = "Case 1: the blue cube has to come off first.

<<<<<<< SEARCH
1. Move the gripper around the red cube.
=======
1. Move the gripper around the blue cube.
2. Put the blue cube on the table.
3. Move the gripper around the red cube.
>>>>>>> REPLACE";

#[test]
fn critic_v_corrects_until_no_issue_and_keeps_the_authors_numbering_quirk() {
    let script = |feedback: &[&'static str], corrections: &[&'static str]| {
        let observe: &[&str] = &OBSERVATIONS;
        Scripted::with(&[
            (demo2code::OBSERVE, observe),
            (critic::SOURCE_ACTIONS, &[SOURCE_PLAN]),
            (critic::FEEDBACK, feedback),
            (critic::CORRECTION, corrections),
        ])
    };
    let no_issue = "- No issue: the plan works in this scene.";
    // Authors: the numbered SEARCH line does not match the unnumbered plan, so the plan is
    // unchanged; the second feedback says no issue and the loop stops.
    let transport = script(&[FEEDBACK_BLOCKED, no_issue], &[CORRECTION_NUMBERED]);
    let plan = pollster::block_on(critic::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap();
    assert_eq!(plan.steps.len(), 3);
    assert_eq!(plan.steps[0], "Move the gripper around the red cube.");
    assert_eq!(plan.rounds, Some(2));
    // The feedback sees the plan numbered and the target's views; the correction is text
    // only and sees it one action per line, unnumbered.
    let feedback = transport.requests(critic::FEEDBACK);
    let text = text_of(&messages(&feedback[0])[1]);
    assert!(
        text.contains("1. Move the gripper around the red cube.\n2. Close"),
        "{text}"
    );
    assert_eq!(images(&messages(&feedback[0])[1]), 6);
    let correction = transport.requests(critic::CORRECTION);
    let text = text_of(&messages(&correction[0])[1]);
    assert!(
        text.contains("The plan:\nMove the gripper around the red cube.\nClose"),
        "{text}"
    );
    assert!(
        text.contains("Feedback:\nThe red cube is covered by the blue cube"),
        "{text}"
    );
    assert_eq!(images(&messages(&correction[0])[1]), 0);
    // The unadapted plan's call is text only, with the source objects.
    let source = transport.requests(critic::SOURCE_ACTIONS);
    assert_eq!(images(&messages(&source[0])[1]), 0);
    assert!(!text_of(&messages(&source[0])[1]).contains("blue_cube"));

    // Repaired: the numbers are dropped before matching, so the edit applies.
    let transport = script(&[FEEDBACK_BLOCKED, no_issue], &[CORRECTION_NUMBERED]);
    let plan =
        pollster::block_on(critic::run(&client(transport, None), &inputs(Fidelity::Repaired))).unwrap();
    assert_eq!(
        plan.steps,
        [
            "Move the gripper around the blue cube.",
            "Put the blue cube on the table.",
            "Move the gripper around the red cube.",
            "Close the gripper to grasp the red cube.",
            "Drop the red cube into the box."
        ]
    );
    assert!(plan.deviations.iter().any(|d| d.contains("without list numbers")));

    // The loop stops at the budget when the critic never says no issue.
    let mut capped = inputs(Fidelity::Authors);
    capped.budget = 2;
    let transport = script(
        &[FEEDBACK_BLOCKED, FEEDBACK_BLOCKED, FEEDBACK_BLOCKED],
        &[CORRECTION_NUMBERED, CORRECTION_NUMBERED],
    );
    let plan = pollster::block_on(critic::run(&client(transport.clone(), None), &capped)).unwrap();
    assert_eq!(plan.rounds, Some(2));
    assert_eq!(transport.requests(critic::FEEDBACK).len(), 2);
    assert_eq!(transport.requests(critic::CORRECTION).len(), 2);
    assert_eq!(critic::shape(3, 2).calls_max, 4 + 4);

    // A correction without the empty line the authors split on fails the unit, reply kept.
    let transport = script(&[FEEDBACK_BLOCKED], &["Move the blue cube first."]);
    let error =
        pollster::block_on(critic::run(&client(transport, None), &inputs(Fidelity::Authors))).unwrap_err();
    assert_eq!(error.reply(), Some("Move the blue cube first."));
    assert!(error.to_string().contains("critic.correction"), "{error}");
}

#[test]
fn statler_plans_in_rounds_and_lets_the_model_write_the_state() {
    let predicted = "- (OnTopOf blue_cube red_cube)\n- (OnTopOf box floor)";
    let round_one = "Clear the red cube first.\n1. Grasp the blue cube.\n2. Put the blue cube on the table.\n- (GripperOpen)\n- (OnTopOf blue_cube floor)";
    let round_two = "Now the red cube.\n1. Grasp the red cube.\n2. Drop the red cube into the box.\n- (InsideOf red_cube box)\ngoal reached";
    let transport = Scripted::with(&[
        (gpt4v::DESCRIBE, &[DESCRIPTION]),
        (statler::STATE, &[predicted]),
        (statler::ACTIONS, &[round_one, round_two]),
    ]);
    let plan = pollster::block_on(statler::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap();
    assert_eq!(
        plan.steps,
        [
            "Grasp the blue cube.",
            "Put the blue cube on the table.",
            "Grasp the red cube.",
            "Drop the red cube into the box."
        ]
    );
    assert_eq!(plan.rounds, Some(2));
    // The state call sees the partial tier and the ground truth; the first round sees the
    // prediction joined with it, the second only what the model wrote.
    let state = transport.requests(statler::STATE);
    let text = text_of(&messages(&state[0])[1]);
    assert!(text.contains("Partial ground truth:\n- (GripperOpen)"), "{text}");
    assert!(!text.contains("(Open ?x)"), "{text}");
    let rounds = transport.requests(statler::ACTIONS);
    let first = text_of(&messages(&rounds[0])[1]);
    assert!(first.contains("Actions so far:\nNone"), "{first}");
    assert!(
        first.contains("- (OnTopOf box floor)\n- (OnTopOf red_cube floor)"),
        "{first}"
    );
    let second = text_of(&messages(&rounds[1])[1]);
    assert!(
        second.contains("Current world state:\n- (GripperOpen)\n- (OnTopOf blue_cube floor)\n\n"),
        "{second}"
    );
    assert!(
        second.contains("1. Grasp the blue cube.\n2. Put the blue cube on the table."),
        "{second}"
    );
    // The same six initial views every round.
    assert!(rounds.iter().all(|r| images(&messages(r)[1]) == 6));

    // The authors' stop rule keeps a numbered "Goal reached." with a period in the plan and
    // runs to the budget; repaired stops there and removes it.
    let numbered_stop = "1. Grasp the red cube.\n2. Goal reached.";
    let mut capped = inputs(Fidelity::Authors);
    capped.budget = 2;
    let transport = Scripted::with(&[
        (gpt4v::DESCRIBE, &[DESCRIPTION]),
        (statler::STATE, &[predicted]),
        (statler::ACTIONS, &[numbered_stop, numbered_stop]),
    ]);
    let plan = pollster::block_on(statler::run(&client(transport, None), &capped)).unwrap();
    assert_eq!(plan.rounds, Some(2));
    assert_eq!(plan.steps.iter().filter(|s| *s == "Goal reached.").count(), 2);
    capped.fidelity = Fidelity::Repaired;
    let transport = Scripted::with(&[
        (gpt4v::DESCRIBE, &[DESCRIPTION]),
        (statler::STATE, &[predicted]),
        (statler::ACTIONS, &[numbered_stop, numbered_stop]),
    ]);
    let plan = pollster::block_on(statler::run(&client(transport, None), &capped)).unwrap();
    assert_eq!(plan.steps, ["Grasp the red cube."]);
    assert_eq!(plan.rounds, Some(1));
    assert_eq!(statler::shape(3, 2).calls_max, 4);
}

const EVENTS: &str = r#"{"question": "Is the red cube in the box?", "conjunction": "and", "parse_event": ["grasp the red cube", "drop the red cube into the box"], "event_object": ["red_cube", "red_cube, box"], "classify": "manipulation"}"#;
const GROUNDED: &str = r#"{"event_queue": ["grasp the blue cube", "put the blue cube on the table", "grasp the red cube", "drop the red cube into the box"]}"#;
const NOT_VERIFIED: &str = r#"{"event_queue": ["grasp the red cube", "drop the red cube into the box"], "verified": false, "reason": "the blue cube covers the red cube"}"#;
const VERIFIED: &str = r#"{"event_queue": ["grasp the blue cube", "put the blue cube on the table", "grasp the red cube", "drop the red cube into the box"], "verified": true, "reason": "the queue clears the red cube first"}"#;

fn morevqa_script(ground: &[&'static str], verify: &[&'static str]) -> Arc<Scripted> {
    let api: &[&str] = &["verify_action(\"Is the red cube in the box?\")"; 4];
    Scripted::with(&[
        (gpt4v::DESCRIBE, &[DESCRIPTION]),
        (morevqa::PARSE, &[EVENTS]),
        (morevqa::GROUND, ground),
        (morevqa::VERIFY_API, api),
        (morevqa::VERIFY, verify),
        (
            morevqa::VQA_API,
            &["vqa(\"What is on the red cube?\")\nvqa(\"Is the box open?\")\nvqa(\"Where is the box?\")"],
        ),
        (morevqa::VQA, &["The blue cube.\nYes.\nRight of the cubes."]),
        (morevqa::PLAN, &[PLAN]),
    ])
}

#[test]
fn morevqa_grounds_and_verifies_until_verified_then_asks_and_plans() {
    let transport = morevqa_script(&[GROUNDED, GROUNDED], &[NOT_VERIFIED, VERIFIED]);
    let plan = pollster::block_on(morevqa::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap();
    assert_eq!(plan.steps.len(), 4);
    assert_eq!(plan.rounds, Some(2));
    // Code generation gets the question form of the instruction.
    assert_eq!(plan.instruction.as_deref(), Some("Is the red cube in the box?"));
    assert!(plan.deviations[0].contains("capped at the scenario's budget"));
    assert!(
        plan.deviations
            .iter()
            .any(|d| d.contains("ran 2 of its 10 rounds and verified"))
    );
    let purposes: Vec<&str> = plan.stages.iter().map(|s| s.purpose.as_str()).collect();
    assert_eq!(
        purposes,
        [
            "gpt4v.describe",
            "morevqa.parse",
            "morevqa.ground",
            "morevqa.verify_api",
            "morevqa.verify",
            "morevqa.ground",
            "morevqa.verify_api",
            "morevqa.verify",
            "morevqa.vqa_api",
            "morevqa.vqa",
            "morevqa.plan"
        ]
    );
    // Authors: the second grounding is the first's prompt again (no slot for the reason).
    let ground = transport.requests(morevqa::GROUND);
    assert!(!text_of(&messages(&ground[1])[1]).contains("blue cube covers"));
    // The verification sees the call and the grounded queue; the plan sees the answers,
    // the full target state and only the end-effector predicates.
    let verify = transport.requests(morevqa::VERIFY);
    let text = text_of(&messages(&verify[0])[1]);
    assert!(
        text.contains("Call: verify_action(\"Is the red cube in the box?\")"),
        "{text}"
    );
    assert!(text.contains("1. grasp the blue cube"), "{text}");
    let plan_request = &transport.requests(morevqa::PLAN)[0];
    let text = text_of(&messages(plan_request)[1]);
    assert!(
        text.contains("Answers about the scene:\nThe blue cube."),
        "{text}"
    );
    assert!(text.contains("- (OnTopOf blue_cube red_cube)"), "{text}");
    assert!(!text.contains("(OnTopOf ?a ?b)"), "{text}");
    assert_eq!(morevqa::shape(3, 10).calls_min, 8);

    // The loop stops at the budget when nothing verifies.
    let mut capped = inputs(Fidelity::Authors);
    capped.budget = 2;
    let transport = morevqa_script(&[GROUNDED, GROUNDED], &[NOT_VERIFIED, NOT_VERIFIED]);
    let plan = pollster::block_on(morevqa::run(&client(transport.clone(), None), &capped)).unwrap();
    assert_eq!(plan.rounds, Some(2));
    assert!(plan.deviations.iter().any(|d| d.contains("without verifying")));
    assert_eq!(transport.requests(morevqa::VERIFY).len(), 2);

    // Authors: a fenced JSON reply fails as json.loads would; repaired reads it, and shows
    // the failed check's reason to the next grounding.
    let fenced_events = "```json\n{\"question\": \"Is the red cube in the box?\", \"parse_event\": [\"grasp the red cube\"], \"event_object\": [\"red_cube\"]}\n```";
    let transport = Scripted::with(&[
        (gpt4v::DESCRIBE, &[DESCRIPTION]),
        (morevqa::PARSE, &[fenced_events]),
    ]);
    let error =
        pollster::block_on(morevqa::run(&client(transport, None), &inputs(Fidelity::Authors))).unwrap_err();
    assert!(
        error.to_string().contains("morevqa.parse") && error.to_string().contains("not a JSON object"),
        "{error}"
    );
    let transport = morevqa_script(&[GROUNDED, GROUNDED], &[NOT_VERIFIED, VERIFIED]);
    transport.set(morevqa::PARSE, &[fenced_events]);
    let plan = pollster::block_on(morevqa::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Repaired),
    ))
    .unwrap();
    assert_eq!(plan.rounds, Some(2));
    let ground = transport.requests(morevqa::GROUND);
    assert!(
        text_of(&messages(&ground[1])[1])
            .contains("The last check of the queue failed: the blue cube covers the red cube")
    );
}

const RECOMMENDED: &str = "Two kinds of action.\n1. pick_up: grasp an object from the table\n2. drop_in: release a held object into a container";
const PROPOSED: &str = "The tier covers what we need; one helper:\n- (reachable ?x): the arm can reach ?x";
const PICK_UP: &str = "Action name:\n- pick_up\nParameters:\n1. ?x: the object\nPreconditions\n```\n(and (GripperOpen) (OnTopOf ?x floor))\n```\nEffects\n```\n(and (GripperHolding ?x) (not (GripperOpen)) (not (OnTopOf ?x floor)))\n```";
const DROP_IN_NEEDS_OPEN: &str = "Action name:\n- drop_in\nParameters:\n1. ?x: the held object\n2. ?b: the container\nPreconditions\n```\n(and (GripperHolding ?x) (Open ?b))\n```\nEffects\n```\n(and (InsideOf ?x ?b) (GripperOpen) (not (GripperHolding ?x)))\n```";
const PROBLEM_REPLY: &str = "Initial state\n```\n(:objects red_cube box floor)\n```\n```\n(:init (GripperOpen) (OnTopOf red_cube floor))\n```\nGoal state\n```\n(:goal (InsideOf red_cube box))\n```";
const REFINED: &str = "The box is never open, so drop_in can never apply; drop the condition.\n```\n(define (domain llmdm)\n  (:requirements :strips :negative-preconditions)\n  (:predicates (GripperOpen) (GripperHolding ?x) (OnTopOf ?x ?y) (InsideOf ?x ?y))\n  (:action pick_up :parameters (?x) :precondition (and (GripperOpen) (OnTopOf ?x floor))\n    :effect (and (GripperHolding ?x) (not (GripperOpen)) (not (OnTopOf ?x floor))))\n  (:action drop_in :parameters (?x ?b) :precondition (GripperHolding ?x)\n    :effect (and (InsideOf ?x ?b) (GripperOpen) (not (GripperHolding ?x)))))\n```";
const TRANSLATED: &str = "1. Pick up the red cube.\n2. Drop the red cube into the box.";

fn llmdm_script(drop_in: &'static str, refine: &[&'static str], translate: &[&'static str]) -> Arc<Scripted> {
    Scripted::with(&[
        (gpt4v::DESCRIBE, &[DESCRIPTION]),
        (llmdm::ACTIONS, &[RECOMMENDED]),
        (llmdm::PREDICATES, &[PROPOSED]),
        (llmdm::ACTION, &[PICK_UP, drop_in]),
        (llmdm::PROBLEM, &[PROBLEM_REPLY]),
        (llmdm::REFINE, refine),
        (llmdm::TRANSLATE, translate),
    ])
}

#[test]
fn llm_dm_builds_a_domain_plans_refines_on_failure_and_translates_the_plan() {
    // The model's drop_in needs an open box that never is: no plan; the refinement drops
    // the condition and the planner solves the refined domain.
    let transport = llmdm_script(DROP_IN_NEEDS_OPEN, &[REFINED], &[TRANSLATED]);
    let plan = pollster::block_on(llmdm::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap();
    assert_eq!(
        plan.steps,
        ["Pick up the red cube.", "Drop the red cube into the box."]
    );
    assert_eq!(plan.rounds, Some(1));
    assert!(plan.deviations[0].contains("not Fast Downward"));
    // The predicates joined the tier's, cut at their first `:`; each action has its call.
    let actions = transport.requests(llmdm::ACTION);
    assert_eq!(actions.len(), 2);
    let text = text_of(&messages(&actions[0])[1]);
    assert!(text.contains("(reachable ?x)\n(OverOf ?a ?b)"), "{text}");
    assert!(!text.contains("the arm can reach"), "{text}");
    // The refinement sees the domain, the problem and the planner's report.
    let refine = transport.requests(llmdm::REFINE);
    let text = text_of(&messages(&refine[0])[1]);
    assert!(
        text.contains("(:action drop_in\n    :parameters (?x ?b)"),
        "{text}"
    );
    assert!(text.contains("(:goal (InsideOf red_cube box))"), "{text}");
    assert!(text.contains("Plan not found by the nesy planner"), "{text}");
    let translate = transport.requests(llmdm::TRANSLATE);
    let text = text_of(&messages(&translate[0])[1]);
    assert!(
        text.contains("1. (pick_up red_cube)\n2. (drop_in red_cube box)"),
        "{text}"
    );

    // Never solvable within a budget of one: the authors do not solve after the last
    // refinement and hand "None" to code generation; repaired solves once more, then ends
    // without a plan.
    let mut one = inputs(Fidelity::Authors);
    one.budget = 1;
    let still_closed = "Keep it.\n```\n(define (domain llmdm) (:requirements :strips :negative-preconditions)\n (:predicates (GripperOpen) (GripperHolding ?x) (OnTopOf ?x ?y) (InsideOf ?x ?y) (Open ?x))\n (:action drop_in :parameters (?x ?b) :precondition (and (GripperHolding ?x) (Open ?b)) :effect (InsideOf ?x ?b)))\n```";
    let transport = llmdm_script(DROP_IN_NEEDS_OPEN, &[still_closed], &[]);
    let plan = pollster::block_on(llmdm::run(&client(transport.clone(), None), &one)).unwrap();
    assert_eq!(plan.steps, ["None"]);
    assert_eq!(transport.requests(llmdm::REFINE).len(), 1);
    one.fidelity = Fidelity::Repaired;
    let transport = llmdm_script(DROP_IN_NEEDS_OPEN, &[still_closed], &[]);
    let error = pollster::block_on(llmdm::run(&client(transport, None), &one)).unwrap_err();
    assert!(error.is_unresolved(), "{error}");

    // A formula that does not parse goes back as the planner's report, with its position,
    // in both modes (the authors' code raises there: a deviation).
    let broken = "Action name:\n- drop_in\nParameters:\n1. ?x\n2. ?b\nPreconditions\n```\n(and (GripperHolding ?x)\n```\nEffects\n```\n(InsideOf ?x ?b)\n```";
    let transport = llmdm_script(broken, &[REFINED], &[TRANSLATED]);
    let plan = pollster::block_on(llmdm::run(
        &client(transport.clone(), None),
        &inputs(Fidelity::Authors),
    ))
    .unwrap();
    assert_eq!(plan.steps.len(), 2);
    assert!(
        plan.deviations
            .iter()
            .any(|d| d.contains("the authors' code raises"))
    );
    let text = text_of(&messages(&transport.requests(llmdm::REFINE)[0])[1]);
    assert!(text.contains("the domain does not parse"), "{text}");

    // An action reply with "Effects" twice fails as the authors' split does.
    let twice = "Action name:\n- drop_in\nPreconditions\n```\n(GripperHolding ?x)\n```\nEffects\n```\n(InsideOf ?x ?b)\n```\nEffects again";
    let transport = llmdm_script(twice, &[], &[]);
    let error =
        pollster::block_on(llmdm::run(&client(transport, None), &inputs(Fidelity::Authors))).unwrap_err();
    assert!(error.to_string().contains("\"Effects\" 2 times"), "{error}");
}
