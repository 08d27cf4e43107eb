//! `nesy cassette replies` over a run's cassettes: which induction, patch and translation
//! replies nesy's parsers read, first tries and re-asks apart, per method.

use crate::common;

use serde_json::{Value, json};

/// One recorded call with `purpose`, `user_turns` user messages and the reply `content`.
fn interaction(purpose: &str, user_turns: usize, content: &str, finish: &str, constrained: bool) -> Value {
    let mut messages = vec![json!({"role": "system", "content": "You predict actions."})];
    for turn in 0..user_turns {
        if turn > 0 {
            messages.push(json!({"role": "assistant", "content": "(an earlier reply)"}));
        }
        messages.push(json!({"role": "user", "content": format!("turn {turn}")}));
    }
    let mut body = json!({"model": "m", "messages": messages, "max_tokens": 768});
    if constrained {
        body["grammar"] = json!("root ::= \"x\"");
    }
    json!({
        "key": "0", "purpose": purpose, "recorded_at": "2026-12-05T00:00:00Z", "latency_ms": 1.0,
        "request": {"method": "POST", "path": "/chat/completions", "body": body},
        "response": {"status": 200, "headers": {}, "body": {
            "choices": [{"index": 0, "message": {"role": "assistant", "content": content}, "finish_reason": finish}],
            "usage": {"prompt_tokens": 10, "completion_tokens": 10},
            "timings": {"prompt_ms": 100.4, "predicted_ms": 200.2}
        }}
    })
}

fn cassette(interactions: Vec<Value>) -> String {
    serde_json::to_string_pretty(&json!({
        "schema_version": 1,
        "meta": {"recorder": "test", "created_at": "2026-12-05T00:00:00Z", "updated_at": "2026-12-05T00:00:00Z", "model": "m", "backend": "llamacpp"},
        "interactions": interactions,
    }))
    .unwrap()
}

const BLOCK: &str = "* Prediction Rationale:\n- The lid opened.\n* Predicted Action:\nAction Semantic:\n- open the lid\nPrecondition:\nNone\nEffect:\n- (Open box)\n";

#[test]
fn replies_counts_first_tries_and_re_asks_per_method() {
    let scratch = common::scratch();
    let cassettes = scratch.path().join("cassettes");
    let scenario = cassettes.join("obst_low_00_s0");
    std::fs::create_dir_all(&scenario).unwrap();
    // NeSyCR: a first try in prose (not read), its re-ask read; a second first try read; a
    // patch cut off at the cap.
    std::fs::write(
        scenario.join("nesycr.json"),
        cassette(vec![
            interaction(
                "induce",
                1,
                "I think the lid was opened by the robot.",
                "stop",
                true,
            ),
            interaction("induce", 2, BLOCK, "stop", true),
            interaction("induce", 1, BLOCK, "stop", true),
            interaction(
                "patch",
                1,
                "* Refinement rationale:\n- Open it first.\n\n* Refinement patch:\n<<<<<<< SEARCH\n",
                "length",
                true,
            ),
        ]),
    )
    .unwrap();
    // A baseline's stages are not judged.
    std::fs::write(
        scenario.join("demo2code.json"),
        cassette(vec![interaction(
            "d2c.observe",
            1,
            "- The lid is open.",
            "stop",
            false,
        )]),
    )
    .unwrap();
    let output = common::nesy(&[
        "cassette".into(),
        "replies".into(),
        cassettes.display().to_string(),
        "--json".into(),
    ]);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let rows: Vec<Value> = serde_json::from_slice(&output.stdout).unwrap();
    let row = |purpose: &str| {
        rows.iter()
            .find(|r| r["group"] == "nesycr" && r["purpose"] == purpose)
            .unwrap()["counts"]
            .clone()
    };
    assert_eq!(
        row("induce"),
        json!({"replies": 3, "cut_short": 0, "first": 2, "first_read": 1, "reasked": 1, "reasked_read": 1, "constrained": 3,
               "prompt_tokens": 30, "completion_tokens": 30, "server_ms": 903})
    );
    assert_eq!(row("patch")["cut_short"], 1);
    assert_eq!(row("patch")["first_read"], 0);
    assert_eq!(rows.len(), 2, "only parsed purposes are counted: {rows:?}");

    // The table names the shares.
    let output = common::nesy(&[
        "cassette".into(),
        "replies".into(),
        cassettes.display().to_string(),
    ]);
    let table = String::from_utf8_lossy(&output.stdout);
    assert!(table.contains("1/2 (50.0 %)"), "{table}");
    assert!(table.contains("2 cassette(s)"), "{table}");
}

