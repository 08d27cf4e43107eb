//! Cassettes against an in-process mock server: record → replay byte for byte, FIFO order
//! (by send order when concurrent calls complete out of order),
//! helpful misses, blob de-duplication, secret hygiene, resuming, strict mode, and the
//! inspect/prune/verify tools.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nesy_vlm::{
    BackendKind, BoxFuture, CassetteError, CassetteMode, CassetteOptions, CassetteTransport, ChatRequest,
    Image, Message, Origin, Part, SecretString, TaskContext, Transport, TransportError, VlmClient, VlmConfig,
    VlmError, WireRequest, WireResponse,
};
use nesy_vlm::{CassetteFile, cassette_tools as tools};
use serde_json::json;
use wiremock::matchers::method;
use wiremock::{Mock, MockServer, ResponseTemplate};

use nesy_testkit::{completion, mock_config as config, png};

/// A body whose exact bytes (odd spacing, key order, trailing newline) must survive.
const ODD_BODY: &str = "{ \"id\":\"c-1\",\"model\":\"gpt-5\",  \"choices\":[{\"message\":{\"content\":\"(On a b)\"},\"finish_reason\":\"stop\"}],\"usage\":{\"prompt_tokens\":900,\"completion_tokens\":40}}\n";

fn request(prompt: &str, images: &[&[u8]]) -> ChatRequest {
    let mut parts = vec![Part::text(prompt)];
    parts.extend(
        images
            .iter()
            .map(|bytes| Part::from(Image::png(bytes.to_vec()).unwrap())),
    );
    ChatRequest::new()
        .message(Message::system("You are a careful planner."))
        .message(Message::user(parts))
        .purpose("induce")
        .task(TaskContext::new(
            "induce_operator",
            json!({"ground_truth": ["(OnTopOf a b)"]}),
        ))
}

fn openai(server: &MockServer) -> VlmConfig {
    let mut cfg = config(BackendKind::OpenAi, "gpt-5", &server.uri());
    cfg.api_key = Some(SecretString::new("sk-test-cassette-key-0010"));
    cfg
}

fn with_cassette(mut cfg: VlmConfig, path: &Path, mode: CassetteMode) -> VlmConfig {
    cfg.cassette = Some(nesy_vlm::CassetteSettings {
        path: path.to_path_buf(),
        mode,
        strict: false,
        usage_report: None,
    });
    cfg
}

async fn served(server: &MockServer) -> usize {
    server.received_requests().await.unwrap().len()
}

