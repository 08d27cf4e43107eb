//! Every rendered prompt is pinned by a snapshot under `tests/snapshots/` (regenerate with
//! `UPDATE_SNAPSHOTS=1 cargo test -p nesy-reasoner --test integration prompts::`), and the
//! properties the issue asks of the prompts are asserted directly: the three diagnosis
//! cases, no vacuum function in the finger prompt, the real handle names, `move_parallel`'s
//! five directions, docstring signatures identical to the sandbox's `robot` module.

use std::path::PathBuf;
use std::sync::Arc;

use crate::scenario;
use nesy_core::Embodiment;
use nesy_core::adapt::{
    Ablation, AdaptConfig, InductionRequest, PatchRequest, Reasoner, ReasonerError, ViolationKind,
    derive_goal, identify, run,
};
use nesy_core::verify_procedure;
use nesy_core::{Tier, Vocabulary};
use nesy_reasoner::codegen::CodeGenerationRequest;
use nesy_reasoner::prompts::{Prompts, api_docs};
use nesy_reasoner::translate::StateTranslationRequest;
use nesy_reasoner::{KeyframeImages, NoKeyframes, Views, VlmReasoner, VlmTask};
use nesy_vlm::{BackendKind, ChatRequest, Image, Part, VlmClient};

/// Replays the scenario's replies and records the loop's requests.
#[derive(Default)]
struct Recorder {
    induce: Vec<&'static str>,
    patch: Vec<&'static str>,
    induction_requests: Vec<InductionRequest>,
    patch_requests: Vec<PatchRequest>,
}

impl Reasoner for Recorder {
    async fn induce_operator(&mut self, request: &InductionRequest) -> Result<String, ReasonerError> {
        self.induction_requests.push(request.clone());
        Ok(self.induce.remove(0).to_string())
    }
    async fn propose_patch(&mut self, request: &PatchRequest) -> Result<String, ReasonerError> {
        self.patch_requests.push(request.clone());
        Ok(self.patch.remove(0).to_string())
    }
}

fn recorded() -> Recorder {
    let mut recorder = Recorder {
        induce: vec![
            scenario::APPROACH,
            scenario::GRASP_WRONG,
            scenario::GRASP,
            scenario::CARRY,
            scenario::DROP,
        ],
        patch: vec![scenario::PATCH_NO_MATCH, scenario::PATCH],
        ..Recorder::default()
    };
    pollster::block_on(run(
        &mut recorder,
        &scenario::demo(),
        &scenario::target(),
        &scenario::config(),
    ))
    .unwrap();
    recorder
}

fn reasoner(keyframes: Arc<dyn KeyframeImages>) -> VlmReasoner {
    let config = nesy_testkit::mock_config(BackendKind::OpenAi, "gpt-5", "http://127.0.0.1:9");
    let client = VlmClient::with_transport(
        &config,
        Arc::new(nesy_testkit::InFlightCounter::new(Arc::new(Unused))),
    );
    VlmReasoner::new(client).unwrap().with_keyframes(keyframes)
}

/// Prompts are rendered, never sent, in these tests.
#[derive(Debug)]
struct Unused;

impl nesy_vlm::Transport for Unused {
    fn send<'a>(
        &'a self,
        _: &'a nesy_vlm::WireRequest,
    ) -> nesy_vlm::BoxFuture<'a, Result<nesy_vlm::WireResponse, nesy_vlm::TransportError>> {
        unreachable!("snapshot tests never send")
    }
    fn label(&self) -> String {
        "unused".into()
    }
}

/// The whole request as text: purpose, context kind, then every message with its parts
/// (images as their type and size).
fn render(request: &ChatRequest) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "purpose: {}\n",
        request.purpose.as_deref().unwrap_or("-")
    ));
    let task = request
        .task
        .as_ref()
        .expect("every prompt carries a task context");
    out.push_str(&format!("task context: {}\n", task.kind));
    out.push_str(&format!("reasoning effort: {:?}\n", request.reasoning_effort));
    for message in &request.messages {
        out.push_str(&format!("\n======== {} ========\n", message.role.as_str()));
        for part in &message.parts {
            match part {
                Part::Text(text) => {
                    out.push_str(text);
                    out.push('\n');
                }
                Part::Image(image) => {
                    out.push_str(&format!(
                        "[image {}, {} bytes]\n",
                        image.mime().as_str(),
                        image.bytes().len()
                    ));
                }
            }
        }
    }
    out
}

