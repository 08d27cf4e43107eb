//! Action blocks (`docs/benchmark.md` §9) and procedures (blocks separated by blank lines):
//!
//! ```text
//! OpenGripperToDropOrangeIntoHingeBody
//! - Preconditions:
//!     (GripperHolding orange)
//!     (not (Closed hinge_lid))
//! - Effects:
//!     (InsideOf orange hinge_body)
//!     (not (GripperHolding orange))
//! ```
//!
//! Section bodies may use tabs, `-`/`*`/numbered bullets or bare formulas, formulas may
//! span several lines, and an empty section is `None`. Names are normalised with
//! [`super::normalize_action_name`].

use super::direct;
use super::lines::{Line, header, is_content_line, normalize_action_name, paren_delta, split_lines};
use super::sexpr::{Item, parse_items};
use super::syntax::Converter;
use super::{ParseError, ParseErrorKind};
use crate::formula::{Effect, Formula};
use crate::operator::Operator;

const PRE_LABELS: &[&str] = &["precondition", "pre condition"];
const EFF_LABELS: &[&str] = &["effect"];
/// Either section header (one pass instead of two over an action-name line).
const SECTION_LABELS: &[&str] = &["precondition", "pre condition", "effect"];

/// Section bodies as (start, end) byte ranges, plus the index of the line after the block.
struct SectionSpan {
    start: usize,
    end: usize,
}

