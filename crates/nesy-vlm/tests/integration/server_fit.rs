//! Requests fitted to the server: reply constraints in each backend's own field, what a
//! llama.cpp server announces at `/props` (no pictures to a text-only model, replies sized
//! to the context window, the oldest re-ask turns left out when a conversation outgrows
//! it), a capability refusal that is not retried, and a cassette that replays the
//! announcement with the calls.

use nesy_vlm::{
    BackendKind, CassetteMode, CassetteSettings, ChatRequest, ConstrainMode, Image, Message, Part,
    ReplyConstraint, ReplyForm, ReplyLength, VlmClient, VlmError,
};
use serde_json::{Value, json};
use wiremock::matchers::{method, path};
use wiremock::{Mock, MockServer, ResponseTemplate};

use nesy_testkit::{completion, mock_config as config, png};

fn constrained() -> ChatRequest {
    ChatRequest::new()
        .message(Message::system("List the atoms."))
        .message(Message::user_text("The scene."))
        .purpose("translate")
        .constraint(ReplyConstraint {
            name: "translate".into(),
            grammar: "root ::= \"None\\n\"".into(),
            json_schema: Some(json!({"type": "object", "properties": {"atoms": {"type": "array"}}})),
        })
}

async fn chat_server() -> MockServer {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("None\n")))
        .mount(&server)
        .await;
    server
}

async fn posted_bodies(server: &MockServer) -> Vec<Value> {
    server
        .received_requests()
        .await
        .expect("recording is on")
        .into_iter()
        .filter(|r| r.method == wiremock::http::Method::POST)
        .map(|r| serde_json::from_slice(&r.body).expect("JSON body"))
        .collect()
}

async fn props_server(props: Value) -> MockServer {
    let server = chat_server().await;
    Mock::given(method("GET"))
        .and(path("/props"))
        .respond_with(ResponseTemplate::new(200).set_body_json(props))
        .mount(&server)
        .await;
    server
}

#[tokio::test]
async fn each_backend_receives_the_constraint_in_its_own_field() {
    let grammar = json!("root ::= \"None\\n\"");
    let schema = json!({"type": "object", "properties": {"atoms": {"type": "array"}}});
    let cases = [
        (
            BackendKind::LlamaCpp,
            "grammar",
            grammar.clone(),
            ReplyForm::Grammar,
        ),
        (
            BackendKind::Vllm,
            "structured_outputs",
            json!({ "grammar": grammar }),
            ReplyForm::Grammar,
        ),
        (BackendKind::Ollama, "format", schema.clone(), ReplyForm::Json),
        (
            BackendKind::OpenAi,
            "response_format",
            json!({"type": "json_schema", "json_schema": {"name": "translate", "schema": schema, "strict": true}}),
            ReplyForm::Json,
        ),
    ];
    for (backend, field, expected, form) in cases {
        let server = chat_server().await;
        let mut cfg = config(backend, "m", &format!("{}/v1", server.uri()));
        cfg.api_key = Some(nesy_vlm::SecretString::new("sk-test-0000000000000000"));
        let client = VlmClient::from_config(&cfg).unwrap();
        assert_eq!(client.reply_form(&constrained()), form, "{backend}");
        client.chat(constrained()).await.unwrap();
        let body = posted_bodies(&server).await.remove(0);
        assert_eq!(body[field], expected, "{backend}");
        for other in [
            "grammar",
            "structured_outputs",
            "format",
            "response_format",
            "json_schema",
        ] {
            assert!(
                other == field || body.get(other).is_none(),
                "{backend} also sent {other}"
            );
        }

        // `--vlm-constrain off` sends no constraint at all.
        let server = chat_server().await;
        cfg.base_url = format!("{}/v1", server.uri());
        cfg.defaults.constrain = ConstrainMode::Off;
        let client = VlmClient::from_config(&cfg).unwrap();
        assert_eq!(client.reply_form(&constrained()), ReplyForm::Free);
        client.chat(constrained()).await.unwrap();
        let body = posted_bodies(&server).await.remove(0);
        assert!(body.get(field).is_none(), "{backend} with constraints off");
    }
}

