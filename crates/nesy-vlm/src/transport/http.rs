//! The live transport: reqwest over rustls (ring), with connect, read and total timeouts.

use std::fmt;
use std::sync::Once;
use std::time::Duration;

use reqwest::header::{CONTENT_TYPE, HeaderMap, HeaderValue};

use super::{BoxFuture, Origin, Transport, WireRequest, WireResponse, is_allowed_header};
use crate::capabilities::ServerCapabilities;
use crate::config::Timeouts;
use crate::error::{TimeoutPhase, TransportError};
use crate::profile::BackendKind;
use crate::retry::status_may_pass;
use crate::secret::SecretString;

/// How requests authenticate.
#[derive(Clone, PartialEq, Eq)]
pub enum Auth {
    /// No credentials (local servers).
    None,
    /// `Authorization: Bearer <key>` (OpenAI, vLLM `--api-key`, llama.cpp `--api-key`).
    Bearer(SecretString),
    /// `api-key: <key>` (Azure OpenAI).
    ApiKeyHeader(SecretString),
}

impl fmt::Debug for Auth {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::None => "Auth::None",
            Self::Bearer(_) => "Auth::Bearer(***)",
            Self::ApiKeyHeader(_) => "Auth::ApiKeyHeader(***)",
        })
    }
}

/// The waits between tries of reading what a server announces (three tries in all).
const PROBE_RETRY_WAITS: [Duration; 2] = [Duration::from_millis(500), Duration::from_millis(1500)];

/// Sends wire requests to an OpenAI-compatible server.
pub struct HttpTransport {
    client: reqwest::Client,
    base_url: String,
    auth_headers: HeaderMap,
    auth_kind: &'static str,
    label: String,
    /// Which server's announcement to read, and for which model.
    probe: Option<(BackendKind, String)>,
}

impl fmt::Debug for HttpTransport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("HttpTransport")
            .field("base_url", &self.base_url)
            .field("auth", &self.auth_kind)
            .field("label", &self.label)
            .finish()
    }
}

static INSTALL_CRYPTO: Once = Once::new();

impl HttpTransport {
    /// A transport posting to `base_url` + the request path. `base_url` is used as given
    /// (without a trailing slash), e.g. `https://api.openai.com/v1`.
    pub fn new(
        base_url: &str,
        auth: Auth,
        timeouts: &Timeouts,
        label: impl Into<String>,
    ) -> Result<Self, String> {
        // reqwest is built without a bundled crypto provider; ring is ours. Installing fails
        // harmlessly when the process already chose one.
        INSTALL_CRYPTO.call_once(|| {
            let _ = rustls::crypto::ring::default_provider().install_default();
        });
        let base_url = base_url.trim_end_matches('/').to_string();
        let parsed = reqwest::Url::parse(&base_url).map_err(|err| format!("base URL {base_url:?}: {err}"))?;
        if !matches!(parsed.scheme(), "http" | "https") {
            return Err(format!(
                "base URL {base_url:?} must start with http:// or https://"
            ));
        }
        let mut builder = reqwest::Client::builder()
            .user_agent(concat!("nesy-vlm/", env!("CARGO_PKG_VERSION")))
            .pool_idle_timeout(timeouts.pool_idle);
        if let Some(connect) = timeouts.connect {
            builder = builder.connect_timeout(connect);
        }
        if let Some(read) = timeouts.read {
            builder = builder.read_timeout(read);
        }
        if let Some(total) = timeouts.total {
            builder = builder.timeout(total);
        }
        // A proxy from the environment must not capture loopback traffic (local servers, tests).
        let loopback = matches!(
            parsed.host_str(),
            Some("localhost" | "127.0.0.1" | "[::1]" | "::1")
        );
        if loopback {
            builder = builder.no_proxy();
        }
        let client = builder
            .build()
            .map_err(|err| format!("building the HTTP client: {err}"))?;
        let mut auth_headers = HeaderMap::new();
        let auth_kind = match &auth {
            Auth::None => "none",
            Auth::Bearer(key) => {
                auth_headers.insert(
                    reqwest::header::AUTHORIZATION,
                    secret_header(&format!("Bearer {}", key.expose()))?,
                );
                "bearer"
            }
            Auth::ApiKeyHeader(key) => {
                auth_headers.insert("api-key", secret_header(key.expose())?);
                "api-key"
            }
        };
        Ok(Self {
            client,
            base_url,
            auth_headers,
            auth_kind,
            label: label.into(),
            probe: None,
        })
    }

    /// Reads what the server announces before the first call: llama.cpp's `/props` (image
    /// input, context window) or vLLM's `/models` (context window). Other backends announce
    /// nothing and are not asked.
    pub fn with_probe(mut self, backend: BackendKind, model: impl Into<String>) -> Self {
        self.probe = Some((backend, model.into()));
        self
    }

