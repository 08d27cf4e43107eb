//! What a replay miss shows: the request, the nearest recorded requests as JSON-pointer
//! diffs, and the command that re-records.

use std::fmt;
use std::path::PathBuf;

use serde_json::Value;

use super::CassetteMode;
use crate::error::truncate_chars;

/// One difference between a recorded and a requested body.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JsonDiff {
    /// RFC 6901 pointer to the differing value, e.g. `/messages/1/content/0/text`.
    pub pointer: String,
    /// The recorded value, summarised (`(absent)` if missing).
    pub recorded: String,
    /// The requested value, summarised.
    pub requested: String,
}

/// Every leaf-level difference between two JSON values.
pub(crate) fn json_diff(recorded: &Value, requested: &Value) -> Vec<JsonDiff> {
    let mut out = Vec::new();
    walk(Some(recorded), Some(requested), &mut String::new(), &mut out);
    out
}

fn walk(recorded: Option<&Value>, requested: Option<&Value>, pointer: &mut String, out: &mut Vec<JsonDiff>) {
    match (recorded, requested) {
        (Some(Value::Object(a)), Some(Value::Object(b))) => {
            let mut keys: Vec<&String> = a.keys().chain(b.keys().filter(|k| !a.contains_key(*k))).collect();
            keys.sort();
            for key in keys {
                let len = pointer.len();
                pointer.push('/');
                pointer.push_str(&key.replace('~', "~0").replace('/', "~1"));
                walk(a.get(key), b.get(key), pointer, out);
                pointer.truncate(len);
            }
        }
        (Some(Value::Array(a)), Some(Value::Array(b))) => {
            for index in 0..a.len().max(b.len()) {
                let len = pointer.len();
                pointer.push('/');
                pointer.push_str(&index.to_string());
                walk(a.get(index), b.get(index), pointer, out);
                pointer.truncate(len);
            }
        }
        (a, b) if a == b => {}
        (Some(Value::String(a)), Some(Value::String(b))) => {
            let (recorded, requested) = string_windows(a, b);
            out.push(JsonDiff {
                pointer: pointer.clone(),
                recorded,
                requested,
            });
        }
        (a, b) => out.push(JsonDiff {
            pointer: pointer.clone(),
            recorded: summarize(a),
            requested: summarize(b),
        }),
    }
}

/// How far apart two values are: the number of leaves that differ, where a replaced subtree
/// counts all the leaves it holds (so a different message outweighs a changed word).
pub(crate) fn json_distance(recorded: &Value, requested: &Value) -> usize {
    fn leaves(value: Option<&Value>) -> usize {
        match value {
            None => 0,
            Some(Value::Array(items)) => items.iter().map(|item| leaves(Some(item))).sum::<usize>().max(1),
            Some(Value::Object(map)) => map.values().map(|item| leaves(Some(item))).sum::<usize>().max(1),
            Some(_) => 1,
        }
    }
    fn walk(a: Option<&Value>, b: Option<&Value>) -> usize {
        match (a, b) {
            (Some(Value::Object(x)), Some(Value::Object(y))) => {
                x.iter()
                    .map(|(key, item)| walk(Some(item), y.get(key)))
                    .sum::<usize>()
                    + y.iter()
                        .filter(|(key, _)| !x.contains_key(*key))
                        .map(|(_, item)| leaves(Some(item)))
                        .sum::<usize>()
            }
            (Some(Value::Array(x)), Some(Value::Array(y))) => {
                (0..x.len().max(y.len())).map(|i| walk(x.get(i), y.get(i))).sum()
            }
            (a, b) if a == b => 0,
            (a, b) => leaves(a).max(leaves(b)),
        }
    }
    walk(Some(recorded), Some(requested))
}

fn summarize(value: Option<&Value>) -> String {
    match value {
        None => "(absent)".to_string(),
        Some(value) => truncate_chars(&value.to_string(), 80),
    }
}

/// Two long strings (prompts) shown around their first difference.
fn string_windows(a: &str, b: &str) -> (String, String) {
    let first_diff = a.chars().zip(b.chars()).take_while(|(x, y)| x == y).count();
    let window = |text: &str| {
        let start = first_diff.saturating_sub(30);
        let chars: Vec<char> = text.chars().collect();
        let end = (first_diff + 50).min(chars.len());
        let mut shown: String = chars[start.min(chars.len())..end].iter().collect();
        shown = format!("{shown:?}");
        if start > 0 {
            shown = format!("…{shown}");
        }
        if end < chars.len() {
            shown.push('…');
        }
        shown
    };
    (window(a), window(b))
}

