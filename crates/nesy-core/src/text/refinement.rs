//! The refinement reply (the paper's Refinement Proposal prompt): a "Refinement rationale"
//! section and a "Refinement patch" section holding a SEARCH/REPLACE block of whole action
//! blocks.
//!
//! Every SEARCH/REPLACE block in the reply is parsed and returned, in order; the parser
//! never drops one. Whether more than one block is acceptable is the caller's decision (the
//! adaptation loop rejects such replies with feedback, see `adapt`). Markers are
//! `<<<<<<< SEARCH`, `=======` and `>>>>>>> REPLACE` (five to nine marker characters,
//! case-insensitive keyword); inside a block every line must belong to an action block, and
//! a REPLACE section that is empty or just `None` removes the matched actions.

use serde::{Deserialize, Serialize};

use super::action_block::parse_blocks;
use super::lines::{Line, header, split_lines};
use super::{ParseError, ParseErrorKind};
use crate::patch::Patch;

/// A parsed refinement reply.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RefinementReply {
    /// The "Refinement rationale" text, if present.
    pub rationale: Option<String>,
    /// Every SEARCH/REPLACE block, in order (at least one).
    pub patches: Vec<Patch>,
    /// 1-based line of each block's SEARCH marker.
    pub patch_lines: Vec<usize>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Marker {
    Search,
    Divider,
    Replace,
}

fn marker(line: &Line<'_>) -> Option<Marker> {
    let t = line.text.trim();
    // Fast reject for the bulk of lines (formulas, names, headers): a marker line starts
    // with a marker character or a backtick.
    if !matches!(t.as_bytes().first(), Some(b'<' | b'=' | b'>' | b'`')) {
        return None;
    }
    let t = t.trim_start_matches('`').trim_end_matches('`').trim();
    let run = |c: char| t.chars().take_while(|x| *x == c).count();
    let rest = |n: usize| t[n..].trim();
    let (lt, eq, gt) = (run('<'), run('='), run('>'));
    if (5..=9).contains(&lt) && rest(lt).eq_ignore_ascii_case("search") {
        Some(Marker::Search)
    } else if (5..=9).contains(&eq) && rest(eq).is_empty() {
        Some(Marker::Divider)
    } else if (5..=9).contains(&gt) && rest(gt).eq_ignore_ascii_case("replace") {
        Some(Marker::Replace)
    } else {
        None
    }
}

const RATIONALE: &[&str] = &["refinement rationale", "rationale", "reasoning"];
const PATCH: &[&str] = &["refinement patch", "patch"];

/// Parses a refinement reply.
pub fn parse_refinement_reply(text: &str) -> Result<RefinementReply, ParseError> {
    let lines = split_lines(text);
    let mut patches = Vec::new();
    let mut patch_lines = Vec::new();
    let mut first_marker = None;
    let mut i = 0;
    while i < lines.len() {
        match marker(&lines[i]) {
            None => i += 1,
            Some(Marker::Search) => {
                first_marker.get_or_insert(i);
                let (patch, r) = parse_patch(text, &lines, i)?;
                patches.push(patch);
                patch_lines.push(i + 1);
                i = r + 1;
            }
            Some(m) => {
                let what = if m == Marker::Divider {
                    "`=======`"
                } else {
                    "`>>>>>>> REPLACE`"
                };
                return Err(ParseError::at(
                    text,
                    lines[i].content_start(),
                    ParseErrorKind::Syntax,
                    format!("`<<<<<<< SEARCH` before {what}"),
                ));
            }
        }
    }
    let Some(first_marker) = first_marker else {
        return Err(ParseError::at(
            text,
            text.len(),
            ParseErrorKind::NoPatch,
            "a `<<<<<<< SEARCH` / `=======` / `>>>>>>> REPLACE` block",
        ));
    };
    Ok(RefinementReply {
        rationale: rationale(text, &lines, first_marker),
        patches,
        patch_lines,
    })
}

