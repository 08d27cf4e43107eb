//! The baselines through `nesy bench run` over the live HTTP path, against a local server
//! answering every stage with hand-written replies in a chatty model's style (preambles,
//! bold headers, numbered lists, a closing remark) and one mistake each method must survive:
//! Demo2Code's first plan is cut off at the token cap, GPT4V-Robotics' first description
//! comes back with null content (both re-asked), Critic-V's correction numbers its SEARCH
//! line as its prompt's example does (so, as in the authors' code, it does not apply),
//! Statler's first round writes no world state (so the state it is shown next is empty),
//! MoReVQA's first check does not verify its queue (so it grounds again), and LLM-DM's first
//! domain cannot reach the goal (so the planner's report goes back and the refined domain is
//! solved). The live run records one cassette per
//! unit; replaying them offline twice gives the same records as the live run.
//!
//! These replies are not a model's: the scores say what this program does in the simulator,
//! nothing about either method.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex};

use serde_json::{Value, json};
use wiremock::matchers::{method, path};
use wiremock::{Mock, MockServer, Request, Respond, ResponseTemplate};

const SCENARIO: &str = "obst_low_00_s0";

/// The program every code-generation call gets: a plausible first attempt that handles the
/// cubes (highest first) and forgets the fruit.
const PROGRAM: &str = r#"objects = get_obj_names()
cubes = [name for name in objects if name.endswith("_cube")]
box = get_obj_pos("toy_box")
box_size = get_obj_size("toy_box")
# Take stacked cubes from the top down.
cubes.sort(key=lambda name: -get_obj_pos(name)[2])
for cube in cubes:
    height = get_obj_size(cube)[2]
    move_gripper_to(cube, depth=height / 2)
    close_gripper()
    move_to_position([box[0], box[1], box[2] + box_size[2] + height])
    open_gripper()"#;

const PLAN: &str = "Comparing the demonstration with the new scene: the green cube now sits on the red cube, so it has to come off first.

**Plan:**
1. Move the gripper around the green cube.
2. Close the gripper to grasp the green cube.
3. Carry the green cube above the toy box and open the gripper.
4. Move the gripper around the red cube.
5. Close the gripper to grasp the red cube.
6. Carry the red cube above the toy box and open the gripper.
7. Put the fruits into the hinge box as in the demonstration.

Let me know if the plan should be more detailed.";

const DESCRIPTION: &str = "Sure. Here is my analysis of the demonstration.

```text
Task: put the cubes into the toy box and the fruits into the hinge box.
Objects: the cubes and fruits are moved; toy_box and hinge_body are containers.
Actions, in order:
1. Grasp each cube from above and drop it into the toy box.
2. Open the hinge lid by its handle before putting fruit in.
3. Grasp each fruit and drop it into the hinge box.
```

The demonstration never stacks objects.";

/// One reply in the wire format.
fn completion(content: Option<&str>, finish: &str) -> ResponseTemplate {
    ResponseTemplate::new(200).set_body_json(json!({
        "id": "chatcmpl-baseline", "object": "chat.completion", "model": "mock-vlm",
        "choices": [{"index": 0, "message": {"role": "assistant", "content": content}, "finish_reason": finish}],
        "usage": {"prompt_tokens": 2000, "completion_tokens": 200}
    }))
}

/// Answers each stage by its system prompt; counts the requests per stage.
#[derive(Default)]
struct HandWritten {
    seen: Arc<Mutex<BTreeMap<&'static str, usize>>>,
}

