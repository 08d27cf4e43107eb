//! The client against an in-process OpenAI-compatible mock server on 127.0.0.1: request
//! shape per backend profile, image encoding, retries, timeouts, bad bodies, truncation,
//! the concurrency cap and secret hygiene.

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use base64::Engine as _;
use nesy_vlm::{
    BackendKind, ChatRequest, Image, ImageDetail, Message, Origin, Part, ReasoningEffort, SecretString,
    TimeoutPhase, Timeouts, Transport, TransportError, VlmClient, VlmError,
};
use serde_json::{Value, json};
use wiremock::matchers::{header, method, path, query_param};
use wiremock::{Mock, MockServer, ResponseTemplate};

use nesy_testkit::{InFlightCounter, completion, mock_config as config, png};

fn simple_request() -> ChatRequest {
    ChatRequest::new()
        .message(Message::system("You translate scenes into predicates."))
        .message(Message::user_text("Describe the scene."))
        .temperature(0.2)
        .reasoning_effort(ReasoningEffort::Low)
        .max_output_tokens(777)
        .purpose("describe")
}

/// The one POST the server received (a local backend's client also reads what the server
/// announces, with a GET, before its first call).
async fn only_request(server: &MockServer) -> (Value, wiremock::Request) {
    let requests: Vec<wiremock::Request> = server
        .received_requests()
        .await
        .expect("recording is on")
        .into_iter()
        .filter(|r| r.method == wiremock::http::Method::POST)
        .collect();
    assert_eq!(requests.len(), 1, "exactly one request expected");
    let request = requests.into_iter().next().unwrap();
    (serde_json::from_slice(&request.body).expect("JSON body"), request)
}

fn keys(body: &Value) -> Vec<&str> {
    let mut keys: Vec<&str> = body.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort();
    keys
}

#[tokio::test]
async fn openai_reasoning_profile_sends_max_completion_tokens_and_no_temperature() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .and(path("/v1/chat/completions"))
        .and(header("authorization", "Bearer sk-test-openai-key-0001"))
        .respond_with(
            ResponseTemplate::new(200)
                .set_body_json(completion("ok"))
                .insert_header("x-request-id", "req_42"),
        )
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::OpenAi, "gpt-5", &format!("{}/v1", server.uri()));
    cfg.api_key = Some(SecretString::new("sk-test-openai-key-0001"));
    let client = VlmClient::from_config(&cfg).unwrap();
    let reply = client.chat(simple_request()).await.unwrap();
    assert_eq!(reply.text, "ok");
    assert_eq!(reply.request_id.as_deref(), Some("req_42"));
    assert_eq!(reply.origin, Origin::Live);

    let (body, request) = only_request(&server).await;
    assert_eq!(
        keys(&body),
        ["max_completion_tokens", "messages", "model", "reasoning_effort"]
    );
    assert_eq!(body["model"], "gpt-5");
    assert_eq!(body["max_completion_tokens"], 777);
    assert_eq!(body["reasoning_effort"], "low");
    assert_eq!(
        body["messages"],
        json!([
            {"role": "system", "content": "You translate scenes into predicates."},
            {"role": "user", "content": "Describe the scene."}
        ])
    );
    assert_eq!(request.headers.get("content-type").unwrap(), "application/json");
    assert!(request.headers.get("api-key").is_none());
}

#[tokio::test]
async fn openai_chat_model_gets_temperature_not_reasoning_effort() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::OpenAi, "gpt-4o", &server.uri());
    cfg.api_key = Some(SecretString::new("sk-test-openai-key-0002"));
    VlmClient::from_config(&cfg)
        .unwrap()
        .chat(simple_request())
        .await
        .unwrap();
    let (body, _) = only_request(&server).await;
    assert_eq!(
        keys(&body),
        ["max_completion_tokens", "messages", "model", "temperature"]
    );
    assert_eq!(body["temperature"], 0.2);
}