/// A recorded request close to the one that missed.
#[derive(Debug, Clone, PartialEq)]
pub struct NearMatch {
    /// Index of the interaction in the cassette.
    pub index: usize,
    /// Its purpose label.
    pub purpose: Option<String>,
    /// Its path, when it differs from the request's.
    pub path: String,
    /// All differences, recorded versus requested.
    pub diffs: Vec<JsonDiff>,
}

/// Why nothing could be replayed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MissReason {
    /// The cassette file does not exist.
    NoCassette,
    /// No interaction has this request's key.
    NotRecorded,
    /// The request was recorded this many times and all were already replayed.
    Exhausted {
        /// Recordings of this exact request.
        recorded: usize,
    },
}

/// A replay miss, rendered as a report a person can act on.
#[derive(Debug, Clone, PartialEq)]
pub struct CassetteMiss {
    /// The cassette.
    pub cassette: PathBuf,
    /// The mode it was opened in.
    pub mode: CassetteMode,
    /// Why it missed.
    pub reason: MissReason,
    /// The request's path.
    pub path: String,
    /// The request key.
    pub key: String,
    /// A one-paragraph summary of the request.
    pub summary: String,
    /// Up to three nearest recorded requests.
    pub nearest: Vec<NearMatch>,
    /// The shell command that re-records.
    pub rerecord_command: String,
}

/// Shown per near match.
const DIFFS_SHOWN: usize = 8;

impl fmt::Display for CassetteMiss {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "cassette miss in {} (mode {})",
            self.cassette.display(),
            self.mode
        )?;
        match &self.reason {
            MissReason::NoCassette => writeln!(f, "  the cassette file does not exist")?,
            MissReason::NotRecorded => {
                writeln!(f, "  no recorded request matches (key {})", &self.key[..12])?
            }
            MissReason::Exhausted { recorded } => writeln!(
                f,
                "  this exact request was recorded {recorded} time(s) and every recording was already replayed \
                 (the run makes more identical calls than the recording did)"
            )?,
        }
        writeln!(f, "  request: POST {}", self.path)?;
        for line in self.summary.lines() {
            writeln!(f, "    {line}")?;
        }
        if !self.nearest.is_empty() {
            writeln!(f, "  nearest recorded requests (recorded -> requested):")?;
        }
        for near in &self.nearest {
            let purpose = near
                .purpose
                .as_deref()
                .map(|p| format!(", purpose {p}"))
                .unwrap_or_default();
            let path = if near.path != self.path {
                format!(", path {}", near.path)
            } else {
                String::new()
            };
            writeln!(
                f,
                "  - interaction #{}{purpose}{path}: {} difference(s)",
                near.index,
                near.diffs.len()
            )?;
            for diff in near.diffs.iter().take(DIFFS_SHOWN) {
                writeln!(
                    f,
                    "      {}: {} -> {}",
                    if diff.pointer.is_empty() {
                        "/"
                    } else {
                        &diff.pointer
                    },
                    diff.recorded,
                    diff.requested
                )?;
            }
            if near.diffs.len() > DIFFS_SHOWN {
                writeln!(f, "      … and {} more", near.diffs.len() - DIFFS_SHOWN)?;
            }
        }
        writeln!(
            f,
            "  to record the missing calls against a live model (credentials in the environment), run:"
        )?;
        write!(f, "    {}", self.rerecord_command)
    }
}

/// A short description of a canonical request body.
pub(crate) fn summarize_request(body: &Value, purpose: Option<&str>) -> String {
    let mut lines = Vec::new();
    let model = body.get("model").and_then(Value::as_str).unwrap_or("(none)");
    let messages = body.get("messages").and_then(Value::as_array);
    let images = count_image_refs(body);
    lines.push(format!(
        "model {model}, {} message(s), {images} image(s){}",
        messages.map_or(0, Vec::len),
        purpose.map(|p| format!(", purpose {p}")).unwrap_or_default()
    ));
    if let Some(text) = messages.and_then(|m| m.iter().rev().find_map(message_text)) {
        lines.push(format!("last text: {:?}", truncate_chars(&text, 120)));
    }
    lines.join("\n")
}

fn message_text(message: &Value) -> Option<String> {
    match message.get("content")? {
        Value::String(text) => Some(text.clone()),
        Value::Array(parts) => parts
            .iter()
            .rev()
            .find_map(|p| p.get("text").and_then(Value::as_str))
            .map(str::to_string),
        _ => None,
    }
}

