//! Line-level helpers shared by the reply parsers: line splitting with offsets, markdown
//! fences, bullets, section headers with case and plural drift, action-name normalisation.

use winnow::prelude::*;
use winnow::token::{one_of, take_while};

/// One line of a document: its 1-based number, byte range (without the line end) and text.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Line<'a> {
    pub start: usize,
    pub text: &'a str,
}

impl<'a> Line<'a> {
    pub fn end(&self) -> usize {
        self.start + self.text.len()
    }

    pub fn is_blank(&self) -> bool {
        self.text.trim().is_empty()
    }

    /// A markdown code fence (```` ``` ```` or `~~~`, with or without a language).
    pub fn is_fence(&self) -> bool {
        let t = self.text.trim_start();
        t.starts_with("```") || t.starts_with("~~~")
    }

    /// Offset of the first non-whitespace character.
    pub fn content_start(&self) -> usize {
        self.start + (self.text.len() - self.text.trim_start().len())
    }
}

/// Splits a document into lines; `\r` before `\n` is not part of the line.
pub(crate) fn split_lines(doc: &str) -> Vec<Line<'_>> {
    let mut out = Vec::new();
    let mut start = 0;
    for piece in doc.split('\n') {
        let text = piece.strip_suffix('\r').unwrap_or(piece);
        out.push(Line { start, text });
        start += piece.len() + 1;
    }
    out
}

/// Strips list and markdown decoration from the start of a line: whitespace, `#` headings,
/// `-`/`*`/`•`/`+` bullets, `1.`/`1)` numbering, `>` quotes and `**`/`__` emphasis.
/// Returns the rest and how many bytes were stripped.
pub(crate) fn strip_decoration(text: &str) -> (&str, usize) {
    let mut rest = text;
    loop {
        let before = rest.len();
        rest = rest.trim_start();
        // Fast exit for the bulk of lines (formulas, names, prose): no marker starts with a
        // parenthesis or a letter.
        if no_marker_here(rest) {
            break;
        }
        let mut input = rest;
        let marker: ModalResult<()> = (|| {
            let digits = take_while(0.., |c: char| c.is_ascii_digit()).parse_next(&mut input)?;
            if digits.is_empty() {
                one_of(['-', '*', '•', '+', '#', '>', '_']).parse_next(&mut input)?;
            } else {
                one_of(['.', ')']).parse_next(&mut input)?;
            }
            Ok(())
        })();
        if marker.is_ok() {
            rest = input;
        }
        if rest.len() == before {
            break;
        }
    }
    (rest, text.len() - rest.len())
}

/// True if no decoration marker (digit, `-`, `*`, `•`, `+`, `#`, `>`, `_`) can start at the
/// beginning of `text`.
fn no_marker_here(text: &str) -> bool {
    matches!(text.as_bytes().first(), None | Some(b'(' | b')' | b'a'..=b'z' | b'A'..=b'Z'))
}

/// Like [`strip_decoration`] but removes only one leading bullet (`-`, `*`, `•`, `+` or
/// numbering) and the whitespace around it.
pub(crate) fn strip_bullet(text: &str) -> &str {
    let t = text.trim_start();
    if no_marker_here(t) {
        return t;
    }
    let mut input = t;
    let marker: ModalResult<()> = (|| {
        let digits = take_while(0.., |c: char| c.is_ascii_digit()).parse_next(&mut input)?;
        if digits.is_empty() {
            one_of(['-', '*', '•', '+']).parse_next(&mut input)?;
        } else {
            one_of(['.', ')']).parse_next(&mut input)?;
        }
        Ok(())
    })();
    if marker.is_ok() { input.trim_start() } else { t }
}

/// Compares a header label with a normalised one (lower case, single spaces) while
/// ignoring case, emphasis (`*`, `_`, backticks, `#`), hyphens and runs of whitespace,
/// and tolerating a trailing `s` (plural drift). No allocation: this runs on every
/// non-formula line.
fn label_matches(raw: &str, label: &str) -> bool {
    let mut cleaned = raw
        .chars()
        .filter(|c| !matches!(c, '*' | '_' | '`' | '#' | '-'))
        .map(|c| {
            if c.is_whitespace() {
                ' '
            } else {
                c.to_ascii_lowercase()
            }
        })
        .peekable();
    // Skip leading spaces and collapse inner runs.
    let mut normalized = std::iter::from_fn(move || {
        let c = cleaned.next()?;
        if c == ' ' {
            while cleaned.peek() == Some(&' ') {
                cleaned.next();
            }
            cleaned.peek()?; // a trailing space ends the label
        }
        Some(c)
    })
    .skip_while(|c| *c == ' ');
    let mut want = label.chars();
    loop {
        match (normalized.next(), want.next()) {
            (None, None) => return true,
            (Some('s'), None) => return normalized.next().is_none(),
            (Some(a), Some(b)) if a == b => {}
            _ => return false,
        }
    }
}