#[tokio::test]
async fn record_then_replay_is_byte_identical_and_offline() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(
            ResponseTemplate::new(200)
                .set_body_raw(ODD_BODY.as_bytes().to_vec(), "application/json")
                .insert_header("x-request-id", "req_rec")
                .insert_header("set-cookie", "session=abc")
                .insert_header("openai-organization", "org-secret"),
        )
        .mount(&server)
        .await;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.json");
    let image = png(32, 3);

    let recorder =
        VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::Once)).unwrap();
    let wire = recorder.wire_request(&request("first", &[&image]));
    let live = recorder.transport().send(&wire).await.unwrap();
    assert_eq!(live.origin, Origin::Live);
    assert_eq!(&live.body[..], ODD_BODY.as_bytes());
    let live_chat = recorder.chat(request("second", &[&image])).await.unwrap();
    assert_eq!(served(&server).await, 2);

    // Replay with a config whose server does not exist and with no key: nothing goes out.
    let mut offline = config(BackendKind::OpenAi, "gpt-5", "http://127.0.0.1:9");
    offline.cassette = Some(nesy_vlm::CassetteSettings {
        path: path.clone(),
        mode: CassetteMode::None,
        strict: true,
        usage_report: None,
    });
    let replayer = VlmClient::from_config(&offline).unwrap();
    let replayed = replayer.transport().send(&wire).await.unwrap();
    assert_eq!(replayed.origin, Origin::Replayed);
    assert_eq!(replayed.status, live.status);
    assert_eq!(&replayed.body[..], &live.body[..], "byte-identical body");
    assert_eq!(replayed.request_id(), Some("req_rec"));
    let replayed_chat = replayer.chat(request("second", &[&image])).await.unwrap();
    assert_eq!(replayed_chat.text, live_chat.text);
    assert_eq!(replayed_chat.usage, live_chat.usage);
    assert_eq!(replayed_chat.origin, Origin::Replayed);
    assert_eq!(served(&server).await, 2, "replay must not touch the server");
    let usage = replayer.finish().expect("strict: every interaction used");
    assert_eq!(usage.total.replayed_calls, 1);

    // The file: schema, metadata, allowlisted headers only, images by reference.
    let text = std::fs::read_to_string(&path).unwrap();
    let file = CassetteFile::load(&path).unwrap();
    assert_eq!(file.schema_version, 1);
    assert_eq!(file.meta.model.as_deref(), Some("gpt-5"));
    assert_eq!(file.meta.backend.as_deref(), Some("openai"));
    assert!(file.meta.recorder.starts_with("nesy-vlm "));
    assert_eq!(file.interactions[1].purpose.as_deref(), Some("induce"));
    let headers: Vec<&str> = file.interactions[0]
        .outcome()
        .unwrap()
        .unwrap()
        .headers
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(headers, ["content-type", "x-request-id"]);
    for forbidden in [
        "set-cookie",
        "session=abc",
        "org-secret",
        "sk-test-cassette",
        "ground_truth",
        "base64,",
    ] {
        assert!(!text.contains(forbidden), "{forbidden} in cassette:\n{text}");
    }
    assert!(text.contains("blob:sha256:"));
}

#[tokio::test]
async fn identical_requests_replay_in_recorded_order_then_miss() {
    let server = MockServer::start().await;
    for (priority, answer) in [(1u8, "first answer"), (2, "second answer")] {
        Mock::given(method("POST"))
            .respond_with(ResponseTemplate::new(200).set_body_json(completion(answer)))
            .up_to_n_times(1)
            .with_priority(priority)
            .mount(&server)
            .await;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fifo.json");
    let recorder = VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::All)).unwrap();
    for expected in ["first answer", "second answer"] {
        assert_eq!(recorder.chat(request("same", &[])).await.unwrap().text, expected);
    }
    let replayer =
        VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::None)).unwrap();
    // The task context is not part of the key: a different one replays the same recording.
    let other_task = request("same", &[]).task(TaskContext::new("other_task", json!({"anything": 1})));
    assert_eq!(replayer.chat(other_task).await.unwrap().text, "first answer");
    assert_eq!(
        replayer.chat(request("same", &[])).await.unwrap().text,
        "second answer"
    );
    let err = replayer.chat(request("same", &[])).await.unwrap_err().to_string();
    assert!(
        err.contains("recorded 2 time(s) and every recording was already replayed"),
        "{err}"
    );
}

#[tokio::test]
async fn a_miss_explains_itself_with_json_pointer_diffs_and_the_rerecord_command() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("miss.json");
    let recorder = VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::All)).unwrap();
    recorder
        .chat(request("Put the red block on the tray.", &[]))
        .await
        .unwrap();
    recorder
        .chat(request(
            "Something entirely different about drawers and lids.",
            &[&png(16, 1)],
        ))
        .await
        .unwrap();

    let replayer =
        VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::None)).unwrap();
    let err = replayer
        .chat(request("Put the blue block on the tray.", &[]))
        .await
        .unwrap_err();
    let VlmError::Cassette(CassetteError::Miss(miss)) = &err else {
        panic!("expected a cassette miss, got {err:?}")
    };
    assert_eq!(miss.nearest[0].index, 0, "the red-block request is nearest");
    assert_eq!(miss.nearest[0].diffs.len(), 1);
    assert_eq!(miss.nearest[0].diffs[0].pointer, "/messages/1/content");
    let text = err.to_string();
    for needle in [
        path.to_str().unwrap(),
        "mode none",
        "no recorded request matches",
        "request: POST /chat/completions",
        "model gpt-5, 2 message(s), 0 image(s), purpose induce",
        "/messages/1/content: \"Put the red block on the tray.\" -> \"Put the blue block on the tray.\"",
        "NESY_CASSETTE_MODE=new_episodes ",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in:\n{text}");
    }
    // A miss is not retried, and it never reached the server.
    assert_eq!(served(&server).await, 2);
    assert_eq!(replayer.usage().total.attempts, 1);
}

