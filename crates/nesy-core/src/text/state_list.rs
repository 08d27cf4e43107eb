//! The paper's state list: `- (OnTopOf a b)` lines, or `None`.

use super::lines::{is_content_line, split_lines};
use super::sexpr::{Item, parse_items};
use super::syntax::Converter;
use super::{ParseError, ParseErrorKind};
use crate::atom::Atom;
use crate::formula::Formula;
use crate::state::State;

/// Parses a state list: one ground atom per bullet line (`-`, `*`, `•`, numbered or bare),
/// or `None` for the empty state. Prose lines before the first atom and after the last are
/// ignored, as are markdown fences; prose between atoms, variables and non-atom formulas
/// are errors.
pub fn parse_state_list(text: &str) -> Result<State, ParseError> {
    let lines = split_lines(text);
    let relevant: Vec<_> = lines.iter().filter(|l| !l.is_blank() && !l.is_fence()).collect();
    let first = relevant.iter().position(|l| is_content_line(l.text));
    let Some(first) = first else {
        let at = relevant.first().map_or(text.len(), |l| l.content_start());
        return Err(ParseError::at(
            text,
            at,
            ParseErrorKind::Empty,
            "a list of `- (Atom ...)` lines or `None`",
        ));
    };
    // The list runs from the first content line to the last one; formulas may continue
    // over several lines while parentheses are open. Prose in between is an error.
    let mut depth: isize = 0;
    let mut end = relevant[first].end();
    let mut prose: Option<usize> = None;
    for l in &relevant[first..] {
        if depth <= 0 && !is_content_line(l.text) {
            prose.get_or_insert(l.content_start());
            continue;
        }
        if let Some(at) = prose {
            return Err(ParseError::at(
                text,
                at,
                ParseErrorKind::Syntax,
                "a `- (Atom ...)` line (prose is only allowed before and after the list)",
            ));
        }
        depth += super::lines::paren_delta(l.text);
        end = l.end();
    }
    let start = relevant[first].content_start();
    let items = parse_items(text, start, end)?;
    let conv = Converter::new(text, false);
    let mut atoms = Vec::new();
    let mut saw_none = None;
    for item in &items {
        match item {
            Item::None(at) => saw_none = Some(*at),
            Item::Expr(e) => {
                let f = conv.formula(e, &mut Vec::new())?;
                match f {
                    Formula::Atom(p) => match p.as_atom() {
                        Some(a) => atoms.push(a),
                        None => return Err(conv.err(e.span.start, ParseErrorKind::Syntax, "a ground atom")),
                    },
                    // `(and (A) (B))` lists the same atoms as two lines would.
                    Formula::And(parts)
                        if parts
                            .iter()
                            .all(|p| matches!(p, Formula::Atom(a) if a.as_atom().is_some())) =>
                    {
                        atoms.extend(parts.iter().filter_map(|p| match p {
                            Formula::Atom(a) => a.as_atom(),
                            _ => None,
                        }));
                    }
                    _ => {
                        return Err(conv.err(
                            e.span.start,
                            ParseErrorKind::Syntax,
                            "a ground atom (a state lists only true atoms, no connectives)",
                        ));
                    }
                }
            }
        }
    }
    if let Some(at) = saw_none
        && !atoms.is_empty()
    {
        return Err(ParseError::at(
            text,
            at,
            ParseErrorKind::Syntax,
            "either `None` or atoms, not both",
        ));
    }
    Ok(State::from_atoms(atoms.into_iter().collect::<Vec<Atom>>()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_model_output() {
        let text = "Here is the state:\r\n```\r\n- (OnTopOf apple floor)\r\n* (GripperOpen)\r\n3. (Closed\r\n   hinge_lid)\r\n```\r\nThat's all.";
        let s = parse_state_list(text).unwrap();
        assert_eq!(s.len(), 3);
        assert!(s.contains(&Atom::new("Closed", &["hinge_lid"])));
        assert_eq!(parse_state_list("None").unwrap(), State::new());
        assert_eq!(parse_state_list("- None").unwrap(), State::new());
        // A conjunction of atoms is the same list.
        let s = parse_state_list("(and (GripperOpen) (Closed hinge_lid))").unwrap();
        assert_eq!(s.len(), 2);
    }

    #[test]
    fn rejects_nonsense() {
        let err = parse_state_list("- (A)\nsomething else\n- (B)").unwrap_err();
        assert_eq!((err.line, err.column), (2, 1));
        assert!(parse_state_list("- (not (A))").is_err());
        assert!(parse_state_list("- (P ?x)").is_err());
        assert!(parse_state_list("").is_err());
        assert!(parse_state_list("- (A)\nNone").is_err());
    }

    #[test]
    fn display_round_trips() {
        let s = State::from_atoms([Atom::new("OnTopOf", &["a", "b"]), Atom::new("GripperOpen", &[])]);
        assert_eq!(parse_state_list(&s.to_string()).unwrap(), s);
    }
}
