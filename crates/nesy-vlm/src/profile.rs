//! Backend profiles: how each kind of server wants the same request. A profile decides the
//! path, the token-cap field, whether temperature and `reasoning_effort` may be sent, whether
//! `model` and image `detail` go in the body, and how to authenticate.

use std::fmt;
use std::str::FromStr;

use base64::Engine as _;
use serde_json::{Map, Value, json};

use crate::constraint::{ConstrainMode, ReplyForm, body_fields, form_for};
use crate::request::{ChatRequest, ImageDetail, Part, ReasoningEffort, ReplyLength};

/// What stands between the text parts of a message sent without images.
const TEXT_PART_SEPARATOR: &str = "\n\n";
/// The kind of server.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BackendKind {
    /// OpenAI's API (`https://api.openai.com/v1`).
    #[serde(rename = "openai")]
    OpenAi,
    /// Azure OpenAI, classic deployment path with `api-version` and the `api-key` header.
    Azure,
    /// Azure OpenAI's v1 API (`{endpoint}/openai/v1`), `model` = deployment name.
    AzureV1,
    /// vLLM's OpenAI-compatible server.
    Vllm,
    /// Ollama's `/v1` compatibility endpoint.
    Ollama,
    /// llama.cpp's `llama-server`.
    #[serde(rename = "llamacpp")]
    LlamaCpp,
}

impl BackendKind {
    /// The canonical name used in configuration and cassette metadata.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::OpenAi => "openai",
            Self::Azure => "azure",
            Self::AzureV1 => "azure-v1",
            Self::Vllm => "vllm",
            Self::Ollama => "ollama",
            Self::LlamaCpp => "llamacpp",
        }
    }

    /// The base URL used when none is configured (`None` where there is no sensible one).
    pub fn default_base_url(self) -> Option<&'static str> {
        match self {
            Self::OpenAi => Some("https://api.openai.com/v1"),
            Self::Azure | Self::AzureV1 => None,
            Self::Vllm => Some("http://localhost:8000/v1"),
            Self::Ollama => Some("http://localhost:11434/v1"),
            Self::LlamaCpp => Some("http://localhost:8080/v1"),
        }
    }

    /// Whether the backend is a server run by the user (vLLM, Ollama, llama.cpp) rather
    /// than a hosted API.
    pub fn is_local(self) -> bool {
        matches!(self, Self::Vllm | Self::Ollama | Self::LlamaCpp)
    }

    /// Whether the backend refuses requests without a key.
    pub fn requires_api_key(self) -> bool {
        matches!(self, Self::OpenAi | Self::Azure | Self::AzureV1)
    }
}

impl fmt::Display for BackendKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for BackendKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().replace('_', "-").as_str() {
            "openai" => Ok(Self::OpenAi),
            "azure" | "azure-classic" => Ok(Self::Azure),
            "azure-v1" => Ok(Self::AzureV1),
            "vllm" => Ok(Self::Vllm),
            "ollama" => Ok(Self::Ollama),
            "llamacpp" | "llama.cpp" | "llama-cpp" => Ok(Self::LlamaCpp),
            other => Err(format!(
                "unknown backend {other:?}; expected openai, azure, azure-v1, vllm, ollama or llamacpp"
            )),
        }
    }
}

/// Whether the model is a reasoning model (no temperature, `reasoning_effort` allowed).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReasoningMode {
    /// Decide from the model name: `o1`, `o3`, `o4*`, `gpt-5*` (except `*-chat*`) on OpenAI
    /// and Azure; never on local servers.
    #[default]
    Auto,
    /// It is a reasoning model.
    On,
    /// It is not.
    Off,
}

impl FromStr for ReasoningMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "on" | "true" | "yes" => Ok(Self::On),
            "off" | "false" | "no" => Ok(Self::Off),
            other => Err(format!(
                "unknown reasoning mode {other:?}; expected auto, on or off"
            )),
        }
    }
}