#[tokio::test]
async fn azure_classic_uses_deployment_path_api_version_and_api_key_header() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .and(path("/openai/deployments/my-gpt5/chat/completions"))
        .and(query_param("api-version", "2025-04-01-preview"))
        .and(header("api-key", "azure-test-key-0003"))
        .respond_with(
            ResponseTemplate::new(200)
                .set_body_json(completion("ok"))
                .insert_header("apim-request-id", "apim-7"),
        )
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::Azure, "gpt-5", &server.uri());
    cfg.azure_deployment = Some("my-gpt5".into());
    cfg.api_key = Some(SecretString::new("azure-test-key-0003"));
    let reply = VlmClient::from_config(&cfg)
        .unwrap()
        .chat(simple_request())
        .await
        .unwrap();
    assert_eq!(reply.request_id.as_deref(), Some("apim-7"));
    let (body, request) = only_request(&server).await;
    // The deployment is in the path, so no `model`; a reasoning deployment gets no temperature.
    assert_eq!(
        keys(&body),
        ["max_completion_tokens", "messages", "reasoning_effort"]
    );
    assert!(request.headers.get("authorization").is_none());
}

#[tokio::test]
async fn azure_v1_sends_deployment_as_model_under_openai_v1() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .and(path("/openai/v1/chat/completions"))
        .and(header("api-key", "azure-test-key-0004"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let vars = [
        ("NESY_VLM_BACKEND", "azure-v1".to_string()),
        ("NESY_VLM_MODEL", "gpt-4o-deploy".to_string()),
        ("AZURE_OPENAI_ENDPOINT", server.uri()),
        ("AZURE_OPENAI_API_KEY", "azure-test-key-0004".to_string()),
    ];
    let env: std::collections::HashMap<String, String> =
        vars.iter().map(|(k, v)| (k.to_string(), v.clone())).collect();
    let cfg = nesy_vlm::VlmConfig::resolve(&Default::default(), &env).unwrap();
    VlmClient::from_config(&cfg)
        .unwrap()
        .chat(simple_request())
        .await
        .unwrap();
    let (body, _) = only_request(&server).await;
    assert_eq!(
        keys(&body),
        ["max_completion_tokens", "messages", "model", "temperature"]
    );
    assert_eq!(body["model"], "gpt-4o-deploy");
}

#[tokio::test]
async fn local_servers_get_max_tokens_and_their_auth_rules() {
    for (backend, key, detail_sent) in [
        (BackendKind::Vllm, Some("vllm-test-key-0005"), true),
        (BackendKind::Ollama, None, false),
        (BackendKind::LlamaCpp, None, false),
    ] {
        let server = MockServer::start().await;
        Mock::given(method("POST"))
            .and(path("/v1/chat/completions"))
            .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
            .mount(&server)
            .await;
        let mut cfg = config(backend, "qwen2.5-vl-7b", &format!("{}/v1", server.uri()));
        cfg.api_key = key.map(SecretString::new);
        cfg.defaults.image_detail = Some(ImageDetail::High);
        let image = Image::png(png(8, 1)).unwrap();
        let request = simple_request().message(Message::user(vec![Part::text("look"), image.into()]));
        VlmClient::from_config(&cfg).unwrap().chat(request).await.unwrap();
        let (body, http) = only_request(&server).await;
        // Not a reasoning model: temperature yes, reasoning_effort no; the cap is max_tokens.
        assert_eq!(
            keys(&body),
            ["max_tokens", "messages", "model", "temperature"],
            "{backend}"
        );
        assert_eq!(body["max_tokens"], 777);
        assert_eq!(body["model"], "qwen2.5-vl-7b");
        let image_url = &body["messages"][2]["content"][1]["image_url"];
        assert_eq!(
            image_url.get("detail").is_some(),
            detail_sent,
            "{backend}: {image_url}"
        );
        let auth = http
            .headers
            .get("authorization")
            .map(|v| v.to_str().unwrap().to_string());
        assert_eq!(auth, key.map(|k| format!("Bearer {k}")), "{backend}");
    }
}

#[tokio::test]
async fn images_are_sent_as_base64_png_data_urls_in_order() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::OpenAi, "gpt-4.1", &server.uri());
    cfg.api_key = Some(SecretString::new("sk-test-openai-key-0006"));
    cfg.defaults.image_detail = Some(ImageDetail::Low);
    let (top, front) = (png(64, 1), png(64, 2));
    let request = ChatRequest::new().message(Message::user(vec![
        Part::text("top view:"),
        Image::png(top.clone())
            .unwrap()
            .with_detail(ImageDetail::High)
            .into(),
        Part::text("front view:"),
        Image::png(front.clone()).unwrap().into(),
    ]));
    VlmClient::from_config(&cfg).unwrap().chat(request).await.unwrap();
    let (body, _) = only_request(&server).await;
    let content = body["messages"][0]["content"].as_array().unwrap();
    assert_eq!(content.len(), 4);
    assert_eq!(content[0], json!({"type": "text", "text": "top view:"}));
    assert_eq!(content[2], json!({"type": "text", "text": "front view:"}));
    for (part, bytes, detail) in [(&content[1], &top, "high"), (&content[3], &front, "low")] {
        assert_eq!(part["type"], "image_url");
        assert_eq!(part["image_url"]["detail"], detail);
        let url = part["image_url"]["url"].as_str().unwrap();
        let payload = url.strip_prefix("data:image/png;base64,").expect("PNG data URL");
        assert_eq!(
            &base64::engine::general_purpose::STANDARD.decode(payload).unwrap(),
            bytes
        );
    }
}

