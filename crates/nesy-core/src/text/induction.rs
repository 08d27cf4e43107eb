//! The operator-induction reply (the paper's Action Prediction prompt):
//!
//! ```text
//! * Prediction Rationale:
//! - The gripper closed around the orange, so ...
//! * Predicted Action:
//! Action Semantic:
//! - Close gripper to grasp orange
//! Precondition:
//! - (GripperSurrounding orange)
//! - (forall (?y - thing) (not (GripperHolding ?y)))
//! Effect:
//! - (GripperHolding orange)
//! - (not (GripperOpen))
//! ```
//!
//! "Action Semantic", "Precondition" and "Effect" are required, in that order; their
//! headers tolerate case and plural drift, markdown emphasis and bullets. The name is the
//! first line of the semantic section (its bullet dropped), normalised to CamelCase.
//! Preconditions may be `None`; effects may not be empty. Prose after the effects is
//! ignored.

use serde::{Deserialize, Serialize};

use super::action_block::{effect_items, precondition_items};
use super::lines::{Line, header, normalize_action_name, split_lines, strip_bullet};
use super::{ParseError, ParseErrorKind};
use crate::operator::Operator;

/// A parsed induction reply.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InductionReply {
    /// The "Prediction Rationale" text, if the reply has one.
    pub rationale: Option<String>,
    /// The action semantic as written (its first line, without the bullet).
    pub semantic: String,
    /// The induced operator, named by the normalised semantic.
    pub operator: Operator,
}

const RATIONALE: &[&str] = &["prediction rationale", "rationale", "reasoning"];
const PREDICTED: &[&str] = &["predicted action"];
const SEMANTIC: &[&str] = &["action semantic", "action name", "action"];
const PRE: &[&str] = &["precondition", "pre condition"];
const EFF: &[&str] = &["effect"];