impl Respond for HandWritten {
    fn respond(&self, request: &Request) -> ResponseTemplate {
        let body: Value = serde_json::from_slice(&request.body).expect("JSON body");
        let messages = body["messages"].as_array().cloned().unwrap_or_default();
        let system = common::message_text(&messages[0]);
        let reask = messages.len() > 2;
        let stage = [
            (
                "observe",
                "You describe a robot demonstration one moment at a time.",
            ),
            ("actions", "You turn a robot demonstration into the action plan"),
            (
                "describe",
                "You analyse a robot demonstration from its keyframes.",
            ),
            ("plan", "You plan robot actions for a new scene"),
            ("code", "You write Python programs"),
            (
                "source",
                "You turn a summarised robot demonstration into its action plan.",
            ),
            ("review", "You review a robot action plan"),
            ("correct", "You correct a robot action plan"),
            ("state", "You describe robot scenes as symbolic states."),
            ("round", "You plan robot actions step by step"),
            ("events", "You parse a robot task into the events"),
            ("ground", "You ground a queue of task events"),
            ("verify_api", "You turn a question about a robot task"),
            ("verify", "You execute a verification call"),
            ("vqa_api", "You write the visual questions"),
            ("vqa", "You answer visual questions"),
            ("queue_plan", "You plan robot actions from a grounded event queue"),
            ("recommend", "You list the actions a robot domain needs."),
            ("predicates", "You propose the predicates of a PDDL domain."),
            ("action", "You write one action of a PDDL domain."),
            ("problem", "You write the PDDL problem of a robot scene."),
            ("refine", "You repair a PDDL domain that failed to plan."),
            ("translate", "You turn a PDDL plan into robot actions in words."),
        ]
        .into_iter()
        .find(|(_, start)| system.starts_with(start))
        .map(|(stage, _)| stage);
        let Some(stage) = stage else {
            return ResponseTemplate::new(400).set_body_string("unexpected request");
        };
        let count = {
            let mut seen = self.seen.lock().unwrap();
            let n = seen.entry(stage).or_default();
            *n += 1;
            *n
        };
        match stage {
            "observe" => {
                let user = common::message_text(&messages[1]);
                let atoms: Vec<&str> = user
                    .split("Symbolic state at this keyframe:\n")
                    .nth(1)
                    .unwrap_or("")
                    .lines()
                    .take_while(|l| l.starts_with("- "))
                    .map(|l| &l[2..])
                    .collect();
                let reply = format!(
                    "Looking at the labelled views, the scene matches the listed state.\n\n**Observation:**\n- The scene shows {}.",
                    atoms.join(", ")
                );
                completion(Some(&reply), "stop")
            }
            "actions" if !reask => completion(Some(&PLAN[..PLAN.len() / 3]), "length"),
            "actions" | "plan" => completion(Some(PLAN), "stop"),
            "describe" if !reask => completion(None, "stop"),
            "describe" => completion(Some(DESCRIPTION), "stop"),
            "source" => completion(Some(SOURCE_PLAN), "stop"),
            "review" if count == 1 => completion(
                Some(
                    "Checking the plan against the scene.\n- The green cube sits on the red cube, so step 1 cannot grasp the red cube.",
                ),
                "stop",
            ),
            "review" => completion(Some("- No issue."), "stop"),
            "correct" => completion(Some(CORRECTION), "stop"),
            "state" => completion(
                Some("- (OnTopOf toy_box floor)\n- (OnTopOf green_cube red_cube)"),
                "stop",
            ),
            "round" if count == 1 => completion(
                Some(
                    "First the cubes.\n1. Grasp the green cube.\n2. Drop the green cube into the toy box.\n3. Grasp the red cube.",
                ),
                "stop",
            ),
            "events" => completion(Some(EVENTS), "stop"),
            "ground" => completion(Some(QUEUE), "stop"),
            "verify_api" => completion(
                Some("verify_action(\"Are the cubes in the toy box and the fruit in the hinge box?\")"),
                "stop",
            ),
            "verify" if count == 1 => completion(
                Some(
                    r#"{"event_queue": ["grasp the red cube", "drop it into the toy box"], "verified": false, "reason": "the green cube is on the red cube"}"#,
                ),
                "stop",
            ),
            "verify" => completion(
                Some(&format!(
                    "{{\"event_queue\": {}, \"verified\": true, \"reason\": \"the stack is cleared first\"}}",
                    &QUEUE[15..QUEUE.len() - 1]
                )),
                "stop",
            ),
            "vqa_api" => completion(
                Some(
                    "vqa(\"What is on the red cube?\")\nvqa(\"Is the hinge lid open?\")\nvqa(\"Where is the toy box?\")",
                ),
                "stop",
            ),
            "vqa" => completion(
                Some(
                    "What is on the red cube? The green cube.\nIs the hinge lid open? No.\nWhere is the toy box? Next to the cubes.",
                ),
                "stop",
            ),
            "queue_plan" => completion(Some(PLAN), "stop"),
            "recommend" => completion(
                Some(
                    "Two actions cover the domain.\n\n1. pick_up: grasp an object from the table\n2. drop_in: release a held object into a container",
                ),
                "stop",
            ),
            "predicates" => completion(
                Some("The tier covers most of it.\n- (reachable ?x): the arm can reach ?x"),
                "stop",
            ),
            "action" if common::message_text(&messages[1]).contains("pick_up") => {
                completion(Some(PICK_UP), "stop")
            }
            "action" => completion(Some(DROP_IN), "stop"),
            "problem" => completion(Some(PROBLEM), "stop"),
            "refine" => completion(Some(REFINED), "stop"),
            "translate" => completion(
                Some("1. Pick up the red cube.\n2. Drop the red cube into the toy box."),
                "stop",
            ),
            "round" => completion(
                Some(
                    "1. Drop the red cube into the toy box.\n2. Grasp the blue cube.\n3. Drop the blue cube into the toy box.\n- (InsideOf red_cube toy_box)\ngoal reached",
                ),
                "stop",
            ),
            _ => completion(
                Some(&format!(
                    "Here is the program.\n\n```python\n{PROGRAM}\n```\n\nIt reads every position at run time."
                )),
                "stop",
            ),
        }
    }
}