/// The Critic-V request whose reply (Gemma 3 270M through llama.cpp, state-text setting)
/// echoed "…Its ground-truth state follows.scene, as its ground-truth state (no pictures in
/// this setting): - (GripperClosed) …": the server had joined the user message's two text
/// parts with nothing between them.
#[tokio::test]
async fn a_message_of_text_parts_is_one_string_with_the_parts_a_blank_line_apart() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let cfg = config(BackendKind::LlamaCpp, "gemma3-270m-q4_k_m", &server.uri());
    let request = ChatRequest::new().message(Message::user(vec![
        Part::text("Review the plan for this scene. The scene's ground-truth state follows."),
        Part::text("scene, as its ground-truth state (no pictures in this setting):\n- (GripperClosed)"),
    ]));
    VlmClient::from_config(&cfg).unwrap().chat(request).await.unwrap();
    let (body, _) = only_request(&server).await;
    assert_eq!(
        body["messages"][0]["content"],
        json!(
            "Review the plan for this scene. The scene's ground-truth state follows.\n\n\
             scene, as its ground-truth state (no pictures in this setting):\n- (GripperClosed)"
        )
    );
}

#[tokio::test(start_paused = true)]
async fn rate_limit_waits_for_retry_after_on_a_paused_clock() {
    let server = MockServer::start().await;
    let limited = json!({"error": {"message": "Rate limit reached", "type": "requests", "code": "rate_limit_exceeded"}});
    Mock::given(method("POST"))
        .respond_with(
            ResponseTemplate::new(429)
                .set_body_json(limited.clone())
                .insert_header("retry-after", "7"),
        )
        .up_to_n_times(1)
        .with_priority(1)
        .mount(&server)
        .await;
    Mock::given(method("POST"))
        .respond_with(
            ResponseTemplate::new(429)
                .set_body_json(limited)
                .insert_header("retry-after-ms", "2500"),
        )
        .up_to_n_times(1)
        .with_priority(2)
        .mount(&server)
        .await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("after the wait")))
        .with_priority(3)
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::OpenAi, "gpt-5", &server.uri());
    cfg.api_key = Some(SecretString::new("sk-test-openai-key-0007"));
    // No HTTP timers on the paused clock: it would jump to them while the socket is waited for.
    cfg.timeouts = Timeouts {
        connect: None,
        read: None,
        total: None,
        pool_idle: None,
    };
    let client = VlmClient::from_config(&cfg).unwrap();
    let virtual_start = tokio::time::Instant::now();
    let real_start = std::time::Instant::now();
    let reply = client.chat(simple_request()).await.unwrap();
    let waited = virtual_start.elapsed();
    assert_eq!(reply.text, "after the wait");
    assert_eq!(reply.attempts, 3);
    // 7 s from `retry-after`, then 2.5 s from `retry-after-ms`, and nothing else.
    assert!(
        waited >= Duration::from_millis(9_500) && waited < Duration::from_millis(9_600),
        "{waited:?}"
    );
    assert!(real_start.elapsed() < Duration::from_secs(5), "no real sleeping");
    assert_eq!(client.usage().total.attempts, 3);
}

#[tokio::test]
async fn server_error_then_success_is_retried() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(500).set_body_string("upstream exploded"))
        .up_to_n_times(1)
        .with_priority(1)
        .mount(&server)
        .await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("fine now")))
        .with_priority(2)
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::Vllm, "qwen", &server.uri());
    cfg.api_key = None;
    let client = VlmClient::from_config(&cfg).unwrap();
    let reply = client.chat(simple_request()).await.unwrap();
    assert_eq!((reply.text.as_str(), reply.attempts), ("fine now", 2));
    let usage = client.usage();
    assert_eq!(
        (usage.total.calls, usage.total.attempts, usage.total.failed_calls),
        (1, 2, 0)
    );
    assert_eq!(usage.total.prompt_tokens, 120);
    assert_eq!(usage.by_purpose["describe"].reasoning_tokens, 12);
}