/// Collects a section body that starts at `inline` (offset on the header line) and
/// continues over the following content lines. Returns the span, the index of the first
/// line after it and, if that line is a header with one of the `stop` labels, the offset of
/// its inline content (what [`header`] returns for it). With `allow_blank`, blank lines
/// inside the body are skipped (used for preconditions, which must be followed by the
/// effects header anyway).
fn section(
    lines: &[Line<'_>],
    header_idx: usize,
    inline: usize,
    stop: &[&str],
    allow_blank: bool,
) -> (SectionSpan, usize, Option<usize>) {
    let header_line = &lines[header_idx];
    let inline_text = &header_line.text[inline - header_line.start..];
    let mut depth = paren_delta(inline_text);
    let mut end = if inline_text.trim().is_empty() {
        inline
    } else {
        header_line.end()
    };
    let mut i = header_idx + 1;
    let mut stopped_at = None;
    while i < lines.len() {
        let l = &lines[i];
        // A line opening a formula (the bulk of a body) is content: not a fence, not blank,
        // not a header. The general tests below agree; this skips them.
        if depth > 0 || l.text.trim_start().starts_with('(') {
            depth += paren_delta(l.text);
            end = l.end();
            i += 1;
            continue;
        }
        if l.is_fence() {
            break;
        }
        if l.is_blank() {
            if allow_blank {
                i += 1;
                continue;
            }
            break;
        }
        if !stop.is_empty()
            && let Some(at) = header(l, stop)
        {
            stopped_at = Some(at);
            break;
        }
        if !is_content_line(l.text) {
            break;
        }
        depth += paren_delta(l.text);
        end = l.end();
        i += 1;
    }
    (
        SectionSpan {
            start: inline,
            end: end.max(inline),
        },
        i,
        stopped_at,
    )
}

/// Parses the formulas of a precondition body (`None` or formulas).
pub(crate) fn precondition_items(doc: &str, start: usize, end: usize) -> Result<Vec<Formula>, ParseError> {
    direct_or_general(doc, start, end, direct::preconditions, general_precondition_items)
}

/// The direct reader's answer for the body `doc[start..end]`, or the general path's where the
/// direct reader defers (every error comes from the general path). Debug builds (every test,
/// the fuzz targets) check that the two agree wherever the direct reader answers.
fn direct_or_general<T: PartialEq + std::fmt::Debug>(
    doc: &str,
    start: usize,
    end: usize,
    direct: fn(&str, usize, usize) -> Option<T>,
    general: fn(&str, usize, usize) -> Result<T, ParseError>,
) -> Result<T, ParseError> {
    let Some(items) = direct(doc, start, end) else {
        return general(doc, start, end);
    };
    debug_assert_eq!(
        Ok(&items),
        general(doc, start, end).as_ref(),
        "direct reader disagrees on {:?}",
        &doc[start..end]
    );
    Ok(items)
}

/// [`precondition_items`] through the s-expression tree: every input, and every error.
fn general_precondition_items(doc: &str, start: usize, end: usize) -> Result<Vec<Formula>, ParseError> {
    let conv = Converter::new(doc, false);
    let items = parse_items(doc, start, end)?;
    let mut out = Vec::new();
    let mut none_at = None;
    for item in &items {
        match item {
            Item::None(at) => none_at = Some(*at),
            Item::Expr(e) => out.push(conv.formula(e, &mut Vec::new())?),
        }
    }
    if let (Some(at), false) = (none_at, out.is_empty()) {
        return Err(ParseError::at(
            doc,
            at,
            ParseErrorKind::Syntax,
            "either `None` or formulas, not both",
        ));
    }
    Ok(out)
}

/// Parses the effects of an effect body (`None` or effects; `(and ...)` is flattened).
pub(crate) fn effect_items(doc: &str, start: usize, end: usize) -> Result<Vec<Effect>, ParseError> {
    direct_or_general(doc, start, end, direct::effects, general_effect_items)
}

/// [`effect_items`] through the s-expression tree: every input, and every error.
fn general_effect_items(doc: &str, start: usize, end: usize) -> Result<Vec<Effect>, ParseError> {
    let conv = Converter::new(doc, false);
    let items = parse_items(doc, start, end)?;
    let mut out = Vec::new();
    let mut none_at = None;
    for item in &items {
        match item {
            Item::None(at) => none_at = Some(*at),
            Item::Expr(e) => out.extend(conv.effects(e, &mut Vec::new())?),
        }
    }
    if let (Some(at), false) = (none_at, out.is_empty()) {
        return Err(ParseError::at(
            doc,
            at,
            ParseErrorKind::Syntax,
            "either `None` or effects, not both",
        ));
    }
    Ok(out)
}

fn next_significant(lines: &[Line<'_>], from: usize) -> Option<usize> {
    (from..lines.len()).find(|&j| !lines[j].is_blank() && !lines[j].is_fence())
}

/// Parses the action blocks in `lines`. With `strict`, every non-blank, non-fence line must
/// belong to a block (inside SEARCH/REPLACE); otherwise prose is allowed before the first
/// block and after the last one, but not between blocks.
pub(crate) fn parse_blocks(doc: &str, lines: &[Line<'_>], strict: bool) -> Result<Vec<Operator>, ParseError> {
    let mut ops = Vec::new();
    let mut prose_after: Option<usize> = None;
    let mut i = 0;
    while i < lines.len() {
        let l = &lines[i];
        if l.is_blank() || l.is_fence() {
            i += 1;
            continue;
        }
        if header(l, SECTION_LABELS).is_some() {
            return Err(ParseError::at(
                doc,
                l.content_start(),
                ParseErrorKind::Syntax,
                "an action name on the line before the section header",
            ));
        }
        let next = next_significant(lines, i + 1);
        let pre_header = next.and_then(|j| header(&lines[j], PRE_LABELS).map(|at| (j, at)));
        let Some((pre_idx, pre_inline)) = pre_header else {
            let formula_line = is_content_line(l.text) && !l.text.trim().eq_ignore_ascii_case("none");
            if strict || formula_line && !ops.is_empty() && prose_after.is_none() {
                let expected = if formula_line {
                    "an action name line (this formula is outside any `- Preconditions:`/`- Effects:` section)"
                } else {
                    "an action name followed by a `- Preconditions:` line"
                };
                return Err(ParseError::at(
                    doc,
                    l.content_start(),
                    ParseErrorKind::Syntax,
                    expected,
                ));
            }
            if !ops.is_empty() && prose_after.is_none() {
                prose_after = Some(l.content_start());
            }
            i += 1;
            continue;
        };
        if let Some(at) = prose_after {
            return Err(ParseError::at(
                doc,
                at,
                ParseErrorKind::Syntax,
                "an action block (prose is only allowed before the first block and after the last)",
            ));
        }
        let Some(name) = normalize_action_name(l.text) else {
            return Err(ParseError::at(
                doc,
                l.content_start(),
                ParseErrorKind::Syntax,
                "an action name",
            ));
        };
        // The preconditions end at the effects header, if there is one: a fence, a prose
        // line or the end of the lines are not one.
        let (pre_span, after_pre, eff_header) = section(lines, pre_idx, pre_inline, EFF_LABELS, true);
        let Some(eff_inline) = eff_header else {
            let at = lines.get(after_pre).map_or(doc.len(), |l| l.content_start());
            return Err(ParseError::at(
                doc,
                at,
                ParseErrorKind::MissingSection,
                format!("a `- Effects:` line for action {name}, or a formula of its preconditions"),
            ));
        };
        let (eff_span, after_eff, _) = section(lines, after_pre, eff_inline, &[], false);
        let pre = precondition_items(doc, pre_span.start, pre_span.end)?;
        let eff = effect_items(doc, eff_span.start, eff_span.end)?;
        ops.push(Operator::new(name, pre, eff));
        i = after_eff;
    }
    Ok(ops)
}

/// Parses a procedure: zero or more action blocks, with prose allowed before the first
/// and after the last. The text `None` alone is the empty procedure.
pub fn parse_procedure(text: &str) -> Result<Vec<Operator>, ParseError> {
    let lines = split_lines(text);
    let significant: Vec<_> = lines.iter().filter(|l| !l.is_blank() && !l.is_fence()).collect();
    if significant.len() == 1 && significant[0].text.trim().eq_ignore_ascii_case("none") {
        return Ok(Vec::new());
    }
    parse_blocks(text, &lines, false)
}

/// Parses exactly one action block (prose around it is allowed).
pub fn parse_action_block(text: &str) -> Result<Operator, ParseError> {
    let mut ops = parse_procedure(text)?;
    match ops.len() {
        1 => Ok(ops.remove(0)),
        0 => Err(ParseError::at(
            text,
            0,
            ParseErrorKind::Empty,
            "an action block: a name line, `- Preconditions:` and `- Effects:`",
        )),
        n => Err(ParseError::at(
            text,
            0,
            ParseErrorKind::Syntax,
            format!("exactly one action block, found {n}"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::operator::format_procedure;

    #[test]
    fn paper_identification_example() {
        let text = "OpenGripperToDropOrangeIntoHingeBody\n- Preconditions:\n  - (GripperHolding orange)\n  - (not (Closed hinge_lid))\n- Effects:\n  - (InsideOf orange hinge_body)\n  - (not (GripperHolding orange))\n";
        let op = parse_action_block(text).unwrap();
        assert_eq!(op.name, "OpenGripperToDropOrangeIntoHingeBody");
        assert_eq!(op.pre.len(), 2);
        assert_eq!(op.pre[1].to_string(), "(not (Closed hinge_lid))");
        assert_eq!(op.eff.len(), 2);
        assert_eq!(parse_action_block(&op.to_string()).unwrap(), op);
    }

    #[test]
    fn procedure_round_trip_with_none_and_multiline() {
        let text = "Here is the plan:\r\n\r\nGrasp Orange\r\n- Preconditions:\r\n\tNone\r\n- Effects:\r\n\t(GripperHolding orange)\r\n\r\nLiftOrange\r\n- preconditions:\r\n* (forall (?y - thing)\r\n     (not (OnTopOf ?y orange)))\r\n- Effect:\r\n1. (OverOf orange floor)\r\n\r\nDone.";
        let ops = parse_procedure(text).unwrap();
        assert_eq!(ops.len(), 2);
        assert_eq!(ops[0].name, "GraspOrange");
        assert!(ops[0].pre.is_empty());
        assert_eq!(
            ops[1].pre[0].to_string(),
            "(forall (?y - thing) (not (OnTopOf ?y orange)))"
        );
        assert_eq!(parse_procedure(&format_procedure(&ops)).unwrap(), ops);
        assert_eq!(parse_procedure("None").unwrap(), vec![]);
    }

    /// The direct reader against the general path on well-formed bodies and on every
    /// variant with one character deleted or one structural piece inserted: where the direct
    /// reader answers, the answer is the general path's.
    #[test]
    fn direct_reader_agrees_with_the_general_path() {
        const BODIES: [&str; 7] = [
            "\n\t(VacuumSuction)\n\t(forall (?y - thing) (not (OnTopOf ?y green_cylinder)))\n",
            "- (exists (?a ?b - block ?c) (and (on ?a ?b) (not (= ?a ?c))))\n* (imply (A) (or (B x) (C)))",
            "1. (and (A) (not (B)))\n2) (forall (?x - thing)\n   (when (C ?x) (and (D ?x) (not (E ?x)))))",
            "\tNone\n",
            "(not (GripperHolding orange)) (OverOf orange floor)",
            "+ (forall (?x ?y - thing) (when (and (P ?x) (Q ?y)) (not (R ?x ?y))))",
            "(or) (and) (= a b)",
        ];
        const PIECES: [&str; 12] = [
            "(", ")", " ", "?", "-", "x", "None", "\n- ", ";", "•", "and ", "?y",
        ];
        let mut checked = 0;
        let mut answered = 0;
        let mut check = |text: &str| {
            let end = text.len();
            if let Some(fast) = direct::preconditions(text, 0, end) {
                assert_eq!(Ok(fast), general_precondition_items(text, 0, end), "{text:?}");
                answered += 1;
            }
            if let Some(fast) = direct::effects(text, 0, end) {
                assert_eq!(Ok(fast), general_effect_items(text, 0, end), "{text:?}");
                answered += 1;
            }
            checked += 1;
        };
        for body in BODIES {
            check(body);
            for (at, c) in body.char_indices() {
                check(&format!("{}{}", &body[..at], &body[at + c.len_utf8()..]));
                for piece in PIECES {
                    check(&format!("{}{piece}{}", &body[..at], &body[at..]));
                }
            }
        }
        // Several random edits at once.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: usize| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n as u64) as usize
        };
        for _ in 0..20_000 {
            let mut text = BODIES[next(BODIES.len())].to_string();
            for _ in 0..1 + next(4) {
                let at = next(text.len() + 1);
                let at = (0..=at).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
                if next(2) == 0 && at < text.len() {
                    text.remove(at);
                } else {
                    text.insert_str(at, PIECES[next(PIECES.len())]);
                }
            }
            check(&text);
        }
        assert!(
            checked > 20_000 && answered > 5_000,
            "{checked} checked, {answered} answered"
        );
    }

    #[test]
    fn errors_have_positions() {
        let err = parse_procedure("A\n- Preconditions:\n\t(X)\nB\n- Effects:\n\t(Y)").unwrap_err();
        assert_eq!(err.kind, ParseErrorKind::MissingSection);
        assert_eq!(err.line, 4);
        let err = parse_procedure("A\n- Preconditions:\n\t(X ?v)\n- Effects:\n\t(Y)").unwrap_err();
        assert_eq!(
            (err.line, err.column, err.kind),
            (3, 5, ParseErrorKind::UnboundVariable)
        );
        let err = parse_procedure("A\n- Preconditions:\n\t(X)\n- Effects:\n\t(Y)\nprose\nB\n- Preconditions:\n\tNone\n- Effects:\n\t(Z)")
            .unwrap_err();
        assert_eq!(err.line, 6);
    }
}
