//! How often a model's recorded replies can be read: for every induction, patch and
//! translation reply in a set of cassettes, whether nesy-core's parser reads it, counted
//! separately for the first reply of each conversation (the model's first try) and for the
//! replies to re-asks. It measures the layout only; whether the verifier then accepts what
//! was read is the loop's business.
//!
//! Replies held to a JSON schema are written out in the prompt's layout first, as the loop
//! does. A JSON patch names the actions of its SEARCH side, which only the procedure of its
//! request can expand, so it counts as read when it is the schema's object.

use std::collections::BTreeMap;

use nesy_core::text::{normalize_reply, parse_induction_reply, parse_refinement_reply, parse_state_list};
use nesy_vlm::CassetteFile;
use serde::Serialize;
use serde_json::Value;

use crate::constraints::{induction_layout, patch_layout, translation_layout};

/// The purposes whose replies have a layout nesy-core parses.
pub const READ_PURPOSES: [&str; 3] = ["induce", "patch", "translate"];

/// Counts for one group of replies (one method and purpose).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct ReplyCounts {
    /// Replies recorded (with a status of 200).
    pub replies: u64,
    /// Replies cut off at the token cap or the context window (`finish_reason` `length`).
    pub cut_short: u64,
    /// First replies of a conversation (a request with one user turn).
    pub first: u64,
    /// First replies the parser read.
    pub first_read: u64,
    /// Replies to re-asks.
    pub reasked: u64,
    /// Replies to re-asks the parser read.
    pub reasked_read: u64,
    /// Replies held to a grammar or a JSON schema.
    pub constrained: u64,
    /// Prompt tokens, as the server counted them.
    pub prompt_tokens: u64,
    /// Reply tokens, as the server counted them.
    pub completion_tokens: u64,
    /// Milliseconds the server spent reading prompts and generating, when it reports them
    /// (llama.cpp's `timings`); unlike the call latency, this leaves out queueing.
    pub server_ms: u64,
}

impl ReplyCounts {
    /// The share of first replies that were read, or `None` without any.
    pub fn first_try_share(&self) -> Option<f64> {
        (self.first > 0).then(|| self.first_read as f64 / self.first as f64)
    }

    fn add(&mut self, other: &ReplyCounts) {
        self.replies += other.replies;
        self.cut_short += other.cut_short;
        self.first += other.first;
        self.first_read += other.first_read;
        self.reasked += other.reasked;
        self.reasked_read += other.reasked_read;
        self.constrained += other.constrained;
        self.prompt_tokens += other.prompt_tokens;
        self.completion_tokens += other.completion_tokens;
        self.server_ms += other.server_ms;
    }
}

/// Reply counts by group (the caller's label, e.g. the method) and purpose.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Readability {
    /// `(group, purpose)` to counts.
    pub groups: BTreeMap<(String, String), ReplyCounts>,
}

impl Readability {
    /// Counts the induction, patch and translation replies of `cassette` under `group`.
    pub fn add_cassette(&mut self, group: &str, cassette: &CassetteFile) {
        for interaction in &cassette.interactions {
            let Some(purpose) = interaction.purpose.as_deref() else {
                continue;
            };
            if !READ_PURPOSES.contains(&purpose) {
                continue;
            }
            let Some(response) = interaction
                .response
                .as_ref()
                .filter(|response| response.status == 200)
                .and_then(|response| response.body.as_ref())
                .and_then(|raw| serde_json::from_str::<Value>(raw.get()).ok())
            else {
                continue;
            };
            let choice = &response["choices"][0];
            let text = choice["message"]["content"].as_str().unwrap_or("");
            let body = &interaction.request.body;
            let users = nesy_vlm::cassette_tools::user_turns(body);
            let counts = self
                .groups
                .entry((group.to_owned(), purpose.to_owned()))
                .or_default();
            counts.replies += 1;
            counts.cut_short += u64::from(choice["finish_reason"] == "length");
            counts.prompt_tokens += response["usage"]["prompt_tokens"].as_u64().unwrap_or(0);
            counts.completion_tokens += response["usage"]["completion_tokens"].as_u64().unwrap_or(0);
            let timings = &response["timings"];
            let ms = timings["prompt_ms"].as_f64().unwrap_or(0.0)
                + timings["predicted_ms"].as_f64().unwrap_or(0.0);
            counts.server_ms += ms.round() as u64;
            // A JSON schema reaches llama.cpp as `json_schema`, vLLM inside `structured_outputs`,
            // Ollama as `format` and OpenAI as `response_format`; a grammar is text.
            let json_form = ["response_format", "format", "json_schema"]
                .iter()
                .any(|f| body.get(f).is_some())
                || body["structured_outputs"].get("json").is_some();
            counts.constrained +=
                u64::from(nesy_vlm::CONSTRAINT_FIELDS.iter().any(|f| body.get(f).is_some()));
            let read = reads(purpose, text, json_form);
            if users <= 1 {
                counts.first += 1;
                counts.first_read += u64::from(read);
            } else {
                counts.reasked += 1;
                counts.reasked_read += u64::from(read);
            }
        }
    }