fn snapshot_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots")
}

#[track_caller]
fn assert_snapshot(name: &str, actual: &str) {
    let path = snapshot_dir().join(format!("{name}.txt"));
    if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
        std::fs::create_dir_all(snapshot_dir()).unwrap();
        std::fs::write(&path, actual).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e}; create it with UPDATE_SNAPSHOTS=1 cargo test -p nesy-reasoner --test integration prompts::",
            path.display()
        )
    });
    if expected != actual {
        let (line, (want, got)) = expected
            .lines()
            .zip(actual.lines())
            .enumerate()
            .find(|(_, (a, b))| a != b)
            .map(|(i, pair)| (i + 1, pair))
            .unwrap_or((
                expected.lines().count().min(actual.lines().count()) + 1,
                ("<end>", "<end>"),
            ));
        panic!(
            "{} differs from the rendered prompt at line {line}:\n  snapshot: {want:?}\n  rendered: {got:?}\n(the lengths are {} and {} lines); if the change is intended, run UPDATE_SNAPSHOTS=1 cargo test -p nesy-reasoner --test integration prompts:: and review the diff",
            path.display(),
            expected.lines().count(),
            actual.lines().count()
        );
    }
}

fn roundtrip(request: &ChatRequest) -> VlmTask {
    let context = request.task.as_ref().unwrap();
    let task = VlmTask::from_task_context(context).unwrap();
    assert_eq!(task.kind(), context.kind);
    assert_eq!(Some(task.purpose()), request.purpose.as_deref());
    assert_eq!(
        task.to_task_context(),
        *context,
        "the context survives a JSON round trip"
    );
    task
}

#[test]
fn induction_prompts() {
    let recorder = recorded();
    let with_images = reasoner(scenario::keyframes());
    let first = with_images
        .induction_request(&recorder.induction_requests[0])
        .unwrap();
    roundtrip(&first);
    assert_snapshot("induction_full_images", &render(&first));

    let retry = &recorder.induction_requests[2];
    assert_eq!((retry.step, retry.attempt, retry.feedback.len()), (1, 1, 1));
    let retry = with_images.induction_request(retry).unwrap();
    roundtrip(&retry);
    assert_snapshot("induction_retry_with_feedback", &render(&retry));

    let mut extended = recorder.induction_requests[3].clone();
    extended.task.tier = Tier::Extended;
    for s in [&mut extended.previous, &mut extended.next] {
        s.insert("(FingerGripper)".parse().unwrap());
    }
    let text_only = reasoner(Arc::new(NoKeyframes))
        .induction_request(&extended)
        .unwrap();
    assert!(
        text_only
            .messages
            .iter()
            .flat_map(|m| &m.parts)
            .all(|p| matches!(p, Part::Text(_)))
    );
    assert_snapshot("induction_extended_text_only", &render(&text_only));
    let user = render(&text_only);
    assert!(
        user.contains("The vacuum tool picks up the cube under it"),
        "the vacuum example shows in the extended tier"
    );
    assert!(
        !render(&first).contains("The vacuum tool picks up"),
        "but not in the full tier"
    );
    assert!(
        !render(&first).contains("(FingerGripper)"),
        "examples are projected onto the full tier"
    );
}

