//! # nesy-testkit
//!
//! What several crates' tests and benchmarks need and would otherwise each copy: the body of
//! a chat-completion reply, real PNG images, a client configuration pointed at a mock server
//! with fast retries, a transport wrapper that counts calls in flight, and the workspace
//! root. It is a dev-dependency only (`publish = false`): no library or binary links it.
//!
//! ```
//! let body = nesy_testkit::completion("(OnTopOf red_cube floor)");
//! assert_eq!(body["choices"][0]["message"]["content"], "(OnTopOf red_cube floor)");
//! let image = nesy_testkit::png(16, 1);
//! assert_eq!(&image[1..4], b"PNG");
//! assert!(nesy_testkit::workspace_root().join("Cargo.toml").is_file());
//! ```

use std::collections::{BTreeMap, VecDeque};
use std::path::PathBuf;
#[cfg(feature = "policy-worker")]
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use nesy_vlm::{
    BackendKind, BoxFuture, Origin, RetryPolicy, Timeouts, Transport, TransportError, VlmConfig, WireRequest,
    WireResponse,
};
use serde_json::{Value, json};

/// The workspace's root folder (where the top-level `Cargo.toml`, `fixtures/` and `assets/`
/// are), found from this crate's own manifest so that it holds from any crate's tests.
pub fn workspace_root() -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    here.parent()
        .and_then(|crates| crates.parent())
        .map(PathBuf::from)
        .unwrap_or(here)
}

/// Path of the scene fixture `fixtures/scenes/<name>.json`.
pub fn scene_fixture(name: &str) -> PathBuf {
    workspace_root()
        .join("fixtures/scenes")
        .join(format!("{name}.json"))
}

/// Copies the folder `from` and everything below it to `to` (created if missing).
pub fn copy_tree(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).expect("creating the copy's folder");
    for entry in std::fs::read_dir(from)
        .expect("reading the folder to copy")
        .flatten()
    {
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).expect("copying a file");
        }
    }
}

/// A chat-completions success body whose one choice says `text` and stopped normally, with
/// token usage (including reasoning tokens) so that accounting has something to count.
pub fn completion(text: &str) -> Value {
    json!({
        "id": "chatcmpl-test",
        "object": "chat.completion",
        "model": "mock-model",
        "choices": [{"index": 0, "message": {"role": "assistant", "content": text}, "finish_reason": "stop"}],
        "usage": {"prompt_tokens": 120, "completion_tokens": 30,
                  "completion_tokens_details": {"reasoning_tokens": 12}}
    })
}

/// A configuration for `backend` whose base URL is a mock server, with millisecond retries
/// and second-scale timeouts, so that tests of failure paths finish quickly.
pub fn mock_config(backend: BackendKind, model: &str, base_url: &str) -> VlmConfig {
    let mut config = VlmConfig::new(backend, model);
    config.base_url = base_url.to_string();
    config.retry = RetryPolicy {
        max_attempts: 3,
        base_delay: Duration::from_millis(5),
        max_delay: Duration::from_millis(20),
        max_retry_after: Duration::from_secs(120),
    };
    config.timeouts = Timeouts {
        connect: Some(Duration::from_secs(5)),
        read: Some(Duration::from_secs(10)),
        total: Some(Duration::from_secs(10)),
        pool_idle: Some(Duration::from_secs(60)),
    };
    config
}

/// A real RGB PNG of `size`×`size` pixels: smooth gradients plus deterministic noise, so it
/// compresses like a rendered keyframe rather than like a flat colour.
pub fn png(size: u32, seed: u64) -> Vec<u8> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut data = Vec::with_capacity((size * size * 3) as usize);
    for y in 0..size {
        for x in 0..size {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let noise = (state & 0x0F) as u32;
            data.push(((x * 255 / size) + noise).min(255) as u8);
            data.push(((y * 255 / size) + noise).min(255) as u8);
            data.push((((x + y) * 127 / size) + noise).min(255) as u8);
        }
    }
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, size, size);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().expect("png header");
    writer.write_image_data(&data).expect("png data");
    writer.finish().expect("png finish");
    out
}

/// An 8-bit RGB PNG (as nesy renders them) as a JPEG at `quality`, keeping every `shrink`-th
/// pixel in each direction: a photograph-like frame made from a rendered one.
pub fn jpeg_from_png(png_bytes: &[u8], shrink: u32, quality: u8) -> Vec<u8> {
    let decoder = png::Decoder::new(std::io::Cursor::new(png_bytes));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut pixels = vec![0; reader.output_buffer_size().expect("a PNG of known size")];
    let info = reader.next_frame(&mut pixels).expect("PNG pixels");
    assert_eq!(info.color_type, png::ColorType::Rgb, "an RGB PNG");
    let shrink = shrink.max(1);
    let (width, height) = (info.width / shrink, info.height / shrink);
    let mut rgb = Vec::with_capacity((width * height * 3) as usize);
    for y in 0..height {
        for x in 0..width {
            let i = ((shrink * y * info.width + shrink * x) * 3) as usize;
            rgb.extend_from_slice(&pixels[i..i + 3]);
        }
    }
    let mut out = Vec::new();
    jpeg_encoder::Encoder::new(&mut out, quality)
        .encode(&rgb, width as u16, height as u16, jpeg_encoder::ColorType::Rgb)
        .expect("JPEG encoding");
    out
}

/// Wraps a transport and records the largest number of calls in flight at once, to test the
/// client's concurrency cap.
#[derive(Debug)]
pub struct InFlightCounter {
    /// The transport that answers.
    pub inner: Arc<dyn Transport>,
    /// Calls in flight now.
    pub now: AtomicUsize,
    /// The most calls that were in flight at once.
    pub max: AtomicUsize,
}

