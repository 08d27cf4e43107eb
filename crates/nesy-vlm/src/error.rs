//! Typed errors of the client and its transports.

use std::fmt;

use serde::Deserialize;

use crate::cassette::CassetteError;
use crate::config::ConfigError;
use crate::response::Usage;

/// Everything a chat call can fail with. Each variant that comes from a server carries the
/// HTTP status (where there is one), the provider's error body and the request id, so a
/// failure in a long benchmark run can be looked up on the provider's side.
#[derive(Debug, thiserror::Error)]
pub enum VlmError {
    /// The configuration is incomplete or contradictory.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The request cannot be sent as built (for example an image that is not PNG/JPEG).
    #[error("invalid request: {0}")]
    InvalidRequest(String),
    /// The request holds more images than the endpoint accepts
    /// ([`crate::VlmConfig::max_images_per_request`]); it was not sent.
    #[error(
        "the request holds {images} images, more than the {limit} this endpoint accepts per request (max_images_per_request); it was not sent"
    )]
    TooManyImages {
        /// Images in the request.
        images: usize,
        /// The configured limit.
        limit: usize,
    },
    /// The transport failed without an HTTP response (timeout, refused connection, cut body).
    #[error("{error} (after {attempts} attempt(s))")]
    Transport {
        /// What went wrong on the last attempt (shown in the message, so not also a `source`).
        error: TransportError,
        /// Attempts made, including the last.
        attempts: u32,
    },
    /// The server answered with a non-success status.
    #[error("HTTP {status} on {path}{}: {provider}{}", request_id_suffix(request_id), attempts_suffix(*attempts))]
    Http {
        /// The HTTP status code.
        status: u16,
        /// The request path (relative to the base URL).
        path: String,
        /// The provider's error object, parsed tolerantly, with the raw body.
        provider: Box<ProviderError>,
        /// `x-request-id` / `apim-request-id` of the failed response.
        request_id: Option<String>,
        /// Attempts made, including the last.
        attempts: u32,
    },
    /// A success status whose body is not a chat-completions response.
    #[error(
        "invalid response body (HTTP {status}{}): {detail}; body starts {excerpt:?}",
        request_id_suffix(request_id)
    )]
    InvalidResponse {
        /// The HTTP status code.
        status: u16,
        /// What is wrong: the JSON error with line and column, or the missing field.
        detail: String,
        /// The first bytes of the body.
        excerpt: String,
        /// Request id, if the server sent one.
        request_id: Option<String>,
    },
    /// The reply was cut short (`finish_reason == "length"`): at the token cap, or because
    /// the server's context window filled up first ([`VlmError::cutoff`] tells which).
    #[error(
        "output cut short (finish_reason \"length\"): {}{}",
        Cutoff::of(*cap, usage.as_ref(), *context),
        request_id_suffix(request_id)
    )]
    Truncated {
        /// The text produced before the cut.
        partial_text: String,
        /// Token usage, if reported.
        usage: Option<Usage>,
        /// Request id, if the server sent one.
        request_id: Option<String>,
        /// The output-token cap the request carried (the client fills it in).
        cap: Option<u32>,
        /// The context window the server announced, if it did (the client fills it in).
        context: Option<u32>,
    },
    /// The server announced that it cannot take what the request carries (image input to a
    /// text-only model); the request was not sent.
    #[error("{capability} is not supported: {detail}")]
    Unsupported {
        /// What is missing, e.g. `image input`.
        capability: String,
        /// Who said so and what the request carried.
        detail: String,
    },
    /// The prompt alone would fill the server's context window; the request was not sent.
    #[error(
        "the prompt needs about {estimated} tokens and the server's context window holds {context} (prompt and reply together); it was not sent"
    )]
    ContextExceeded {
        /// The prompt's estimated size in tokens (an estimate that errs high).
        estimated: u32,
        /// The context window the server announced.
        context: u32,
    },
    /// The model refused (a `refusal` message or `finish_reason == "content_filter"`).
    #[error("model refused{}: {reason}", request_id_suffix(request_id))]
    Refusal {
        /// The refusal text, or a note that the content filter stopped the output.
        reason: String,
        /// Request id, if the server sent one.
        request_id: Option<String>,
    },
    /// A cassette failed: a miss in replay mode, a corrupt file, unused interactions.
    #[error(transparent)]
    Cassette(#[from] CassetteError),
}