#[tokio::test]
async fn images_are_stored_once_per_content_hash() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blobs.json");
    let (top, front) = (png(384, 1), png(384, 2));
    let client = VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::All)).unwrap();
    for step in 0..4 {
        client
            .chat(request(&format!("step {step}"), &[&top, &front]))
            .await
            .unwrap();
    }
    let mut blobs: Vec<PathBuf> = std::fs::read_dir(dir.path().join("blobs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    blobs.sort();
    assert_eq!(blobs.len(), 2, "two distinct images across four calls");
    for blob in &blobs {
        let bytes = std::fs::read(blob).unwrap();
        assert!(bytes == top || bytes == front);
    }
    let size = std::fs::metadata(&path).unwrap().len();
    assert!(
        size < 16 * 1024,
        "cassette holds references, not images: {size} bytes"
    );
    assert!(size * 10 < (top.len() + front.len()) as u64);
    let inspection = tools::inspect(&path).unwrap();
    assert_eq!(inspection.distinct_images, 2);
    assert_eq!(inspection.interactions.iter().map(|i| i.images).sum::<usize>(), 8);
    assert!(tools::verify(&path).unwrap().is_empty());
}

#[tokio::test]
async fn secrets_echoed_by_a_server_are_redacted_and_auth_headers_never_stored() {
    let key = "sk-test-echoed-secret-0011";
    let server = MockServer::start().await;
    let echoed =
        json!({"choices": [{"message": {"content": format!("your key is {key}")}, "finish_reason": "stop"}]});
    Mock::given(method("POST"))
        .respond_with(
            ResponseTemplate::new(200)
                .set_body_json(echoed)
                .insert_header("authorization", format!("Bearer {key}"))
                .insert_header("api-key", key),
        )
        .mount(&server)
        .await;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("secret.json");
    let mut cfg = openai(&server);
    cfg.api_key = Some(SecretString::new(key));
    let client = VlmClient::from_config(&with_cassette(cfg, &path, CassetteMode::All)).unwrap();
    client.chat(request("hello", &[])).await.unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(!text.contains(key), "{text}");
    assert!(text.contains("[REDACTED]"));
    assert!(
        !text.to_ascii_lowercase().contains("authorization") && !text.contains("api-key"),
        "{text}"
    );
}

#[tokio::test]
async fn new_episodes_resumes_a_broken_recording() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("resume.json");
    // A first run recorded one call and then "crashed".
    let first = VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::Once)).unwrap();
    first.chat(request("call 1", &[])).await.unwrap();
    drop(first);
    // The rerun replays call 1 and records call 2.
    let second =
        VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::NewEpisodes)).unwrap();
    assert_eq!(
        second.chat(request("call 1", &[])).await.unwrap().origin,
        Origin::Replayed
    );
    assert_eq!(
        second.chat(request("call 2", &[])).await.unwrap().origin,
        Origin::Live
    );
    assert_eq!(served(&server).await, 2);
    assert_eq!(CassetteFile::load(&path).unwrap().interactions.len(), 2);
    // No temporary or lock files are left behind.
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["resume.json"]);
    // `once` with an existing file is replay-only.
    let once = VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::Once)).unwrap();
    assert!(once.chat(request("call 3", &[])).await.is_err());
}

