//! Turning a policy file's bytes into the source text the interpreter compiles, the way
//! Python reads a `.py` file: a UTF-8 byte-order mark is dropped, and a PEP 263 coding
//! declaration on line 1 or 2 (`# -*- coding: latin-1 -*-`) chooses the encoding.
//!
//! The interpreter is handed a `str`, which makes CPython ignore any coding line, so the
//! declaration has to be honoured here. UTF-8 (the default), ASCII and Latin-1 are read;
//! any other declared encoding is refused by name rather than misread. Every error says
//! where the first bad byte is, as line, column and byte offset.
//!
//! ```
//! use nesy_policy::{SourceError, decode_policy_source};
//!
//! let latin = b"# -*- coding: latin-1 -*-\nprint('caf\xe9')\n";
//! assert_eq!(decode_policy_source(latin).unwrap(), "# -*- coding: latin-1 -*-\nprint('café')\n");
//!
//! let err = decode_policy_source(b"x = 1\ny = '\xff'\n").unwrap_err();
//! assert!(matches!(err, SourceError::InvalidBytes { line: 2, column: 6, offset: 11, .. }));
//! ```

/// Why a policy file's bytes cannot be read as source text.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum SourceError {
    /// A byte that is not valid in the file's encoding.
    #[error(
        "line {line}, column {column} (byte offset {offset}): invalid {encoding} byte 0x{byte:02x}; save the file as UTF-8 or declare its encoding on line 1 or 2 (PEP 263)"
    )]
    InvalidBytes {
        /// The encoding the file was read in.
        encoding: &'static str,
        /// 1-based line of the bad byte.
        line: usize,
        /// 1-based column (in characters) of the bad byte.
        column: usize,
        /// 0-based byte offset of the bad byte.
        offset: usize,
        /// The bad byte.
        byte: u8,
    },
    /// A coding declaration naming an encoding nesy does not read.
    #[error(
        "line {line}: the coding declaration names {declared:?}; policies may be UTF-8, ASCII or Latin-1"
    )]
    UnsupportedEncoding {
        /// 1-based line of the declaration.
        line: usize,
        /// The encoding as written.
        declared: String,
    },
    /// A UTF-8 byte-order mark together with a declaration of another encoding, which
    /// Python also refuses.
    #[error("line {line}: the file starts with a UTF-8 byte-order mark but declares {declared:?}")]
    BomConflict {
        /// 1-based line of the declaration.
        line: usize,
        /// The encoding as written.
        declared: String,
    },
}

/// The encodings a policy may be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Utf8,
    Ascii,
    Latin1,
}

impl Encoding {
    fn name(self) -> &'static str {
        match self {
            Encoding::Utf8 => "UTF-8",
            Encoding::Ascii => "ASCII",
            Encoding::Latin1 => "Latin-1",
        }
    }

    /// Python's spellings of the three, after its normalisation (lower case, `_` for `-`).
    fn from_declared(declared: &str) -> Option<Encoding> {
        let normal = declared.to_ascii_lowercase().replace('-', "_");
        match normal.as_str() {
            "utf_8" | "utf8" | "u8" | "utf" | "cp65001" => Some(Encoding::Utf8),
            "ascii" | "us_ascii" | "646" => Some(Encoding::Ascii),
            "latin_1" | "latin1" | "latin" | "l1" | "iso_8859_1" | "iso8859_1" | "8859" | "cp819"
            | "iso_ir_100" => Some(Encoding::Latin1),
            _ => None,
        }
    }
}

/// Decodes a policy file's bytes as CPython would read the file: a UTF-8 byte-order mark is
/// dropped, and a PEP 263 declaration on line 1 or 2 picks UTF-8, ASCII or Latin-1.
pub fn decode_policy_source(bytes: &[u8]) -> Result<String, SourceError> {
    let (bom, body) = match bytes.strip_prefix(b"\xef\xbb\xbf") {
        Some(rest) => (true, rest),
        None => (false, bytes),
    };
    let encoding = match coding_declaration(body) {
        None => Encoding::Utf8,
        Some((line, declared)) => match Encoding::from_declared(&declared) {
            Some(Encoding::Utf8) => Encoding::Utf8,
            Some(_) if bom => return Err(SourceError::BomConflict { line, declared }),
            Some(other) => other,
            None => return Err(SourceError::UnsupportedEncoding { line, declared }),
        },
    };
    match encoding {
        Encoding::Utf8 => match std::str::from_utf8(body) {
            Ok(text) => Ok(text.to_owned()),
            Err(err) => Err(invalid_byte(body, err.valid_up_to(), encoding)),
        },
        Encoding::Ascii => match body.iter().position(|b| !b.is_ascii()) {
            None => Ok(body.iter().map(|&b| b as char).collect()),
            Some(at) => Err(invalid_byte(body, at, encoding)),
        },
        // Every byte is the code point of the same value.
        Encoding::Latin1 => Ok(body.iter().map(|&b| b as char).collect()),
    }
}