/// If `line` is a section header whose label is one of `labels` (already normalised,
/// singular; a trailing `s` is tolerated), returns the byte offset in the document where the
/// header's inline content starts (after the colon and any closing emphasis).
pub(crate) fn header(line: &Line<'_>, labels: &[&str]) -> Option<usize> {
    let (rest, stripped) = strip_decoration(line.text);
    // Fast reject: formula lines are the bulk of long procedures.
    if rest.is_empty() || rest.starts_with('(') || rest.starts_with(')') {
        return None;
    }
    let (label, after) = match rest.find(':') {
        Some(i) => (&rest[..i], Some(i + 1)),
        None => (rest, None),
    };
    if !labels.iter().any(|l| label_matches(label, l)) {
        return None;
    }
    match after {
        Some(i) => {
            let tail = &rest[i..];
            let trimmed = tail.trim_start_matches(['*', '_', ' ', '\t']);
            Some(line.start + stripped + i + (tail.len() - trimmed.len()))
        }
        None => Some(line.end()),
    }
}

/// True if a line (after its bullet) starts a formula or says `None`: the lines a section
/// body is made of.
pub(crate) fn is_content_line(text: &str) -> bool {
    let t = strip_bullet(text);
    t.starts_with('(') || t.starts_with(')') || {
        let w = t.trim_end().trim_end_matches(['.', ',']);
        w.eq_ignore_ascii_case("none")
    }
}

/// Net parenthesis depth change of a line.
pub(crate) fn paren_delta(text: &str) -> isize {
    text.chars()
        .map(|c| match c {
            '(' => 1,
            ')' => -1,
            _ => 0,
        })
        .sum()
}

/// Turns an action name as a model writes it into a CamelCase identifier:
/// `Move gripper to surround orange` and `move_gripper_to_surround_orange` both become
/// `MoveGripperToSurroundOrange`; an existing CamelCase name is kept as is. Markdown
/// emphasis, backticks, bullets and a trailing colon or period are dropped. Returns `None`
/// if nothing alphanumeric remains.
pub fn normalize_action_name(raw: &str) -> Option<String> {
    let (rest, _) = strip_decoration(raw);
    let mut out = String::new();
    for word in rest.split(|c: char| !c.is_alphanumeric()) {
        let mut chars = word.chars();
        if let Some(first) = chars.next() {
            out.extend(first.to_uppercase());
            out.push_str(chars.as_str());
        }
    }
    if out.is_empty() { None } else { Some(out) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names() {
        assert_eq!(
            normalize_action_name("Move gripper to surround orange").unwrap(),
            "MoveGripperToSurroundOrange"
        );
        assert_eq!(
            normalize_action_name("- **MoveGripperToSurroundOrange**").unwrap(),
            "MoveGripperToSurroundOrange"
        );
        assert_eq!(
            normalize_action_name("open_gripper_to_drop_orange.").unwrap(),
            "OpenGripperToDropOrange"
        );
        assert_eq!(
            normalize_action_name("1. `CloseHingeLid`").unwrap(),
            "CloseHingeLid"
        );
        assert!(normalize_action_name("- **").is_none());
    }

    #[test]
    fn label_drift() {
        assert!(label_matches("Preconditions", "precondition"));
        assert!(label_matches("**Pre-Conditions** ", "precondition"));
        assert!(label_matches("  Action   Semantic", "action semantic"));
        assert!(label_matches("ACTION SEMANTICS", "action semantic"));
        assert!(!label_matches("Action Semantic Notes", "action semantic"));
        assert!(!label_matches("Preconditionss", "precondition"));
        assert!(!label_matches("Effect of the action", "effect"));
        assert!(!label_matches("", "effect"));
    }

    #[test]
    fn headers() {
        let doc = "**Preconditions:** None\n### predicted action\n* Effect:\n- Action Semantics: - Do it";
        let ls = split_lines(doc);
        let at = header(&ls[0], &["precondition"]).unwrap();
        assert_eq!(&doc[at..ls[0].end()], "None");
        assert!(header(&ls[1], &["predicted action"]).is_some());
        assert!(header(&ls[2], &["effect"]).is_some());
        assert!(header(&ls[2], &["precondition"]).is_none());
        let at = header(&ls[3], &["action semantic"]).unwrap();
        assert_eq!(&doc[at..], "- Do it");
    }
}