#[tokio::test]
async fn two_recorders_appending_to_one_cassette_lose_nothing() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("shared.json");
    let a =
        VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::NewEpisodes)).unwrap();
    let b =
        VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::NewEpisodes)).unwrap();
    let calls = (0..8).map(|i| {
        let client = if i % 2 == 0 { a.clone() } else { b.clone() };
        async move { client.chat(request(&format!("call {i}"), &[])).await }
    });
    let results = futures::future::join_all(calls).await;
    assert!(results.iter().all(Result::is_ok));
    assert_eq!(CassetteFile::load(&path).unwrap().interactions.len(), 8);
}

#[tokio::test]
async fn strict_mode_reports_unused_and_prune_drops_them() {
    let server = MockServer::start().await;
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(completion("ok")))
        .mount(&server)
        .await;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("strict.json");
    let report = dir.path().join("usage.json");
    let recorder = VlmClient::from_config(&with_cassette(openai(&server), &path, CassetteMode::All)).unwrap();
    recorder.chat(request("kept", &[&png(16, 7)])).await.unwrap();
    recorder.chat(request("stale", &[&png(16, 8)])).await.unwrap();

    let mut cfg = with_cassette(openai(&server), &path, CassetteMode::None);
    let settings = cfg.cassette.as_mut().unwrap();
    settings.strict = true;
    settings.usage_report = Some(report.clone());
    let replayer = VlmClient::from_config(&cfg).unwrap();
    replayer.chat(request("kept", &[&png(16, 7)])).await.unwrap();
    let err = replayer.finish().unwrap_err().to_string();
    assert!(
        err.contains("1 recorded interaction(s) were not used") && err.contains("#1 (purpose induce"),
        "{err}"
    );

    let usage = tools::load_usage_report(&report).unwrap();
    assert_eq!((usage.used.len(), usage.unused.len()), (1, 1));
    let dry = tools::prune(&path, &usage, true, true).unwrap();
    assert_eq!(
        (dry.kept, dry.dropped.clone(), dry.removed_blobs.len()),
        (1, vec![1], 1)
    );
    assert_eq!(
        CassetteFile::load(&path).unwrap().interactions.len(),
        2,
        "dry run changes nothing"
    );
    let done = tools::prune(&path, &usage, true, false).unwrap();
    assert_eq!(done, dry);
    assert_eq!(CassetteFile::load(&path).unwrap().interactions.len(), 1);
    assert_eq!(std::fs::read_dir(dir.path().join("blobs")).unwrap().count(), 1);
    assert!(tools::verify(&path).unwrap().is_empty());

    // Verify notices a missing blob and a hand-edited request.
    let blob = std::fs::read_dir(dir.path().join("blobs"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    std::fs::remove_file(&blob).unwrap();
    let text = std::fs::read_to_string(&path).unwrap().replace("kept", "edited");
    std::fs::write(&path, text).unwrap();
    let problems: Vec<String> = tools::verify(&path)
        .unwrap()
        .into_iter()
        .map(|p| p.message)
        .collect();
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(
        problems.iter().any(|p| p.contains("is missing"))
            && problems.iter().any(|p| p.contains("was it edited"))
    );
}

#[test]
fn opening_modes_that_record_without_a_live_transport_fails_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.json");
    let err = CassetteTransport::open(&path, CassetteMode::NewEpisodes, None, CassetteOptions::default())
        .unwrap_err();
    assert!(err.to_string().contains("needs to record"), "{err}");
    std::fs::write(
        &path,
        "{\"schema_version\": 1, \"meta\": {}, \"interactions\": [}",
    )
    .unwrap();
    let err =
        CassetteTransport::open(&path, CassetteMode::None, None, CassetteOptions::default()).unwrap_err();
    assert!(err.to_string().contains("x.json:1:"), "{err}");
    let _: Arc<dyn Transport> = Arc::new(
        CassetteTransport::open(
            dir.path().join("absent.json"),
            CassetteMode::None,
            None,
            CassetteOptions::default(),
        )
        .unwrap(),
    );
}