/// Parses the SEARCH/REPLACE block whose SEARCH marker is line `search_at`; returns the
/// patch and the index of its REPLACE marker line.
fn parse_patch(text: &str, lines: &[Line<'_>], search_at: usize) -> Result<(Patch, usize), ParseError> {
    let divider = (search_at + 1..lines.len()).find(|&j| marker(&lines[j]).is_some());
    let Some(d) = divider.filter(|&d| marker(&lines[d]) == Some(Marker::Divider)) else {
        let at = divider.map_or(text.len(), |d| lines[d].content_start());
        return Err(ParseError::at(
            text,
            at,
            ParseErrorKind::UnterminatedPatch,
            format!(
                "a `=======` line ending the SEARCH section opened on line {}",
                search_at + 1
            ),
        ));
    };
    let end = (d + 1..lines.len()).find(|&j| marker(&lines[j]).is_some());
    let Some(r) = end.filter(|&r| marker(&lines[r]) == Some(Marker::Replace)) else {
        let at = end.map_or(text.len(), |r| lines[r].content_start());
        return Err(ParseError::at(
            text,
            at,
            ParseErrorKind::UnterminatedPatch,
            format!(
                "a `>>>>>>> REPLACE` line closing the block opened on line {}",
                search_at + 1
            ),
        ));
    };
    let search = parse_blocks(text, &lines[search_at + 1..d], true)?;
    if search.is_empty() {
        return Err(ParseError::at(
            text,
            lines[search_at].content_start(),
            ParseErrorKind::EmptySearch,
            "at least one action block between `<<<<<<< SEARCH` and `=======`",
        ));
    }
    let replace_lines = &lines[d + 1..r];
    let replace = if only_none(replace_lines) {
        Vec::new()
    } else {
        parse_blocks(text, replace_lines, true)?
    };
    Ok((Patch { search, replace }, r))
}

/// True if a REPLACE section's only significant line is `None`, which removes the matched
/// actions.
fn only_none(replace_lines: &[Line<'_>]) -> bool {
    let mut sig = replace_lines.iter().filter(|l| !l.is_blank() && !l.is_fence());
    match (sig.next(), sig.next()) {
        (Some(l), None) => l.text.trim().eq_ignore_ascii_case("none"),
        _ => false,
    }
}

/// The text under a rationale header before the first marker, up to a patch header if one
/// comes first.
fn rationale(text: &str, lines: &[Line<'_>], first_marker: usize) -> Option<String> {
    (0..first_marker)
        .find_map(|i| header(&lines[i], RATIONALE).map(|at| (i, at)))
        .map(|(i, at)| {
            let end = (i + 1..first_marker)
                .find(|&j| header(&lines[j], PATCH).is_some())
                .unwrap_or(first_marker);
            let mut parts = vec![text[at..lines[i].end()].trim()];
            parts.extend(
                lines[i + 1..end]
                    .iter()
                    .filter(|l| !l.is_fence())
                    .map(|l| l.text.trim()),
            );
            parts.join("\n").trim().to_string()
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_exploration_example() {
        let reply = "* Refinement rationale:\n- The lid is closed, so the orange cannot be dropped.\n\n* Refinement patch:\n```\n<<<<<<< SEARCH\nOpenGripperToDropOrangeIntoHingeBody\n- Preconditions:\n\t(GripperHolding orange)\n\t(not (Closed hinge_lid))\n- Effects:\n\t(InsideOf orange hinge_body)\n=======\nMoveHeldOrangeOverFloor\n- Preconditions:\n\t(GripperHolding orange)\n- Effects:\n\t(OverOf orange floor)\n>>>>>>> REPLACE\n```\n";
        let r = parse_refinement_reply(reply).unwrap();
        assert_eq!(r.patches.len(), 1);
        assert_eq!(
            r.patches[0].search[0].name,
            "OpenGripperToDropOrangeIntoHingeBody"
        );
        assert_eq!(r.patches[0].replace[0].name, "MoveHeldOrangeOverFloor");
        assert!(r.rationale.unwrap().contains("lid is closed"));
        let again = parse_refinement_reply(&r.patches[0].to_string()).unwrap();
        assert_eq!(again.patches[0], r.patches[0]);
    }

    #[test]
    fn errors() {
        assert_eq!(
            parse_refinement_reply("no patch here").unwrap_err().kind,
            ParseErrorKind::NoPatch
        );
        let open = "<<<<<<< SEARCH\nA\n- Preconditions:\n\tNone\n- Effects:\n\t(B)\n=======\n";
        let err = parse_refinement_reply(open).unwrap_err();
        assert_eq!(err.kind, ParseErrorKind::UnterminatedPatch);
        let empty = "<<<<<<< SEARCH\n=======\n>>>>>>> REPLACE";
        assert_eq!(
            parse_refinement_reply(empty).unwrap_err().kind,
            ParseErrorKind::EmptySearch
        );
        let removal =
            "<<<<<<< SEARCH\nA\n- Preconditions:\n\tNone\n- Effects:\n\t(B)\n=======\nNone\n>>>>>>> REPLACE";
        assert!(
            parse_refinement_reply(removal).unwrap().patches[0]
                .replace
                .is_empty()
        );
    }
}