#[tokio::test]
async fn insufficient_quota_is_never_retried_and_client_errors_neither() {
    for (status, body, request_id) in [
        (
            429,
            json!({"error": {"message": "You exceeded your current quota", "type": "insufficient_quota", "code": "insufficient_quota"}}),
            "req_quota",
        ),
        (
            400,
            json!({"error": {"message": "Unsupported parameter: 'max_tokens'", "type": "invalid_request_error", "param": "max_tokens"}}),
            "req_bad",
        ),
    ] {
        let server = MockServer::start().await;
        Mock::given(method("POST"))
            .respond_with(
                ResponseTemplate::new(status)
                    .set_body_json(body)
                    .insert_header("x-request-id", request_id),
            )
            .mount(&server)
            .await;
        let mut cfg = config(BackendKind::OpenAi, "gpt-5", &server.uri());
        cfg.api_key = Some(SecretString::new("sk-test-openai-key-0008"));
        let client = VlmClient::from_config(&cfg).unwrap();
        let err = client.chat(simple_request()).await.unwrap_err();
        assert_eq!(
            server.received_requests().await.unwrap().len(),
            1,
            "HTTP {status} must not be retried"
        );
        assert_eq!(err.status(), Some(status));
        assert_eq!(err.request_id(), Some(request_id));
        assert_eq!(err.attempts(), Some(1));
        let VlmError::Http { provider, .. } = &err else {
            panic!("{err:?}")
        };
        if status == 429 {
            assert!(provider.is_insufficient_quota());
        } else {
            assert_eq!(provider.param.as_deref(), Some("max_tokens"));
        }
        assert!(err.to_string().contains(request_id), "{err}");
        assert_eq!(client.usage().total.failed_calls, 1);
    }
}

#[tokio::test]
async fn a_slow_server_times_out_and_is_retried_within_the_budget() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(
            ResponseTemplate::new(200)
                .set_body_json(completion("too late"))
                .set_delay(Duration::from_secs(3)),
        )
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::Vllm, "qwen", &server.uri());
    cfg.timeouts.total = Some(Duration::from_millis(200));
    cfg.retry.max_attempts = 2;
    let started = std::time::Instant::now();
    let err = VlmClient::from_config(&cfg)
        .unwrap()
        .chat(simple_request())
        .await
        .unwrap_err();
    assert!(
        started.elapsed() < Duration::from_millis(1500),
        "{:?}",
        started.elapsed()
    );
    match err {
        VlmError::Transport {
            error: TransportError::Timeout { phase, .. },
            attempts,
        } => {
            assert_eq!(phase, TimeoutPhase::Response);
            assert_eq!(attempts, 2);
        }
        other => panic!("expected a timeout, got {other:?}"),
    }
}

#[tokio::test]
async fn connection_refused_is_a_typed_transport_error() {
    // Bind then drop a listener: the port is closed on loopback.
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut cfg = config(
        BackendKind::LlamaCpp,
        "local",
        &format!("http://127.0.0.1:{port}"),
    );
    cfg.retry.max_attempts = 2;
    let err = VlmClient::from_config(&cfg)
        .unwrap()
        .chat(simple_request())
        .await
        .unwrap_err();
    assert!(
        matches!(
            err,
            VlmError::Transport {
                error: TransportError::Connect(_),
                attempts: 2
            }
        ),
        "{err:?}"
    );
}