impl InFlightCounter {
    /// A counter around `inner`, at zero.
    pub fn new(inner: Arc<dyn Transport>) -> Self {
        Self {
            inner,
            now: AtomicUsize::new(0),
            max: AtomicUsize::new(0),
        }
    }
}

impl Transport for InFlightCounter {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(async move {
            let now = self.now.fetch_add(1, Ordering::SeqCst) + 1;
            self.max.fetch_max(now, Ordering::SeqCst);
            let result = self.inner.send(request).await;
            self.now.fetch_sub(1, Ordering::SeqCst);
            result
        })
    }

    fn label(&self) -> String {
        "counter".into()
    }

    fn capabilities(&self) -> BoxFuture<'_, nesy_vlm::ServerCapabilities> {
        self.inner.capabilities()
    }
}

/// A named test of a test binary built with `harness = false`.
#[cfg(feature = "policy-worker")]
pub type NamedTest = (&'static str, fn());

/// The `main` of a test binary that executes policies in-process through a library entry
/// point: the sandbox starts its worker by re-executing the running binary with
/// [`nesy_policy::WORKER_SUBCOMMAND`], so this binary is its own worker. Called so, it serves
/// one episode; otherwise it runs `tests` (those whose name contains the first free command
/// line argument, if one is given), each catching its own panic, and closes with a line
/// `N passed, N failed`.
///
/// The worker the tests then hand to the library is [`own_worker`].
#[cfg(feature = "policy-worker")]
pub fn run_tests_or_worker(tests: &[NamedTest]) -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some(nesy_policy::WORKER_SUBCOMMAND) {
        return nesy_policy::worker_main(&nesy_policy::SimEpisodes);
    }
    let filter = args.iter().find(|a| !a.starts_with('-')).cloned();
    let (mut passed, mut failed) = (0, 0);
    for (name, test) in tests {
        if filter.as_deref().is_some_and(|f| !name.contains(f)) {
            continue;
        }
        match std::panic::catch_unwind(test) {
            Ok(()) => {
                println!("test {name} ... ok");
                passed += 1;
            }
            Err(_) => {
                println!("test {name} ... FAILED");
                failed += 1;
            }
        }
    }
    println!("{passed} passed, {failed} failed");
    if failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// This test binary as the sandbox's worker (see [`run_tests_or_worker`]).
#[cfg(feature = "policy-worker")]
pub fn own_worker() -> nesy_policy::WorkerCommand {
    nesy_policy::WorkerCommand::current_exe().expect("the running test binary")
}

/// The prefix that makes [`Scripted`] answer with `finish_reason: length`, cut off after the
/// text that follows it.
pub const TRUNCATED: &str = "<length>";
/// The reply that makes [`Scripted`] answer with a null `content`.
pub const NULL_CONTENT: &str = "<null>";

/// A transport that answers each request purpose from its own queue of scripted replies and
/// keeps every request it was sent, for tests of call flows (the reasoner's, the baselines').
/// A purpose whose queue is empty fails, not retryable.
#[derive(Debug, Default)]
pub struct Scripted {
    replies: Mutex<BTreeMap<String, VecDeque<String>>>,
    seen: Mutex<Vec<WireRequest>>,
}

impl Scripted {
    /// A script: for each purpose, its replies in order.
    pub fn with(replies: &[(&str, &[&str])]) -> Arc<Self> {
        let map = replies
            .iter()
            .map(|(purpose, texts)| (purpose.to_string(), texts.iter().map(|t| t.to_string()).collect()))
            .collect();
        Arc::new(Scripted {
            replies: Mutex::new(map),
            seen: Mutex::default(),
        })
    }

    /// Replaces the queue of `purpose` with `replies`.
    pub fn set(&self, purpose: &str, replies: &[&str]) {
        let queue = replies.iter().map(|t| t.to_string()).collect();
        self.replies.lock().unwrap().insert(purpose.to_owned(), queue);
    }

    /// The requests of `purpose` sent so far, in order.
    pub fn requests(&self, purpose: &str) -> Vec<WireRequest> {
        self.seen
            .lock()
            .unwrap()
            .iter()
            .filter(|r| r.purpose.as_deref() == Some(purpose))
            .cloned()
            .collect()
    }
}

impl Transport for Scripted {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(async move {
            self.seen.lock().unwrap().push(request.clone());
            let purpose = request.purpose.clone().unwrap_or_default();
            let reply = self
                .replies
                .lock()
                .unwrap()
                .get_mut(&purpose)
                .and_then(VecDeque::pop_front)
                .ok_or_else(|| TransportError::Failed {
                    message: format!("script has no reply left for purpose {purpose:?}"),
                    retryable: false,
                })?;
            let body = match reply.strip_prefix(TRUNCATED) {
                Some(partial) => {
                    let mut body = completion(partial);
                    body["choices"][0]["finish_reason"] = "length".into();
                    // A reply stopped by its cap has used all of it, as servers report.
                    let cap = ["max_tokens", "max_completion_tokens"]
                        .iter()
                        .find_map(|field| request.body.get(*field).and_then(Value::as_u64));
                    if let Some(cap) = cap {
                        body["usage"]["completion_tokens"] = cap.into();
                    }
                    body
                }
                None if reply == NULL_CONTENT => {
                    let mut body = completion("");
                    body["choices"][0]["message"]["content"] = Value::Null;
                    body
                }
                None => completion(&reply),
            };
            Ok(WireResponse::new(
                200,
                serde_json::to_vec(&body).unwrap(),
                Origin::Offline,
            ))
        })
    }

    fn label(&self) -> String {
        "scripted".into()
    }
}