#[tokio::test]
async fn a_text_only_llamacpp_server_gets_no_pictures_and_replies_sized_to_its_window() {
    let server = props_server(json!({
        "default_generation_settings": {"n_ctx": 1024},
        "modalities": {"vision": false, "audio": false}
    }))
    .await;
    let cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    let client = VlmClient::from_config(&cfg).unwrap();
    let caps = client.capabilities().await;
    assert_eq!((caps.images, caps.context_tokens), (Some(false), Some(1024)));

    let with_image = ChatRequest::new()
        .message(Message::system("Look."))
        .message(Message::user(vec![
            Part::text("The scene."),
            Image::png(png(4, 1)).unwrap().into(),
        ]));
    let error = client.chat(with_image).await.unwrap_err();
    assert!(matches!(error, VlmError::Unsupported { .. }), "{error}");
    assert!(
        error.to_string().contains("GET /props announces text input only"),
        "{error}"
    );
    assert!(posted_bodies(&server).await.is_empty(), "nothing was sent");

    // A short prompt leaves room for the local per-purpose cap (768 for translation)...
    client.chat(constrained()).await.unwrap();
    assert_eq!(posted_bodies(&server).await[0]["max_tokens"], 768);
    // ...a long one does not: the reply gets the room that is left of the 1024 tokens.
    let mut long = constrained();
    long.messages[1] = Message::user_text("z".repeat(1500));
    client.chat(long).await.unwrap();
    let cap = posted_bodies(&server).await[1]["max_tokens"].as_u64().unwrap();
    assert!((400..768).contains(&cap), "{cap}");
    // ...and a call whose answer is one line gets the brief cap, whatever its purpose.
    let brief = ChatRequest::new()
        .purpose("d2c.observe")
        .reply_length(ReplyLength::Brief)
        .message(Message::system("Observe."))
        .message(Message::user_text("The scene."));
    client.chat(brief).await.unwrap();
    assert_eq!(posted_bodies(&server).await[2]["max_tokens"], 256);
}

#[tokio::test]
async fn a_conversation_that_outgrows_the_window_loses_its_oldest_re_asks_first() {
    let server = props_server(json!({"default_generation_settings": {"n_ctx": 600}})).await;
    let cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    let client = VlmClient::from_config(&cfg).unwrap();
    let mut chat = ChatRequest::new()
        .message(Message::system("Answer in the layout."))
        .message(Message::user_text("The task."))
        .max_output_tokens(100);
    for turn in 0..6 {
        chat = chat
            .message(Message::assistant(format!("reply {turn} {}", "x".repeat(300))))
            .message(Message::user_text(format!("correction {turn}")));
    }
    client.chat(chat).await.unwrap();
    let body = posted_bodies(&server).await.remove(0);
    let messages = body["messages"].as_array().unwrap();
    assert_eq!(messages[1]["content"], "The task.");
    let last = messages.last().unwrap();
    assert_eq!(last["content"], "correction 5", "the latest turn stays");
    assert!(messages.len() < 14 && messages.len() >= 4, "{}", messages.len());
    assert!(
        messages[2]["content"].as_str().unwrap().starts_with("reply "),
        "turns go in pairs"
    );

    // A task that alone does not fit is not sent.
    let huge = ChatRequest::new()
        .message(Message::system("s"))
        .message(Message::user_text("y".repeat(4000)));
    let error = client.chat(huge).await.unwrap_err();
    assert!(
        matches!(error, VlmError::ContextExceeded { context: 600, .. }),
        "{error}"
    );
}

#[tokio::test]
async fn a_refused_capability_is_not_retried() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(500).set_body_json(json!({
            "error": {"code": 500, "message": "image input is not supported - hint: if this is unexpected, you may need to provide the mmproj", "type": "server_error"}
        })))
        .mount(&server)
        .await;
    // vLLM's profile reads `/models`, which this server does not serve: nothing announced.
    let cfg = config(BackendKind::Vllm, "m", &format!("{}/v1", server.uri()));
    let client = VlmClient::from_config(&cfg).unwrap();
    let request = ChatRequest::new()
        .message(Message::system("Look."))
        .message(Message::user(vec![
            Part::text("The scene."),
            Image::png(png(4, 1)).unwrap().into(),
        ]));
    let error = client.chat(request).await.unwrap_err();
    let VlmError::Http {
        status: 500,
        provider,
        attempts,
        ..
    } = &error
    else {
        panic!("{error}");
    };
    assert_eq!(provider.missing_capability(), Some("image input"));
    assert_eq!(*attempts, 1);
    assert_eq!(posted_bodies(&server).await.len(), 1);
}

