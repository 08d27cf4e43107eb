//! The typed request: messages made of text and image parts, plus per-call options and the
//! task context that travels beside the wire body.

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::constraint::ReplyConstraint;
use crate::error::VlmError;

/// Who speaks a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Instructions that frame the conversation.
    System,
    /// OpenAI's newer name for system instructions to reasoning models.
    Developer,
    /// The caller.
    User,
    /// The model (for few-shot examples or multi-turn repair).
    Assistant,
}

impl Role {
    /// The wire name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::System => "system",
            Self::Developer => "developer",
            Self::User => "user",
            Self::Assistant => "assistant",
        }
    }
}

/// How closely the server should look at an image (`image_url.detail`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ImageDetail {
    /// Let the server decide.
    Auto,
    /// A single low-resolution tile (cheap).
    Low,
    /// Full tiling (what keyframe images need to read small objects).
    High,
}

impl ImageDetail {
    /// The wire name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Low => "low",
            Self::High => "high",
        }
    }
}

impl FromStr for ImageDetail {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "low" => Ok(Self::Low),
            "high" => Ok(Self::High),
            other => Err(format!(
                "unknown image detail {other:?}; expected auto, low or high"
            )),
        }
    }
}

/// `reasoning_effort` for reasoning models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReasoningEffort {
    /// No reasoning tokens (GPT-5.1 and later).
    None,
    /// The least reasoning (GPT-5).
    Minimal,
    /// Low effort.
    Low,
    /// Medium effort (the usual server default).
    Medium,
    /// High effort.
    High,
    /// Extra-high effort, where offered.
    Xhigh,
}

impl ReasoningEffort {
    /// The wire name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Minimal => "minimal",
            Self::Low => "low",
            Self::Medium => "medium",
            Self::High => "high",
            Self::Xhigh => "xhigh",
        }
    }
}

impl FromStr for ReasoningEffort {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "none" => Ok(Self::None),
            "minimal" => Ok(Self::Minimal),
            "low" => Ok(Self::Low),
            "medium" => Ok(Self::Medium),
            "high" => Ok(Self::High),
            "xhigh" => Ok(Self::Xhigh),
            other => Err(format!(
                "unknown reasoning effort {other:?}; expected none, minimal, low, medium, high or xhigh"
            )),
        }
    }
}

/// The media type of an image, detected from its magic bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageMime {
    /// `image/png`.
    Png,
    /// `image/jpeg`.
    Jpeg,
    /// `image/webp`.
    Webp,
}

impl ImageMime {
    /// The media type string.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Png => "image/png",
            Self::Jpeg => "image/jpeg",
            Self::Webp => "image/webp",
        }
    }

    fn detect(bytes: &[u8]) -> Option<Self> {
        if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
            Some(Self::Png)
        } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
            Some(Self::Jpeg)
        } else if bytes.len() >= 12 && &bytes[..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
            Some(Self::Webp)
        } else {
            None
        }
    }
}

/// Encoded image bytes, shared cheaply between requests (keyframes are reused across calls).
#[derive(Clone, PartialEq, Eq)]
pub struct Image {
    bytes: Arc<[u8]>,
    mime: ImageMime,
    detail: Option<ImageDetail>,
}

impl Image {
    /// An image from PNG bytes; anything else is rejected with the bytes' first signature.
    pub fn png(bytes: impl Into<Arc<[u8]>>) -> Result<Self, VlmError> {
        let image = Self::from_encoded(bytes)?;
        if image.mime != ImageMime::Png {
            return Err(VlmError::InvalidRequest(format!(
                "expected PNG bytes, got {}",
                image.mime.as_str()
            )));
        }
        Ok(image)
    }

    /// An image from PNG, JPEG or WebP bytes, the type detected from the magic bytes.
    pub fn from_encoded(bytes: impl Into<Arc<[u8]>>) -> Result<Self, VlmError> {
        let bytes = bytes.into();
        let mime = ImageMime::detect(&bytes).ok_or_else(|| {
            let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
            VlmError::InvalidRequest(format!(
                "image of {} bytes is not PNG, JPEG or WebP (starts with {})",
                bytes.len(),
                head.join(" ")
            ))
        })?;
        Ok(Self {
            bytes,
            mime,
            detail: None,
        })
    }

    /// Sets this image's `detail`, overriding the client's default.
    pub fn with_detail(mut self, detail: ImageDetail) -> Self {
        self.detail = Some(detail);
        self
    }

    /// The encoded bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The detected media type.
    pub fn mime(&self) -> ImageMime {
        self.mime
    }

    /// The per-image detail, if set.
    pub fn detail(&self) -> Option<ImageDetail> {
        self.detail
    }
}

impl fmt::Debug for Image {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Image({}, {} bytes, detail {:?})",
            self.mime.as_str(),
            self.bytes.len(),
            self.detail
        )
    }
}

/// One part of a message's content.
#[derive(Debug, Clone, PartialEq)]
pub enum Part {
    /// Text.
    Text(String),
    /// An image, sent as a base64 data URL.
    Image(Image),
}

impl Part {
    /// A text part.
    pub fn text(text: impl Into<String>) -> Self {
        Self::Text(text.into())
    }
}

impl From<Image> for Part {
    fn from(image: Image) -> Self {
        Self::Image(image)
    }
}

/// One chat message.
#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    /// Who speaks.
    pub role: Role,
    /// Text and image parts, in order.
    pub parts: Vec<Part>,
}

impl Message {
    /// A message with the given parts.
    pub fn new(role: Role, parts: Vec<Part>) -> Self {
        Self { role, parts }
    }

    /// A system message.
    pub fn system(text: impl Into<String>) -> Self {
        Self::new(Role::System, vec![Part::text(text)])
    }