fn find(lines: &[Line<'_>], from: usize, labels: &[&str]) -> Option<(usize, usize)> {
    (from..lines.len()).find_map(|i| header(&lines[i], labels).map(|at| (i, at)))
}

fn missing(doc: &str, at: usize, what: &str) -> ParseError {
    ParseError::at(
        doc,
        at,
        ParseErrorKind::MissingSection,
        format!("a `{what}:` section"),
    )
}

/// Parses an induction reply into an operator.
pub fn parse_induction_reply(text: &str) -> Result<InductionReply, ParseError> {
    let lines = split_lines(text);
    if lines.iter().all(|l| l.is_blank() || l.is_fence()) {
        return Err(ParseError::at(
            text,
            0,
            ParseErrorKind::Empty,
            "an induction reply with an `Action Semantic:` section",
        ));
    }
    let rationale_hdr = find(&lines, 0, RATIONALE);
    let Some((sem_idx, sem_inline)) = find(&lines, 0, SEMANTIC) else {
        return Err(missing(text, text.len(), "Action Semantic"));
    };
    let Some((pre_idx, pre_inline)) = find(&lines, sem_idx + 1, PRE) else {
        return Err(missing(text, text.len(), "Precondition"));
    };
    let Some((eff_idx, eff_inline)) = find(&lines, pre_idx + 1, EFF) else {
        return Err(missing(text, text.len(), "Effect"));
    };

    let rationale = rationale_hdr.filter(|(i, _)| *i < sem_idx).map(|(i, inline)| {
        let end = find(&lines, i + 1, PREDICTED).map_or(sem_idx, |(j, _)| j.min(sem_idx));
        let mut parts: Vec<&str> = Vec::new();
        let first = text[inline..lines[i].end()].trim();
        if !first.is_empty() {
            parts.push(first);
        }
        parts.extend(
            lines[i + 1..end]
                .iter()
                .filter(|l| !l.is_fence())
                .map(|l| l.text.trim()),
        );
        parts.join("\n").trim().to_string()
    });

    // The name: inline text after "Action Semantic:" or the first non-blank line after it.
    let inline_sem = text[sem_inline..lines[sem_idx].end()].trim();
    let semantic_line = if !inline_sem.is_empty() {
        Some((sem_inline, inline_sem))
    } else {
        lines[sem_idx + 1..pre_idx]
            .iter()
            .find(|l| !l.is_blank() && !l.is_fence())
            .map(|l| (l.content_start(), l.text.trim()))
    };
    let Some((sem_at, sem_text)) = semantic_line else {
        return Err(ParseError::at(
            text,
            lines[pre_idx].start,
            ParseErrorKind::MissingSection,
            "an action semantic line (e.g. `- Close gripper to grasp orange`) after `Action Semantic:`",
        ));
    };
    let semantic = strip_bullet(sem_text).trim().to_string();
    let Some(name) = normalize_action_name(&semantic) else {
        return Err(ParseError::at(
            text,
            sem_at,
            ParseErrorKind::Syntax,
            "an action name",
        ));
    };

    // Preconditions: everything between the two headers (blank lines and fences skipped).
    let pre_end = lines[eff_idx].start;
    let pre = precondition_items(text, pre_inline, pre_end.max(pre_inline))?;

    // Effects: content lines after the header, up to the first prose line at depth 0.
    let mut end = lines[eff_idx].end();
    let mut depth = super::lines::paren_delta(&text[eff_inline..lines[eff_idx].end()]);
    for l in &lines[eff_idx + 1..] {
        if l.is_fence() {
            continue; // fences around or inside the section are transparent
        }
        if depth <= 0 && !l.is_blank() && !super::lines::is_content_line(l.text) {
            break;
        }
        depth += super::lines::paren_delta(l.text);
        if !l.is_blank() {
            end = l.end();
        }
    }
    let eff = effect_items(text, eff_inline, end.max(eff_inline))?;
    if eff.is_empty() {
        return Err(ParseError::at(
            text,
            eff_inline,
            ParseErrorKind::EmptyEffects,
            "at least one effect (an action that changes nothing explains no transition)",
        ));
    }
    Ok(InductionReply {
        rationale,
        semantic,
        operator: Operator::new(name, pre, eff),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAPER_EXAMPLE: &str = "\
* Prediction Rationale:
- The gripper was open around the orange and is now closed holding it.

* Predicted Action:
Action Semantic:
- Move gripper to surround orange
Precondition:
- (GripperSurrounding orange)
- (GripperOpen)
- (forall (?y - thing)
    (not (GripperHolding ?y))
  )
Effect:
- (GripperClosed)
- (GripperHolding orange)
- (not (GripperOpen))
- (not (GripperSurrounding orange))

I hope this helps.";

    #[test]
    fn parses_the_paper_operator() {
        let r = parse_induction_reply(PAPER_EXAMPLE).unwrap();
        assert_eq!(r.operator.name, "MoveGripperToSurroundOrange");
        assert_eq!(r.semantic, "Move gripper to surround orange");
        assert_eq!(r.operator.pre.len(), 3);
        assert_eq!(
            r.operator.pre[2].to_string(),
            "(forall (?y - thing) (not (GripperHolding ?y)))"
        );
        assert_eq!(r.operator.eff.len(), 4);
        assert!(r.rationale.unwrap().contains("holding it"));
    }

    #[test]
    fn typed_errors() {
        let no_effect = PAPER_EXAMPLE.replace("Effect:", "Result:");
        assert_eq!(
            parse_induction_reply(&no_effect).unwrap_err().kind,
            ParseErrorKind::MissingSection
        );
        let empty = "Action Semantic:\n- Wait\nPrecondition:\nNone\nEffect:\nNone\n";
        assert_eq!(
            parse_induction_reply(empty).unwrap_err().kind,
            ParseErrorKind::EmptyEffects
        );
        let none_pre =
            "**Action Semantic:** - Wait here\n**Preconditions:** None\n**Effects:**\n- (Waited)\n";
        let r = parse_induction_reply(none_pre).unwrap();
        assert_eq!(r.operator.name, "WaitHere");
        assert!(r.operator.pre.is_empty());
    }
}
