//! S-expressions with byte spans, parsed with winnow.
//!
//! A pre-scan checks parenthesis balance and nesting depth first, so that an unclosed `(`
//! is reported where it was opened and hostile input cannot exhaust the stack.

use std::ops::Range;

use winnow::error::{ContextError, ErrMode};
use winnow::prelude::*;
use winnow::stream::{LocatingSlice, Location, Stream};
use winnow::token::{any, take_while};

use super::{ParseError, ParseErrorKind};

/// Deepest nesting accepted. Real formulas stay below 20.
pub(crate) const MAX_DEPTH: usize = 128;

type In<'a> = LocatingSlice<&'a str>;

/// An s-expression: a list or a token, with its byte span in the whole document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct SExpr<'a> {
    pub kind: SKind<'a>,
    pub span: Range<usize>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum SKind<'a> {
    List(Vec<SExpr<'a>>),
    Token(&'a str),
}

impl<'a> SExpr<'a> {
    pub(crate) fn token(&self) -> Option<&'a str> {
        match self.kind {
            SKind::Token(t) => Some(t),
            SKind::List(_) => None,
        }
    }

    pub(crate) fn list(&self) -> Option<&[SExpr<'a>]> {
        match &self.kind {
            SKind::List(items) => Some(items),
            SKind::Token(_) => None,
        }
    }
}

/// One item of a bulleted section: a formula or the word `None`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Item<'a> {
    Expr(SExpr<'a>),
    None(usize),
}

fn is_token_char(c: char) -> bool {
    !c.is_whitespace() && c != '(' && c != ')' && c != ';'
}

fn ws(i: &mut In<'_>) -> ModalResult<()> {
    loop {
        take_while(0.., char::is_whitespace).parse_next(i)?;
        if i.starts_with(';') {
            take_while(0.., |c| c != '\n').parse_next(i)?;
        } else {
            return Ok(());
        }
    }
}

fn token<'a>(i: &mut In<'a>) -> ModalResult<&'a str> {
    take_while(1.., is_token_char).parse_next(i)
}

fn list<'a>(i: &mut In<'a>) -> ModalResult<Vec<SExpr<'a>>> {
    '('.parse_next(i)?;
    let mut items = Vec::new();
    loop {
        ws(i)?;
        if i.starts_with(')') {
            any.parse_next(i)?;
            return Ok(items);
        }
        if i.is_empty() {
            return Err(ErrMode::Cut(ContextError::new()));
        }
        items.push(sexpr(i)?);
    }
}

fn sexpr<'a>(i: &mut In<'a>) -> ModalResult<SExpr<'a>> {
    let start = i.current_token_start();
    let kind = if i.starts_with('(') {
        SKind::List(list(i)?)
    } else {
        SKind::Token(token(i)?)
    };
    Ok(SExpr {
        kind,
        span: start..i.previous_token_end(),
    })
}

/// Checks balance and depth of `doc[start..end]`, honouring `;` comments.
fn prescan(doc: &str, start: usize, end: usize) -> Result<(), ParseError> {
    let mut open: Vec<usize> = Vec::new();
    let mut in_comment = false;
    for (off, c) in doc[start..end].char_indices() {
        let at = start + off;
        match c {
            '\n' => in_comment = false,
            _ if in_comment => {}
            ';' => in_comment = true,
            '(' => {
                open.push(at);
                if open.len() > MAX_DEPTH {
                    return Err(ParseError::at(
                        doc,
                        at,
                        ParseErrorKind::TooDeep,
                        format!("at most {MAX_DEPTH} nested parentheses"),
                    ));
                }
            }
            ')' if open.pop().is_none() => {
                return Err(ParseError::at(
                    doc,
                    at,
                    ParseErrorKind::Unbalanced,
                    "no `)` here: it closes nothing",
                ));
            }
            _ => {}
        }
    }
    if let Some(&at) = open.last() {
        let (line, col) = super::line_col(doc, at);
        return Err(ParseError::at(
            doc,
            end,
            ParseErrorKind::Unbalanced,
            format!("`)` to close the `(` opened at line {line}, column {col}"),
        ));
    }
    Ok(())
}

/// Runs a winnow parser over `doc[start..end]` and shifts spans to document offsets.
fn run<'a, O>(
    doc: &'a str,
    start: usize,
    end: usize,
    mut parser: impl FnMut(&mut In<'a>) -> ModalResult<O>,
) -> Result<O, ParseError> {
    let mut input = LocatingSlice::new(&doc[start..end]);
    parser(&mut input).map_err(|_| {
        let consumed = (end - start) - input.eof_offset();
        ParseError::at(doc, start + consumed, ParseErrorKind::Syntax, "an s-expression")
    })
}

fn shift(e: &mut SExpr<'_>, by: usize) {
    e.span = e.span.start + by..e.span.end + by;
    if let SKind::List(items) = &mut e.kind {
        items.iter_mut().for_each(|x| shift(x, by));
    }
}