/// `resend` sends the picked first tries again without their grammar to a live server and
/// records the answers; a second run sends nothing again; `replies` reads the new cassette.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn resend_asks_the_same_prompts_again_without_their_constraint() {
    use wiremock::matchers::{method, path};
    use wiremock::{Mock, MockServer, ResponseTemplate};

    let scratch = common::scratch();
    let source = scratch.path().join("nesycr.json");
    let recorded = vec![
        interaction("induce", 1, BLOCK, "stop", true),
        interaction("induce", 2, BLOCK, "stop", true),
        interaction("patch", 1, "no patch", "stop", true),
        // The first prompt again (another run reached it): sent once.
        interaction("induce", 1, "Sure! The robot opened the lid.", "stop", true),
        interaction("induce", 1, "The lid is closed.", "stop", true),
    ];
    std::fs::write(&source, cassette(recorded)).unwrap();
    // Two different first tries: make the last distinct so that both are sent.
    let mut file: Value = serde_json::from_str(&std::fs::read_to_string(&source).unwrap()).unwrap();
    file["interactions"][4]["request"]["body"]["messages"][1]["content"] = json!("another scene");
    std::fs::write(&source, serde_json::to_string_pretty(&file).unwrap()).unwrap();

    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .respond_with(
            ResponseTemplate::new(200).set_body_json(nesy_testkit::completion("The lid is open now.")),
        )
        .mount(&server)
        .await;
    let out = scratch.path().join("resent").join("free.json");
    let args: Vec<String> = [
        "cassette",
        "resend",
        &source.display().to_string(),
        "--out",
        &out.display().to_string(),
        "--purposes",
        "induce",
        "--first-tries",
        "--strip-constraints",
        "--vlm-backend",
        "llamacpp",
        "--vlm-base-url",
        &format!("{}/v1", server.uri()),
        "--vlm-model",
        "m",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let again = args.clone();
    let output = tokio::task::spawn_blocking(move || common::nesy(&args))
        .await
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert_eq!(
        output.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        stdout.contains("2 request(s) answered, 0 failed (sent without their constraints)"),
        "{stdout}"
    );
    assert!(
        String::from_utf8_lossy(&output.stderr)
            .contains("1 picked request(s) repeat an earlier one and are sent once"),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let posted: Vec<Value> = server
        .received_requests()
        .await
        .unwrap()
        .iter()
        .filter(|r| r.method == wiremock::http::Method::POST)
        .map(|r| serde_json::from_slice(&r.body).unwrap())
        .collect();
    assert_eq!(
        posted.len(),
        2,
        "the two distinct induction first tries, not the repeat, the re-ask or the patch"
    );
    assert!(
        posted
            .iter()
            .all(|b| b.get("grammar").is_none() && b["max_tokens"] == 768)
    );

    // Resumable: a second run answers from the new cassette and sends nothing.
    let output = tokio::task::spawn_blocking(move || common::nesy(&again))
        .await
        .unwrap();
    assert_eq!(output.status.code(), Some(0));
    let posts = server
        .received_requests()
        .await
        .unwrap()
        .iter()
        .filter(|r| r.method == wiremock::http::Method::POST)
        .count();
    assert_eq!(posts, 2);

    let (code, stdout, _) = common::run(&["cassette", "replies", &out.display().to_string(), "--json"]);
    assert_eq!(code, Some(0));
    let rows: Value = serde_json::from_str(&stdout).unwrap();
    let counts = &rows[0]["counts"];
    assert_eq!(
        (
            counts["first"].as_u64(),
            counts["first_read"].as_u64(),
            counts["constrained"].as_u64()
        ),
        (Some(2), Some(0), Some(0))
    );
}