#[tokio::test]
async fn a_cassette_keeps_what_the_server_announced_for_its_replay() {
    let server = props_server(json!({
        "default_generation_settings": {"n_ctx": 1024},
        "modalities": {"vision": false}
    }))
    .await;
    let dir = tempfile::tempdir().unwrap();
    let cassette = dir.path().join("c.json");
    let mut cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    cfg.cassette = Some(CassetteSettings {
        path: cassette.clone(),
        mode: CassetteMode::All,
        strict: false,
        usage_report: None,
    });
    VlmClient::from_config(&cfg)
        .unwrap()
        .chat(constrained())
        .await
        .unwrap();
    let recorded = nesy_vlm::CassetteFile::load(&cassette).unwrap();
    let server_meta = recorded.meta.server.clone().unwrap();
    assert_eq!(
        (server_meta.images, server_meta.context_tokens),
        (Some(false), Some(1024))
    );

    // Replayed with the server gone, the same request is sized the same way and found.
    drop(server);
    cfg.base_url = "http://127.0.0.1:9/v1".into();
    cfg.cassette.as_mut().unwrap().mode = CassetteMode::None;
    let client = VlmClient::from_config(&cfg).unwrap();
    assert_eq!(client.capabilities().await.context_tokens, Some(1024));
    client.chat(constrained()).await.unwrap();
    // The default, sending constraints, is left out of the metadata.
    assert_eq!(recorded.meta.constrain, ConstrainMode::Auto);
    assert!(
        !std::fs::read_to_string(&cassette)
            .unwrap()
            .contains("\"constrain\"")
    );
}

/// A run refused before its first call (its prompt outgrows the window) still leaves a
/// cassette with the announcement, and its replay is refused the same way instead of
/// missing a recording.
#[tokio::test]
async fn a_refusal_before_any_call_replays_as_the_same_refusal() {
    let server = props_server(json!({"default_generation_settings": {"n_ctx": 256}})).await;
    let dir = tempfile::tempdir().unwrap();
    let cassette = dir.path().join("c.json");
    let mut cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    cfg.cassette = Some(CassetteSettings {
        path: cassette.clone(),
        mode: CassetteMode::NewEpisodes,
        strict: false,
        usage_report: None,
    });
    let long = || {
        ChatRequest::new()
            .message(Message::user_text("the scene holds a red cube. ".repeat(400)))
            .purpose("translate")
    };
    let client = VlmClient::from_config(&cfg).unwrap();
    let live = client.chat(long()).await.unwrap_err().to_string();
    assert!(live.contains("context window holds 256"), "{live}");
    client.finish().unwrap();
    assert!(posted_bodies(&server).await.is_empty(), "nothing was sent");
    let recorded = nesy_vlm::CassetteFile::load(&cassette).unwrap();
    assert!(recorded.interactions.is_empty());
    assert_eq!(recorded.meta.server.unwrap().context_tokens, Some(256));

    drop(server);
    cfg.base_url = "http://127.0.0.1:9/v1".into();
    cfg.cassette.as_mut().unwrap().mode = CassetteMode::None;
    let replayed = VlmClient::from_config(&cfg)
        .unwrap()
        .chat(long())
        .await
        .unwrap_err()
        .to_string();
    assert_eq!(replayed, live);
}

#[tokio::test]
async fn a_cassette_recorded_without_constraints_says_so() {
    let server = props_server(json!({"default_generation_settings": {"n_ctx": 4096}})).await;
    let dir = tempfile::tempdir().unwrap();
    let cassette = dir.path().join("c.json");
    let mut cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    cfg.defaults.constrain = ConstrainMode::Off;
    cfg.cassette = Some(CassetteSettings {
        path: cassette.clone(),
        mode: CassetteMode::All,
        strict: false,
        usage_report: None,
    });
    VlmClient::from_config(&cfg)
        .unwrap()
        .chat(constrained())
        .await
        .unwrap();
    assert!(posted_bodies(&server).await[0].get("grammar").is_none());
    // A replay reads it back, so that it rebuilds the same unconstrained bodies.
    let recorded = nesy_vlm::CassetteFile::load(&cassette).unwrap();
    assert_eq!(recorded.meta.constrain, ConstrainMode::Off);
}

/// Answers chat requests with HTTP 400 and `body` ahead of the server's other answers: the
/// first `times` of them, or all.
async fn refuse_first(server: &MockServer, body: &'static str, times: Option<u64>) {
    let refusal = Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .respond_with(ResponseTemplate::new(400).set_body_raw(body, "application/json"))
        .with_priority(1);
    match times {
        Some(n) => refusal.up_to_n_times(n).mount(server).await,
        None => refusal.mount(server).await,
    }
}

