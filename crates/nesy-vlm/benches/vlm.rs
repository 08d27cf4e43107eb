//! Benchmarks of the VLM client's hot paths.
//!
//! - `replay/*`: one chat call answered from a cassette, with two 384×384 PNG keyframes:
//!   building the body (base64), canonicalising it (decoding and hashing both images on every
//!   call), the key lookup, and parsing the response. Target: under 1 ms. `rendered` uses
//!   two views rendered by nesy-sim (`benches/data/`, made with `nesy render --scene
//!   fixtures/scenes/composite_all_finger.json --size 384`); `noisy` uses synthetic images
//!   with per-pixel noise, a worst case about twenty times larger.
//! - `overhead/*`: a chat call through the client against an in-process mock server, next
//!   to a raw reqwest POST of the same body to the same server, for a text prompt and for
//!   the rendered two-image prompt. After the Criterion groups an interleaved run prints the
//!   ratio of medians.

use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group};
use nesy_vlm::{
    BackendKind, CassetteMode, CassetteOptions, CassetteTransport, ChatRequest, Image, Message, Part,
    RetryPolicy, SecretString, Transport, VlmClient, VlmConfig,
};
use serde_json::json;
use wiremock::matchers::method;
use wiremock::{Mock, MockServer, ResponseTemplate};

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("runtime")
}

/// The two rendered keyframes.
fn rendered_views() -> (Vec<u8>, Vec<u8>) {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/data");
    let read = |name: &str| std::fs::read(data.join(name)).expect("bench image");
    (read("top.png"), read("front.png"))
}

/// Two synthetic 384×384 images with per-pixel noise (poorly compressible).
fn noisy_views() -> (Vec<u8>, Vec<u8>) {
    (nesy_testkit::png(384, 1), nesy_testkit::png(384, 2))
}

/// A request with two images, built from the bytes each time (nothing about the images is
/// cached between calls).
fn image_request(views: &(Vec<u8>, Vec<u8>)) -> ChatRequest {
    ChatRequest::new()
        .message(Message::system(
            "Translate the keyframes into the symbolic state.",
        ))
        .message(Message::user(vec![
            Part::text("Top view, then front view. List every predicate that holds."),
            Image::png(views.0.clone()).expect("png").into(),
            Image::png(views.1.clone()).expect("png").into(),
        ]))
        .purpose("bench")
}

fn text_request() -> ChatRequest {
    let prompt = "Propose a SEARCH/REPLACE patch for the first violated precondition. ".repeat(30);
    ChatRequest::new()
        .message(Message::system("You repair symbolic procedures."))
        .message(Message::user_text(prompt))
}

fn server_config(server: &MockServer) -> VlmConfig {
    let mut cfg = nesy_testkit::mock_config(BackendKind::OpenAi, "gpt-5", &server.uri());
    cfg.api_key = Some(SecretString::new("sk-bench-not-a-real-key"));
    cfg.retry = RetryPolicy {
        max_attempts: 1,
        ..RetryPolicy::default()
    };
    cfg
}

async fn mock_server() -> MockServer {
    // Recording would keep a copy of every request body for the whole run.
    let server = MockServer::builder().disable_request_recording().start().await;
    let body = json!({
        "id": "chatcmpl-bench", "model": "gpt-5",
        "choices": [{"index": 0, "message": {"role": "assistant", "content": "(OnTopOf red_block tray)\n(Closed drawer)"},
                     "finish_reason": "stop"}],
        "usage": {"prompt_tokens": 1600, "completion_tokens": 220, "completion_tokens_details": {"reasoning_tokens": 180}}
    });
    Mock::given(method("POST"))
        .respond_with(ResponseTemplate::new(200).set_body_json(body))
        .mount(&server)
        .await;
    server
}

