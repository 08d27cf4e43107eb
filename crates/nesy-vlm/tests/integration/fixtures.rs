//! Committed fixture cassettes: one replays offline, and no file anywhere under `fixtures/`
//! contains anything that looks like a credential.

use std::path::{Path, PathBuf};

use nesy_vlm::cassette_tools as tools;
use nesy_vlm::{BackendKind, CassetteMode, CassetteSettings, ChatRequest, Image, Message, Part, VlmClient};

fn fixtures_dir() -> PathBuf {
    nesy_testkit::workspace_root().join("fixtures")
}

fn smoke_cassette() -> PathBuf {
    fixtures_dir().join("cassettes/vlm-smoke.json")
}

fn smoke_request() -> ChatRequest {
    ChatRequest::new()
        .message(Message::system(
            "List the predicates that hold in the scene, one per line.",
        ))
        .message(Message::user(vec![
            Part::text("Top view, then front view."),
            Image::png(nesy_testkit::png(24, 11)).unwrap().into(),
            Image::png(nesy_testkit::png(24, 12)).unwrap().into(),
        ]))
        .purpose("smoke")
}

fn smoke_config(base_url: &str, mode: CassetteMode) -> nesy_vlm::VlmConfig {
    let mut cfg = nesy_testkit::mock_config(BackendKind::OpenAi, "gpt-5-mini", base_url);
    cfg.cassette = Some(CassetteSettings {
        path: smoke_cassette(),
        mode,
        strict: true,
        usage_report: None,
    });
    cfg
}

#[tokio::test]
async fn the_smoke_fixture_replays_offline() {
    let client = VlmClient::from_config(&smoke_config("http://127.0.0.1:9", CassetteMode::None)).unwrap();
    let reply = client.chat(smoke_request()).await.unwrap();
    assert_eq!(reply.text, "(OnTopOf red_block table)\n(Open drawer)");
    assert_eq!(reply.usage.unwrap().reasoning_tokens, 64);
    client.finish().unwrap();
    assert!(tools::verify(&smoke_cassette()).unwrap().is_empty());
}

/// Re-creates the smoke fixture from the mock server (run with `--ignored`).
#[tokio::test]
#[ignore = "rewrites fixtures/cassettes/vlm-smoke.json"]
async fn regenerate_smoke_fixture() {
    use wiremock::{Mock, MockServer, ResponseTemplate, matchers::method};
    let server = MockServer::start().await;
    let mut body = nesy_testkit::completion("(OnTopOf red_block table)\n(Open drawer)");
    body["model"] = "gpt-5-mini-2025-08-07".into();
    body["usage"]["completion_tokens_details"]["reasoning_tokens"] = 64.into();
    Mock::given(method("POST"))
        .respond_with(
            ResponseTemplate::new(200)
                .set_body_json(body)
                .insert_header("x-request-id", "req_fixture"),
        )
        .mount(&server)
        .await;
    let mut cfg = smoke_config(&server.uri(), CassetteMode::All);
    cfg.api_key = Some(nesy_vlm::SecretString::new("sk-fixture-not-a-real-key"));
    VlmClient::from_config(&cfg)
        .unwrap()
        .chat(smoke_request())
        .await
        .unwrap();
}

/// Header names that carry credentials; found as a JSON key with a string value they betray
/// a recorded secret (an object merely *named* "cookie" in a scene is not flagged).
const SECRET_HEADERS: &[&str] = &[
    "authorization",
    "proxy-authorization",
    "api-key",
    "x-api-key",
    "cookie",
    "set-cookie",
];

/// `"<name>": "` (any case, any spacing) somewhere in the text.
fn header_with_string_value(lower: &str, name: &str) -> bool {
    let quoted = format!("\"{name}\"");
    lower.match_indices(&quoted).any(|(at, _)| {
        let rest = lower[at + quoted.len()..].trim_start();
        rest.strip_prefix(':')
            .is_some_and(|value| value.trim_start().starts_with('"'))
    })
}

/// `Bearer <token>` with a token of at least 8 characters.
fn bearer_token(lower: &str) -> bool {
    lower.match_indices("bearer ").any(|(at, _)| {
        lower[at + 7..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || "-._~+/".contains(*c))
            .count()
            >= 8
    })
}

fn looks_like_openai_key(text: &str) -> Option<String> {
    text.match_indices("sk-").find_map(|(at, _)| {
        let tail: String = text[at + 3..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
            .collect();
        (tail.len() >= 20).then(|| format!("sk-{}…", &tail[..4]))
    })
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            walk(&path, out)
        } else {
            out.push(path)
        }
    }
}

#[test]
fn no_fixture_anywhere_contains_a_secret() {
    let mut files = Vec::new();
    walk(&fixtures_dir(), &mut files);
    assert!(
        files.iter().any(|f| f.ends_with("vlm-smoke.json")),
        "the scan must see the fixtures tree"
    );
    let mut findings = Vec::new();
    for file in files {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        }; // binary (blobs, MCAP)
        let lower = text.to_ascii_lowercase();
        for name in SECRET_HEADERS {
            if header_with_string_value(&lower, name) {
                findings.push(format!("{}: a {name:?} header value", file.display()));
            }
        }
        if bearer_token(&lower) {
            findings.push(format!("{}: a bearer token", file.display()));
        }
        if let Some(key) = looks_like_openai_key(&text) {
            findings.push(format!(
                "{}: contains what looks like an API key ({key})",
                file.display()
            ));
        }
    }
    assert!(
        findings.is_empty(),
        "possible secrets in fixtures:\n{}",
        findings.join("\n")
    );
}

#[test]
fn the_secret_scan_catches_what_it_should() {
    assert!(looks_like_openai_key("key sk-proj-AbCdEfGhIjKlMnOpQrStUv").is_some());
    assert!(looks_like_openai_key("\"sk-short\" and risk-free").is_none());
    assert!(header_with_string_value(
        r#"{"headers": {"authorization" :  "bearer x"}}"#,
        "authorization"
    ));
    assert!(header_with_string_value(r#"{"api-key":"abc"}"#, "api-key"));
    assert!(!header_with_string_value(
        r#"{"objects": ["cookie"], "cookie": {"mass": 0.1}}"#,
        "cookie"
    ));
    assert!(bearer_token("authorization: bearer eyjhbgcioijiuzi1ni"));
    assert!(!bearer_token("the bearer of bad news"));
}