#[tokio::test]
async fn truncated_and_invalid_bodies_are_typed_errors_with_position() {
    for (body, expected) in [
        (
            &br#"{"id":"x","choices":[{"message":{"content":"(OnTo"#[..],
            "truncated JSON at line 1 column 49",
        ),
        (b"<html>502 Bad Gateway</html>", "invalid JSON at line 1 column 1"),
        (br#"{"choices": "nope"}"#, "invalid JSON"),
    ] {
        let server = MockServer::start().await;
        Mock::given(method("POST"))
            .respond_with(ResponseTemplate::new(200).set_body_raw(body.to_vec(), "application/json"))
            .mount(&server)
            .await;
        let cfg = config(BackendKind::Ollama, "llava", &server.uri());
        let err = VlmClient::from_config(&cfg)
            .unwrap()
            .chat(simple_request())
            .await
            .unwrap_err();
        assert!(
            matches!(err, VlmError::InvalidResponse { status: 200, .. }),
            "{err:?}"
        );
        assert!(err.to_string().contains(expected), "{err}");
        assert_eq!(
            server.received_requests().await.unwrap().len(),
            1,
            "a bad body is not retried"
        );
    }
}

#[tokio::test]
async fn finish_reason_length_and_refusals_are_errors_and_still_accounted() {
    let server = MockServer::start().await;
    let mut truncated = completion("(OnTopOf red_block");
    truncated["choices"][0]["finish_reason"] = json!("length");
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(truncated))
        .up_to_n_times(1)
        .with_priority(1)
        .mount(&server)
        .await;
    let refusal = json!({"choices": [{"message": {"content": null, "refusal": "I can't help with that."}, "finish_reason": "stop"}]});
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(refusal))
        .with_priority(2)
        .mount(&server)
        .await;
    let client = VlmClient::from_config(&config(BackendKind::Vllm, "qwen", &server.uri())).unwrap();
    match client.chat(simple_request()).await.unwrap_err() {
        VlmError::Truncated {
            partial_text, usage, ..
        } => {
            assert_eq!(partial_text, "(OnTopOf red_block");
            assert_eq!(usage.unwrap().completion_tokens, 30);
        }
        other => panic!("{other:?}"),
    }
    assert!(
        matches!(client.chat(simple_request()).await.unwrap_err(), VlmError::Refusal { reason, .. } if reason == "I can't help with that.")
    );
    let usage = client.usage();
    assert_eq!(
        (
            usage.total.calls,
            usage.total.failed_calls,
            usage.total.completion_tokens
        ),
        (2, 2, 30)
    );
}

#[tokio::test]
async fn concurrency_cap_is_enforced() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(
            ResponseTemplate::new(200)
                .set_body_json(completion("ok"))
                .set_delay(Duration::from_millis(150)),
        )
        .mount(&server)
        .await;
    for (cap, calls) in [(2usize, 6usize), (6, 6)] {
        let mut cfg = config(BackendKind::Vllm, "qwen", &server.uri());
        cfg.max_concurrency = cap;
        let http: Arc<dyn Transport> = Arc::new(VlmClient::http_transport(&cfg).unwrap());
        let counter = Arc::new(InFlightCounter::new(http));
        let client = VlmClient::with_transport(&cfg, counter.clone());
        let started = std::time::Instant::now();
        let results = futures::future::join_all((0..calls).map(|_| client.chat(simple_request()))).await;
        let wall_ms = started.elapsed().as_secs_f64() * 1e3;
        assert!(results.iter().all(Result::is_ok));
        // Calls in flight together share their waiting time; their latencies add up.
        let usage = client.usage().total;
        assert!(usage.latency_ms_total >= calls as f64 * 150.0, "{usage:?}");
        assert!(
            (150.0..=wall_ms).contains(&usage.waiting_ms_total),
            "waited {} ms of {wall_ms} ms",
            usage.waiting_ms_total
        );
        let max = counter.max.load(Ordering::SeqCst);
        if cap == 2 {
            assert_eq!(max, 2, "at most two calls in flight");
            assert!(
                started.elapsed() >= Duration::from_millis(3 * 150),
                "{:?}",
                started.elapsed()
            );
        } else {
            // Without the cap binding, the same counter sees more in flight: it measures.
            assert!(max > 2, "uncapped run reached only {max}");
        }
    }
}