/// Where a reply that stopped with `finish_reason: length` was cut off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cutoff {
    /// At the output-token cap the request carried.
    TokenCap(u32),
    /// Before that cap: the server's context window was full after `generated` tokens.
    ContextWindow {
        /// Tokens generated before the cut.
        generated: u32,
    },
    /// The request carried no cap and the server did not report its usage.
    Unstated,
}

impl Cutoff {
    /// Tells the cases apart: a reply whose prompt and output together reached the context
    /// window the server announced stopped because the window was full; otherwise the cap
    /// the request carried stopped it.
    ///
    /// ```
    /// use nesy_vlm::{Cutoff, Usage};
    /// let usage = Usage { prompt_tokens: 8000, completion_tokens: 192, ..Usage::default() };
    /// assert_eq!(Cutoff::of(Some(512), Some(&usage), Some(8192)), Cutoff::ContextWindow { generated: 192 });
    /// assert_eq!(Cutoff::of(Some(512), Some(&usage), None), Cutoff::TokenCap(512));
    /// ```
    pub fn of(cap: Option<u32>, usage: Option<&Usage>, context: Option<u32>) -> Cutoff {
        // Servers count a few framing tokens differently; a reply this close to the window
        // ran into it.
        const SLACK_TOKENS: u64 = 16;
        if let (Some(usage), Some(context)) = (usage, context)
            && usage.prompt_tokens + usage.completion_tokens + SLACK_TOKENS >= u64::from(context)
        {
            return Cutoff::ContextWindow {
                generated: u32::try_from(usage.completion_tokens).unwrap_or(u32::MAX),
            };
        }
        match cap {
            Some(cap) => Cutoff::TokenCap(cap),
            None => Cutoff::Unstated,
        }
    }
}

impl std::fmt::Display for Cutoff {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Cutoff::TokenCap(cap) => write!(f, "cut off at the token cap ({cap} tokens)"),
            Cutoff::ContextWindow { generated } => write!(
                f,
                "cut off when the server's context window was full ({generated} tokens generated)"
            ),
            Cutoff::Unstated => {
                f.write_str("cut off by the server (no token cap was sent and no usage reported)")
            }
        }
    }
}

impl VlmError {
    /// Where a truncated reply was cut off (`None` for every other error).
    pub fn cutoff(&self) -> Option<Cutoff> {
        match self {
            Self::Truncated {
                cap, usage, context, ..
            } => Some(Cutoff::of(*cap, usage.as_ref(), *context)),
            _ => None,
        }
    }

    /// The HTTP status, for errors that came with one.
    pub fn status(&self) -> Option<u16> {
        match self {
            Self::Http { status, .. } | Self::InvalidResponse { status, .. } => Some(*status),
            _ => None,
        }
    }

    /// The provider's request id, for errors that came with one.
    pub fn request_id(&self) -> Option<&str> {
        match self {
            Self::Http { request_id, .. }
            | Self::InvalidResponse { request_id, .. }
            | Self::Truncated { request_id, .. }
            | Self::Refusal { request_id, .. } => request_id.as_deref(),
            _ => None,
        }
    }

    /// How many attempts the call made before failing, where the client counted them.
    pub fn attempts(&self) -> Option<u32> {
        match self {
            Self::Http { attempts, .. } | Self::Transport { attempts, .. } => Some(*attempts),
            _ => None,
        }
    }
}

fn request_id_suffix(request_id: &Option<String>) -> String {
    request_id
        .as_ref()
        .map(|id| format!(" [request id {id}]"))
        .unwrap_or_default()
}

fn attempts_suffix(attempts: u32) -> String {
    if attempts > 1 {
        format!(" (after {attempts} attempts)")
    } else {
        String::new()
    }
}

/// The provider's error object (`{"error": {"message", "type", "code", "param"}}`), read
/// tolerantly: servers differ, so every field is optional and the raw body is kept.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ProviderError {
    /// `error.message`, or the body text when it is not the usual shape.
    pub message: String,
    /// `error.type`, e.g. `insufficient_quota`, `invalid_request_error`.
    pub error_type: Option<String>,
    /// `error.code`, e.g. `rate_limit_exceeded`, `insufficient_quota`.
    pub code: Option<String>,
    /// `error.param`, the request field the server objected to.
    pub param: Option<String>,
    /// The raw body, cut to 4 KiB.
    pub body: String,
}