const PICK_UP: &str = "**Action name:**\n- pick_up\nParameters:\n1. ?x: the object\nPreconditions\n```\n(and (GripperOpen) (OnTopOf ?x floor))\n```\nEffects\n```\n(and (GripperHolding ?x) (not (GripperOpen)) (not (OnTopOf ?x floor)))\n```";

/// The mistake: dropping needs an open container, and the toy box never is.
const DROP_IN: &str = "**Action name:**\n- drop_in\nParameters:\n1. ?x: the held object\n2. ?b: the container\nPreconditions\n```\n(and (GripperHolding ?x) (Open ?b))\n```\nEffects\n```\n(and (InsideOf ?x ?b) (GripperOpen) (not (GripperHolding ?x)))\n```";

const PROBLEM: &str = "From the views:\n\nInitial state\n```\n(:objects red_cube green_cube blue_cube toy_box floor)\n```\n```\n(:init (GripperOpen) (OnTopOf red_cube floor) (OnTopOf toy_box floor))\n```\nGoal state\n```\n(:goal (InsideOf red_cube toy_box))\n```";

const REFINED: &str = "The toy box has no lid, so drop_in should not need it open.\n```\n(define (domain llmdm)\n  (:requirements :strips :negative-preconditions)\n  (:predicates (GripperOpen) (GripperHolding ?x) (OnTopOf ?x ?y) (InsideOf ?x ?y))\n  (:action pick_up :parameters (?x) :precondition (and (GripperOpen) (OnTopOf ?x floor))\n    :effect (and (GripperHolding ?x) (not (GripperOpen)) (not (OnTopOf ?x floor))))\n  (:action drop_in :parameters (?x ?b) :precondition (GripperHolding ?x)\n    :effect (and (InsideOf ?x ?b) (GripperOpen) (not (GripperHolding ?x)))))\n```";

const EVENTS: &str = r#"{"question": "Are the cubes in the toy box and the fruit in the hinge box?", "conjunction": "and", "parse_event": ["put the cubes into the toy box", "put the fruit into the hinge box"], "event_object": ["red_cube, green_cube, blue_cube, toy_box", "lemon, hinge_body"], "classify": "manipulation"}"#;

const QUEUE: &str = r#"{"event_queue": ["move the green cube off the red cube", "put the cubes into the toy box", "open the hinge lid", "put the lemon into the hinge box"]}"#;

const SOURCE_PLAN: &str = "**Demonstrated plan:**
1. Move the gripper around the red cube.
2. Close the gripper to grasp the red cube.
3. Drop the red cube into the toy box.
4. Put the fruits into the hinge box.";

