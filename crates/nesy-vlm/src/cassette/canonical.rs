//! The cassette key: a SHA-256 over the path and the canonical JSON body (object keys
//! sorted, no whitespace), with every base64 image replaced by a reference to its content
//! hash. Headers never take part, and neither does the task context.

use std::fmt::Write as _;

use base64::Engine as _;
use serde_json::{Map, Value};
use sha2::{Digest, Sha256};

/// An image found in a request body.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct FoundImage {
    /// Hex SHA-256 of the decoded bytes.
    pub sha256: String,
    /// File extension for the blob (`png`, `jpg`, `webp`, `gif`, `bin`).
    pub ext: &'static str,
    /// The decoded bytes, when asked for (recording needs them, replay does not).
    pub bytes: Option<Vec<u8>>,
}

impl FoundImage {
    /// The string that replaces the data URL in a stored body.
    pub(crate) fn reference(&self) -> String {
        format!("{BLOB_SCHEME}{}.{}", self.sha256, self.ext)
    }

    /// The blob's file name under `blobs/`.
    pub(crate) fn file_name(&self) -> String {
        format!("{}.{}", self.sha256, self.ext)
    }
}

/// Prefix of image references in stored bodies: `blob:sha256:<hex>.<ext>`.
pub(crate) const BLOB_SCHEME: &str = "blob:sha256:";

/// A request body in canonical form, with its key.
#[derive(Debug, Clone)]
pub(crate) struct Canonical {
    pub body: Value,
    pub key: String,
    pub images: Vec<FoundImage>,
}

/// Canonicalises a body: images become references, then the key is computed.
pub(crate) fn canonicalize(path: &str, body: &Value, keep_image_bytes: bool) -> Canonical {
    let mut images = Vec::new();
    let body = replace_images(body, keep_image_bytes, &mut images);
    let key = request_key(path, &body);
    Canonical { body, key, images }
}

/// The key of a path and an already canonical (image-free) body.
pub(crate) fn request_key(path: &str, body: &Value) -> String {
    let mut text = Vec::with_capacity(1024);
    text.extend_from_slice(b"POST ");
    text.extend_from_slice(path.as_bytes());
    text.push(b'\n');
    write_canonical(body, &mut text);
    hex(&Sha256::digest(&text))
}

/// Lower-case hex.
pub(crate) fn hex(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len() * 2);
    for byte in bytes {
        let _ = write!(out, "{byte:02x}");
    }
    out
}

fn replace_images(value: &Value, keep_bytes: bool, images: &mut Vec<FoundImage>) -> Value {
    match value {
        Value::String(text) => match image_from_data_url(text, keep_bytes) {
            Some(image) => {
                let reference = Value::String(image.reference());
                images.push(image);
                reference
            }
            None => value.clone(),
        },
        Value::Array(items) => Value::Array(
            items
                .iter()
                .map(|item| replace_images(item, keep_bytes, images))
                .collect(),
        ),
        Value::Object(map) => {
            let mut out = Map::new();
            for (key, item) in map {
                out.insert(key.clone(), replace_images(item, keep_bytes, images));
            }
            Value::Object(out)
        }
        other => other.clone(),
    }
}

/// Decodes `data:<mime>;base64,<payload>`; anything else (or bad base64) is left alone.
fn image_from_data_url(text: &str, keep_bytes: bool) -> Option<FoundImage> {
    let rest = text.strip_prefix("data:")?;
    let header_end = rest.get(..rest.len().min(128))?.find(',')?;
    let (header, payload) = (&rest[..header_end], &rest[header_end + 1..]);
    let mime = header.strip_suffix(";base64")?;
    let bytes = base64::engine::general_purpose::STANDARD.decode(payload).ok()?;
    let ext = match mime {
        "image/png" => "png",
        "image/jpeg" | "image/jpg" => "jpg",
        "image/webp" => "webp",
        "image/gif" => "gif",
        _ => "bin",
    };
    Some(FoundImage {
        sha256: hex(&Sha256::digest(&bytes)),
        ext,
        bytes: keep_bytes.then_some(bytes),
    })
}

/// Compact JSON with object keys sorted by their UTF-8 bytes, independent of how the map was
/// built (serde_json's `preserve_order` may be on elsewhere in the workspace).
pub(crate) fn write_canonical(value: &Value, out: &mut Vec<u8>) {
    match value {
        Value::Object(map) => {
            let mut entries: Vec<(&String, &Value)> = map.iter().collect();
            entries.sort_unstable_by(|a, b| a.0.as_bytes().cmp(b.0.as_bytes()));
            out.push(b'{');
            for (index, (key, item)) in entries.into_iter().enumerate() {
                if index > 0 {
                    out.push(b',');
                }
                // Writing a string to a Vec cannot fail.
                let _ = serde_json::to_writer(&mut *out, key);
                out.push(b':');
                write_canonical(item, out);
            }
            out.push(b'}');
        }
        Value::Array(items) => {
            out.push(b'[');
            for (index, item) in items.iter().enumerate() {
                if index > 0 {
                    out.push(b',');
                }
                write_canonical(item, out);
            }
            out.push(b']');
        }
        scalar => {
            let _ = serde_json::to_writer(&mut *out, scalar);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn key_ignores_key_order_but_not_values_or_path() {
        let a: Value = serde_json::from_str(
            r#"{"model":"m","messages":[{"role":"user","content":"hi"}],"max_tokens":5}"#,
        )
        .unwrap();
        let b: Value = serde_json::from_str(
            r#"{"max_tokens":5,"messages":[{"content":"hi","role":"user"}],"model":"m"}"#,
        )
        .unwrap();
        assert_eq!(
            canonicalize("/chat/completions", &a, false).key,
            canonicalize("/chat/completions", &b, false).key
        );
        let c = json!({"max_tokens":6,"messages":[{"content":"hi","role":"user"}],"model":"m"});
        assert_ne!(
            canonicalize("/chat/completions", &a, false).key,
            canonicalize("/chat/completions", &c, false).key
        );
        assert_ne!(
            canonicalize("/chat/completions", &a, false).key,
            canonicalize("/v2/chat", &a, false).key
        );
    }

    #[test]
    fn images_become_content_references() {
        let png = b"\x89PNG\r\n\x1a\nfake";
        let url = format!(
            "data:image/png;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(png)
        );
        let body = json!({"messages":[{"content":[{"type":"image_url","image_url":{"url":url}}]}]});
        let canonical = canonicalize("/p", &body, true);
        let expected_hash = hex(&Sha256::digest(png));
        assert_eq!(canonical.images.len(), 1);
        assert_eq!(canonical.images[0].sha256, expected_hash);
        assert_eq!(canonical.images[0].bytes.as_deref(), Some(&png[..]));
        assert_eq!(
            canonical
                .body
                .pointer("/messages/0/content/0/image_url/url")
                .unwrap(),
            &Value::String(format!("blob:sha256:{expected_hash}.png"))
        );
        // Canonicalising a stored body again is the identity, so stored keys can be checked.
        assert_eq!(canonicalize("/p", &canonical.body, false).key, canonical.key);
    }

    #[test]
    fn canonical_text_is_sorted_and_compact() {
        let mut out = Vec::new();
        write_canonical(&json!({"b":[1,{"d":null,"c":"x\"y"}],"a":0.5}), &mut out);
        assert_eq!(
            String::from_utf8(out).unwrap(),
            r#"{"a":0.5,"b":[1,{"c":"x\"y","d":null}]}"#
        );
    }
}