/// A vocabulary file's predicates reach every prompt that lists predicates, with their
/// kinds; the built-ins keep their lines.
#[test]
fn a_vocabulary_file_extends_the_prompts() {
    let file = nesy_testkit::workspace_root().join("fixtures/vocabulary/fine-parts.toml");
    let vocabulary = nesy_core::parse_vocabulary_file(&std::fs::read_to_string(file).unwrap()).unwrap();
    let recorder = recorded();
    let mut induction = recorder.induction_requests[0].clone();
    induction.task.vocabulary = vocabulary.clone();
    let rendered = render(
        &reasoner(Arc::new(NoKeyframes))
            .induction_request(&induction)
            .unwrap(),
    );
    assert_snapshot("induction_with_vocabulary_file", &rendered);
    let mut patch = recorder.patch_requests[0].clone();
    patch.task.vocabulary = vocabulary.clone();
    let prompts = Prompts::builtin().unwrap();
    let translation = StateTranslationRequest {
        view_set: "target/initial".into(),
        instruction: "Gather the screws on the tray.".into(),
        objects: vec!["black_screws".into(), "tray".into()],
        tier: Tier::Full,
        vocabulary,
        known: Default::default(),
        views: views(3),
        ground_truth: None,
    };
    let translation =
        nesy_reasoner::translate::build_request(&prompts, &translation, &Default::default()).unwrap();
    for text in [
        rendered,
        render(&reasoner(Arc::new(NoKeyframes)).patch_request(&patch).unwrap()),
        render(&translation),
    ] {
        assert!(text.contains("(OnTopOf ?a ?b): ?a is resting on and supported by ?b."));
        assert!(text.contains("(Finegrained ?x - parts): ?x consists of many small loose parts"));
        assert!(text.contains("(Gathered ?x - parts): the parts of ?x lie together in one pile."));
    }
}

#[test]
fn refinement_prompts() {
    let recorder = recorded();
    let r = reasoner(Arc::new(NoKeyframes));
    let first = r.patch_request(&recorder.patch_requests[0]).unwrap();
    roundtrip(&first);
    assert_snapshot("refinement_precondition", &render(&first));
    let second = r.patch_request(&recorder.patch_requests[1]).unwrap();
    assert_snapshot("refinement_with_feedback", &render(&second));

    // A goal violation: the procedure without its last action.
    let base = &recorder.patch_requests[0];
    let procedure = base.procedure[..3].to_vec();
    let goal = derive_goal(&scenario::demo_states(), &Vocabulary::new());
    let report = verify_procedure(&scenario::demo_states()[0], &procedure, Some(&goal));
    let violation = identify(&report, &procedure).expect("the goal is not reached");
    assert_eq!(violation.kind, ViolationKind::Goal);
    let goal_request = PatchRequest {
        iteration: 0,
        kind: ViolationKind::Goal,
        procedure: procedure.clone(),
        executed: procedure.clone(),
        erroneous: None,
        remaining: Vec::new(),
        failing_step: None,
        initial_state: scenario::demo_states()[0].clone(),
        error_state: violation.state.clone(),
        unmet: violation.unmet.clone(),
        feedback: Vec::new(),
        task: base.task.clone(),
    };
    let goal_chat = r.patch_request(&goal_request).unwrap();
    roundtrip(&goal_chat);
    assert_snapshot("refinement_goal", &render(&goal_chat));

    // Identification ablated: the loop only shows the plan and the initial state.
    let mut recorder = Recorder {
        induce: vec![
            scenario::APPROACH,
            scenario::GRASP,
            scenario::CARRY,
            scenario::DROP,
        ],
        patch: vec![scenario::PATCH],
        ..Recorder::default()
    };
    let config = AdaptConfig {
        ablation: Ablation::NO_IDENTIFICATION,
        ..scenario::config()
    };
    pollster::block_on(run(
        &mut recorder,
        &scenario::demo(),
        &scenario::target(),
        &config,
    ))
    .unwrap();
    assert_eq!(recorder.patch_requests[0].kind, ViolationKind::Unidentified);
    let blind = r.patch_request(&recorder.patch_requests[0]).unwrap();
    assert_snapshot("refinement_unidentified", &render(&blind));

    let system = &first.messages[0].parts;
    let Part::Text(system) = &system[0] else { panic!() };
    for case in [
        "1. Missing actions",
        "2. Redundant actions",
        "3. Different end effector",
    ] {
        assert!(system.contains(case), "the refiner lists all three cases: {case}");
    }
    assert!(
        system.contains("every later action that only served it"),
        "cascading removals"
    );
    for pair in [
        "FingerGripper/VacuumSuction",
        "GripperOpen/VacuumInactive",
        "GripperClosed/VacuumActive",
        "GripperSurrounding/VacuumAligned",
        "GripperHolding/VacuumAttached",
    ] {
        assert!(system.contains(pair), "conversion {pair}");
    }
}