/// Parses exactly one s-expression (with surrounding whitespace and comments).
pub(crate) fn parse_single<'a>(doc: &'a str, start: usize, end: usize) -> Result<SExpr<'a>, ParseError> {
    prescan(doc, start, end)?;
    let (mut e, rest) = run(doc, start, end, |i| {
        ws(i)?;
        if i.is_empty() {
            return Ok((None, i.current_token_start()));
        }
        let e = sexpr(i)?;
        ws(i)?;
        Ok((Some(e), i.current_token_start()))
    })?;
    let Some(mut expr) = e.take() else {
        return Err(ParseError::at(
            doc,
            end,
            ParseErrorKind::Empty,
            "an expression in parentheses",
        ));
    };
    if start + rest < end {
        return Err(ParseError::at(
            doc,
            start + rest,
            ParseErrorKind::Syntax,
            "end of input after one expression",
        ));
    }
    shift(&mut expr, start);
    Ok(expr)
}

/// Parses every top-level s-expression of `doc[start..end]`.
pub(crate) fn parse_all<'a>(doc: &'a str, start: usize, end: usize) -> Result<Vec<SExpr<'a>>, ParseError> {
    prescan(doc, start, end)?;
    let mut items = run(doc, start, end, |i| {
        let mut out = Vec::new();
        loop {
            ws(i)?;
            if i.is_empty() {
                return Ok(out);
            }
            out.push(sexpr(i)?);
        }
    })?;
    items.iter_mut().for_each(|x| shift(x, start));
    Ok(items)
}

fn bullet(i: &mut In<'_>) -> ModalResult<bool> {
    let checkpoint = i.checkpoint();
    let marker: ModalResult<()> = (|| {
        let digits = take_while(0.., |c: char| c.is_ascii_digit()).parse_next(i)?;
        if digits.is_empty() {
            winnow::token::one_of(['-', '*', '•', '+']).parse_next(i)?;
        } else {
            winnow::token::one_of(['.', ')']).parse_next(i)?;
        }
        take_while(0.., |c: char| c == ' ' || c == '\t').parse_next(i)?;
        Ok(())
    })();
    if marker.is_ok() {
        Ok(true)
    } else {
        i.reset(&checkpoint);
        Ok(false)
    }
}

/// Parses a bulleted section body: formulas in parentheses, optionally each behind a
/// `-`/`*`/`•`/numbered bullet, or the word `None`.
pub(crate) fn parse_items<'a>(doc: &'a str, start: usize, end: usize) -> Result<Vec<Item<'a>>, ParseError> {
    prescan(doc, start, end)?;
    enum Raw<'a> {
        Expr(SExpr<'a>),
        None(usize),
        Bad(usize),
    }
    let raw = run(doc, start, end, |i| {
        let mut out = Vec::new();
        loop {
            ws(i)?;
            if i.is_empty() {
                return Ok(out);
            }
            bullet(i)?;
            ws(i)?;
            if i.is_empty() {
                return Ok(out);
            }
            let at = i.current_token_start();
            if i.starts_with('(') {
                out.push(Raw::Expr(sexpr(i)?));
            } else if i.starts_with("```") || i.starts_with("~~~") {
                // A markdown fence inside a section: transparent.
                take_while(0.., |c| c != '\n').parse_next(i)?;
            } else {
                let t = token(i)?;
                let word = t.trim_end_matches(['.', ',']);
                if word.eq_ignore_ascii_case("none") {
                    out.push(Raw::None(at));
                } else {
                    out.push(Raw::Bad(at));
                    return Ok(out);
                }
            }
        }
    })?;
    let mut items = Vec::with_capacity(raw.len());
    for r in raw {
        match r {
            Raw::Expr(mut e) => {
                shift(&mut e, start);
                items.push(Item::Expr(e));
            }
            Raw::None(at) => items.push(Item::None(start + at)),
            Raw::Bad(at) => {
                return Err(ParseError::at(
                    doc,
                    start + at,
                    ParseErrorKind::Syntax,
                    "a formula in parentheses (optionally after a `-` bullet) or `None`",
                ));
            }
        }
    }
    Ok(items)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_and_errors() {
        let doc = "x\n(a (b c) d)";
        let e = parse_single(doc, 2, doc.len()).unwrap();
        assert_eq!(e.span, 2..doc.len());
        let inner = &e.list().unwrap()[1];
        assert_eq!(&doc[inner.span.clone()], "(b c)");
        let err = parse_single("(a (b c)", 0, 8).unwrap_err();
        assert_eq!(err.kind, ParseErrorKind::Unbalanced);
        assert!(err.expected.contains("line 1, column 1"), "{err}");
        let err = parse_single("(a) (b)", 0, 7).unwrap_err();
        assert_eq!((err.line, err.column), (1, 5));
        let deep = "(".repeat(1000) + &")".repeat(1000);
        assert_eq!(
            parse_single(&deep, 0, deep.len()).unwrap_err().kind,
            ParseErrorKind::TooDeep
        );
    }

    #[test]
    fn bulleted_items() {
        let doc = "- (A)\n* (B x)\n1. (C)\n\t(D)\nNone";
        let items = parse_items(doc, 0, doc.len()).unwrap();
        assert_eq!(items.len(), 5);
        assert!(matches!(items[4], Item::None(_)));
        let err = parse_items("- (A)\n- prose here", 0, 18).unwrap_err();
        assert_eq!((err.line, err.column), (2, 3));
    }
}