/// Which body field carries the output-token cap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TokenCapField {
    /// `max_completion_tokens` (OpenAI and Azure; required by reasoning models).
    MaxCompletionTokens,
    /// `max_tokens` (llama.cpp, Ollama, which silently drop the other; vLLM accepts both).
    MaxTokens,
}

impl TokenCapField {
    /// The body field name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::MaxCompletionTokens => "max_completion_tokens",
            Self::MaxTokens => "max_tokens",
        }
    }
}

/// How the profile authenticates (the key itself lives only in the HTTP transport).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AuthScheme {
    /// `Authorization: Bearer <key>`, if a key is configured.
    Bearer,
    /// `api-key: <key>`.
    ApiKeyHeader,
}

/// Output-token caps by what a call is for, applied when neither the request nor the
/// configuration sets a cap. A local server generates tens of tokens per second, so an
/// unbounded reply that runs away costs minutes; each cap leaves room for a full answer of
/// its kind with a short rationale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReplyCaps {
    /// Operator induction (`induce`): an action block.
    pub induce: u32,
    /// Refinement (`patch`): one SEARCH/REPLACE block. Its grammar lets the SEARCH side
    /// quote up to eight actions of the procedure and the REPLACE side hold six blocks, so a
    /// reply held to it can need about 2,000 tokens; a smaller cap cuts such a reply off
    /// before the grammar lets it end.
    pub patch: u32,
    /// State translation (`translate`): a list of atoms.
    pub translate: u32,
    /// Code generation (`codegen`): a whole policy.
    pub codegen: u32,
    /// Every other purpose (the baselines' stages).
    pub other: u32,
    /// A call of any purpose whose answer is one line, a verdict or a few items
    /// ([`ReplyLength::Brief`]).
    pub brief: u32,
}

impl ReplyCaps {
    /// The caps used for local backends (vLLM, Ollama, llama.cpp) by default.
    pub const LOCAL: ReplyCaps = ReplyCaps {
        induce: 768,
        patch: 2048,
        translate: 768,
        codegen: 2048,
        other: 1024,
        brief: 256,
    };

    /// The cap for a call labelled `purpose` whose answer has length `length`.
    ///
    /// ```
    /// use nesy_vlm::{ReplyCaps, ReplyLength};
    /// assert_eq!(ReplyCaps::LOCAL.cap_for(Some("codegen"), ReplyLength::Open), 2048);
    /// assert_eq!(ReplyCaps::LOCAL.cap_for(Some("gpt4v.plan"), ReplyLength::Open), 1024);
    /// assert_eq!(ReplyCaps::LOCAL.cap_for(Some("d2c.observe"), ReplyLength::Brief), 256);
    /// ```
    pub fn cap_for(&self, purpose: Option<&str>, length: ReplyLength) -> u32 {
        if length == ReplyLength::Brief {
            return self.brief;
        }
        match purpose {
            Some("induce") => self.induce,
            Some("patch") => self.patch,
            Some("translate") => self.translate,
            Some("codegen") => self.codegen,
            _ => self.other,
        }
    }
}

/// Per-call defaults that the profile applies when the request does not set them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BodyDefaults {
    /// Default output-token cap.
    pub max_output_tokens: Option<u32>,
    /// Caps by purpose, for calls that set none when `max_output_tokens` is unset too.
    pub reply_caps: Option<ReplyCaps>,
    /// Default temperature (ignored for reasoning models).
    pub temperature: Option<f32>,
    /// Default reasoning effort (sent only to reasoning models).
    pub reasoning_effort: Option<ReasoningEffort>,
    /// Default image detail.
    pub image_detail: Option<ImageDetail>,
    /// Whether a request's [`ReplyConstraint`](crate::ReplyConstraint) is sent.
    pub constrain: ConstrainMode,
}

