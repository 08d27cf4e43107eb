//! Reading a chat-completions response tolerantly: compatible servers differ in which fields
//! they send, so unknown fields are ignored and usage may be missing.

use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::error::{ProviderError, VlmError, truncate_chars};
use crate::transport::Origin;

/// Token usage of one call. Reasoning tokens are part of `completion_tokens` (as OpenAI
/// bills them) and also reported separately.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Usage {
    /// Input tokens, images included.
    pub prompt_tokens: u64,
    /// Output tokens, reasoning included.
    pub completion_tokens: u64,
    /// Hidden reasoning tokens (`completion_tokens_details.reasoning_tokens`).
    pub reasoning_tokens: u64,
    /// Input tokens served from the prompt cache (`prompt_tokens_details.cached_tokens`).
    pub cached_prompt_tokens: u64,
}

/// Why generation stopped.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FinishReason {
    /// A natural end or a stop sequence.
    Stop,
    /// The token cap (reported as [`VlmError::Truncated`], never returned in a response).
    Length,
    /// The content filter (reported as [`VlmError::Refusal`]).
    ContentFilter,
    /// The model asked for a tool.
    ToolCalls,
    /// The server did not say.
    Unknown,
    /// Any other value, kept verbatim.
    Other(String),
}

impl FinishReason {
    fn from_wire(value: Option<&str>) -> Self {
        match value {
            Some("stop") | Some("end_turn") | Some("eos") => Self::Stop,
            Some("length") | Some("max_tokens") => Self::Length,
            Some("content_filter") => Self::ContentFilter,
            Some("tool_calls") | Some("function_call") => Self::ToolCalls,
            None => Self::Unknown,
            Some(other) => Self::Other(other.to_string()),
        }
    }
}

/// The result of a successful chat call.
#[derive(Debug, Clone, PartialEq)]
pub struct ChatResponse {
    /// The assistant's text.
    pub text: String,
    /// Why generation stopped (never `Length` or `ContentFilter`: those are errors).
    pub finish_reason: FinishReason,
    /// Token usage, when the server reported it.
    pub usage: Option<Usage>,
    /// The model the server says answered.
    pub model: Option<String>,
    /// The response's `id`.
    pub response_id: Option<String>,
    /// The request id header (`x-request-id` / `apim-request-id`).
    pub request_id: Option<String>,
    /// Wall time of the call, retries and back-off included.
    pub latency: Duration,
    /// Attempts made (1 when the first succeeded).
    pub attempts: u32,
    /// Where the answer came from: a live server, a cassette, an offline responder.
    pub origin: Origin,
    /// The message's `content` was null (or absent) and no `reasoning_content` held text,
    /// so [`text`](Self::text) is empty because the server sent nothing, not an empty
    /// string. The reply readers name this in the re-ask.
    pub content_was_null: bool,
}

#[derive(Deserialize)]
struct WireCompletion {
    id: Option<String>,
    model: Option<String>,
    #[serde(default)]
    choices: Vec<WireChoice>,
    usage: Option<WireUsage>,
    error: Option<serde_json::Value>,
}

#[derive(Deserialize)]
struct WireChoice {
    message: Option<WireMessage>,
    finish_reason: Option<String>,
}

#[derive(Deserialize)]
struct WireMessage {
    content: Option<serde_json::Value>,
    refusal: Option<String>,
    /// vLLM's and DeepSeek's field for a reasoning model's thinking (some servers put the
    /// whole answer there and leave `content` null).
    reasoning_content: Option<String>,
}

#[derive(Deserialize)]
struct WireUsage {
    prompt_tokens: Option<u64>,
    completion_tokens: Option<u64>,
    completion_tokens_details: Option<WireCompletionDetails>,
    prompt_tokens_details: Option<WirePromptDetails>,
}

#[derive(Deserialize)]
struct WireCompletionDetails {
    reasoning_tokens: Option<u64>,
}