    /// GETs a JSON document, trying again after a short wait when the failure may pass (a
    /// connection or timeout error, a status such as a 503 from a server still loading its
    /// model):
    /// a missed announcement would send pictures to a text-only server for the whole run.
    async fn get_json(&self, url: &str) -> Result<serde_json::Value, String> {
        let mut waits = PROBE_RETRY_WAITS.iter();
        loop {
            match self.get_json_once(url).await {
                Err((error, true)) => match waits.next() {
                    Some(wait) => {
                        tracing::debug!("reading {url} failed ({error}); trying again in {wait:?}");
                        tokio::time::sleep(*wait).await;
                    }
                    None => return Err(error),
                },
                other => return other.map_err(|(error, _)| error),
            }
        }
    }

    /// One GET; an error says whether it may pass on a second try.
    async fn get_json_once(&self, url: &str) -> Result<serde_json::Value, (String, bool)> {
        let response = self
            .client
            .get(url)
            .headers(self.auth_headers.clone())
            .send()
            .await
            .map_err(described)?;
        let status = response.status().as_u16();
        if !response.status().is_success() {
            return Err((format!("HTTP {status}"), status_may_pass(status)));
        }
        let bytes = response.bytes().await.map_err(described)?;
        serde_json::from_slice(&bytes).map_err(|e| (format!("not JSON: {e}"), false))
    }

    async fn probe_capabilities(&self) -> ServerCapabilities {
        let Some((backend, model)) = &self.probe else {
            return ServerCapabilities::UNKNOWN;
        };
        let read = match backend {
            BackendKind::LlamaCpp => {
                // `/props` lives at the server's root, beside `/v1`.
                let root = self.base_url.strip_suffix("/v1").unwrap_or(&self.base_url);
                let url = format!("{root}/props");
                self.get_json(&url)
                    .await
                    .map(|props| ServerCapabilities::from_llamacpp_props(&props))
                    .map_err(|e| (url, e))
            }
            BackendKind::Vllm => {
                let url = format!("{}/models", self.base_url);
                self.get_json(&url)
                    .await
                    .map(|list| ServerCapabilities::from_models_list(&list, model))
                    .map_err(|e| (url, e))
            }
            _ => return ServerCapabilities::UNKNOWN,
        };
        read.unwrap_or_else(|(url, error)| {
            tracing::warn!("could not read what the server announces at {url} ({error}); assuming nothing");
            ServerCapabilities::UNKNOWN
        })
    }

    /// The base URL requests are sent to.
    pub fn base_url(&self) -> &str {
        &self.base_url
    }

    async fn post(&self, request: &WireRequest) -> Result<WireResponse, TransportError> {
        let url = format!("{}{}", self.base_url, request.path);
        let body = serde_json::to_vec(&request.body).map_err(|err| TransportError::Failed {
            message: format!("encoding the body: {err}"),
            retryable: false,
        })?;
        let response = self
            .client
            .post(&url)
            .headers(self.auth_headers.clone())
            .header(CONTENT_TYPE, "application/json")
            .body(body)
            .send()
            .await
            .map_err(classify)?;
        let status = response.status().as_u16();
        let headers = response
            .headers()
            .iter()
            .filter(|(name, _)| is_allowed_header(name.as_str()))
            .filter_map(|(name, value)| Some((name.as_str().to_string(), value.to_str().ok()?.to_string())))
            .collect();
        let body = response.bytes().await.map_err(classify)?;
        Ok(WireResponse {
            status,
            headers,
            body,
            origin: Origin::Live,
        })
    }
}

fn secret_header(value: &str) -> Result<HeaderValue, String> {
    let mut header = HeaderValue::from_str(value)
        .map_err(|_| "the API key contains characters not allowed in a header")?;
    header.set_sensitive(true);
    Ok(header)
}

/// A failed GET of an announcement as (what went wrong, whether it may pass).
fn described(err: reqwest::Error) -> (String, bool) {
    let error = classify(err);
    let may_pass = error.is_retryable();
    (error.to_string(), may_pass)
}

fn classify(err: reqwest::Error) -> TransportError {
    // reqwest's Display of a chain hides the cause; include it.
    let mut message = err.to_string();
    let mut source = std::error::Error::source(&err);
    while let Some(cause) = source {
        message.push_str(": ");
        message.push_str(&cause.to_string());
        source = cause.source();
    }
    if err.is_timeout() {
        let phase = if err.is_connect() {
            TimeoutPhase::Connect
        } else {
            TimeoutPhase::Response
        };
        TransportError::Timeout { phase, message }
    } else if err.is_connect() {
        TransportError::Connect(message)
    } else if err.is_body() || err.is_decode() {
        TransportError::Body(message)
    } else if err.is_request() {
        TransportError::Connect(message)
    } else {
        TransportError::Failed {
            message,
            retryable: false,
        }
    }
}

impl Transport for HttpTransport {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(self.post(request))
    }

    fn label(&self) -> String {
        self.label.clone()
    }

    fn capabilities(&self) -> BoxFuture<'_, ServerCapabilities> {
        Box::pin(self.probe_capabilities())
    }
}