/// `verify` on a hand-made hostile cassette: a blob reference that is a path (`../`, an
/// absolute device), a blob that is a named pipe, a stored credential header and an empty
/// success body. None of them may be opened, block or pass.
#[test]
fn verify_refuses_paths_pipes_credentials_and_empty_successes() {
    let fixtures = nesy_testkit::workspace_root().join("fixtures/cassettes");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("hostile.json");
    let mut file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixtures.join("adapt-realstyle.json")).unwrap())
            .unwrap();
    let refs: Vec<String> = {
        let text = file.to_string();
        text.match_indices("blob:sha256:")
            .map(|(at, _)| text[at..].split('"').next().unwrap().to_string())
            .collect()
    };
    assert!(refs.len() >= 3, "the fixture holds images");
    std::fs::create_dir(dir.path().join("blobs")).unwrap();
    let pipe_name = format!("{}.png", "ab".repeat(32));
    let pipe = dir.path().join("blobs").join(&pipe_name);
    let made = std::process::Command::new("mkfifo").arg(&pipe).status().unwrap();
    assert!(made.success());
    let text = file
        .to_string()
        .replacen(&refs[0], "blob:sha256:../../../../../etc/hostname", 1)
        .replacen(&refs[1], "blob:sha256:/dev/zero", 1)
        .replacen(&refs[2], &format!("blob:sha256:{pipe_name}"), 1);
    file = serde_json::from_str(&text).unwrap();
    let interactions = file["interactions"].as_array_mut().unwrap();
    interactions[0]["response"]["headers"]["authorization"] = json!("Bearer sk-stored-by-hand-0001");
    let response = interactions[1]["response"].as_object_mut().unwrap();
    response.remove("body");
    response.remove("body_text");
    std::fs::write(&path, serde_json::to_string_pretty(&file).unwrap()).unwrap();

    let started = std::time::Instant::now();
    let problems: Vec<String> = tools::verify(&path)
        .unwrap()
        .into_iter()
        .map(|p| p.message)
        .collect();
    assert!(
        started.elapsed() < std::time::Duration::from_secs(10),
        "no blocking read"
    );
    let has = |needle: &str| problems.iter().any(|p| p.contains(needle));
    assert!(
        has("\"../../../../../etc/hostname\" is not a content address"),
        "{problems:?}"
    );
    assert!(has("\"/dev/zero\" is not a content address"), "{problems:?}");
    assert!(has("is not a regular file"), "{problems:?}");
    assert!(
        has("header `authorization` is not on the allowlist"),
        "{problems:?}"
    );
    assert!(has("with no body"), "{problems:?}");
    assert!(
        problems.iter().all(|p| !p.contains("sk-stored-by-hand")),
        "{problems:?}"
    );
}

/// Answers the n-th call it is sent with `answer n`; the first call takes longest, so it
/// completes (and is appended to a cassette) after the others.
#[derive(Debug, Default)]
struct FirstCallFinishesLast {
    sent: std::sync::atomic::AtomicUsize,
}

impl Transport for FirstCallFinishesLast {
    fn send<'a>(&'a self, _request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        let n = self.sent.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        Box::pin(async move {
            if n == 0 {
                tokio::time::sleep(std::time::Duration::from_millis(200)).await;
            }
            let body = serde_json::to_vec(&completion(&format!("answer {n}"))).unwrap();
            Ok(WireResponse::new(200, body, Origin::Live))
        })
    }

    fn label(&self) -> String {
        "first call finishes last".into()
    }
}