fn views(seed: u64) -> Views {
    let png = |s| Image::png(nesy_testkit::png(16, s)).unwrap();
    Views::new([
        ("top", png(seed)),
        ("front", png(seed + 1)),
        ("back", png(seed + 2)),
    ])
}

#[test]
fn state_translation_prompts() {
    let prompts = Prompts::builtin().unwrap();
    let mut request = StateTranslationRequest {
        view_set: "target/initial".into(),
        instruction: "Put the fruits in the hinge box.".into(),
        objects: scenario::OBJECTS.iter().map(|o| o.to_string()).collect(),
        tier: Tier::Full,
        vocabulary: Vocabulary::new(),
        known: scenario::state(&["(GripperOpen)"]),
        views: views(5),
        ground_truth: Some(scenario::target().init),
    };
    let full = nesy_reasoner::translate::build_request(&prompts, &request, &Default::default()).unwrap();
    roundtrip(&full);
    assert_snapshot("state_translation_full_images", &render(&full));
    request.tier = Tier::Partial;
    request.known = Default::default();
    let partial = nesy_reasoner::translate::build_request(&prompts, &request, &Default::default()).unwrap();
    assert_snapshot("state_translation_partial", &render(&partial));
    assert!(
        !render(&partial).contains("Open hinge_lid"),
        "partial tier examples hold no Open/Closed"
    );
}

fn codegen_request(embodiment: Embodiment, extended: bool) -> ChatRequest {
    // The adapted procedure: the recorded run's last request with the accepted patch applied.
    let adapted = {
        let last = recorded().patch_requests.pop().unwrap();
        let patch = &nesy_core::text::parse_refinement_reply(scenario::PATCH)
            .unwrap()
            .patches[0];
        nesy_core::apply_patch(&last.procedure, patch, last.failing_step.unwrap())
            .unwrap()
            .procedure
    };
    let request = CodeGenerationRequest {
        instruction: "Put the fruits in the hinge box.".into(),
        objects: scenario::OBJECTS.iter().map(|o| o.to_string()).collect(),
        procedure: adapted,
        plan: Vec::new(),
        embodiment,
        extended,
        tools: false,
        protective_stop: false,
    };
    let prompts = Prompts::builtin().unwrap();
    let (chat, used) = nesy_reasoner::codegen::build_request(
        &prompts,
        &request,
        &nesy_vlm::PurposeSettings::default().codegen,
    )
    .unwrap();
    assert_eq!(used, extended || embodiment == Embodiment::Vacuum);
    chat
}

fn text(request: &ChatRequest) -> String {
    render(request)
}

#[test]
fn code_generation_prompts() {
    let finger = codegen_request(Embodiment::Finger, false);
    roundtrip(&finger);
    assert_snapshot("code_generation_finger", &render(&finger));
    let extended = codegen_request(Embodiment::Vacuum, true);
    roundtrip(&extended);
    assert_snapshot("code_generation_extended_vacuum", &render(&extended));

    let finger = text(&finger);
    for name in api_docs::VACUUM_FUNCTIONS {
        assert!(!finger.contains(name), "the finger prompt never shows {name}");
    }
    assert!(!finger.contains("vacuum"), "nor mentions the vacuum tool at all");
    let extended = text(&extended);
    for name in api_docs::all_functions() {
        // The tool-use functions only for a scene with a tool, which this is not.
        let offered = !api_docs::TOOL_FUNCTIONS.contains(&name);
        assert_eq!(
            extended.contains(&format!("def {name}(")),
            offered,
            "{name} is documented: {offered}"
        );
    }
    assert!(extended.contains("never mix"));
    assert!(extended.contains("- End effector:\nvacuum suction tool"));
    for prompt in [&finger, &extended] {
        assert!(
            prompt.contains("\"left\" (-y), \"right\" (+y), \"front\" (+x), \"back\" (-x) or \"up\" (+z)")
        );
        for handle in ["hinge_handle", "top_drawer_handle", "bottom_drawer_handle"] {
            assert!(prompt.contains(handle));
        }
        assert!(!prompt.contains("\"top_handle\"") && !prompt.contains("\"bottom_handle\""));
    }
}