/// A resolved backend profile: everything needed to turn a [`ChatRequest`] into a wire body.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// The backend.
    pub kind: BackendKind,
    /// The model name sent in the body (for classic Azure: the deployment, used in the path).
    pub model: String,
    /// The request path relative to the base URL (with the query, for classic Azure).
    pub path: String,
    /// The token-cap field.
    pub token_cap_field: TokenCapField,
    /// The auth header scheme.
    pub auth: AuthScheme,
    /// Whether the body carries `model` (classic Azure takes it from the path).
    pub sends_model: bool,
    /// Whether image parts carry `detail` (Ollama and llama.cpp do not use it).
    pub sends_image_detail: bool,
    /// Whether the model is treated as a reasoning model.
    pub reasoning: bool,
    /// Defaults for fields the request leaves unset.
    pub defaults: BodyDefaults,
}

/// Whether a model name looks like an OpenAI reasoning model.
pub(crate) fn looks_like_reasoning_model(model: &str) -> bool {
    let name = model.rsplit('/').next().unwrap_or(model).to_ascii_lowercase();
    let o_series = ["o1", "o3", "o4"].iter().any(|prefix| {
        name == *prefix
            || name
                .strip_prefix(prefix)
                .is_some_and(|rest| rest.starts_with('-'))
    });
    (o_series || name.starts_with("gpt-5")) && !name.contains("-chat")
}

impl Profile {
    /// Resolves a profile. `azure_deployment` and `azure_api_version` matter only for
    /// classic Azure (the deployment defaults to the model name).
    pub fn new(
        kind: BackendKind,
        model: &str,
        reasoning: ReasoningMode,
        azure_deployment: Option<&str>,
        azure_api_version: &str,
        defaults: BodyDefaults,
    ) -> Self {
        let reasoning = match reasoning {
            ReasoningMode::On => true,
            ReasoningMode::Off => false,
            ReasoningMode::Auto => {
                matches!(
                    kind,
                    BackendKind::OpenAi | BackendKind::Azure | BackendKind::AzureV1
                ) && looks_like_reasoning_model(model)
            }
        };
        let (path, sends_model) = match kind {
            BackendKind::Azure => (
                format!(
                    "/openai/deployments/{}/chat/completions?api-version={}",
                    azure_deployment.unwrap_or(model),
                    azure_api_version
                ),
                false,
            ),
            _ => ("/chat/completions".to_string(), true),
        };
        let token_cap_field = match kind {
            BackendKind::OpenAi | BackendKind::Azure | BackendKind::AzureV1 => {
                TokenCapField::MaxCompletionTokens
            }
            BackendKind::Vllm | BackendKind::Ollama | BackendKind::LlamaCpp => TokenCapField::MaxTokens,
        };
        let auth = match kind {
            BackendKind::Azure | BackendKind::AzureV1 => AuthScheme::ApiKeyHeader,
            _ => AuthScheme::Bearer,
        };
        let sends_image_detail = !matches!(kind, BackendKind::Ollama | BackendKind::LlamaCpp);
        Self {
            kind,
            model: model.to_string(),
            path,
            token_cap_field,
            auth,
            sends_model,
            sends_image_detail,
            reasoning,
            defaults,
        }
    }

    /// The output-token cap `request` is sent with: its own, else the configured default,
    /// else the cap for its purpose.
    pub fn output_cap(&self, request: &ChatRequest) -> Option<u32> {
        request
            .max_output_tokens
            .or(self.defaults.max_output_tokens)
            .or_else(|| {
                self.defaults
                    .reply_caps
                    .map(|caps| caps.cap_for(request.purpose.as_deref(), request.reply_length))
            })
    }

    /// The form `request`'s reply takes: held to its grammar, to its JSON schema, or free,
    /// by what this backend takes and the configured [`ConstrainMode`].
    pub fn reply_form(&self, request: &ChatRequest) -> ReplyForm {
        form_for(self.kind, self.defaults.constrain, request.constraint.as_ref())
    }

