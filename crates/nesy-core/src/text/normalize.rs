//! Typography a model adds that carries no meaning, undone before a reply is parsed: a
//! `<think>…</think>` section, Unicode dashes and bullets at the start of a line, curly quotes,
//! and inline code around atoms (`` `(GripperOpen)` ``). The raw reply is kept wherever
//! replies are recorded; only the parser sees the normalised text, so positions in a parse
//! error refer to it.

/// The characters models write as a list bullet instead of `-`.
const BULLETS: [char; 12] = [
    '\u{2010}', '\u{2011}', '\u{2012}', '\u{2013}', '\u{2014}', '\u{2015}', '\u{2212}', '\u{2022}',
    '\u{25e6}', '\u{25aa}', '\u{2023}', '\u{25cf}',
];

/// Returns `reply` with meaningless typography undone (see the module documentation).
///
/// ```
/// use nesy_core::text::normalize_reply;
///
/// let reply = "<think>the lid is shut</think>\nState:\n\u{2013} `(Closed hinge_lid)`\n\u{2022} (GripperOpen)\n";
/// assert_eq!(normalize_reply(reply), "\nState:\n- (Closed hinge_lid)\n- (GripperOpen)\n");
/// ```
pub fn normalize_reply(reply: &str) -> String {
    let without_thinking = strip_thinking(reply);
    let mut out = String::with_capacity(without_thinking.len());
    for line in without_thinking.split_inclusive('\n') {
        let indent = line.len() - line.trim_start().len();
        let (lead, rest) = line.split_at(indent);
        out.push_str(lead);
        let rest = match rest.chars().next() {
            Some(c) if BULLETS.contains(&c) => {
                out.push('-');
                &rest[c.len_utf8()..]
            }
            _ => rest,
        };
        for c in rest.chars() {
            match c {
                '\u{2018}' | '\u{2019}' => out.push('\''),
                '\u{201c}' | '\u{201d}' => out.push('"'),
                _ => out.push(c),
            }
        }
    }
    unquote_atoms(&out)
}

/// Drops every `<think>…</think>` (or `<thinking>…</thinking>`) section; an unclosed one runs
/// to the end of the reply only if nothing follows it, so an answer is never swallowed.
fn strip_thinking(reply: &str) -> String {
    let mut out = String::with_capacity(reply.len());
    let mut rest = reply;
    loop {
        let open = ["<think>", "<thinking>"]
            .iter()
            .filter_map(|tag| rest.find(tag).map(|at| (at, *tag)))
            .min();
        let Some((at, tag)) = open else {
            out.push_str(rest);
            return out;
        };
        let close = if tag == "<think>" {
            "</think>"
        } else {
            "</thinking>"
        };
        match rest[at..].find(close) {
            Some(end) => {
                out.push_str(&rest[..at]);
                rest = &rest[at + end + close.len()..];
            }
            None => {
                out.push_str(rest);
                return out;
            }
        }
    }
}

/// `` `(Atom a b)` `` becomes `(Atom a b)`: inline code spans whose content is a
/// parenthesised form lose their backticks. Other code spans are left alone.
fn unquote_atoms(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('`') {
        let after = &rest[open + 1..];
        match after.find('`') {
            Some(close)
                if {
                    // A span never crosses a line: a fence's backticks around a one-line
                    // formula are not a span.
                    let inner = after[..close].trim();
                    inner.starts_with('(') && inner.ends_with(')') && !after[..close].contains('\n')
                } =>
            {
                out.push_str(&rest[..open]);
                out.push_str(after[..close].trim());
                rest = &after[close + 1..];
            }
            _ => {
                out.push_str(&rest[..open + 1]);
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fences_and_plain_code_spans_are_kept() {
        let reply = "```\n- (GripperOpen)\n```\nUse `None` for an empty state.";
        assert_eq!(normalize_reply(reply), reply);
        // A fenced one-line formula keeps its fences.
        let reply = "Preconditions\n```\n(and (GripperOpen) (OnTopOf ?x floor))\n```\n";
        assert_eq!(normalize_reply(reply), reply);
    }

    #[test]
    fn an_unclosed_think_section_is_kept_rather_than_swallowing_the_answer() {
        assert_eq!(
            normalize_reply("<think>hmm\n- (GripperOpen)"),
            "<think>hmm\n- (GripperOpen)"
        );
        assert_eq!(
            normalize_reply("<thinking>a</thinking>- (A)<think>b</think>"),
            "- (A)"
        );
    }

    #[test]
    fn dashes_count_only_as_bullets_at_the_start_of_a_line() {
        assert_eq!(normalize_reply("  \u{2014} (A)"), "  - (A)");
        assert_eq!(normalize_reply("a \u{2014} b"), "a \u{2014} b");
        assert_eq!(
            normalize_reply("\u{201c}lid\u{201d} \u{2018}x\u{2019}"),
            "\"lid\" 'x'"
        );
    }
}
