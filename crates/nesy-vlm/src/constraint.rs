//! Replies held to a grammar. A caller that knows what a reply must look like (the atoms a
//! state may hold, the action block an operator is written in, the SEARCH side a patch may
//! quote) attaches a [`ReplyConstraint`], and the backend profile sends it in the server's
//! own dialect:
//!
//! | backend | grammar (the reply's own layout) | JSON schema |
//! |---|---|---|
//! | llama.cpp | `grammar` (GBNF) | `json_schema` |
//! | vLLM | `structured_outputs.grammar` | `structured_outputs.json` |
//! | Ollama | — | `format` |
//! | OpenAI, Azure | — | `response_format` (`json_schema`, strict) |
//!
//! A grammar keeps the reply in the layout the prompt asks for, so the same parser reads
//! it; a JSON-only backend gets the schema when the caller supplied one and can turn a JSON
//! reply back into that layout ([`ReplyForm::Json`]), and no constraint otherwise.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

use crate::profile::BackendKind;

/// What a reply must look like.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplyConstraint {
    /// A short name (`induce`, `patch`, ...), which OpenAI's `response_format` requires.
    pub name: String,
    /// A GBNF grammar of the whole reply in the layout the prompt asks for.
    pub grammar: String,
    /// The reply's content as a JSON schema, for backends that constrain only to JSON;
    /// `None` leaves those backends unconstrained.
    pub json_schema: Option<Value>,
}

/// Whether requests carry their constraints (`--vlm-constrain`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ConstrainMode {
    /// Wherever the backend takes a form the constraint has.
    #[default]
    Auto,
    /// Never: replies are free text, read by the parsers and re-asked within the budgets.
    Off,
}

impl ConstrainMode {
    /// True for [`ConstrainMode::Auto`].
    pub fn is_auto(&self) -> bool {
        *self == ConstrainMode::Auto
    }

    /// `auto` or `off`.
    pub fn as_str(self) -> &'static str {
        match self {
            ConstrainMode::Auto => "auto",
            ConstrainMode::Off => "off",
        }
    }
}

impl fmt::Display for ConstrainMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for ConstrainMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "auto" | "on" => Ok(ConstrainMode::Auto),
            "off" | "none" => Ok(ConstrainMode::Off),
            other => Err(format!("unknown constrain mode {other:?}; expected auto or off")),
        }
    }
}

/// The form a reply takes, given the constraint its request was sent with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReplyForm {
    /// Unconstrained text.
    Free,
    /// Text held to the grammar (the prompt's own layout).
    Grammar,
    /// A JSON document held to the schema; the caller reads it back into the layout.
    Json,
}

impl ReplyForm {
    /// `free`, `grammar` or `json`.
    pub fn as_str(self) -> &'static str {
        match self {
            ReplyForm::Free => "free",
            ReplyForm::Grammar => "grammar",
            ReplyForm::Json => "json",
        }
    }
}

/// Which form `backend` is sent for `constraint` under `mode`.
pub(crate) fn form_for(
    backend: BackendKind,
    mode: ConstrainMode,
    constraint: Option<&ReplyConstraint>,
) -> ReplyForm {
    let Some(constraint) = constraint.filter(|_| mode == ConstrainMode::Auto) else {
        return ReplyForm::Free;
    };
    match backend {
        BackendKind::LlamaCpp | BackendKind::Vllm => ReplyForm::Grammar,
        BackendKind::Ollama | BackendKind::OpenAi | BackendKind::Azure | BackendKind::AzureV1 => {
            if constraint.json_schema.is_some() {
                ReplyForm::Json
            } else {
                ReplyForm::Free
            }
        }
    }
}

/// Every body field a constraint travels in, whatever the backend: llama.cpp's `grammar`
/// and `json_schema`, vLLM's `structured_outputs`, Ollama's `format`, and OpenAI's and
/// Azure's `response_format`.
pub const CONSTRAINT_FIELDS: [&str; 5] = [
    "grammar",
    "json_schema",
    "structured_outputs",
    "format",
    "response_format",
];