    /// Builds the JSON body for a request. Images become base64 data URLs.
    pub fn build_body(&self, request: &ChatRequest) -> Value {
        let mut body = Map::new();
        if self.sends_model {
            body.insert("model".into(), Value::String(self.model.clone()));
        }
        let messages = request.messages.iter().map(|message| {
            let texts: Option<Vec<&str>> = message
                .parts
                .iter()
                .map(|part| match part {
                    Part::Text(text) => Some(text.as_str()),
                    Part::Image(_) => None,
                })
                .collect();
            // A message of text alone is sent as one string, its parts a blank line apart:
            // llama.cpp's chat templates join an array's text parts with nothing between
            // them, and a recorded prompt read "…state follows.scene, as its ground-truth
            // state…" where two parts met.
            let content = match texts {
                Some(texts) => Value::String(texts.join(TEXT_PART_SEPARATOR)),
                None => Value::Array(message.parts.iter().map(|part| self.part_json(part)).collect()),
            };
            json!({ "role": message.role.as_str(), "content": content })
        });
        body.insert("messages".into(), Value::Array(messages.collect()));
        if let Some(cap) = self.output_cap(request) {
            body.insert(self.token_cap_field.as_str().into(), Value::from(cap));
        }
        let temperature = request.temperature.or(self.defaults.temperature);
        if let Some(temperature) = temperature.filter(|_| !self.reasoning) {
            // Through f64 via the shortest decimal text, so 0.2f32 is sent as 0.2.
            let value: f64 = temperature.to_string().parse().unwrap_or(f64::from(temperature));
            body.insert("temperature".into(), Value::from(value));
        }
        if let Some(effort) = request
            .reasoning_effort
            .or(self.defaults.reasoning_effort)
            .filter(|_| self.reasoning)
        {
            body.insert("reasoning_effort".into(), Value::from(effort.as_str()));
        }
        if let Some(constraint) = &request.constraint {
            for (key, value) in body_fields(self.kind, self.reply_form(request), constraint) {
                body.insert(key, value);
            }
        }
        for (key, value) in &request.extra {
            body.insert(key.clone(), value.clone());
        }
        Value::Object(body)
    }

    fn part_json(&self, part: &Part) -> Value {
        match part {
            Part::Text(text) => json!({ "type": "text", "text": text }),
            Part::Image(image) => {
                let mut url = String::with_capacity(image.bytes().len() * 4 / 3 + 32);
                url.push_str("data:");
                url.push_str(image.mime().as_str());
                url.push_str(";base64,");
                base64::engine::general_purpose::STANDARD.encode_string(image.bytes(), &mut url);
                let mut image_url = Map::new();
                image_url.insert("url".into(), Value::String(url));
                if let Some(detail) = image
                    .detail()
                    .or(self.defaults.image_detail)
                    .filter(|_| self.sends_image_detail)
                {
                    image_url.insert("detail".into(), Value::from(detail.as_str()));
                }
                json!({ "type": "image_url", "image_url": image_url })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reasoning_model_names() {
        for name in [
            "o1",
            "o3-mini",
            "o4-mini-2025-04-16",
            "gpt-5",
            "gpt-5.2",
            "openai/gpt-5-mini",
        ] {
            assert!(looks_like_reasoning_model(name), "{name}");
        }
        for name in [
            "gpt-4o",
            "gpt-4.1",
            "gpt-5-chat-latest",
            "qwen2.5-vl",
            "o1x",
            "llava:13b",
        ] {
            assert!(!looks_like_reasoning_model(name), "{name}");
        }
    }

    #[test]
    fn backend_names_parse() {
        assert_eq!("llama.cpp".parse::<BackendKind>(), Ok(BackendKind::LlamaCpp));
        assert_eq!("AZURE_V1".parse::<BackendKind>(), Ok(BackendKind::AzureV1));
        assert!(
            "bedrock"
                .parse::<BackendKind>()
                .unwrap_err()
                .contains("expected openai")
        );
    }
}
