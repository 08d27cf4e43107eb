//! Line-level helpers shared by the reply parsers: line splitting with offsets, markdown
//! fences, bullets, section headers with case and plural drift, action-name normalisation.

/// One line of a document: its 1-based number, byte range (without the line end) and text.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Line<'a> {
    pub start: usize,
    pub text: &'a str,
}

impl<'a> Line<'a> {
    pub(crate) fn end(&self) -> usize {
        self.start + self.text.len()
    }

    pub(crate) fn is_blank(&self) -> bool {
        self.text.trim().is_empty()
    }

    /// A markdown code fence (```` ``` ```` or `~~~`, with or without a language).
    pub(crate) fn is_fence(&self) -> bool {
        let t = self.text.trim_start();
        t.starts_with("```") || t.starts_with("~~~")
    }

    /// Offset of the first non-whitespace character.
    pub(crate) fn content_start(&self) -> usize {
        self.start + (self.text.len() - self.text.trim_start().len())
    }
}

/// Splits a document into lines; `\r` before `\n` is not part of the line.
pub(crate) fn split_lines(doc: &str) -> Vec<Line<'_>> {
    // `str::split('\n')` searches line by line through `memchr` and a slice comparison,
    // which costs more than the scan itself on lines of 20–60 bytes. `\n` and `\r` are
    // ASCII, so every cut is a character boundary.
    let bytes = doc.as_bytes();
    let mut out = Vec::with_capacity(bytes.len() / 24 + 1);
    let mut start = 0;
    let line = |start: usize, end: usize| {
        let end = if end > start && bytes[end - 1] == b'\r' {
            end - 1
        } else {
            end
        };
        Line {
            start,
            text: &doc[start..end],
        }
    };
    while let Some(i) = find_newline(bytes, start) {
        out.push(line(start, i));
        start = i + 1;
    }
    out.push(line(start, bytes.len()));
    out
}

/// The first `\n` at or after `from`, eight bytes at a time.
fn find_newline(bytes: &[u8], from: usize) -> Option<usize> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGHS: u64 = 0x8080_8080_8080_8080;
    let mut i = from;
    while let Some(chunk) = bytes.get(i..i + 8) {
        let word = u64::from_le_bytes(chunk.try_into().unwrap_or([0; 8])) ^ (ONES * u64::from(b'\n'));
        // The lowest set high bit marks the first zero byte, i.e. the first `\n` (the
        // classic test can only misfire above a true zero byte).
        let zeros = word.wrapping_sub(ONES) & !word & HIGHS;
        if zeros != 0 {
            return Some(i + (zeros.trailing_zeros() / 8) as usize);
        }
        i += 8;
    }
    bytes[i..].iter().position(|&b| b == b'\n').map(|p| i + p)
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
        if let Some(n) = leading_marker(rest, &['-', '*', '•', '+', '#', '>', '_']) {
            rest = &rest[n..];
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
    match leading_marker(t, &['-', '*', '•', '+']) {
        Some(n) => t[n..].trim_start(),
        None => t,
    }
}

/// The byte length of the list marker at the start of `text`: digits followed by `.` or
/// `)`, or else one of `markers`.
fn leading_marker(text: &str, markers: &[char]) -> Option<usize> {
    let digits = text.bytes().take_while(u8::is_ascii_digit).count();
    if digits == 0 {
        let c = text.chars().next()?;
        markers.contains(&c).then(|| c.len_utf8())
    } else {
        matches!(text.as_bytes().get(digits), Some(b'.' | b')')).then_some(digits + 1)
    }
}

