//! What a server says it can take: image input and the context window. The client reads it
//! once, before its first call, so that it never sends pictures to a text-only model and
//! never asks for more tokens than the context has room for.
//!
//! llama.cpp's `llama-server` announces both at `GET /props`; vLLM reports the context at
//! `GET /v1/models` (`max_model_len`). Other servers say nothing, and nothing is assumed.
//! A cassette records what was read, so a replay builds the same requests.

use serde::{Deserialize, Serialize};
use serde_json::Value;

/// What a server accepts, as far as it says. `None` everywhere means "not announced".
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ServerCapabilities {
    /// Whether it takes image input.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub images: Option<bool>,
    /// The context window of one request, in tokens (prompt and reply together).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub context_tokens: Option<u32>,
    /// Where this was read, e.g. `GET /props` (for messages and the run manifest).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<String>,
}

impl ServerCapabilities {
    /// Nothing announced.
    pub const UNKNOWN: ServerCapabilities = ServerCapabilities {
        images: None,
        context_tokens: None,
        source: None,
    };

    /// Reads llama.cpp's `/props` body: `modalities.vision` (or an `input_modalities` list
    /// naming `image`) and `default_generation_settings.n_ctx`, the context of one slot.
    ///
    /// ```
    /// use nesy_vlm::ServerCapabilities;
    /// let props = serde_json::json!({
    ///     "default_generation_settings": { "n_ctx": 8192 },
    ///     "modalities": { "vision": false, "audio": false }
    /// });
    /// let caps = ServerCapabilities::from_llamacpp_props(&props);
    /// assert_eq!(caps.images, Some(false));
    /// assert_eq!(caps.context_tokens, Some(8192));
    /// ```
    pub fn from_llamacpp_props(props: &Value) -> Self {
        let vision = props
            .pointer("/modalities/vision")
            .and_then(Value::as_bool)
            .or_else(|| {
                find_key(props, "input_modalities")
                    .and_then(Value::as_array)
                    .map(|list| list.iter().any(|m| m.as_str() == Some("image")))
            });
        let context = token_count(
            props
                .pointer("/default_generation_settings/n_ctx")
                .or_else(|| props.pointer("/n_ctx")),
        );
        ServerCapabilities {
            images: vision,
            context_tokens: context,
            source: Some("GET /props".into()),
        }
    }

    /// Reads an OpenAI-style `/models` list: the entry for `model` (or the only entry), and
    /// its `max_model_len` (vLLM). Image support is not announced there.
    ///
    /// ```
    /// use nesy_vlm::ServerCapabilities;
    /// let models = serde_json::json!({"data": [{"id": "qwen", "max_model_len": 32768}]});
    /// assert_eq!(ServerCapabilities::from_models_list(&models, "qwen").context_tokens, Some(32768));
    /// ```
    pub fn from_models_list(models: &Value, model: &str) -> Self {
        let entries = models.get("data").and_then(Value::as_array);
        let entry = entries.and_then(|list| {
            list.iter()
                .find(|m| m.get("id").and_then(Value::as_str) == Some(model))
                .or(if list.len() == 1 { list.first() } else { None })
        });
        let context = token_count(entry.and_then(|m| m.get("max_model_len")));
        ServerCapabilities {
            images: None,
            context_tokens: context,
            source: Some("GET /models".into()),
        }
    }

    /// True when the server said it takes no images.
    pub fn refuses_images(&self) -> bool {
        self.images == Some(false)
    }

    /// Where the capabilities were read, for messages.
    pub fn source_label(&self) -> &str {
        self.source.as_deref().unwrap_or("the server")
    }
}

/// A positive token count that fits in `u32`, or `None`.
fn token_count(value: Option<&Value>) -> Option<u32> {
    value
        .and_then(Value::as_u64)
        .and_then(|n| u32::try_from(n).ok())
        .filter(|&n| n > 0)
}

/// The first value of `key` anywhere in `value` (depth first).
fn find_key<'a>(value: &'a Value, key: &str) -> Option<&'a Value> {
    match value {
        Value::Object(map) => map
            .get(key)
            .or_else(|| map.values().find_map(|v| find_key(v, key))),
        Value::Array(list) => list.iter().find_map(|v| find_key(v, key)),
        _ => None,
    }
}

/// A deliberately high estimate of a request's prompt tokens, from its text and images: a
/// request sized by it fits the context even for tokenizers that split symbols finely.
/// Three bytes per token (English prose runs near four), plus a few tokens of chat framing
/// per message and a fixed allowance per image.
pub(crate) fn estimate_prompt_tokens(body_text_bytes: usize, messages: usize, images: usize) -> u32 {
    const BYTES_PER_TOKEN: usize = 3;
    const FRAMING_PER_MESSAGE: usize = 8;
    const TOKENS_PER_IMAGE: usize = 768;
    let tokens = body_text_bytes.div_ceil(BYTES_PER_TOKEN)
        + messages * FRAMING_PER_MESSAGE
        + images * TOKENS_PER_IMAGE;
    u32::try_from(tokens).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn llamacpp_props_in_both_shapes() {
        let newer = json!({
            "default_generation_settings": {"n_ctx": 4096},
            "model_info": {"architecture": {"input_modalities": ["text", "image"]}}
        });
        let caps = ServerCapabilities::from_llamacpp_props(&newer);
        assert_eq!((caps.images, caps.context_tokens), (Some(true), Some(4096)));
        let silent = ServerCapabilities::from_llamacpp_props(&json!({"build_info": "b1"}));
        assert_eq!((silent.images, silent.context_tokens), (None, None));
        assert!(!silent.refuses_images());
    }

    #[test]
    fn models_list_picks_the_named_model() {
        let list = json!({"data": [{"id": "a", "max_model_len": 1}, {"id": "b", "max_model_len": 2}]});
        assert_eq!(
            ServerCapabilities::from_models_list(&list, "b").context_tokens,
            Some(2)
        );
        assert_eq!(
            ServerCapabilities::from_models_list(&list, "c").context_tokens,
            None
        );
    }

    #[test]
    fn estimates_err_high() {
        assert_eq!(estimate_prompt_tokens(3000, 2, 0), 1016);
        assert_eq!(estimate_prompt_tokens(0, 1, 2), 8 + 1536);
    }
}