const CORRECTION: &str = "Case 1: the green cube must be moved first.

<<<<<<< SEARCH
1. Move the gripper around the red cube.
=======
1. Move the gripper around the green cube.
2. Drop the green cube into the toy box.
3. Move the gripper around the red cube.
>>>>>>> REPLACE";

const BASELINES: &str = "demo2code,gpt4v-robotics,critic-v,morevqa,statler,llm-dm";

fn bench(run: &Path, demos: &Path, vlm: &str) -> std::process::Output {
    bench_with(run, demos, vlm, BASELINES, SCENARIO, &[])
}

/// `nesy bench run` of `methods` on `scenarios`, which must exit 0.
fn bench_with(
    run: &Path,
    demos: &Path,
    vlm: &str,
    methods: &str,
    scenarios: &str,
    extra: &[&str],
) -> std::process::Output {
    let mut args: Vec<String> = vec![
        "bench".into(),
        "run".into(),
        run.display().to_string(),
        "--methods".into(),
        methods.into(),
        "--scenarios".into(),
        scenarios.into(),
        "--vlm".into(),
        vlm.into(),
        "--demos".into(),
        demos.display().to_string(),
    ];
    if vlm != "oracle" {
        args.extend(["--vlm-model".to_owned(), "mock-vlm".to_owned()]);
    }
    args.extend(extra.iter().map(|s| s.to_string()));
    let output = common::nesy(&args);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// The unit records of a run, by method, without the fields that measure time or place.
fn records(run: &Path) -> BTreeMap<String, Value> {
    records_by_unit(run)
        .into_values()
        .map(|r| (r["method"].as_str().unwrap().to_string(), r))
        .collect()
}

/// The unit records of a run by unit (scenario and variant), without the fields that
/// measure time or place, or depend on the responder's configuration and price.
fn records_by_unit(run: &Path) -> BTreeMap<String, Value> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(run.join("results")).unwrap().flatten() {
        for line in std::fs::read_to_string(entry.path()).unwrap().lines() {
            let mut record: Value = serde_json::from_str(line).unwrap();
            for volatile in ["finished_at", "artifacts"] {
                record.as_object_mut().unwrap().remove(volatile);
            }
            let effort = record["effort"].as_object_mut().unwrap();
            effort.retain(|k, _| !k.ends_with("_s"));
            let unit = format!(
                "{}/{}",
                record["scenario"].as_str().unwrap(),
                record["variant"].as_str().unwrap()
            );
            out.insert(unit, record);
        }
    }
    out
}