/// Compares a header label with a normalised one (lower case, single spaces) while
/// ignoring case, emphasis (`*`, `_`, backticks, `#`), hyphens and runs of whitespace,
/// and tolerating a trailing `s` (plural drift). One pass over `raw`, no allocation, and
/// it stops at the first character that cannot match: this runs on every action-name and
/// header line.
fn label_matches(raw: &str, label: &str) -> bool {
    let want = label.as_bytes();
    // How much of `label` has been matched, whether a plural `s` followed it, whether
    // anything was emitted yet (leading whitespace is dropped) and whether a run of
    // whitespace is waiting to be emitted as one space (trailing whitespace is dropped).
    let (mut matched, mut plural, mut started, mut space) = (0, false, false, false);
    let mut emit = |c: char| -> bool {
        if plural {
            return false;
        }
        if want.get(matched).is_some_and(|&w| w as char == c) {
            matched += 1;
            true
        } else if matched == want.len() && c == 's' {
            plural = true;
            true
        } else {
            false
        }
    };
    for c in raw.chars() {
        if matches!(c, '*' | '_' | '`' | '#' | '-') {
            continue;
        }
        if c.is_whitespace() {
            space = started;
            continue;
        }
        if space && !emit(' ') {
            return false;
        }
        space = false;
        started = true;
        if !emit(c.to_ascii_lowercase()) {
            return false;
        }
    }
    matched == want.len()
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
    let (label, after) = match rest.bytes().position(|b| b == b':') {
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
    // Bytes, not characters: UTF-8 continuation bytes are never `(` or `)`.
    text.bytes()
        .map(|b| match b {
            b'(' => 1,
            b')' => -1,
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
    let mut out = String::with_capacity(rest.len());
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

    /// The straightforward versions these helpers replaced (iterator adapters, `winnow`,
    /// `str::split`), kept as the reference the fast ones must agree with.
    mod reference {
        use winnow::prelude::*;
        use winnow::token::{one_of, take_while};

        pub(super) fn split_lines(doc: &str) -> Vec<(usize, &str)> {
            let mut out = Vec::new();
            let mut start = 0;
            for piece in doc.split('\n') {
                out.push((start, piece.strip_suffix('\r').unwrap_or(piece)));
                start += piece.len() + 1;
            }
            out
        }

        fn marker(input: &mut &str, markers: &[char]) -> ModalResult<()> {
            let digits = take_while(0.., |c: char| c.is_ascii_digit()).parse_next(input)?;
            if digits.is_empty() {
                one_of(|c: char| markers.contains(&c)).parse_next(input)?;
            } else {
                one_of(['.', ')']).parse_next(input)?;
            }
            Ok(())
        }

        pub(super) fn strip_decoration(text: &str) -> (&str, usize) {
            let mut rest = text;
            loop {
                let before = rest.len();
                rest = rest.trim_start();
                let mut input = rest;
                if marker(&mut input, &['-', '*', '•', '+', '#', '>', '_']).is_ok() {
                    rest = input;
                }
                if rest.len() == before {
                    break;
                }
            }
            (rest, text.len() - rest.len())
        }

        pub(super) fn strip_bullet(text: &str) -> &str {
            let t = text.trim_start();
            let mut input = t;
            if marker(&mut input, &['-', '*', '•', '+']).is_ok() {
                input.trim_start()
            } else {
                t
            }
        }

        pub(super) fn label_matches(raw: &str, label: &str) -> bool {
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
            let mut normalized = std::iter::from_fn(move || {
                let c = cleaned.next()?;
                if c == ' ' {
                    while cleaned.peek() == Some(&' ') {
                        cleaned.next();
                    }
                    cleaned.peek()?;
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
    }

    /// Every string of up to four fragments from a set that covers the markers, labels,
    /// whitespace kinds and line ends.
    fn fragment_strings() -> Vec<String> {
        const FRAGMENTS: [&str; 24] = [
            " ",
            "\t",
            "\u{a0}",
            "\r",
            "\n",
            "-",
            "*",
            "•",
            "#",
            "_",
            "`",
            ">",
            "1",
            "12",
            ".",
            ")",
            "s",
            "S",
            ":",
            "(x)",
            "Pre",
            "condition",
            "Effect",
            "action  semantic",
        ];
        let mut out = vec![String::new()];
        let mut frontier = vec![String::new()];
        for _ in 0..4 {
            frontier = frontier
                .iter()
                .flat_map(|s| FRAGMENTS.iter().map(move |f| format!("{s}{f}")))
                .collect();
            out.extend(frontier.iter().cloned());
        }
        out
    }

    #[test]
    fn fast_helpers_agree_with_the_reference() {
        const LABELS: [&str; 5] = ["precondition", "pre condition", "effect", "action semantic", "s"];
        for text in fragment_strings() {
            let fast: Vec<(usize, &str)> = split_lines(&text).iter().map(|l| (l.start, l.text)).collect();
            assert_eq!(fast, reference::split_lines(&text), "{text:?}");
            assert_eq!(
                strip_decoration(&text),
                reference::strip_decoration(&text),
                "{text:?}"
            );
            assert_eq!(strip_bullet(&text), reference::strip_bullet(&text), "{text:?}");
            for label in LABELS {
                assert_eq!(
                    label_matches(&text, label),
                    reference::label_matches(&text, label),
                    "{text:?} against {label:?}"
                );
            }
        }
        let long = "(a)\r\n\n  (bcdefghijklmnop q)\n\n\n\r\nxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx\ny\r";
        let fast: Vec<(usize, &str)> = split_lines(long).iter().map(|l| (l.start, l.text)).collect();
        assert_eq!(fast, reference::split_lines(long));
    }

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