impl ProviderError {
    /// Reads an error body. Never fails: a body that is not JSON becomes the message.
    /// Anything in it that looks like a credential is redacted
    /// (credential-looking tokens are redacted): providers echo a rejected key in their 401s.
    pub fn from_body(body: &[u8]) -> Self {
        let mut error = Self::parse_body(body);
        error.message = crate::secret::redact_credentials(&error.message);
        error.body = crate::secret::redact_credentials(&error.body);
        error
    }

    /// The capability the server says it lacks, when its error says so: llama.cpp answers a
    /// picture sent to a text-only model with HTTP 500 "image input is not supported". Such
    /// a refusal is not transient and is never retried.
    ///
    /// ```
    /// use nesy_vlm::ProviderError;
    /// let body = br#"{"error":{"code":500,"message":"image input is not supported - hint: if this is unexpected, you may need to provide the mmproj","type":"server_error"}}"#;
    /// assert_eq!(ProviderError::from_body(body).missing_capability(), Some("image input"));
    /// ```
    pub fn missing_capability(&self) -> Option<&'static str> {
        let message = self.message.to_ascii_lowercase();
        let unsupported = ["not supported", "does not support", "unsupported"]
            .iter()
            .any(|phrase| message.contains(phrase));
        let about_images = ["image", "vision", "multimodal"]
            .iter()
            .any(|word| message.contains(word));
        (unsupported && about_images).then_some("image input")
    }

    /// The prompt's size in tokens, when the server refused the request because it does not
    /// fit its context window and said how large it was: llama.cpp's
    /// `exceed_context_size_error` (`n_prompt_tokens`), or vLLM's "you requested N tokens
    /// (P in the messages, …)".
    ///
    /// ```
    /// use nesy_vlm::ProviderError;
    /// let llama = br#"{"error":{"code":400,"message":"request (8236 tokens) exceeds the available context size (8192 tokens), try increasing it","type":"exceed_context_size_error","n_prompt_tokens":8236,"n_ctx":8192}}"#;
    /// assert_eq!(ProviderError::from_body(llama).prompt_tokens_over_context(), Some(8236));
    /// let vllm = br#"{"object":"error","message":"This model's maximum context length is 4096 tokens. However, you requested 4600 tokens (3600 in the messages, 1000 in the completion). Please reduce the length of the messages or completion.","type":"BadRequestError","code":400}"#;
    /// assert_eq!(ProviderError::from_body(vllm).prompt_tokens_over_context(), Some(3600));
    /// assert_eq!(ProviderError::from_body(b"busy").prompt_tokens_over_context(), None);
    /// ```
    pub fn prompt_tokens_over_context(&self) -> Option<u32> {
        if self.error_type.as_deref() == Some("exceed_context_size_error") {
            let body: serde_json::Value = serde_json::from_str(&self.body).ok()?;
            return body["error"]["n_prompt_tokens"]
                .as_u64()
                .and_then(|n| u32::try_from(n).ok());
        }
        let message = &self.message;
        if !message.contains("maximum context length") {
            return None;
        }
        let before = message.split(" in the messages").next()?;
        let digits: String = before
            .chars()
            .rev()
            .take_while(char::is_ascii_digit)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        digits.parse().ok()
    }

    /// This error with every occurrence of `secret` redacted (the configured key, whatever
    /// its shape).
    pub fn without_secret(mut self, secret: &crate::secret::SecretString) -> Self {
        self.message = secret.redact_in(&self.message);
        self.body = secret.redact_in(&self.body);
        self
    }

    fn parse_body(body: &[u8]) -> Self {
        #[derive(Deserialize)]
        struct Envelope {
            error: Option<Inner>,
            message: Option<String>,
        }
        #[derive(Deserialize)]
        struct Inner {
            message: Option<String>,
            #[serde(rename = "type")]
            error_type: Option<serde_json::Value>,
            code: Option<serde_json::Value>,
            param: Option<serde_json::Value>,
        }
        let text = String::from_utf8_lossy(body);
        let raw = truncate_chars(&text, 4096);
        let as_string = |v: Option<serde_json::Value>| match v {
            Some(serde_json::Value::String(s)) => Some(s),
            Some(serde_json::Value::Null) | None => None,
            Some(other) => Some(other.to_string()),
        };
        match serde_json::from_slice::<Envelope>(body) {
            Ok(Envelope {
                error: Some(inner), ..
            }) => Self {
                message: inner.message.unwrap_or_default(),
                error_type: as_string(inner.error_type),
                code: as_string(inner.code),
                param: as_string(inner.param),
                body: raw,
            },
            Ok(Envelope {
                message: Some(message),
                ..
            }) => Self {
                message,
                body: raw,
                ..Self::default()
            },
            _ => Self {
                message: truncate_chars(text.trim(), 300),
                body: raw,
                ..Self::default()
            },
        }
    }

    /// Whether the account is out of credit: such a 429 must never be retried.
    pub fn is_insufficient_quota(&self) -> bool {
        self.code.as_deref() == Some("insufficient_quota")
            || self.error_type.as_deref() == Some("insufficient_quota")
    }
}