/// A local server answering with [`HandWritten`], and its per-stage request counts.
async fn hand_written_server() -> (MockServer, Arc<Mutex<BTreeMap<&'static str, usize>>>) {
    let server = MockServer::start().await;
    let responder = HandWritten::default();
    let seen = responder.seen.clone();
    Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .respond_with(responder)
        .mount(&server)
        .await;
    (server, seen)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn baselines_run_live_record_and_replay_to_the_same_records() {
    let scratch = common::scratch();
    let demos = scratch.path().join("demos");
    let live = scratch.path().join("live");
    let (server, seen) = hand_written_server().await;
    let url = format!("{}/v1", server.uri());
    let (live_dir, demos_dir) = (live.clone(), demos.clone());
    tokio::task::spawn_blocking(move || bench(&live_dir, &demos_dir, &url))
        .await
        .unwrap();
    let live_records = records(&live);
    let seen = seen.lock().unwrap().clone();

    let d2c = &live_records["demo2code"];
    // Demo2Code and Critic-V each observe every keyframe once.
    let keyframes = seen["observe"] as u64 / 2;
    assert!(keyframes >= 3, "{seen:?}");
    let by_purpose = &d2c["effort"]["calls_by_purpose"];
    assert_eq!(by_purpose["d2c.observe"], keyframes);
    // The cut-off plan and its re-ask.
    assert_eq!(by_purpose["d2c.actions"], 2);
    assert_eq!(d2c["spec"]["kind"], "plan");
    assert_eq!(d2c["spec"]["steps"], 7);
    let gpt4v = &live_records["gpt4v-robotics"];
    let by_purpose = &gpt4v["effort"]["calls_by_purpose"];
    // The null-content description and its re-ask, then the plan.
    assert_eq!(by_purpose["gpt4v.describe"], 2);
    assert_eq!(by_purpose["gpt4v.plan"], 1);
    assert_eq!(
        gpt4v["effort"]["images"].as_u64().unwrap(),
        2 * keyframes * 6 + 6,
        "{gpt4v}"
    );
    // Critic-V: the observations, the unadapted plan, two reviews and the one correction
    // between them, which did not apply.
    let critic = &live_records["critic-v"];
    let by_purpose = &critic["effort"]["calls_by_purpose"];
    assert_eq!(by_purpose["d2c.observe"], keyframes);
    assert_eq!(by_purpose["d2c.source_actions"], 1);
    assert_eq!(by_purpose["critic.feedback"], 2);
    assert_eq!(by_purpose["critic.correction"], 1);
    assert_eq!(critic["spec"]["steps"], 4);
    assert_eq!(critic["spec"]["iterations"], 2);
    // Statler: the description, the state, two rounds until "goal reached".
    let statler = &live_records["statler"];
    let by_purpose = &statler["effort"]["calls_by_purpose"];
    assert_eq!(by_purpose["statler.state"], 1);
    assert_eq!(by_purpose["statler.actions"], 2);
    assert_eq!(statler["spec"]["steps"], 6);
    // MoReVQA: the description (re-asked), M1, two rounds of three calls, M3 and the plan.
    let morevqa = &live_records["morevqa"];
    let by_purpose = &morevqa["effort"]["calls_by_purpose"];
    assert_eq!(by_purpose["morevqa.parse"], 1);
    assert_eq!(by_purpose["morevqa.ground"], 2);
    assert_eq!(by_purpose["morevqa.verify"], 2);
    assert_eq!(by_purpose["morevqa.vqa"], 1);
    assert_eq!(morevqa["spec"]["iterations"], 2);
    // LLM-DM: one construction per recommended action, one refinement, then the plan in words.
    let llmdm = &live_records["llm-dm"];
    let by_purpose = &llmdm["effort"]["calls_by_purpose"];
    assert_eq!(by_purpose["llmdm.action"], 2);
    assert_eq!(by_purpose["llmdm.refine"], 1);
    assert_eq!(by_purpose["llmdm.translate"], 1);
    assert_eq!(llmdm["spec"]["steps"], 2);
    assert_eq!(llmdm["spec"]["iterations"], 1);
    // The same program ran for all: it puts the cubes in the box and never the fruit.
    for record in [d2c, gpt4v, critic, morevqa, statler, llmdm] {
        assert_eq!(record["status"], "execution_failed", "{record}");
        assert_eq!(record["scores"]["sr"], 0.0, "{record}");
        assert_eq!(record["scores"]["gc"], 0.5, "{record}");
    }

    // The manifest lists every departure from the authors' code.
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(live.join("manifest.json")).unwrap()).unwrap();
    let deviations = |id: &str| -> String {
        manifest["variants"]
            .as_array()
            .unwrap()
            .iter()
            .find(|v| v["id"] == id)
            .map(|v| v["deviations"].to_string())
            .unwrap_or_default()
    };
    assert!(deviations("llm-dm").contains("not Fast Downward"), "{manifest}");
    assert!(
        deviations("morevqa").contains("authors' loop has no bound"),
        "{manifest}"
    );

    // The report counts the calls per method and stage.
    let stages = std::fs::read_to_string(live.join("tables/stages.csv")).unwrap();
    assert!(
        stages.contains(&format!("demo2code,d2c.observe,1,{keyframes},")),
        "{stages}"
    );
    assert!(stages.contains("critic-v,critic.feedback,1,2,"), "{stages}");
    let report = std::fs::read_to_string(live.join("report.md")).unwrap();
    assert!(report.contains("## Model calls per method and stage"), "{report}");

    // Offline: the live run's cassettes replayed, twice, give the live records.
    let cassettes = live.join("cassettes");
    for name in ["replay-1", "replay-2"] {
        let run = scratch.path().join(name);
        let vlm = format!("replay:{}", cassettes.display());
        let (run_dir, demos_dir) = (run.clone(), demos.clone());
        tokio::task::spawn_blocking(move || bench(&run_dir, &demos_dir, &vlm))
            .await
            .unwrap();
        let replayed = records(&run);
        for (method, record) in &live_records {
            let mut expected = record.clone();
            let mut got = replayed[method].clone();
            for r in [&mut expected, &mut got] {
                r.as_object_mut().unwrap().remove("config_hash");
                r["effort"].as_object_mut().unwrap().remove("cost_usd");
            }
            assert_eq!(got, expected, "{method}");
        }
    }
}