#[tokio::test]
async fn identical_concurrent_requests_replay_in_the_order_they_were_sent() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("concurrent.json");
    let builder =
        VlmClient::from_config(&config(BackendKind::LlamaCpp, "gemma", "http://127.0.0.1:9")).unwrap();
    let wire = builder.wire_request(&request("the same keyframe", &[]));
    let send_both = |transport: Arc<CassetteTransport>| {
        let wire = wire.clone();
        async move {
            let calls = [transport.send(&wire), transport.send(&wire)];
            futures::future::join_all(calls)
                .await
                .into_iter()
                .map(|response| String::from_utf8(response.unwrap().body.to_vec()).unwrap())
                .collect::<Vec<_>>()
        }
    };

    let live: Arc<dyn Transport> = Arc::new(FirstCallFinishesLast::default());
    let recorder =
        CassetteTransport::open(&path, CassetteMode::All, Some(live), CassetteOptions::default()).unwrap();
    let recorded = send_both(Arc::new(recorder)).await;
    assert!(recorded[0].contains("answer 0") && recorded[1].contains("answer 1"));
    let file = CassetteFile::load(&path).unwrap();
    let orders: Vec<Option<u64>> = file.interactions.iter().map(|i| i.send_order).collect();
    assert_eq!(orders, [Some(1), Some(0)], "appended as they completed");

    let replayer =
        CassetteTransport::open(&path, CassetteMode::None, None, CassetteOptions::default()).unwrap();
    assert_eq!(
        send_both(Arc::new(replayer)).await,
        recorded,
        "each caller gets its own reply"
    );
}

/// Gets no response to its first attempt (the read timeout fires), then answers.
#[derive(Debug, Default)]
struct TimesOutOnce {
    sent: std::sync::atomic::AtomicUsize,
}

impl Transport for TimesOutOnce {
    fn send<'a>(&'a self, _request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        let n = self.sent.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        Box::pin(async move {
            if n == 0 {
                return Err(TransportError::Timeout {
                    phase: nesy_vlm::TimeoutPhase::Response,
                    message: "operation timed out".into(),
                });
            }
            let body = serde_json::to_vec(&completion("(On a b)")).unwrap();
            Ok(WireResponse::new(200, body, Origin::Live))
        })
    }

    fn label(&self) -> String {
        "times out once".into()
    }
}

#[tokio::test]
async fn an_attempt_that_got_no_response_replays_as_the_same_failure() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("timeout.json");
    let base = config(BackendKind::LlamaCpp, "gemma", "http://127.0.0.1:9");

    let live: Arc<dyn Transport> = Arc::new(TimesOutOnce::default());
    let recorder =
        VlmClient::from_config_over(&with_cassette(base.clone(), &path, CassetteMode::All), live).unwrap();
    let recorded = recorder.chat(request("a slow keyframe", &[])).await.unwrap();
    let recorded_usage = recorder.finish().unwrap();
    assert_eq!(recorded_usage.total.attempts, 2, "the retry layer tried twice");

    let file = CassetteFile::load(&path).unwrap();
    let kinds: Vec<&str> = file
        .interactions
        .iter()
        .map(|i| {
            i.outcome()
                .unwrap()
                .map_or_else(|failure| failure.kind(), |_| "response")
        })
        .collect();
    assert_eq!(kinds, ["timeout", "response"]);
    assert!(tools::verify(&path).unwrap().is_empty());
    let listed = tools::inspect(&path).unwrap();
    assert_eq!(listed.interactions[0].status, 0);
    assert_eq!(listed.interactions[0].failure.as_deref(), Some("timeout"));

    let replayer = VlmClient::from_config(&with_cassette(base, &path, CassetteMode::None)).unwrap();
    let replayed = replayer.chat(request("a slow keyframe", &[])).await.unwrap();
    assert_eq!(replayed.text, recorded.text);
    let replayed_usage = replayer.finish().unwrap();
    assert_eq!(
        replayed_usage.total.attempts, recorded_usage.total.attempts,
        "the replay fails the first attempt as the live run did"
    );
}