#[tokio::test]
async fn secrets_stay_out_of_debug_output_errors_and_logs() {
    use std::io::Write;
    #[derive(Clone, Default)]
    struct Buffer(Arc<std::sync::Mutex<Vec<u8>>>);
    impl Write for Buffer {
        fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(bytes);
            Ok(bytes.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let logs = Buffer::default();
    let writer = logs.clone();
    let subscriber = tracing_subscriber::fmt()
        .with_max_level(tracing::Level::TRACE)
        .with_writer(move || writer.clone())
        .with_ansi(false)
        .finish();
    let _guard = tracing::subscriber::set_default(subscriber);

    const KEY: &str = "sk-test-never-print-me-0009";
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(503).set_body_string("busy"))
        .mount(&server)
        .await;
    let mut cfg = config(BackendKind::OpenAi, "gpt-5", &server.uri());
    cfg.api_key = Some(SecretString::new(KEY));
    let client = VlmClient::from_config(&cfg).unwrap();
    let err = client.chat(simple_request()).await.unwrap_err();
    let shown = format!("{cfg:?}\n{client:?}\n{err:?}\n{err}\n{:?}", client.transport());
    let logged = String::from_utf8(logs.0.lock().unwrap().clone()).unwrap();
    assert!(logged.contains("retrying"), "the retries were logged: {logged}");
    for text in [&shown, &logged] {
        assert!(!text.contains("never-print-me"), "secret leaked:\n{text}");
    }
    // The key did go on the wire, where it belongs.
    let sent = &server.received_requests().await.unwrap()[0];
    assert_eq!(
        sent.headers.get("authorization").unwrap(),
        &format!("Bearer {KEY}")
    );
}

#[test]
fn a_missing_key_is_a_clear_config_error_but_replay_needs_none() {
    let cfg = config(BackendKind::OpenAi, "gpt-5", "https://api.openai.com/v1");
    let err = VlmClient::from_config(&cfg).unwrap_err().to_string();
    assert!(err.contains("OPENAI_API_KEY"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let mut replay = cfg.clone();
    replay.cassette = Some(nesy_vlm::CassetteSettings {
        path: dir.path().join("c.json"),
        mode: nesy_vlm::CassetteMode::None,
        strict: false,
        usage_report: None,
    });
    VlmClient::from_config(&replay).expect("replay needs no key");
}

#[tokio::test]
async fn absurd_retry_after_headers_do_not_panic() {
    for (name, value) in [
        ("retry-after", "1e20"),
        ("retry-after", "18446744073709551616"),
        ("retry-after", "1e308"),
        ("retry-after-ms", "1e308"),
    ] {
        let server = MockServer::start().await;
        Mock::given(method("POST"))
            .respond_with(
                ResponseTemplate::new(429)
                    .set_body_json(json!({"error": {"message": "slow down", "code": "rate_limit_exceeded"}}))
                    .insert_header(name, value),
            )
            .up_to_n_times(1)
            .with_priority(1)
            .mount(&server)
            .await;
        Mock::given(method("POST"))
            .respond_with(ResponseTemplate::new(200).set_body_json(completion("after the back-off")))
            .with_priority(2)
            .mount(&server)
            .await;
        let mut cfg = config(BackendKind::OpenAi, "gpt-5", &server.uri());
        cfg.api_key = Some(SecretString::new("sk-test-openai-key-0009"));
        let client = VlmClient::from_config(&cfg).unwrap();
        let reply = client.chat(simple_request()).await.unwrap();
        // The unrepresentable wait is ignored for the (5 ms) exponential back-off.
        assert_eq!(reply.text, "after the back-off", "{name}: {value}");
        assert_eq!(reply.attempts, 2, "{name}: {value}");
    }
}

#[tokio::test]
async fn a_key_echoed_in_a_401_never_reaches_the_error() {
    for key in ["sk-proj-test-Ab12cd34EF56gh78", "local-vllm-secret-000"] {
        let server = MockServer::start().await;
        let echo = format!(
            "Incorrect API key provided: {key}. You can find your API key at https://platform.openai.com/account/api-keys."
        );
        Mock::given(method("POST"))
            .respond_with(ResponseTemplate::new(401).set_body_json(
                json!({"error": {"message": echo, "type": "invalid_request_error", "code": "invalid_api_key"}}),
            ))
            .mount(&server)
            .await;
        let mut cfg = config(BackendKind::OpenAi, "gpt-5", &server.uri());
        cfg.api_key = Some(SecretString::new(key));
        let client = VlmClient::from_config(&cfg).unwrap();
        let err = client.chat(simple_request()).await.unwrap_err();
        assert!(matches!(err, VlmError::Http { status: 401, .. }), "{err:?}");
        for shown in [err.to_string(), format!("{err:?}"), format!("{err:#?}")] {
            assert!(!shown.contains(key), "{shown}");
            assert!(!shown.contains("Ab12cd34"), "{shown}");
        }
        assert!(err.to_string().contains("[REDACTED]"), "{err}");
    }
}
