//! `nesy adapt --vlm URL` against a local mock OpenAI-compatible server (wiremock) with a
//! scripted responder: the live HTTP path end to end, through the real binary.
//!
//! The demo is the committed drawer demo; the target is the scene it was recorded in, so the
//! adaptation needs no patch. The responder answers operator
//! induction from the state difference the prompt shows (preconditions: the atoms the step
//! removed; effects: the difference), which the verifier accepts, and code generation with
//! prose around a fenced program.

use crate::common;

use std::sync::{Arc, Mutex};

use serde_json::{Value, json};
use wiremock::matchers::{method, path};
use wiremock::{Mock, MockServer, Request, Respond, ResponseTemplate};

/// Requests seen, by task.
#[derive(Default)]
struct Seen {
    induce: Vec<Value>,
    codegen: Vec<Value>,
    other: Vec<Value>,
}

struct Scripted {
    seen: Arc<Mutex<Seen>>,
}

fn completion(text: &str) -> ResponseTemplate {
    ResponseTemplate::new(200).set_body_json(json!({
        "id": "chatcmpl-mock",
        "object": "chat.completion",
        "model": "mock-vlm",
        "choices": [{"index": 0, "message": {"role": "assistant", "content": text}, "finish_reason": "stop"}],
        "usage": {"prompt_tokens": 1000, "completion_tokens": 100}
    }))
}

impl Respond for Scripted {
    fn respond(&self, request: &Request) -> ResponseTemplate {
        let body: Value = serde_json::from_slice(&request.body).expect("JSON body");
        let system = common::message_text(&body["messages"][0]);
        let mut seen = self.seen.lock().unwrap();
        if system.starts_with("You work out which robot action") {
            let user = common::message_text(&body["messages"][1]);
            seen.induce.push(body.clone());
            completion(&common::operator_from_diff(&user, seen.induce.len()))
        } else if system.starts_with("You write Python programs") {
            seen.codegen.push(body.clone());
            completion(
                "Sure! Following the demonstration summary step by step:\n\n```python\nnames = get_obj_names()\nprint(\"objects:\", names)\n```\n\nThe program only lists the objects.",
            )
        } else {
            seen.other.push(body.clone());
            ResponseTemplate::new(400).set_body_string("unexpected request")
        }
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn adapt_talks_to_a_live_server_and_writes_every_output() {
    let dir = common::scratch();
    // The committed drawer demo (not one recorded here: the expert's motions may change), and
    // its own scene as the target.
    let scene_path = common::workspace().join("fixtures/scenes/drawer_finger.json");
    let demo_path = common::workspace().join("fixtures/demos/adapt-realstyle/demo.mcap");

    let server = MockServer::start().await;
    let seen = Arc::new(Mutex::new(Seen::default()));
    Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .respond_with(Scripted { seen: seen.clone() })
        .mount(&server)
        .await;

    let out = dir.path().join("out");
    let url = format!("{}/v1", server.uri());
    let args = vec![
        "adapt".to_owned(),
        "--demo".into(),
        demo_path.display().to_string(),
        "--target".into(),
        scene_path.display().to_string(),
        "--vlm".into(),
        url,
        "--vlm-model".into(),
        "mock-vlm".into(),
        "--out".into(),
        out.display().to_string(),
        "--json".into(),
    ];
    let output = tokio::task::spawn_blocking(move || common::nesy(&args))
        .await
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        output.status.code(),
        Some(0),
        "stdout:\n{stdout}\nstderr:\n{stderr}"
    );

    let summary: Value = serde_json::from_str(&stdout).expect("--json prints JSON");
    assert_eq!(summary["status"], "succeeded");
    assert_eq!(summary["states"]["source"], "observed");
    assert!(summary["timing"]["vlm_s"].as_f64().unwrap() > 0.0);

    let seen = seen.lock().unwrap();
    assert!(
        seen.other.is_empty(),
        "unexpected requests: {:?}",
        seen.other.len()
    );
    // One induction per demonstrated transition, each with the six keyframe images.
    let transitions = summary["usage"]["by_purpose"]["induce"]["calls"]
        .as_u64()
        .unwrap() as usize;
    assert_eq!(seen.induce.len(), transitions);
    assert_eq!(
        summary["usage"]["total"]["live_calls"].as_u64(),
        Some(transitions as u64 + 1),
        "{}",
        summary["usage"]
    );
    for body in &seen.induce {
        let images = body["messages"][1]["content"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|p| p["type"] == "image_url")
            .count();
        assert_eq!(images, 6);
        assert_eq!(body["model"], "mock-vlm");
    }
    assert_eq!(seen.codegen.len(), 1);

    for file in [
        "world_model.json",
        "adaptation.json",
        "procedure.txt",
        "policy.py",
        "target_scene.json",
        "report.md",
        "summary.json",
        "target_top_marked.png",
        "target_front.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    assert_eq!(
        std::fs::read_to_string(out.join("policy.py")).unwrap().trim(),
        "names = get_obj_names()\nprint(\"objects:\", names)"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("![top view](target_top_marked.png)"), "{report}");
    let procedure = std::fs::read_to_string(out.join("procedure.txt")).unwrap();
    assert!(procedure.contains("# Adapted procedure"), "{procedure}");
}