impl fmt::Display for ProviderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.message.is_empty() {
            "(no error message)"
        } else {
            &self.message
        })?;
        let tags: Vec<String> = [
            ("type", &self.error_type),
            ("code", &self.code),
            ("param", &self.param),
        ]
        .iter()
        .filter_map(|(name, value)| value.as_ref().map(|v| format!("{name}={v}")))
        .collect();
        if !tags.is_empty() {
            write!(f, " ({})", tags.join(", "))?;
        }
        Ok(())
    }
}

/// Cuts a string to at most `max` characters, marking the cut.
pub(crate) fn truncate_chars(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        Some((cut, _)) => format!("{}…", &text[..cut]),
        None => text.to_string(),
    }
}

/// Which timeout fired.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeoutPhase {
    /// Establishing the connection.
    Connect,
    /// Waiting for or reading the response: the read timeout (between bytes) or the total
    /// timeout of the attempt fired.
    Response,
}

/// A transport-level failure: no (complete) HTTP response was obtained.
#[derive(Debug, thiserror::Error)]
pub enum TransportError {
    /// A timeout fired.
    #[error("timed out ({phase:?} timeout): {message}")]
    Timeout {
        /// Which timeout.
        phase: TimeoutPhase,
        /// The underlying error text.
        message: String,
    },
    /// The connection could not be established.
    #[error("connection failed: {0}")]
    Connect(String),
    /// The response body could not be read to the end.
    #[error("reading the response body failed: {0}")]
    Body(String),
    /// A cassette could not answer or record (never retried).
    #[error(transparent)]
    Cassette(#[from] CassetteError),
    /// An offline responder has no answer to give (the reference responder's planner found
    /// no patch within its limits): asking again would get the same non-answer.
    #[error("{0}")]
    Declined(String),
    /// Any other failure; `retryable` tells the retry layer whether to try again.
    #[error("{message}")]
    Failed {
        /// What went wrong.
        message: String,
        /// Whether another attempt may succeed.
        retryable: bool,
    },
}

impl TransportError {
    /// Whether the retry layer may try again: timeouts, connection and body errors are
    /// transient; cassette errors are not.
    pub fn is_retryable(&self) -> bool {
        match self {
            Self::Timeout { .. } | Self::Connect(_) | Self::Body(_) => true,
            Self::Cassette(_) | Self::Declined(_) => false,
            Self::Failed { retryable, .. } => *retryable,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn provider_error_reads_openai_shape_and_quota() {
        let body = br#"{"error":{"message":"You exceeded your current quota","type":"insufficient_quota","param":null,"code":"insufficient_quota"}}"#;
        let err = ProviderError::from_body(body);
        assert!(err.is_insufficient_quota());
        assert_eq!(err.param, None);
        assert_eq!(
            err.to_string(),
            "You exceeded your current quota (type=insufficient_quota, code=insufficient_quota)"
        );
    }

    #[test]
    fn provider_error_tolerates_other_shapes() {
        assert_eq!(
            ProviderError::from_body(b"upstream down").message,
            "upstream down"
        );
        assert_eq!(ProviderError::from_body(br#"{"message":"bad"}"#).message, "bad");
        let numeric = ProviderError::from_body(br#"{"error":{"message":"m","code":429}}"#);
        assert_eq!(numeric.code.as_deref(), Some("429"));
    }
}