    /// The counts of each purpose over every group.
    pub fn by_purpose(&self) -> BTreeMap<String, ReplyCounts> {
        let mut out: BTreeMap<String, ReplyCounts> = BTreeMap::new();
        for ((_, purpose), counts) in &self.groups {
            out.entry(purpose.clone()).or_default().add(counts);
        }
        out
    }
}

/// Whether nesy-core's parser for `purpose` reads `text` (written out of its JSON form
/// first when it was held to a schema).
///
/// ```
/// use nesy_reasoner::readability::reads;
/// assert!(reads("translate", "- (GripperOpen)\n", false));
/// assert!(!reads("translate", "The gripper is open.", false));
/// assert!(reads("translate", r#"{"atoms": ["(GripperOpen)"]}"#, true));
/// ```
pub fn reads(purpose: &str, text: &str, json_form: bool) -> bool {
    let written_out = if json_form {
        match purpose {
            "induce" => induction_layout(text),
            "patch" => return patch_layout(text, &[]).is_some(),
            "translate" => translation_layout(text),
            _ => None,
        }
    } else {
        None
    };
    let text = normalize_reply(written_out.as_deref().unwrap_or(text));
    match purpose {
        "induce" => parse_induction_reply(&text).is_ok(),
        "patch" => parse_refinement_reply(&text).is_ok(),
        "translate" => parse_state_list(&text).is_ok(),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One recorded induction first try whose body carries `field`, answered in JSON.
    fn cassette_with(field: &str, value: Value) -> CassetteFile {
        let mut body = serde_json::json!({"messages": [{"role": "user", "content": "the step"}]});
        body[field] = value;
        let reply = r#"{"rationale": ["The lid opened."], "action_semantic": "open the lid", "preconditions": [], "effects": ["(Open box)"]}"#;
        let text = serde_json::json!({
            "schema_version": 1,
            "meta": {"recorder": "test", "created_at": "x", "updated_at": "x"},
            "interactions": [{
                "key": "0", "purpose": "induce", "recorded_at": "x", "latency_ms": 1.0,
                "request": {"method": "POST", "path": "/chat/completions", "body": body},
                "response": {"status": 200, "headers": {}, "body": {
                    "choices": [{"index": 0, "message": {"role": "assistant", "content": reply}, "finish_reason": "stop"}]
                }}
            }]
        })
        .to_string();
        CassetteFile::parse(std::path::Path::new("c.json"), &text).unwrap()
    }

    #[test]
    fn a_json_schema_in_any_backend_field_is_a_constrained_json_reply() {
        let schema = serde_json::json!({"type": "object"});
        for (field, value) in [
            ("json_schema", schema.clone()),
            ("format", schema.clone()),
            ("structured_outputs", serde_json::json!({"json": schema.clone()})),
            (
                "response_format",
                serde_json::json!({"type": "json_schema", "json_schema": {"schema": schema}}),
            ),
        ] {
            let mut readability = Readability::default();
            readability.add_cassette("m", &cassette_with(field, value));
            let counts = &readability.by_purpose()["induce"];
            assert_eq!(
                (counts.constrained, counts.first, counts.first_read),
                (1, 1, 1),
                "{field}"
            );
        }
    }
}