/// `--methods all` over the three fixture scenarios of the README's small run, replayed:
/// NeSyCR's calls recorded from the offline responder, the six baselines' from the
/// hand-written server; both sets of cassettes together replay twice into the same records,
/// and those are the recorded runs' records.
/// The text-observation setting: every baseline sees each scene's ground-truth state in place
/// of its pictures, and NeSyCR's induction carries the keyframes' states alone, so that a
/// text-only model can answer all of them. No request carries an image; the manifest and the
/// report name the setting.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn in_the_text_observation_setting_no_method_sends_a_picture() {
    let scratch = common::scratch();
    let demos = scratch.path().join("demos");
    let run = scratch.path().join("text");
    let (server, seen) = hand_written_server().await;
    let url = format!("{}/v1", server.uri());
    let methods = format!("{BASELINES},nesycr");
    let (run_dir, demos_dir) = (run.clone(), demos.clone());
    tokio::task::spawn_blocking(move || {
        bench_with(
            &run_dir,
            &demos_dir,
            &url,
            &methods,
            SCENARIO,
            &["--observation", "state-text"],
        )
    })
    .await
    .unwrap();
    // The chat requests (the client also asks the server what it announces).
    let requests: Vec<_> = server
        .received_requests()
        .await
        .unwrap()
        .into_iter()
        .filter(|r| r.method == wiremock::http::Method::POST)
        .collect();
    let mut induction = 0;
    for request in &requests {
        let body: Value = serde_json::from_slice(&request.body).unwrap();
        let text = body.to_string();
        assert!(
            !text.contains("image_url"),
            "a picture was sent: {}",
            &text[..text.len().min(400)]
        );
        if common::message_text(&body["messages"][0])
            .starts_with("You work out which robot action was executed")
        {
            induction += 1;
        }
    }
    assert!(induction > 0, "NeSyCR's induction was never asked");
    // Each scene the baselines were shown came as its state.
    let seen = seen.lock().unwrap().clone();
    assert!(seen["observe"] >= 6 && seen["describe"] >= 1, "{seen:?}");
    let described = requests
        .iter()
        .map(|r| serde_json::from_slice::<Value>(&r.body).unwrap())
        .find(|b| common::message_text(&b["messages"][0]).starts_with("You analyse a robot demonstration"))
        .unwrap();
    let user = common::message_text(&described["messages"][1]);
    assert!(
        user.contains("demo keyframe 1, as its ground-truth state (no pictures in this setting):\n- ("),
        "{user}"
    );
    let records = records(&run);
    for (method, record) in &records {
        assert_eq!(record["effort"]["images"], 0, "{method}");
    }
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(run.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["settings"]["observation"], "state-text");
    let report = std::fs::read_to_string(run.join("report.md")).unwrap();
    assert!(
        report.contains("- observation: each scene's ground-truth state as text"),
        "{report}"
    );
}