#[derive(Deserialize)]
struct WirePromptDetails {
    cached_tokens: Option<u64>,
}

/// The parts of a success body the client needs; latency, attempts and origin are filled in
/// by the client.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ParsedCompletion {
    pub text: String,
    pub finish_reason: FinishReason,
    pub usage: Option<Usage>,
    pub model: Option<String>,
    pub response_id: Option<String>,
    pub content_was_null: bool,
}

/// Parses a 2xx body. `Ok` holds the parsed completion *and* the typed error it amounts to
/// (truncation, refusal), so the caller can still account the tokens of a failed call.
pub(crate) fn parse_completion(
    status: u16,
    body: &[u8],
    request_id: Option<&str>,
) -> Result<(ParsedCompletion, Option<VlmError>), VlmError> {
    let invalid = |detail: String| VlmError::InvalidResponse {
        status,
        detail,
        excerpt: truncate_chars(&String::from_utf8_lossy(body), 200),
        request_id: request_id.map(str::to_string),
    };
    let wire: WireCompletion = serde_json::from_slice(body).map_err(|err| {
        let kind = if err.is_eof() {
            "truncated JSON"
        } else {
            "invalid JSON"
        };
        invalid(format!(
            "{kind} at line {} column {}: {err}",
            err.line(),
            err.column()
        ))
    })?;
    let choice = wire.choices.into_iter().next().ok_or_else(|| match &wire.error {
        // Some proxies wrap a provider error in a 200.
        Some(_) => invalid(format!(
            "an error object instead of choices: {}",
            ProviderError::from_body(body)
        )),
        None => invalid("no `choices[0]` in the response".to_string()),
    })?;
    let usage = wire.usage.map(|u| Usage {
        prompt_tokens: u.prompt_tokens.unwrap_or(0),
        completion_tokens: u.completion_tokens.unwrap_or(0),
        reasoning_tokens: u
            .completion_tokens_details
            .and_then(|d| d.reasoning_tokens)
            .unwrap_or(0),
        cached_prompt_tokens: u.prompt_tokens_details.and_then(|d| d.cached_tokens).unwrap_or(0),
    });
    let finish_reason = FinishReason::from_wire(choice.finish_reason.as_deref());
    let (content, refusal, reasoning) = match choice.message {
        Some(message) => (message.content, message.refusal, message.reasoning_content),
        None => (None, None, None),
    };
    let mut content_was_null = matches!(content, None | Some(serde_json::Value::Null));
    let mut text = content_text(content.as_ref())
        .ok_or_else(|| invalid("`choices[0].message.content` is neither text nor text parts".into()))?;
    // A server that leaves `content` empty and puts the answer in `reasoning_content`: the
    // reply's reader decides whether it holds an answer (and re-asks if not).
    if text.trim().is_empty()
        && let Some(reasoning) = reasoning.filter(|r| !r.trim().is_empty())
    {
        tracing::warn!(
            chars = reasoning.len(),
            "the reply's content is empty or null; reading its reasoning_content instead"
        );
        text = reasoning;
        content_was_null = false;
    }
    let content_was_null = content_was_null && text.is_empty();
    let parsed = ParsedCompletion {
        text: text.clone(),
        finish_reason: finish_reason.clone(),
        usage,
        model: wire.model,
        response_id: wire.id,
        content_was_null,
    };
    let request_id = request_id.map(str::to_string);
    let error = if let Some(reason) = refusal.filter(|r| !r.trim().is_empty()) {
        Some(VlmError::Refusal { reason, request_id })
    } else {
        match finish_reason {
            FinishReason::Length => Some(VlmError::Truncated {
                partial_text: text,
                usage,
                request_id,
                cap: None,
                context: None,
            }),
            FinishReason::ContentFilter => Some(VlmError::Refusal {
                reason: "the provider's content filter stopped the output".to_string(),
                request_id,
            }),
            _ => None,
        }
    };
    Ok((parsed, error))
}

