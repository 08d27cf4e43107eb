//! The transport layer: what sits under the retry layer and turns a wire request into a
//! wire response. HTTP talks to a server; the cassette replays or records; further
//! transports (an offline reference responder) implement the same trait without any change
//! to the client.

use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;

use bytes::Bytes;

use crate::capabilities::ServerCapabilities;
use crate::error::{TransportError, VlmError};
use crate::request::TaskContext;

mod http;

pub use http::{Auth, HttpTransport};

/// A boxed, sendable future, so [`Transport`] stays object-safe (`Arc<dyn Transport>`).
pub type BoxFuture<'a, T> = Pin<Box<dyn Future<Output = T> + Send + 'a>>;

/// What the client hands a transport: a POST of a JSON body to a path, plus context that
/// never goes on the wire.
#[derive(Debug, Clone)]
pub struct WireRequest {
    /// Path and query relative to the base URL, e.g. `/chat/completions` or
    /// `/openai/deployments/d/chat/completions?api-version=2025-04-01-preview`.
    pub path: String,
    /// The JSON body exactly as it is sent.
    pub body: serde_json::Value,
    /// Task context for offline transports; not sent, not part of a cassette key.
    pub task: Option<TaskContext>,
    /// What the call is for (accounting label); not sent, shown in cassettes.
    pub purpose: Option<String>,
}

/// Where a response came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Origin {
    /// A live server.
    Live,
    /// A cassette recording.
    Replayed,
    /// An offline responder computing the answer itself.
    Offline,
}

/// A complete HTTP response as the transport saw it.
#[derive(Clone, PartialEq, Eq)]
pub struct WireResponse {
    /// HTTP status code.
    pub status: u16,
    /// Allowlisted headers only (content type, request ids, rate-limit and retry headers), names lower-case, in order.
    pub headers: Vec<(String, String)>,
    /// The body bytes, unmodified.
    pub body: Bytes,
    /// Where it came from (a replayed response is not waited for before retrying).
    pub origin: Origin,
}

impl WireResponse {
    /// A response with the given status and body and no headers.
    pub fn new(status: u16, body: impl Into<Bytes>, origin: Origin) -> Self {
        Self {
            status,
            headers: Vec::new(),
            body: body.into(),
            origin,
        }
    }

    /// The first value of a header (name compared case-insensitively).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(key, _)| key.eq_ignore_ascii_case(name))
            .map(|(_, value)| value.as_str())
    }

    /// The provider's request id: `x-request-id`, or Azure's `apim-request-id`.
    pub fn request_id(&self) -> Option<&str> {
        self.header("x-request-id")
            .or_else(|| self.header("apim-request-id"))
    }

    /// Whether the status is 2xx.
    pub fn is_success(&self) -> bool {
        (200..300).contains(&self.status)
    }
}

impl fmt::Debug for WireResponse {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("WireResponse")
            .field("status", &self.status)
            .field("headers", &self.headers)
            .field("body_bytes", &self.body.len())
            .field("origin", &self.origin)
            .finish()
    }
}

/// Response headers that may be kept, passed up and recorded. Everything else is dropped at
/// the transport, so credentials and cookies can never reach a log or a cassette.
pub(crate) const ALLOWED_HEADERS: &[&str] = &[
    "content-type",
    "x-request-id",
    "apim-request-id",
    "openai-processing-ms",
    "openai-version",
    "retry-after",
    "retry-after-ms",
    "x-should-retry",
    "x-ratelimit-limit-requests",
    "x-ratelimit-limit-tokens",
    "x-ratelimit-remaining-requests",
    "x-ratelimit-remaining-tokens",
    "x-ratelimit-reset-requests",
    "x-ratelimit-reset-tokens",
];

/// Whether a header name is on the allowlist.
pub(crate) fn is_allowed_header(name: &str) -> bool {
    ALLOWED_HEADERS
        .iter()
        .any(|allowed| allowed.eq_ignore_ascii_case(name))
}

/// Something that answers wire requests. Implementations must be cheap to share
/// (`Arc<dyn Transport>`); the client calls `send` concurrently up to its concurrency cap.
pub trait Transport: Send + Sync + fmt::Debug {
    /// Sends one request and returns the complete response, or a transport failure.
    /// A non-2xx status is a response, not an error: the retry layer decides about it.
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>>;

    /// A short label for logs and cassette metadata, e.g. `"http openai"`.
    fn label(&self) -> String;

    /// Called once at the end of a run: a cassette writes its usage report and, in strict
    /// mode, fails on unused interactions. The default does nothing.
    fn finish(&self) -> Result<(), VlmError> {
        Ok(())
    }

    /// What the server behind this transport announces it can take. The client asks once,
    /// before its first call. The default announces nothing.
    fn capabilities(&self) -> BoxFuture<'_, ServerCapabilities> {
        Box::pin(async { ServerCapabilities::UNKNOWN })
    }
}

impl<T: Transport + ?Sized> Transport for Arc<T> {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        (**self).send(request)
    }
    fn label(&self) -> String {
        (**self).label()
    }
    fn finish(&self) -> Result<(), VlmError> {
        (**self).finish()
    }
    fn capabilities(&self) -> BoxFuture<'_, ServerCapabilities> {
        (**self).capabilities()
    }
}