/// A local server restarted on another port serves the same experiment: the run resumes
/// (here with nothing left to do). Another model is another experiment and is refused.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_live_run_resumes_against_its_server_on_another_port() {
    let scratch = common::scratch();
    let (demos, run) = (scratch.path().join("demos"), scratch.path().join("run"));
    let (first, _) = hand_written_server().await;
    let (second, _) = hand_written_server().await;
    let urls = [format!("{}/v1", first.uri()), format!("{}/v1", second.uri())];
    let (run_dir, demos_dir) = (run.clone(), demos.clone());
    let refused = tokio::task::spawn_blocking(move || {
        for url in &urls {
            bench_with(&run_dir, &demos_dir, url, "demo2code", SCENARIO, &[]);
        }
        let args: Vec<String> = [
            "bench",
            "run",
            &run_dir.display().to_string(),
            "--methods",
            "demo2code",
            "--scenarios",
            SCENARIO,
            "--vlm",
            &urls[1],
            "--vlm-model",
            "another-model",
            "--demos",
            &demos_dir.display().to_string(),
        ]
        .map(str::to_owned)
        .to_vec();
        common::nesy(&args)
    })
    .await
    .unwrap();
    assert_eq!(refused.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("another configuration") && stderr.contains("another-model"),
        "{stderr}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn all_methods_replay_to_identical_records_over_the_fixture_scenarios() {
    const FIXTURES: &str = "obst_low_00_s0,grip_low_02_s0,comb_low_00_s0";
    let scratch = common::scratch();
    let demos = scratch.path().join("demos");
    let oracle = scratch.path().join("oracle");
    let live = scratch.path().join("live");
    let (oracle_dir, demos_dir) = (oracle.clone(), demos.clone());
    tokio::task::spawn_blocking(move || {
        bench_with(
            &oracle_dir,
            &demos_dir,
            "oracle",
            "nesycr",
            FIXTURES,
            &["--record-cassettes"],
        )
    })
    .await
    .unwrap();
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .respond_with(HandWritten::default())
        .mount(&server)
        .await;
    let url = format!("{}/v1", server.uri());
    let (live_dir, demos_dir) = (live.clone(), demos.clone());
    // One unit at a time: the server's replies depend on how often it was asked.
    tokio::task::spawn_blocking(move || {
        bench_with(&live_dir, &demos_dir, &url, BASELINES, FIXTURES, &["--jobs", "1"])
    })
    .await
    .unwrap();
    let mut recorded = records_by_unit(&oracle);
    recorded.extend(records_by_unit(&live));
    assert_eq!(recorded.len(), 3 * 7, "{:?}", recorded.keys());

    let cassettes = scratch.path().join("cassettes");
    for from in [oracle.join("cassettes"), live.join("cassettes")] {
        nesy_testkit::copy_tree(&from, &cassettes);
    }
    let vlm = format!("replay:{}", cassettes.display());
    let mut replays = Vec::new();
    for name in ["replay-1", "replay-2"] {
        let run = scratch.path().join(name);
        let (run_dir, demos_dir, vlm) = (run.clone(), demos.clone(), vlm.clone());
        tokio::task::spawn_blocking(move || {
            bench_with(&run_dir, &demos_dir, &vlm, "all,imitation,replan", FIXTURES, &[])
        })
        .await
        .unwrap();
        replays.push(records_by_unit(&run));
    }
    let strip = |mut r: Value| {
        r.as_object_mut().unwrap().remove("config_hash");
        r["effort"].as_object_mut().unwrap().remove("cost_usd");
        r
    };
    assert_eq!(replays[0], replays[1], "two replays differ");
    // The controls call no model and left no cassette; they replay without one.
    for scenario in FIXTURES.split(',') {
        for control in ["imitation", "replan"] {
            let status = &replays[0][&format!("{scenario}/{control}")]["status"];
            assert_ne!(status, "transport_error", "{scenario}/{control}");
        }
    }
    for (unit, record) in &recorded {
        let got = replays[0]
            .get(unit)
            .unwrap_or_else(|| panic!("{unit} not replayed"));
        assert_eq!(strip(got.clone()), strip(record.clone()), "{unit}");
    }
    // NeSyCR's replayed answers are the responder's: it succeeds on all three.
    for scenario in FIXTURES.split(',') {
        assert_eq!(
            recorded[&format!("{scenario}/nesycr")]["status"],
            "succeeded",
            "{scenario}"
        );
    }
}
