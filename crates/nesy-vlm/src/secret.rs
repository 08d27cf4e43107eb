//! A string that must never reach logs, `Debug` output or files: API keys.

use std::fmt;

/// An API key or other credential. `Debug` prints `SecretString(***)`; there is no
/// `Display` and no `Serialize`, so the value only leaves through [`SecretString::expose`].
#[derive(Clone, PartialEq, Eq)]
pub struct SecretString(Box<str>);

impl SecretString {
    /// Wraps a secret value.
    pub fn new(value: impl Into<String>) -> Self {
        Self(value.into().into_boxed_str())
    }

    /// The secret itself, for the one place that must send it (an HTTP header).
    pub fn expose(&self) -> &str {
        &self.0
    }

    /// Whether the secret is empty (an empty environment variable counts as unset).
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// Shortest secret that is replaced by its exact text: a shorter one would blank out common
/// words.
pub(crate) const MIN_REDACTED_LEN: usize = 8;

/// What a redacted credential is replaced with.
pub(crate) const REDACTED: &str = "[REDACTED]";

impl SecretString {
    /// `text` with every occurrence of this secret replaced by `[REDACTED]` (secrets shorter
    /// than eight characters are left: too short to redact without mangling the text).
    pub fn redact_in(&self, text: &str) -> String {
        if self.0.len() >= MIN_REDACTED_LEN && text.contains(&*self.0) {
            text.replace(&*self.0, REDACTED)
        } else {
            text.to_owned()
        }
    }
}

/// `text` with everything that looks like a credential replaced by [`REDACTED`]: tokens that
/// start with `sk-` or `sk_` (OpenAI-style keys, which providers echo in 401 bodies), the
/// token after `Bearer `, and the value of a `key`, `token`, `secret` or `password`
/// assignment (`api_key = "…"`, as a TOML parser quotes the offending line). Used on every
/// text that comes from a server or a configuration file before it can reach an error
/// message or a log, whether or not the configured key is known there.
pub(crate) fn redact_credentials(text: &str) -> String {
    let is_token_char = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '*' | '.');
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some((at, marker)) = next_credential_marker(rest) {
        out.push_str(&rest[..at]);
        let after = &rest[at + marker.len()..];
        let token_len = after
            .char_indices()
            .find(|&(_, c)| !is_token_char(c))
            .map_or(after.len(), |(i, _)| i);
        // A trailing full stop ends the sentence, not the key.
        let token_len = after[..token_len].trim_end_matches('.').len();
        let prefix_is_token = !marker.starts_with('s');
        if prefix_is_token {
            out.push_str(marker);
        }
        if token_len >= 4 || prefix_is_token && token_len > 0 {
            out.push_str(REDACTED);
        } else if !prefix_is_token {
            out.push_str(marker);
            out.push_str(&after[..token_len]);
        }
        rest = &after[token_len..];
    }
    out.push_str(rest);
    redact_assignments(&out)
}

/// The first `sk-`, `sk_` (at the start of a word) or `Bearer ` in `text`.
fn next_credential_marker(text: &str) -> Option<(usize, &'static str)> {
    const MARKERS: [&str; 3] = ["sk-", "sk_", "Bearer "];
    MARKERS
        .iter()
        .filter_map(|marker| {
            text.match_indices(marker)
                .find(|(at, _)| {
                    marker.starts_with('B')
                        || !text[..*at]
                            .chars()
                            .next_back()
                            .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
                })
                .map(|(at, _)| (at, *marker))
        })
        .min_by_key(|(at, _)| *at)
}

/// Replaces the value in `…key… = value` lines (`api_key = "sk-…"`, `token: xyz`).
fn redact_assignments(text: &str) -> String {
    const NAMES: [&str; 4] = ["key", "token", "secret", "password"];
    let mut out = String::with_capacity(text.len());
    for (i, line) in text.split('\n').enumerate() {
        if i > 0 {
            out.push('\n');
        }
        let split = line.find(['=', ':']).filter(|&at| {
            let name = line[..at]
                .trim()
                .trim_start_matches(['|', ' '])
                .to_ascii_lowercase();
            let name = name.rsplit(|c: char| c.is_whitespace()).next().unwrap_or("");
            NAMES.iter().any(|n| name.ends_with(n)) && !line[at + 1..].trim().is_empty()
        });
        match split {
            Some(at) if !line[at + 1..].contains(REDACTED) => {
                out.push_str(&line[..=at]);
                out.push(' ');
                out.push_str(REDACTED);
            }
            _ => out.push_str(line),
        }
    }
    out
}

impl fmt::Debug for SecretString {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("SecretString(***)")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn debug_hides_the_value() {
        let secret = SecretString::new("sk-test-very-secret");
        let shown = format!("{secret:?} {:#?}", Some(&secret));
        assert!(!shown.contains("very-secret"), "{shown}");
        assert_eq!(secret.expose(), "sk-test-very-secret");
    }

    #[test]
    fn credentials_are_redacted_from_server_and_file_text() {
        let echoed = r#"{"error":{"message":"Incorrect API key provided: sk-proj-Ab12_cd34-EF56. You can find your API key at https://platform.openai.com/account/api-keys.","type":"invalid_request_error","code":"invalid_api_key"}}"#;
        let shown = redact_credentials(echoed);
        assert!(!shown.contains("Ab12"), "{shown}");
        assert!(shown.contains("provided: [REDACTED]. You can find"), "{shown}");
        assert!(shown.contains("api-keys"), "{shown}");
        assert_eq!(
            redact_credentials("authorization: Bearer abc.def-ghi"),
            "authorization: Bearer [REDACTED]"
        );
        assert_eq!(redact_credentials("sent Bearer abc"), "sent Bearer [REDACTED]");
        let toml_error = "TOML parse error at line 3, column 1\n  |\n3 | api_key = \"local-secret\"\n  | ^^^^^^^\nunknown field `api_key`";
        let shown = redact_credentials(toml_error);
        assert!(!shown.contains("local-secret"), "{shown}");
        assert!(shown.contains("unknown field `api_key`"), "{shown}");
        // Ordinary words are left alone.
        for plain in [
            "task-sk-ranking",
            "ask-me",
            "risk_level 3",
            "sk-1",
            "no keys here",
        ] {
            assert_eq!(redact_credentials(plain), plain);
        }
    }

    #[test]
    fn a_known_secret_is_redacted_by_its_text() {
        let key = SecretString::new("local-secret-42");
        assert_eq!(key.redact_in("bad key local-secret-42!"), "bad key [REDACTED]!");
        assert_eq!(SecretString::new("short").redact_in("short"), "short");
    }
}