/// `content` may be a string, null (e.g. only a refusal), or an array of parts.
fn content_text(content: Option<&serde_json::Value>) -> Option<String> {
    match content {
        None | Some(serde_json::Value::Null) => Some(String::new()),
        Some(serde_json::Value::String(text)) => Some(text.clone()),
        Some(serde_json::Value::Array(parts)) => Some(
            parts
                .iter()
                .filter_map(|part| part.get("text").and_then(|t| t.as_str()))
                .collect::<Vec<_>>()
                .join(""),
        ),
        Some(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_server_without_usage_is_fine() {
        let body = br#"{"choices":[{"message":{"content":"hi"},"finish_reason":"stop"}],"x_extra":1}"#;
        let (parsed, error) = parse_completion(200, body, None).unwrap();
        assert_eq!(parsed.text, "hi");
        assert_eq!(parsed.usage, None);
        assert!(error.is_none());
    }

    #[test]
    fn an_answer_left_in_reasoning_content_is_read_when_content_is_null() {
        let body = br#"{"choices":[{"message":{"content":null,"reasoning_content":"- (GripperOpen)"},"finish_reason":"stop"}]}"#;
        assert_eq!(
            parse_completion(200, body, None).unwrap().0.text,
            "- (GripperOpen)"
        );
        // With an answer in `content`, the reasoning stays out of it.
        let body = br#"{"choices":[{"message":{"content":"None","reasoning_content":"thinking"},"finish_reason":"stop"}]}"#;
        assert_eq!(parse_completion(200, body, None).unwrap().0.text, "None");
    }

    #[test]
    fn usage_details_are_read() {
        let body = br#"{"id":"c1","model":"m","choices":[{"message":{"content":[{"type":"text","text":"a"},{"type":"text","text":"b"}]},"finish_reason":"stop"}],
            "usage":{"prompt_tokens":10,"completion_tokens":7,"completion_tokens_details":{"reasoning_tokens":5},"prompt_tokens_details":{"cached_tokens":4}}}"#;
        let (parsed, _) = parse_completion(200, body, None).unwrap();
        assert_eq!(parsed.text, "ab");
        assert_eq!(
            parsed.usage,
            Some(Usage {
                prompt_tokens: 10,
                completion_tokens: 7,
                reasoning_tokens: 5,
                cached_prompt_tokens: 4
            })
        );
    }

    #[test]
    fn refusal_and_length_are_errors() {
        let refusal =
            br#"{"choices":[{"message":{"content":null,"refusal":"I can't help"},"finish_reason":"stop"}]}"#;
        let (_, error) = parse_completion(200, refusal, Some("req-1")).unwrap();
        assert!(matches!(error, Some(VlmError::Refusal { ref reason, .. }) if reason == "I can't help"));
        let length = br#"{"choices":[{"message":{"content":"(OnTop"},"finish_reason":"length"}]}"#;
        let (_, error) = parse_completion(200, length, None).unwrap();
        assert!(
            matches!(error, Some(VlmError::Truncated { ref partial_text, .. }) if partial_text == "(OnTop")
        );
    }

    #[test]
    fn bad_bodies_name_line_and_column() {
        let err = parse_completion(200, br#"{"choices":[{"mess"#, Some("r"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("truncated JSON at line 1 column"), "{err}");
        let err = parse_completion(200, b"<html>", None).unwrap_err().to_string();
        assert!(err.contains("invalid JSON at line 1 column 1"), "{err}");
        let err = parse_completion(200, br#"{"choices":[]}"#, None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("no `choices[0]`"), "{err}");
        let err =
            parse_completion(200, br#"{"error":{"message":"upstream quota","code":"x"}}"#, None).unwrap_err();
        assert!(
            err.to_string()
                .contains("an error object instead of choices: upstream quota (code=x)"),
            "{err}"
        );
    }
}
