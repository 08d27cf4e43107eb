//! Reading the JSON objects MoReVQA's stages answer with. The authors `json.loads` the whole
//! reply, so prose or a fence around the object raises; [`crate::Fidelity::Repaired`] takes
//! the object out of a fence or from its first `{` to its last `}`.

use serde_json::{Map, Value};

use crate::parse::{first_block, prepared};

/// The JSON object of `reply`: the whole reply (with `**` removed) when `tolerant` is false,
/// else also the first fenced block or the text from the first `{` to the last `}`.
pub(crate) fn object(reply: &str, tolerant: bool) -> Result<Map<String, Value>, String> {
    let strict = reply.replace("**", "");
    let mut candidates = vec![strict.trim().to_string()];
    if tolerant {
        let text = prepared(reply);
        if let Ok(block) = first_block(&text) {
            candidates.push(block);
        }
        if let (Some(start), Some(end)) = (text.find('{'), text.rfind('}'))
            && start < end
        {
            candidates.push(text[start..=end].to_string());
        }
    }
    let mut last = String::new();
    for candidate in &candidates {
        match serde_json::from_str::<Value>(candidate) {
            Ok(Value::Object(map)) => return Ok(map),
            Ok(other) => last = format!("it is JSON but not an object (found {})", kind(&other)),
            Err(e) => last = format!("it is not a JSON object: {e}"),
        }
    }
    Err(last)
}

fn kind(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// A string field.
pub(crate) fn string(map: &Map<String, Value>, key: &str) -> Result<String, String> {
    match map.get(key) {
        Some(Value::String(s)) if !s.trim().is_empty() => Ok(s.trim().to_string()),
        Some(other) => Err(format!("its \"{key}\" is {}, not a text", kind(other))),
        None => Err(format!("it has no \"{key}\" key")),
    }
}

/// A list of strings (one string is a list of one).
pub(crate) fn strings(map: &Map<String, Value>, key: &str) -> Result<Vec<String>, String> {
    match map.get(key) {
        Some(Value::Array(items)) => items
            .iter()
            .map(|item| match item {
                Value::String(s) => Ok(s.trim().to_string()),
                other => Err(format!("its \"{key}\" holds {}, not only texts", kind(other))),
            })
            .collect(),
        Some(Value::String(s)) => Ok(vec![s.trim().to_string()]),
        Some(other) => Err(format!("its \"{key}\" is {}, not a list of texts", kind(other))),
        None => Err(format!("it has no \"{key}\" key")),
    }
}

/// A boolean field (`"true"`/`"false"` as text too).
pub(crate) fn boolean(map: &Map<String, Value>, key: &str) -> Result<bool, String> {
    match map.get(key) {
        Some(Value::Bool(b)) => Ok(*b),
        Some(Value::String(s)) if s.eq_ignore_ascii_case("true") => Ok(true),
        Some(Value::String(s)) if s.eq_ignore_ascii_case("false") => Ok(false),
        Some(other) => Err(format!("its \"{key}\" is {}, not true or false", kind(other))),
        None => Err(format!("it has no \"{key}\" key")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strict_reads_the_whole_reply_and_tolerant_finds_the_object() {
        let fenced = "Here:\n```json\n{\"verified\": true}\n```";
        assert!(object(fenced, false).unwrap_err().contains("not a JSON object"));
        assert_eq!(boolean(&object(fenced, true).unwrap(), "verified"), Ok(true));
        let prose = "The queue is {\"event_queue\": [\"a\", \"b\"]} as asked.";
        assert_eq!(
            strings(&object(prose, true).unwrap(), "event_queue").unwrap(),
            ["a", "b"]
        );
        assert!(object("[1, 2]", false).unwrap_err().contains("not an object"));
        let map = object("{\"q\": 3}", false).unwrap();
        assert!(string(&map, "q").unwrap_err().contains("a number"));
        assert!(string(&map, "x").unwrap_err().contains("no \"x\" key"));
    }
}