/// The docstrings document exactly the sandbox's `robot` functions, with the same
/// parameters and defaults (nesy-policy's signatures, which mirror nesy-sim's defaults).
#[test]
fn docstring_signatures_match_the_sandbox() {
    let documented: Vec<String> = api_docs::EMBEDDED
        .iter()
        .flat_map(|(_, docs)| docs.lines())
        .filter_map(|l| l.strip_prefix("def "))
        .map(|l| l.trim_end_matches(':').replace('"', "'"))
        .collect();
    assert_eq!(documented, nesy_policy::api_signatures());
    assert_eq!(
        api_docs::all_functions().collect::<Vec<_>>(),
        nesy_policy::api_function_names()
    );
    assert!(api_docs::FINGER_DOCS.contains(&format!("depth={}", nesy_sim::api::DEFAULT_DEPTH)));
    assert!(api_docs::FINGER_DOCS.contains(&format!(
        "lift_clearance={}",
        nesy_sim::api::DEFAULT_LIFT_CLEARANCE
    )));
}

#[test]
fn every_template_renders() {
    let names: Vec<&str> = Prompts::template_names().collect();
    assert_eq!(names.len(), 12);
    // Rendering each kind above exercises every template; loading compiles them all.
    Prompts::load().unwrap();
}

/// A backend that holds replies only to JSON gets each call's schema in its own field, and
/// the JSON it answers with reaches the loop written out in the prompt's layout.
#[test]
fn json_only_backends_get_the_schema_and_their_replies_are_written_out() {
    use nesy_core::text::{normalize_reply, parse_induction_reply, parse_refinement_reply};
    use nesy_testkit::Scripted;

    let recorder = recorded();
    let induction = &recorder.induction_requests[0];
    let patch = &recorder.patch_requests[0];
    let first_action = patch.procedure[0].display_name();
    let patch_reply = format!(
        r#"{{"rationale": ["Keep the first action."], "search": ["{first_action}"], "replace": []}}"#
    );
    let induce_reply = r#"{"rationale": ["The gripper moved."], "action_semantic": "approach the handle",
        "preconditions": ["(GripperOpen)"], "effects": ["(not (GripperOpen))"]}"#;
    for backend in [BackendKind::OpenAi, BackendKind::Ollama] {
        let transport = Scripted::with(&[("induce", &[induce_reply]), ("patch", &[patch_reply.as_str()])]);
        let config = nesy_testkit::mock_config(backend, "m", "http://127.0.0.1:9");
        let mut reasoner = VlmReasoner::new(VlmClient::with_transport(&config, transport.clone())).unwrap();
        let text = pollster::block_on(reasoner.induce_operator(induction)).unwrap();
        assert!(
            text.starts_with("* Prediction Rationale:\n- The gripper moved.\n"),
            "{text}"
        );
        let parsed = parse_induction_reply(&normalize_reply(&text)).unwrap();
        assert_eq!(parsed.operator.pre.len(), 1);
        let text = pollster::block_on(reasoner.propose_patch(patch)).unwrap();
        let parsed = parse_refinement_reply(&normalize_reply(&text)).unwrap();
        assert_eq!(parsed.patches[0].search, patch.procedure[..1]);
        assert!(parsed.patches[0].replace.is_empty());

        let body = &transport.requests("induce")[0].body;
        let schema = match backend {
            BackendKind::OpenAi => {
                assert_eq!(body["response_format"]["type"], "json_schema");
                assert_eq!(body["response_format"]["json_schema"]["name"], "induce");
                assert_eq!(body["response_format"]["json_schema"]["strict"], true);
                body["response_format"]["json_schema"]["schema"].clone()
            }
            _ => body["format"].clone(),
        };
        assert_eq!(
            schema["required"],
            serde_json::json!(["rationale", "action_semantic", "preconditions", "effects"])
        );
        assert!(body.get("grammar").is_none());
    }
}