/// Image references in a canonical body.
pub(crate) fn count_image_refs(value: &Value) -> usize {
    match value {
        Value::String(text) => usize::from(text.starts_with(super::canonical::BLOB_SCHEME)),
        Value::Array(items) => items.iter().map(count_image_refs).sum(),
        Value::Object(map) => map.values().map(count_image_refs).sum(),
        _ => 0,
    }
}

/// The command line of this process, quoted for a POSIX shell, prefixed with the mode that
/// records what is missing.
pub(crate) fn rerecord_command() -> String {
    rerecord_command_for(std::env::args())
}

/// [`rerecord_command`] for a given command line.
///
/// A `--vlm replay:PATH` source only ever replays, so repeating it would miss again: it is
/// dropped, which leaves the model configured in the environment, and the cassette moves to
/// `NESY_CASSETTE` so that the missing calls are recorded into the same file.
fn rerecord_command_for(args: impl IntoIterator<Item = String>) -> String {
    let mut kept = Vec::new();
    let mut cassette = None;
    let mut args = args.into_iter().peekable();
    while let Some(arg) = args.next() {
        let replay_path = if arg == "--vlm" {
            match args.peek().and_then(|next| next.strip_prefix("replay:")) {
                Some(path) => {
                    let path = path.to_string();
                    args.next();
                    Some(path)
                }
                None => None,
            }
        } else {
            arg.strip_prefix("--vlm=replay:").map(str::to_string)
        };
        match replay_path {
            Some(path) => cassette = Some(path),
            None => kept.push(shell_quote(&arg)),
        }
    }
    let prefix = match cassette {
        Some(path) => format!("NESY_CASSETTE={} ", shell_quote(&path)),
        None => String::new(),
    };
    format!("{prefix}NESY_CASSETTE_MODE=new_episodes {}", kept.join(" "))
}

fn shell_quote(arg: &str) -> String {
    let safe = !arg.is_empty()
        && arg
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_@%+=:,./-".contains(c));
    if safe {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn diffs_use_json_pointers() {
        let recorded = json!({"model":"m","messages":[{"role":"user","content":"put the red block on the tray"}],"a/b":1});
        let requested = json!({"model":"m","messages":[{"role":"user","content":"put the blue block on the tray"}],"temperature":0.0});
        let diffs = json_diff(&recorded, &requested);
        let pointers: Vec<&str> = diffs.iter().map(|d| d.pointer.as_str()).collect();
        assert_eq!(pointers, ["/a~1b", "/messages/0/content", "/temperature"]);
        assert_eq!(diffs[0].requested, "(absent)");
        assert!(diffs[1].recorded.contains("red block") && diffs[1].requested.contains("blue block"));
        assert_eq!(diffs[2].recorded, "(absent)");
    }

    #[test]
    fn distance_weighs_replaced_subtrees() {
        let recorded = json!({"m": [{"t": "a"}, {"t": "b"}]});
        assert_eq!(json_distance(&recorded, &recorded), 0);
        assert_eq!(
            json_distance(&recorded, &json!({"m": [{"t": "a"}, {"t": "c"}]})),
            1
        );
        assert_eq!(json_distance(&recorded, &json!({"m": "flat"})), 2);
        assert_eq!(
            json_distance(
                &recorded,
                &json!({"m": [{"t": "a"}, {"t": "b"}], "x": {"y": 1, "z": 2}})
            ),
            2
        );
    }

    #[test]
    fn a_replay_source_becomes_the_cassette_to_record_into() {
        let args = |line: &str| line.split(' ').map(str::to_string).collect::<Vec<_>>();
        assert_eq!(
            rerecord_command_for(args("nesy adapt --demo d --vlm replay:fixtures/c.json --execute")),
            "NESY_CASSETTE=fixtures/c.json NESY_CASSETTE_MODE=new_episodes nesy adapt --demo d --execute"
        );
        assert_eq!(
            rerecord_command_for(args("nesy adapt --vlm=replay:c.json")),
            "NESY_CASSETTE=c.json NESY_CASSETTE_MODE=new_episodes nesy adapt"
        );
        assert_eq!(
            rerecord_command_for(args("nesy adapt --vlm oracle")),
            "NESY_CASSETTE_MODE=new_episodes nesy adapt --vlm oracle"
        );
    }

    #[test]
    fn quoting() {
        assert_eq!(shell_quote("--demo=fixtures/a.json"), "--demo=fixtures/a.json");
        assert_eq!(shell_quote("it's here"), r"'it'\''s here'");
    }
}