fn replay(c: &mut Criterion) {
    let rt = runtime();
    let mut group = c.benchmark_group("replay");
    for (name, views) in [("rendered", rendered_views()), ("noisy", noisy_views())] {
        eprintln!("{name}: PNG sizes {} and {} bytes", views.0.len(), views.1.len());
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("bench.json");
        let cfg = rt.block_on(async {
            let server = mock_server().await;
            let mut cfg = server_config(&server);
            cfg.cassette = Some(nesy_vlm::CassetteSettings {
                path: path.clone(),
                mode: CassetteMode::All,
                strict: false,
                usage_report: None,
            });
            let client = VlmClient::from_config(&cfg).expect("client");
            client.chat(image_request(&views)).await.expect("record");
            cfg.cassette = None;
            cfg
        });
        let options = CassetteOptions {
            allow_playback_repeats: true,
            ..CassetteOptions::default()
        };
        let cassette: Arc<dyn Transport> =
            Arc::new(CassetteTransport::open(&path, CassetteMode::None, None, options).expect("cassette"));
        let client = VlmClient::with_transport(&cfg, cassette);
        group.bench_function(format!("{name}/two_384px_images"), |b| {
            b.iter_batched(
                || image_request(&views),
                |request| rt.block_on(client.chat(request)).expect("replay"),
                criterion::BatchSize::SmallInput,
            )
        });
        group.bench_function(format!("{name}/build_body_only"), |b| {
            b.iter_batched(
                || image_request(&views),
                |request| client.wire_request(&request),
                criterion::BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

struct OverheadRig {
    rt: tokio::runtime::Runtime,
    _server: MockServer,
    url: String,
    raw: reqwest::Client,
    client: VlmClient,
}

impl OverheadRig {
    fn new() -> Self {
        let rt = runtime();
        let server = rt.block_on(mock_server());
        let client = VlmClient::from_config(&server_config(&server)).expect("client");
        let raw = reqwest::Client::builder().no_proxy().build().expect("reqwest");
        let url = format!("{}/chat/completions", server.uri());
        Self {
            rt,
            _server: server,
            url,
            raw,
            client,
        }
    }

    fn raw_call(&self, body: &[u8]) -> usize {
        self.rt.block_on(async {
            let response = self
                .raw
                .post(&self.url)
                .header("authorization", "Bearer sk-bench-not-a-real-key")
                .header("content-type", "application/json")
                .body(body.to_vec())
                .send()
                .await
                .expect("send");
            response.bytes().await.expect("body").len()
        })
    }

    fn client_call(&self, request: &ChatRequest) -> usize {
        self.rt
            .block_on(self.client.chat(request.clone()))
            .expect("chat")
            .text
            .len()
    }
}

fn overhead(c: &mut Criterion) {
    let rig = OverheadRig::new();
    let mut group = c.benchmark_group("overhead");
    for (name, request) in [
        ("text", text_request()),
        ("two_384px_images", image_request(&rendered_views())),
    ] {
        let body = serde_json::to_vec(&rig.client.wire_request(&request).body).expect("json");
        group.bench_function(format!("{name}/raw_reqwest"), |b| b.iter(|| rig.raw_call(&body)));
        group.bench_function(format!("{name}/client"), |b| b.iter(|| rig.client_call(&request)));
    }
    group.finish();
}

/// Interleaves raw and client calls so both see the same machine state, and prints medians
/// and their ratio.
fn overhead_ratio() {
    let rig = OverheadRig::new();
    for (name, request) in [
        ("text", text_request()),
        ("two_384px_images", image_request(&rendered_views())),
    ] {
        let body = serde_json::to_vec(&rig.client.wire_request(&request).body).expect("json");
        let (mut raw, mut client) = (Vec::new(), Vec::new());
        for round in 0..400 {
            let start = Instant::now();
            rig.raw_call(&body);
            let raw_time = start.elapsed();
            let start = Instant::now();
            rig.client_call(&request);
            let client_time = start.elapsed();
            if round >= 50 {
                raw.push(raw_time);
                client.push(client_time);
            }
        }
        let median = |v: &mut Vec<Duration>| {
            v.sort();
            v[v.len() / 2]
        };
        let (raw, client) = (median(&mut raw), median(&mut client));
        println!(
            "overhead ratio [{name}]: client {:.1} µs / raw reqwest {:.1} µs = {:.2}x (medians of 350 interleaved calls)",
            client.as_secs_f64() * 1e6,
            raw.as_secs_f64() * 1e6,
            client.as_secs_f64() / raw.as_secs_f64()
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = replay, overhead
}

fn main() {
    benches();
    overhead_ratio();
    Criterion::default().configure_from_args().final_summary();
}
