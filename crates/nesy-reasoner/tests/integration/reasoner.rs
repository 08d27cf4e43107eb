//! `VlmReasoner` driven through nesy-core's adaptation loop by an in-process transport that
//! answers in real-model style: prose around the answers, odd bullets and headers, a wrong
//! operator the verifier rejects and that is re-predicted, a patch whose SEARCH block
//! matches nothing and is then fixed; then code generation and state translation on the
//! same client, with per-purpose accounting and typed task contexts.

use std::sync::Arc;

use crate::scenario;
use nesy_core::Embodiment;
use nesy_core::adapt::{Outcome, Problem, TraceEvent, Verdict, run};
use nesy_core::{Tier, Vocabulary};
use nesy_pipeline::synth::SandboxChecks;
use nesy_reasoner::codegen::{CodeGenerationRequest, CodegenError};
use nesy_reasoner::translate::TranslationProblem;
use nesy_reasoner::translate::{StateTranslationRequest, TranslateError};
use nesy_reasoner::{Views, VlmReasoner, VlmTask};
use nesy_testkit::{NULL_CONTENT, Scripted, TRUNCATED};
use nesy_vlm::{BackendKind, Image, VlmClient, WireRequest};

fn client(transport: Arc<Scripted>) -> VlmClient {
    let config = nesy_testkit::mock_config(BackendKind::OpenAi, "gpt-5", "http://127.0.0.1:9");
    VlmClient::with_transport(&config, transport)
}

fn messages(request: &WireRequest) -> &Vec<serde_json::Value> {
    request.body["messages"].as_array().unwrap()
}

fn image_count(message: &serde_json::Value) -> usize {
    message["content"].as_array().map_or(0, |parts| {
        parts.iter().filter(|p| p["type"] == "image_url").count()
    })
}

fn text_of(message: &serde_json::Value) -> String {
    match &message["content"] {
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Array(parts) => parts
            .iter()
            .filter_map(|p| p["text"].as_str())
            .collect::<Vec<_>>()
            .join("\n"),
        other => panic!("unexpected content {other}"),
    }
}