/// The body fields that carry `constraint` to `backend` in `form`.
pub(crate) fn body_fields(
    backend: BackendKind,
    form: ReplyForm,
    constraint: &ReplyConstraint,
) -> Vec<(String, Value)> {
    let schema = || constraint.json_schema.clone().unwrap_or(Value::Null);
    match (form, backend) {
        (ReplyForm::Free, _) => Vec::new(),
        (ReplyForm::Grammar, BackendKind::LlamaCpp) => {
            vec![("grammar".into(), Value::String(constraint.grammar.clone()))]
        }
        (ReplyForm::Grammar, BackendKind::Vllm) => vec![(
            "structured_outputs".into(),
            json!({ "grammar": constraint.grammar }),
        )],
        (ReplyForm::Json, BackendKind::LlamaCpp) => vec![("json_schema".into(), schema())],
        (ReplyForm::Json, BackendKind::Vllm) => {
            vec![("structured_outputs".into(), json!({ "json": schema() }))]
        }
        (ReplyForm::Json, BackendKind::Ollama) => vec![("format".into(), schema())],
        (ReplyForm::Json, BackendKind::OpenAi | BackendKind::Azure | BackendKind::AzureV1) => vec![(
            "response_format".into(),
            json!({
                "type": "json_schema",
                "json_schema": { "name": constraint.name, "schema": schema(), "strict": true }
            }),
        )],
        // `form_for` never picks a grammar for a backend without one.
        (ReplyForm::Grammar, _) => Vec::new(),
    }
}

/// A GBNF string literal for `text`: quoted, with `"`, `\` and control characters escaped.
///
/// ```
/// assert_eq!(nesy_vlm::gbnf_literal("a \"b\"\n"), r#""a \"b\"\n""#);
/// ```
pub fn gbnf_literal(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\x{:02X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constraint(json: bool) -> ReplyConstraint {
        ReplyConstraint {
            name: "translate".into(),
            grammar: "root ::= \"None\"".into(),
            json_schema: json.then(|| json!({"type": "object"})),
        }
    }

    #[test]
    fn each_backend_takes_its_own_field() {
        let c = constraint(true);
        let fields = |backend| {
            let form = form_for(backend, ConstrainMode::Auto, Some(&c));
            (form, body_fields(backend, form, &c))
        };
        assert_eq!(
            fields(BackendKind::LlamaCpp),
            (
                ReplyForm::Grammar,
                vec![("grammar".into(), json!("root ::= \"None\""))]
            )
        );
        assert_eq!(
            fields(BackendKind::Vllm),
            (
                ReplyForm::Grammar,
                vec![(
                    "structured_outputs".into(),
                    json!({"grammar": "root ::= \"None\""})
                )]
            )
        );
        assert_eq!(
            fields(BackendKind::Ollama),
            (
                ReplyForm::Json,
                vec![("format".into(), json!({"type": "object"}))]
            )
        );
        assert_eq!(
            fields(BackendKind::OpenAi),
            (
                ReplyForm::Json,
                vec![(
                    "response_format".into(),
                    json!({"type": "json_schema", "json_schema": {"name": "translate", "schema": {"type": "object"}, "strict": true}})
                )]
            )
        );
    }

    #[test]
    fn off_and_missing_forms_send_nothing() {
        let c = constraint(false);
        assert_eq!(
            form_for(BackendKind::LlamaCpp, ConstrainMode::Off, Some(&c)),
            ReplyForm::Free
        );
        assert_eq!(
            form_for(BackendKind::OpenAi, ConstrainMode::Auto, Some(&c)),
            ReplyForm::Free
        );
        assert_eq!(
            form_for(BackendKind::LlamaCpp, ConstrainMode::Auto, None),
            ReplyForm::Free
        );
        assert!(
            "loose"
                .parse::<ConstrainMode>()
                .unwrap_err()
                .contains("auto or off")
        );
    }
}