    /// A user message of text only.
    pub fn user_text(text: impl Into<String>) -> Self {
        Self::new(Role::User, vec![Part::text(text)])
    }

    /// A user message of several parts.
    pub fn user(parts: Vec<Part>) -> Self {
        Self::new(Role::User, parts)
    }

    /// An assistant message.
    pub fn assistant(text: impl Into<String>) -> Self {
        Self::new(Role::Assistant, vec![Part::text(text)])
    }
}

/// Structured information about the task a call serves (for example the ground-truth states of
/// the scene). It travels beside the wire body: it is never sent to a server and never part
/// of a cassette key, but a transport may use it (an offline reference responder answers
/// from it).
#[derive(Debug, Clone, PartialEq)]
pub struct TaskContext {
    /// What kind of task this is, e.g. `"induce_operator"`; lets a transport dispatch.
    pub kind: String,
    /// The task's data.
    pub data: Arc<serde_json::Value>,
}

impl TaskContext {
    /// A task context of the given kind.
    pub fn new(kind: impl Into<String>, data: serde_json::Value) -> Self {
        Self {
            kind: kind.into(),
            data: Arc::new(data),
        }
    }
}

/// How long a call's answer is expected to be. A local server generates tens of tokens per
/// second, so a one-line answer gets a smaller cap than an open one
/// ([`crate::ReplyCaps::brief`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ReplyLength {
    /// Whatever the call's kind needs (a plan, a program, an action block).
    #[default]
    Open,
    /// One line, a verdict or a few items.
    Brief,
}

/// One chat-completions call, before the backend profile turns it into a wire body.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ChatRequest {
    /// The conversation.
    pub messages: Vec<Message>,
    /// Token cap for this call; the client's default applies when `None`.
    pub max_output_tokens: Option<u32>,
    /// Sampling temperature; dropped for reasoning models, which refuse it.
    pub temperature: Option<f32>,
    /// Reasoning effort; sent only to reasoning models.
    pub reasoning_effort: Option<ReasoningEffort>,
    /// What the call is for (`"induce"`, `"patch"`, ...): accounting groups by it and
    /// cassettes show it. Not sent.
    pub purpose: Option<String>,
    /// Task context for transports that answer offline. Not sent, not hashed.
    pub task: Option<TaskContext>,
    /// What the reply must look like; sent in the backend's dialect where it has one.
    pub constraint: Option<ReplyConstraint>,
    /// How long the answer is expected to be, which picks its output cap on a local backend
    /// when neither the request nor the configuration sets one. Not sent.
    pub reply_length: ReplyLength,
    /// Further body fields sent as given (e.g. `seed`, `response_format`), applied last.
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl ChatRequest {
    /// An empty request; add messages with [`ChatRequest::message`].
    pub fn new() -> Self {
        Self::default()
    }

    /// The number of image parts over all messages.
    pub fn image_count(&self) -> usize {
        self.messages
            .iter()
            .flat_map(|m| &m.parts)
            .filter(|p| matches!(p, Part::Image(_)))
            .count()
    }

    /// Appends a message.
    pub fn message(mut self, message: Message) -> Self {
        self.messages.push(message);
        self
    }

    /// Sets the token cap.
    pub fn max_output_tokens(mut self, tokens: u32) -> Self {
        self.max_output_tokens = Some(tokens);
        self
    }

    /// Sets the temperature.
    pub fn temperature(mut self, temperature: f32) -> Self {
        self.temperature = Some(temperature);
        self
    }

    /// Sets the reasoning effort.
    pub fn reasoning_effort(mut self, effort: ReasoningEffort) -> Self {
        self.reasoning_effort = Some(effort);
        self
    }

    /// Labels the call for accounting.
    pub fn purpose(mut self, purpose: impl Into<String>) -> Self {
        self.purpose = Some(purpose.into());
        self
    }

    /// Says how long the answer is expected to be.
    pub fn reply_length(mut self, length: ReplyLength) -> Self {
        self.reply_length = length;
        self
    }

    /// Attaches task context for offline transports.
    pub fn task(mut self, task: TaskContext) -> Self {
        self.task = Some(task);
        self
    }

    /// Holds the reply to `constraint` where the backend can.
    pub fn constraint(mut self, constraint: ReplyConstraint) -> Self {
        self.constraint = Some(constraint);
        self
    }

    /// Adds a body field sent as given.
    pub fn extra(mut self, key: impl Into<String>, value: serde_json::Value) -> Self {
        self.extra.insert(key.into(), value);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_types_are_detected_and_junk_rejected() {
        assert_eq!(
            Image::from_encoded(b"\x89PNG\r\n\x1a\n....".to_vec())
                .unwrap()
                .mime(),
            ImageMime::Png
        );
        assert_eq!(
            Image::from_encoded(vec![0xFF, 0xD8, 0xFF, 0xE0]).unwrap().mime(),
            ImageMime::Jpeg
        );
        let err = Image::png(b"GIF89a....".to_vec()).unwrap_err().to_string();
        assert!(err.contains("47 49 46 38"), "{err}");
        let err = Image::png(vec![0xFF, 0xD8, 0xFF]).unwrap_err().to_string();
        assert!(err.contains("expected PNG"), "{err}");
    }

    #[test]
    fn enums_parse_with_helpful_errors() {
        assert_eq!("HIGH".parse::<ImageDetail>(), Ok(ImageDetail::High));
        assert!(
            "huge"
                .parse::<ImageDetail>()
                .unwrap_err()
                .contains("auto, low or high")
        );
        assert_eq!("minimal".parse::<ReasoningEffort>(), Ok(ReasoningEffort::Minimal));
    }
}