#[tokio::test]
async fn the_loop_recovers_from_a_rejected_operator_and_a_non_matching_patch() {
    let transport = Scripted::with(&[
        (
            "induce",
            &[
                scenario::APPROACH,
                scenario::GRASP_WRONG,
                scenario::GRASP,
                scenario::CARRY,
                scenario::DROP,
            ],
        ),
        ("patch", &[scenario::PATCH_NO_MATCH, scenario::PATCH]),
    ]);
    let mut reasoner = VlmReasoner::new(client(transport.clone()))
        .unwrap()
        .with_keyframes(scenario::keyframes())
        .with_embodiments(Embodiment::Finger, Embodiment::Finger);
    let adaptation = run(
        &mut reasoner,
        &scenario::demo(),
        &scenario::target(),
        &scenario::config(),
    )
    .await
    .unwrap();

    // The world model verified every transition; the wrong grasp was rejected first.
    assert!(adaptation.world_model.unverified_steps.is_empty());
    let rejected: Vec<_> = adaptation
        .trace
        .events
        .iter()
        .filter_map(|e| match e {
            TraceEvent::Induction {
                step,
                verdict: Verdict::Rejected { feedback },
                ..
            } => Some((*step, feedback.problem.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(rejected.len(), 1);
    assert_eq!(rejected[0].0, 1);
    assert!(matches!(rejected[0].1, Problem::EffectMismatch { .. }));

    // The closed lid was found, the bad patch rejected, the good one accepted.
    let Outcome::Adapted {
        procedure,
        iterations,
        ..
    } = &adaptation.outcome
    else {
        panic!("not adapted: {:#?}", adaptation.outcome);
    };
    assert_eq!(*iterations, 2);
    let names: Vec<&str> = procedure.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "GraspHingeHandle",
            "SwingHingeLidOpen",
            "ReleaseHingeHandle",
            "MoveGripperToSurroundApple",
            "CloseGripperToGraspApple",
            "MoveHeldAppleOverHingeBody",
            "OpenGripperToDropAppleIntoHingeBody",
        ]
    );

    // Induction requests: six labelled images, the task context with the recorded call, and
    // on re-prediction the rejected reply and the verifier's message as follow-up turns.
    let induce = transport.requests("induce");
    assert_eq!(induce.len(), 5);
    for request in &induce {
        assert_eq!(image_count(&messages(request)[1]), 6);
        let text = text_of(&messages(request)[1]);
        assert!(
            text.contains("Before the action, top view:") && text.contains("After the action, back view:")
        );
    }
    let retry = messages(&induce[2]);
    assert_eq!(retry.len(), 4);
    assert_eq!(retry[2]["role"], "assistant");
    assert_eq!(text_of(&retry[2]), scenario::GRASP_WRONG);
    let feedback = text_of(&retry[3]);
    assert!(
        feedback.contains("rejected this answer (attempt 1)"),
        "{feedback}"
    );
    assert!(feedback.contains("- (GripperSurrounding apple)"), "{feedback}");
    let VlmTask::Induction(context) = VlmTask::from_task_context(induce[2].task.as_ref().unwrap()).unwrap()
    else {
        panic!("an induction request carries an induction context");
    };
    assert_eq!((context.request.step, context.request.attempt), (1, 1));
    assert_eq!(context.embodiment, Embodiment::Finger);
    assert_eq!(context.request.feedback.len(), 1);

    // Patch requests are text only; the second carries the failed proposal and why.
    let patch = transport.requests("patch");
    assert_eq!(patch.len(), 2);
    assert!(
        patch
            .iter()
            .all(|r| messages(r).iter().all(|m| image_count(m) == 0))
    );
    let first = text_of(&messages(&patch[0])[1]);
    assert!(
        first.contains("- Unfulfilled preconditions:\n- (Open hinge_lid)"),
        "{first}"
    );
    assert!(
        first.contains("- Erroneous action:\nOpenGripperToDropAppleIntoHingeBody\n"),
        "{first}"
    );
    let second = messages(&patch[1]);
    assert_eq!(second.len(), 4);
    assert!(
        text_of(&second[3]).contains("The patch was not applied"),
        "{}",
        text_of(&second[3])
    );
    let VlmTask::Patch(context) = VlmTask::from_task_context(patch[1].task.as_ref().unwrap()).unwrap() else {
        panic!("a patch request carries a patch context");
    };
    assert_eq!(context.request.failing_step, Some(3));
    assert_eq!(context.target_embodiment, Embodiment::Finger);

    // Code generation on the adapted procedure; the foreign import is stripped and recorded.
    let sorry = "Sorry, I cannot help with that.";
    let codegen = Scripted::with(&[("codegen", &[scenario::CODE, sorry, sorry, sorry])]);
    let reasoner = VlmReasoner::new(client(codegen.clone()))
        .unwrap()
        .with_program_check(Arc::new(SandboxChecks));
    let request = CodeGenerationRequest {
        instruction: "Put the fruits in the hinge box.".into(),
        objects: scenario::OBJECTS.iter().map(|o| o.to_string()).collect(),
        procedure: procedure.clone(),
        plan: Vec::new(),
        embodiment: Embodiment::Finger,
        extended: false,
        tools: false,
        protective_stop: false,
    };
    let policy = reasoner.generate_code(&request).await.unwrap();
    assert!(
        policy
            .code
            .starts_with("import numpy as np\n\nmove_gripper_to(\"hinge_handle\"")
    );
    assert!(policy.code.ends_with("open_gripper()\n"));
    assert_eq!(policy.stripped.len(), 1);
    assert!(policy.stripped[0].text.starts_with("from robot_api import"));
    assert!(!policy.extended);
    let sent = &codegen.requests("codegen")[0];
    let user = text_of(&messages(sent)[1]);
    assert!(
        user.contains("- Demonstration summary:\n1. GraspHingeHandle\n2. SwingHingeLidOpen\n"),
        "{user}"
    );
    let VlmTask::CodeGeneration(context) = VlmTask::from_task_context(sent.task.as_ref().unwrap()).unwrap()
    else {
        panic!("a code generation context");
    };
    assert_eq!(context.action_names[6], "7. OpenGripperToDropAppleIntoHingeBody");
    assert_eq!(context.procedure, *procedure);
    // Replies without code are re-asked; when the budget runs out, a typed error keeps them.
    match reasoner.generate_code(&request).await {
        Err(CodegenError::NoProgram { attempts }) => {
            assert_eq!(attempts.len(), nesy_reasoner::codegen::CODEGEN_ATTEMPTS);
            assert!(attempts.iter().all(|a| a.reply.starts_with("Sorry")));
            assert!(
                attempts[0]
                    .problem
                    .to_string()
                    .starts_with("reply could not be read"),
                "{}",
                attempts[0].problem
            );
        }
        other => panic!("{other:?}"),
    }
    let usage = reasoner.client().usage();
    assert_eq!(
        usage.by_purpose["codegen"].calls,
        1 + nesy_reasoner::codegen::CODEGEN_ATTEMPTS as u64
    );
}

#[tokio::test]
async fn cut_off_and_empty_induction_and_patch_replies_are_re_asked_before_the_loop_reads_them() {
    let cut = |text: &str| format!("{TRUNCATED}{}", &text[..text.len() / 2]);
    let approach_cut = cut(scenario::APPROACH);
    let patch_cut = cut(scenario::PATCH);
    let transport = Scripted::with(&[
        (
            "induce",
            &[
                &approach_cut,
                scenario::APPROACH,
                NULL_CONTENT,
                scenario::GRASP,
                scenario::CARRY,
                scenario::DROP,
            ],
        ),
        ("patch", &[&patch_cut, scenario::PATCH]),
    ]);
    let mut reasoner = VlmReasoner::new(client(transport.clone()))
        .unwrap()
        .with_keyframes(scenario::keyframes())
        .with_embodiments(Embodiment::Finger, Embodiment::Finger);
    let adaptation = run(
        &mut reasoner,
        &scenario::demo(),
        &scenario::target(),
        &scenario::config(),
    )
    .await
    .unwrap();
    assert!(
        matches!(adaptation.outcome, Outcome::Adapted { iterations: 1, .. }),
        "{:#?}",
        adaptation.outcome
    );
    // Each re-ask carries the cut-off or empty reply and says what was wrong with it; the
    // loop itself saw only whole replies (no induction was rejected).
    let induce = transport.requests("induce");
    assert_eq!(induce.len(), 6);
    let reask = text_of(&messages(&induce[1])[3]);
    assert!(
        reask.contains("cut off at the token cap") && reask.contains("Answer more briefly"),
        "{reask}"
    );
    let reask = text_of(&messages(&induce[3])[3]);
    assert!(reask.contains("`content` was null"), "{reask}");
    assert!(!adaptation.trace.events.iter().any(|e| matches!(
        e,
        TraceEvent::Induction {
            verdict: Verdict::Rejected { .. },
            ..
        }
    )));
    let patch = transport.requests("patch");
    assert_eq!(patch.len(), 2);
    assert!(text_of(&messages(&patch[1])[3]).contains("cut off at the token cap"));

    // When the re-ask is cut off too, what the model did say goes to the loop as its reply:
    // the loop rejects it with feedback and asks again within its own attempt budget, so
    // runaway replies cost attempts, not the run.
    let transport = Scripted::with(&[
        (
            "induce",
            &[
                &approach_cut,
                &approach_cut,
                scenario::APPROACH,
                scenario::GRASP,
                scenario::CARRY,
                scenario::DROP,
            ],
        ),
        ("patch", &[scenario::PATCH]),
    ]);
    let mut reasoner = VlmReasoner::new(client(transport.clone()))
        .unwrap()
        .with_keyframes(scenario::keyframes());
    let adaptation = run(
        &mut reasoner,
        &scenario::demo(),
        &scenario::target(),
        &scenario::config(),
    )
    .await
    .unwrap();
    assert!(
        matches!(adaptation.outcome, Outcome::Adapted { .. }),
        "{:#?}",
        adaptation.outcome
    );
    let rejected: Vec<(usize, usize)> = adaptation
        .trace
        .events
        .iter()
        .filter_map(|e| match e {
            TraceEvent::Induction {
                step,
                attempt,
                verdict: Verdict::Rejected { .. },
                ..
            } => Some((*step, *attempt)),
            _ => None,
        })
        .collect();
    assert_eq!(
        rejected,
        [(0, 0)],
        "the cut-off reply is the first step's rejected first attempt"
    );
    let induce = transport.requests("induce");
    assert!(text_of(&messages(&induce[2])[3]).contains("(attempt 1)"));
}

#[tokio::test]
async fn state_translation_adds_checked_atoms_to_the_known_ones() {
    let table = "I see a table.";
    let drifted = "Combining all three views:\n<think>the lid looks shut</think>\n\u{2013} `(Closed hinge_lid)`\n\u{2022} (OnTopOf apple floor)\n\u{2013} (OnTopOf hinge_body floor)";
    let clean = scenario::TRANSLATION.replace("- (OnTopOf banana floor)\n", "");
    let cut_off = format!("{TRUNCATED}- (OnTopOf apple floor)\n- (Clo");
    let transport = Scripted::with(&[(
        "translate",
        &[
            scenario::TRANSLATION,
            &clean,
            table,
            table,
            table,
            "Here they are.",
            drifted,
            NULL_CONTENT,
            &cut_off,
            &clean,
        ],
    )]);
    let reasoner = VlmReasoner::new(client(transport.clone())).unwrap();
    let png = |seed| Image::png(nesy_testkit::png(16, seed)).unwrap();
    let request = StateTranslationRequest {
        view_set: "target/initial".into(),
        instruction: "Put the fruits in the hinge box.".into(),
        objects: scenario::OBJECTS.iter().map(|o| o.to_string()).collect(),
        tier: Tier::Full,
        vocabulary: Vocabulary::new(),
        known: scenario::state(&["(GripperOpen)"]),
        views: Views::new([("top", png(1)), ("front", png(2)), ("back", png(3))]),
        ground_truth: Some(scenario::target().init),
    };
    // An object the scene does not have is not dropped quietly: the reply is re-asked with
    // the name, and the corrected reply is used.
    let translated = reasoner.translate_state(&request).await.unwrap();
    assert_eq!(translated.state, scenario::target().init);
    assert!(translated.rejected.is_empty());
    assert_eq!(translated.reasked.len(), 1);
    let sent = transport.requests("translate");
    let reask = text_of(&messages(&sent[1])[3]);
    assert!(
        reask.contains("`banana` is not an object of this task"),
        "{reask}"
    );
    assert_eq!(image_count(&messages(&sent[0])[1]), 3);
    let VlmTask::StateTranslation(context) =
        VlmTask::from_task_context(sent[0].task.as_ref().unwrap()).unwrap()
    else {
        panic!("a state translation context");
    };
    assert_eq!(context.ground_truth, Some(scenario::target().init));
    // The ground truth never reaches the wire.
    assert!(!sent[0].body.to_string().contains("Closed hinge_lid"));

    // Prose is re-asked with the parse error; when the budget runs out the error says so.
    match reasoner.translate_state(&request).await {
        Err(TranslateError::NoState { attempts, .. }) => {
            assert_eq!(attempts.len(), nesy_reasoner::translate::TRANSLATION_ATTEMPTS);
            let last = attempts.last().unwrap();
            assert_eq!(last.reply, table);
            match &last.problem {
                TranslationProblem::Unreadable { error } => assert_eq!(error.line, 1),
                other => panic!("{other:?}"),
            }
        }
        other => panic!("{other:?}"),
    }
    let sent = transport.requests("translate");
    let reask = text_of(&messages(&sent[4])[3]);
    assert!(reask.contains("could not be read as a state list"), "{reask}");
    // Typographic drift (a preamble, a think section, en-dash bullets, inline code) reads
    // after one re-ask of a reply with no list at all.
    let translated = reasoner.translate_state(&request).await.unwrap();
    assert_eq!(translated.state, scenario::target().init);
    // A null content and a reply cut off at the cap are re-asked, each named as what it is.
    let translated = reasoner.translate_state(&request).await.unwrap();
    assert_eq!(translated.state, scenario::target().init);
    let problems: Vec<String> = translated.reasked.iter().map(|r| r.problem.to_string()).collect();
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(problems[0].contains("`content` was null"), "{problems:?}");
    assert!(problems[1].contains("cut off at the token cap"), "{problems:?}");
    let sent = transport.requests("translate");
    let last = messages(sent.last().unwrap());
    assert!(text_of(&last[3]).contains("`content` was null"));
    assert!(text_of(&last[5]).contains("Answer more briefly"));
    let usage = reasoner.client().usage();
    assert_eq!(usage.by_purpose["translate"].calls, 2 + 3 + 2 + 3);
}

/// A program in a python block, as a model would answer.
fn program(body: &str) -> String {
    format!("Here is the program.\n\n```python\n{body}\n```\n")
}

#[tokio::test]
async fn plausible_but_wrong_programs_are_re_asked_before_anything_runs() {
    let good = program("move_gripper_to(\"red_cube\")\nclose_gripper()\nopen_gripper()");
    let cases: [(&str, String, &str); 5] = [
        (
            "an API function that does not exist",
            program("move_gripper_to(\"red_cube\")\ngrasp_object(\"red_cube\")"),
            "name 'grasp_object' is not defined",
        ),
        (
            "a program cut off mid-line",
            program("move_gripper_to(\"red_cube\")\nclose_gripper()\nopen_gripp"),
            "did you mean 'open_gripper'?",
        ),
        (
            "a code block that never closes",
            "```python\nmove_gripper_to(\"red_cube\")\nclose_gripper()\n".to_string(),
            "is never closed",
        ),
        (
            "a reply cut off at the token cap",
            format!("{TRUNCATED}```python\nmove_gripper_to(\"red_cube\")\nclose_"),
            "cut off at the token cap",
        ),
        (
            "a function of the other end effector",
            program("move_gripper_to(\"red_cube\")\nactivate_vacuum()"),
            "activate_vacuum() is not available: this robot has a finger gripper",
        ),
    ];
    for (what, wrong, expected) in cases {
        let codegen = Scripted::with(&[("codegen", &[wrong.as_str(), good.as_str()])]);
        let reasoner = VlmReasoner::new(client(codegen.clone()))
            .unwrap()
            .with_program_check(Arc::new(SandboxChecks));
        let request = CodeGenerationRequest {
            instruction: "Place the cube in the box.".into(),
            objects: vec!["red_cube".into(), "box".into()],
            procedure: Vec::new(),
            plan: Vec::new(),
            embodiment: Embodiment::Finger,
            extended: false,
            tools: false,
            protective_stop: false,
        };
        let policy = reasoner
            .generate_code(&request)
            .await
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        assert!(
            policy.code.ends_with("open_gripper()\n"),
            "{what}: {}",
            policy.code
        );
        assert_eq!(policy.rejected.len(), 1, "{what}");
        let problem = policy.rejected[0].problem.to_string();
        assert!(problem.contains(expected), "{what}: {problem}");
        // The re-ask carries the wrong reply as the assistant's turn and the reason after it.
        let sent = codegen.requests("codegen");
        assert_eq!(sent.len(), 2, "{what}");
        let turns = messages(&sent[1]);
        assert_eq!(turns.len(), 4, "{what}");
        let feedback = text_of(&turns[3]);
        assert!(feedback.contains(expected), "{what}: {feedback}");
    }
}

#[tokio::test]
async fn a_request_over_the_image_limit_is_refused_before_it_is_sent() {
    let transport = Scripted::with(&[("describe", &["never sent"])]);
    let mut config = nesy_testkit::mock_config(BackendKind::OpenAi, "gpt-5", "http://127.0.0.1:9");
    config.max_images_per_request = Some(2);
    let client = VlmClient::with_transport(&config, transport.clone());
    let image = Image::png(nesy_testkit::png(16, 1)).unwrap();
    let parts = vec![
        nesy_vlm::Part::text("three views"),
        nesy_vlm::Part::Image(image.clone()),
        nesy_vlm::Part::Image(image.clone()),
        nesy_vlm::Part::Image(image),
    ];
    let chat = nesy_vlm::ChatRequest::new()
        .purpose("describe")
        .message(nesy_vlm::Message::user(parts));
    match client.chat(chat).await {
        Err(error @ nesy_vlm::VlmError::TooManyImages { images: 3, limit: 2 }) => {
            assert_eq!(
                nesy_reasoner::failure_kind(&error),
                nesy_core::adapt::ReasonerErrorKind::Refused
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(transport.requests("describe").is_empty());
}