/// The refusal a llama.cpp server sent for a NeSyCR patch proposal against Gemma 3 270M, the
/// ninth turn of a conversation of re-asks: the estimate had the prompt below 7,168 tokens,
/// the server counted 8,236.
const RECORDED_OVERFLOW: &str = r#"{"error":{"code":400,"message":"request (8236 tokens) exceeds the available context size (8192 tokens), try increasing it","type":"exceed_context_size_error","n_prompt_tokens":8236,"n_ctx":8192}}"#;

#[tokio::test]
async fn a_prompt_the_server_counts_larger_is_fitted_again_with_its_count() {
    let server = props_server(json!({"default_generation_settings": {"n_ctx": 8192}})).await;
    refuse_first(&server, RECORDED_OVERFLOW, Some(1)).await;
    Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("* Refinement rationale:\n- x\n")))
        .with_priority(2)
        .mount(&server)
        .await;
    let cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    let client = VlmClient::from_config(&cfg).unwrap();
    // The task and six rejected proposals with their corrections: under the 6,144 tokens that
    // the 2,048-token patch cap leaves of the 8,192-token window, by the estimate.
    let mut request = ChatRequest::new()
        .purpose("patch")
        .message(Message::system("Repair the procedure."))
        .message(Message::user_text("(OnTopOf yellow_cube floor)\n".repeat(340)));
    for turn in 0..6 {
        request = request
            .message(Message::assistant(format!(
                "proposal {turn}: {}",
                "- (OverOf orange hinge_body)\n".repeat(30)
            )))
            .message(Message::user_text(format!(
                "rejected {turn}: {}",
                "- (GripperOpen)\n".repeat(20)
            )));
    }
    let response = client.chat(request).await.unwrap();
    assert!(response.text.starts_with("* Refinement rationale:"));
    let bodies = posted_bodies(&server).await;
    assert_eq!(bodies.len(), 2, "one refusal, then the request fitted again");
    let messages = |b: &Value| b["messages"].as_array().unwrap().len();
    assert_eq!(messages(&bodies[0]), 14);
    assert!(messages(&bodies[1]) < 14, "the oldest re-ask turns were left out");
    assert_eq!(messages(&bodies[1]) % 2, 0);
    // The system prompt, the task and the latest exchange stay.
    assert_eq!(bodies[1]["messages"][1], bodies[0]["messages"][1]);
    assert_eq!(
        bodies[1]["messages"].as_array().unwrap().last(),
        bodies[0]["messages"].as_array().unwrap().last()
    );
}

#[tokio::test]
async fn a_refusal_that_gives_no_count_is_not_sent_again() {
    let server = props_server(json!({"default_generation_settings": {"n_ctx": 8192}})).await;
    refuse_first(
        &server,
        r#"{"error":{"code":400,"message":"bad grammar","type":"invalid_request_error"}}"#,
        None,
    )
    .await;
    let cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    let client = VlmClient::from_config(&cfg).unwrap();
    let error = client.chat(constrained()).await.unwrap_err();
    assert!(matches!(error, VlmError::Http { status: 400, .. }), "{error}");
    assert_eq!(posted_bodies(&server).await.len(), 1);
}

#[tokio::test]
async fn an_announcement_that_fails_once_is_read_on_a_second_try() {
    let server = chat_server().await;
    // A server still loading its model answers 503 at first.
    Mock::given(method("GET"))
        .and(path("/props"))
        .respond_with(ResponseTemplate::new(503).set_body_string("Loading model"))
        .up_to_n_times(1)
        .with_priority(1)
        .mount(&server)
        .await;
    Mock::given(method("GET"))
        .and(path("/props"))
        .respond_with(ResponseTemplate::new(200).set_body_json(json!({
            "default_generation_settings": {"n_ctx": 2048},
            "modalities": {"vision": false}
        })))
        .with_priority(2)
        .mount(&server)
        .await;
    let cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", server.uri()));
    let caps = VlmClient::from_config(&cfg).unwrap().capabilities().await;
    assert_eq!((caps.images, caps.context_tokens), (Some(false), Some(2048)));

    // A server without `/props` (404) is not asked again: it announces nothing.
    let bare = chat_server().await;
    let cfg = config(BackendKind::LlamaCpp, "m", &format!("{}/v1", bare.uri()));
    let caps = VlmClient::from_config(&cfg).unwrap().capabilities().await;
    assert_eq!(caps, nesy_vlm::ServerCapabilities::UNKNOWN);
    let asked = bare.received_requests().await.unwrap();
    assert_eq!(asked.iter().filter(|r| r.url.path() == "/props").count(), 1);
}
