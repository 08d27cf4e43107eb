//! Text formats: parsers and printers for everything nesy exchanges as text.
//!
//! - the paper's state list ([`parse_state_list`]; printed by `State`'s `Display`);
//! - action blocks and procedures ([`parse_procedure`], [`parse_action_block`]; printed by
//!   `Operator`'s `Display` and [`crate::operator::format_procedure`]);
//! - the operator-induction reply ([`parse_induction_reply`]);
//! - the refinement reply with SEARCH/REPLACE patches ([`parse_refinement_reply`]; printed
//!   by [`crate::patch::Patch`]'s `Display`);
//! - single formulas and effects in PDDL syntax ([`parse_formula`], [`parse_effect`]).
//!
//! PDDL domains, problems and plans live in [`crate::pddl`].
//!
//! Every parser accepts real model output — prose before and after, markdown fences, `*`,
//! `-`, `•` and numbered bullets, CRLF line ends, case drift and plural drift in section
//! headers, formulas spanning several lines — and rejects anything else with a
//! [`ParseError`] that carries the 1-based line and column and what was expected there.
//! S-expressions are parsed with `winnow`; the line-oriented layer classifies lines and
//! hands each section's text to the s-expression parser.

mod action_block;
mod direct;
mod induction;
pub(crate) mod lines;
mod normalize;
mod refinement;
pub(crate) mod sexpr;
mod state_list;
pub(crate) mod syntax;

pub use action_block::{parse_action_block, parse_procedure};
pub use induction::{InductionReply, parse_induction_reply};
pub use lines::normalize_action_name;
pub use normalize::normalize_reply;
pub use refinement::{RefinementReply, parse_refinement_reply};
pub use state_list::parse_state_list;

use serde::{Deserialize, Serialize};

use crate::formula::{Effect, Formula};

/// What kind of problem a [`ParseError`] reports, for callers that react to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ParseErrorKind {
    /// Malformed syntax: an unexpected character, token or line.
    Syntax,
    /// Parentheses do not balance.
    Unbalanced,
    /// Nesting deeper than the parser accepts.
    TooDeep,
    /// A required section (e.g. "Effect:") is missing.
    MissingSection,
    /// The effects of an induced operator are empty.
    EmptyEffects,
    /// The reply holds no SEARCH/REPLACE block.
    NoPatch,
    /// A SEARCH/REPLACE block is not closed.
    UnterminatedPatch,
    /// A SEARCH block holds no action.
    EmptySearch,
    /// A variable is used outside any quantifier or parameter list.
    UnboundVariable,
    /// A construct the parser recognises but nesy does not support (e.g. `either` types).
    Unsupported,
    /// The input is empty.
    Empty,
    /// A name is used inconsistently (PDDL: unknown action, wrong arity, unknown object).
    Reference,
}

/// A parse failure with its position and what was expected.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
#[error("line {line}, column {column}: expected {expected}, found {found}")]
pub struct ParseError {
    /// What went wrong, coarsely.
    pub kind: ParseErrorKind,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What the parser wanted at that position.
    pub expected: String,
    /// What it found (a short excerpt, or "end of input").
    pub found: String,
}

impl ParseError {
    /// Builds an error at a byte offset of `doc`.
    pub(crate) fn at(doc: &str, offset: usize, kind: ParseErrorKind, expected: impl Into<String>) -> Self {
        let offset = floor_char_boundary(doc, offset.min(doc.len()));
        let (line, column) = line_col(doc, offset);
        ParseError {
            kind,
            line,
            column,
            expected: shorten(expected.into()),
            found: excerpt(&doc[offset..]),
        }
    }
}

pub(crate) fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// 1-based (line, column) of a byte offset; columns count characters.
pub(crate) fn line_col(doc: &str, offset: usize) -> (usize, usize) {
    let before = &doc[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, doc[line_start..offset].chars().count() + 1)
}

/// Longest `expected` text an error keeps, in characters: it can quote names from the input,
/// and a 10 MB token must not come back in full.
pub const MAX_EXPECTED_CHARS: usize = 300;

fn shorten(text: String) -> String {
    match text.char_indices().nth(MAX_EXPECTED_CHARS) {
        Some((cut, _)) => format!("{}…", &text[..cut]),
        None => text,
    }
}

fn excerpt(rest: &str) -> String {
    let first_line = rest.split('\n').next().unwrap_or("").trim_end_matches('\r');
    if rest.is_empty() {
        "end of input".to_string()
    } else if first_line.trim().is_empty() {
        "end of line".to_string()
    } else {
        let mut s: String = first_line.chars().take(40).collect();
        if first_line.chars().count() > 40 {
            s.push('…');
        }
        format!("`{s}`")
    }
}

/// Parses one formula in PDDL syntax, e.g. `(forall (?y - thing) (not (GripperHolding ?y)))`.
/// Free variables are errors.
pub fn parse_formula(text: &str) -> Result<Formula, ParseError> {
    let item = sexpr::parse_single(text, 0, text.len())?;
    syntax::Converter::new(text, false).formula(&item, &mut Vec::new())
}

/// Parses one effect in PDDL syntax, e.g. `(not (GripperOpen))` or `(when c e)`.
/// A top-level `(and ...)` is accepted only if it holds exactly one effect; use
/// [`parse_effects`] for lists.
pub fn parse_effect(text: &str) -> Result<Effect, ParseError> {
    let mut effects = parse_effects(text)?;
    if effects.len() != 1 {
        return Err(ParseError::at(
            text,
            0,
            ParseErrorKind::Syntax,
            "exactly one effect",
        ));
    }
    Ok(effects.remove(0))
}

/// Parses one effect expression, flattening a top-level `(and ...)` into a list.
pub fn parse_effects(text: &str) -> Result<Vec<Effect>, ParseError> {
    let item = sexpr::parse_single(text, 0, text.len())?;
    syntax::Converter::new(text, false).effects(&item, &mut Vec::new())
}