/// The declared encoding and its line, if line 1 or 2 is a comment matching PEP 263's
/// `coding[:=]\s*([-\w.]+)`. Line 2 counts only when line 1 is blank or a comment.
fn coding_declaration(body: &[u8]) -> Option<(usize, String)> {
    let mut lines = body.split(|&b| b == b'\n');
    for number in 1..=2 {
        let line = lines.next()?;
        let trimmed = line.trim_ascii_start();
        if !trimmed.starts_with(b"#") {
            if number == 1 && trimmed.trim_ascii().is_empty() {
                continue;
            }
            return None;
        }
        if let Some(name) = declared_name(trimmed) {
            return Some((number, name));
        }
    }
    None
}

fn declared_name(comment: &[u8]) -> Option<String> {
    let mut rest = comment;
    while let Some(at) = find(rest, b"coding") {
        let after = &rest[at + b"coding".len()..];
        if let Some((b':' | b'=', value)) = after.split_first() {
            let value = value.trim_ascii_start();
            let name: Vec<u8> = value
                .iter()
                .copied()
                .take_while(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.'))
                .collect();
            if !name.is_empty() {
                return Some(String::from_utf8_lossy(&name).into_owned());
            }
        }
        rest = after;
    }
    None
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

fn invalid_byte(body: &[u8], offset: usize, encoding: Encoding) -> SourceError {
    let before = &body[..offset];
    let line_start = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    // Columns count characters; the part of the line before the bad byte is valid.
    let column = String::from_utf8_lossy(&before[line_start..]).chars().count() + 1;
    SourceError::InvalidBytes {
        encoding: encoding.name(),
        line: before.iter().filter(|&&b| b == b'\n').count() + 1,
        column,
        offset,
        byte: body[offset],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utf8_is_the_default_and_a_bom_is_dropped() {
        assert_eq!(
            decode_policy_source("\u{feff}x = 'é'\n".as_bytes()).unwrap(),
            "x = 'é'\n"
        );
    }

    #[test]
    fn a_declaration_on_line_two_counts_after_a_comment_line_only() {
        let shebang = b"#!/usr/bin/env python3\n# vim: set fileencoding=latin-1 :\nx = '\xe9'\n";
        assert!(decode_policy_source(shebang).unwrap().contains('é'));
        // After a code line, a later comment is no declaration: the file is UTF-8.
        let late = b"x = 1\n# coding: latin-1\ny = '\xe9'\n";
        assert!(matches!(
            decode_policy_source(late),
            Err(SourceError::InvalidBytes { line: 3, .. })
        ));
    }

    #[test]
    fn ascii_refuses_high_bytes_with_their_position() {
        let err = decode_policy_source(b"# coding: ascii\nab\xc3\xa9\n").unwrap_err();
        assert_eq!(
            err,
            SourceError::InvalidBytes {
                encoding: "ASCII",
                line: 2,
                column: 3,
                offset: 18,
                byte: 0xc3
            }
        );
    }

    #[test]
    fn other_encodings_and_bom_conflicts_are_refused_by_name() {
        let err = decode_policy_source(b"# -*- coding: cp1252 -*-\n").unwrap_err();
        assert!(err.to_string().contains("\"cp1252\""), "{err}");
        let err = decode_policy_source(b"\xef\xbb\xbf# coding: latin-1\n").unwrap_err();
        assert!(matches!(err, SourceError::BomConflict { line: 1, .. }));
        // A UTF-8 declaration with a BOM is what Python accepts.
        assert!(decode_policy_source(b"\xef\xbb\xbf# coding: utf-8\n").is_ok());
    }

    #[test]
    fn columns_count_characters_not_bytes() {
        let err = decode_policy_source(
            "é = 1 \u{2014} "
                .as_bytes()
                .iter()
                .copied()
                .chain([0xff])
                .collect::<Vec<_>>()
                .as_slice(),
        )
        .unwrap_err();
        assert!(
            matches!(
                err,
                SourceError::InvalidBytes {
                    line: 1,
                    column: 9,
                    ..
                }
            ),
            "{err:?}"
        );
    }
}
