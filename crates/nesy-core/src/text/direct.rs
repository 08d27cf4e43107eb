//! A direct reader for section bodies: from the text of a `- Preconditions:` or `- Effects:`
//! body straight into formulas and effects, one pass over the bytes, without the
//! s-expression tree, the balance pre-scan or the span bookkeeping of the general path
//! ([`super::sexpr::parse_items`] followed by [`super::syntax::Converter`]).
//!
//! It handles the shape nearly every reply has — ASCII text, bullets, formulas over
//! several lines, `None` — and *defers* everything else: comments, fences, non-ASCII
//! bytes, deep nesting, and every input the general path would reject. Deferring means
//! returning `None`, and the caller then runs the general path, which gives the result or
//! the positioned error. So errors always come from one place, and where this reader does
//! return a value it is the value the general path returns for the same text (debug builds
//! check that on every call, see `action_block`).

use smallvec::SmallVec;

use crate::formula::{AtomPattern, Effect, Formula, Term, TypedVar};
use crate::symbol::Symbol;
use crate::types::ROOT_TYPE;

/// Nesting deeper than this is left to the general path (which accepts up to
/// [`super::sexpr::MAX_DEPTH`] and reports deeper input); real formulas stay below 20.
const DEPTH_LIMIT: usize = 64;

/// The input needs the general path.
struct Defer;

type Read<T> = Result<T, Defer>;

/// `char::is_whitespace` restricted to ASCII (the reader defers on any other byte).
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | 0x0b | 0x0c | b'\r')
}

/// `atom::is_name_char` restricted to ASCII.
fn is_name(t: &str) -> bool {
    !t.is_empty()
        && t.bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.'))
}

/// The connectives and quantifiers, as the general path recognises them (ASCII
/// case-insensitive).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Keyword {
    And,
    Or,
    Not,
    Imply,
    Forall,
    Exists,
    When,
    Eq,
}

fn keyword(t: &str) -> Option<Keyword> {
    // Dispatch on length first: nearly every head is a predicate name longer than six bytes.
    let kw = match t.len() {
        1 => Keyword::Eq,
        2 => Keyword::Or,
        3 if t.as_bytes()[0].eq_ignore_ascii_case(&b'a') => Keyword::And,
        3 => Keyword::Not,
        4 => Keyword::When,
        5 => Keyword::Imply,
        6 if t.as_bytes()[0].eq_ignore_ascii_case(&b'f') => Keyword::Forall,
        6 => Keyword::Exists,
        _ => return None,
    };
    let text = match kw {
        Keyword::And => "and",
        Keyword::Or => "or",
        Keyword::Not => "not",
        Keyword::Imply => "imply",
        Keyword::Forall => "forall",
        Keyword::Exists => "exists",
        Keyword::When => "when",
        Keyword::Eq => "=",
    };
    t.eq_ignore_ascii_case(text).then_some(kw)
}

struct Reader<'a> {
    text: &'a str,
    pos: usize,
    end: usize,
    depth: usize,
    /// Variables bound around the current position.
    scope: SmallVec<[Symbol; 4]>,
}

impl<'a> Reader<'a> {
    fn peek(&self) -> Option<u8> {
        (self.pos < self.end).then(|| self.text.as_bytes()[self.pos])
    }

    fn skip_space(&mut self) {
        let bytes = self.text.as_bytes();
        while self.pos < self.end && is_space(bytes[self.pos]) {
            self.pos += 1;
        }
    }

    /// A token: bytes up to whitespace or a parenthesis. Empty at `(`, `)` or the end;
    /// defers at a comment or a non-ASCII byte.
    fn token(&mut self) -> Read<&'a str> {
        let bytes = self.text.as_bytes();
        let start = self.pos;
        while self.pos < self.end {
            match bytes[self.pos] {
                b'(' | b')' => break,
                b';' | 0x80.. => return Err(Defer),
                b if is_space(b) => break,
                _ => self.pos += 1,
            }
        }
        Ok(&self.text[start..self.pos])
    }

    /// Skips whitespace and expects `c`.
    fn expect(&mut self, c: u8) -> Read<()> {
        self.skip_space();
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(Defer)
        }
    }

    /// Skips whitespace and reads a token that must be non-empty.
    fn word(&mut self) -> Read<&'a str> {
        self.skip_space();
        let t = self.token()?;
        if t.is_empty() { Err(Defer) } else { Ok(t) }
    }

    /// Consumes `(`, tracking depth.
    fn open(&mut self) -> Read<()> {
        self.expect(b'(')?;
        self.depth += 1;
        if self.depth > DEPTH_LIMIT {
            return Err(Defer);
        }
        Ok(())
    }

    /// Consumes `)`, tracking depth.
    fn close(&mut self) -> Read<()> {
        self.expect(b')')?;
        self.depth -= 1;
        Ok(())
    }

    /// True (and consumed) if the next non-blank byte is `)`.
    fn at_close(&mut self) -> bool {
        self.skip_space();
        if self.peek() == Some(b')') {
            self.pos += 1;
            self.depth -= 1;
            true
        } else {
            false
        }
    }

    fn term(&self, t: &str) -> Read<Term> {
        if let Some(v) = t.strip_prefix('?')
            && is_name(v)
        {
            let v = Symbol::new(v);
            return if self.scope.contains(&v) {
                Ok(Term::Var(v))
            } else {
                Err(Defer)
            };
        }
        if is_name(t) {
            Ok(Term::Const(Symbol::new(t)))
        } else {
            Err(Defer)
        }
    }

    /// The arguments of an atom whose head was read, through its `)`.
    fn atom(&mut self, head: &str) -> Read<AtomPattern> {
        if !is_name(head) {
            return Err(Defer);
        }
        let pred = Symbol::new(head);
        let mut args = SmallVec::new();
        while !self.at_close() {
            let t = self.word()?;
            args.push(self.term(t)?);
        }
        Ok(AtomPattern { pred, args })
    }

    /// The head of a list whose `(` was read: a token (a nested list or `()` defers).
    fn head(&mut self) -> Read<&'a str> {
        self.word()
    }

    /// `(?a ?b - type ?c)`, non-empty; untyped variables are `thing`.
    fn typed_vars(&mut self) -> Read<Vec<TypedVar>> {
        self.open()?;
        let mut out: Vec<TypedVar> = Vec::new();
        let mut pending = 0;
        let root = Symbol::new(ROOT_TYPE);
        while !self.at_close() {
            let t = self.word()?;
            if t == "-" {
                let ty = self.word()?;
                if !is_name(ty) || pending == 0 {
                    return Err(Defer);
                }
                let ty = Symbol::new(ty);
                let n = out.len();
                out[n - pending..].iter_mut().for_each(|v| v.ty = ty);
                pending = 0;
                continue;
            }
            match t.strip_prefix('?') {
                Some(v) if is_name(v) => {
                    out.push(TypedVar {
                        name: Symbol::new(v),
                        ty: root,
                    });
                    pending += 1;
                }
                _ => return Err(Defer),
            }
        }
        if out.is_empty() { Err(Defer) } else { Ok(out) }
    }

    /// A formula starting at `(`.
    fn formula(&mut self) -> Read<Formula> {
        self.open()?;
        let head = self.head()?;
        let f = match keyword(head) {
            Some(kw @ (Keyword::And | Keyword::Or)) => {
                let mut parts = Vec::new();
                while !self.at_close() {
                    parts.push(self.formula()?);
                }
                return Ok(if kw == Keyword::And {
                    Formula::And(parts)
                } else {
                    Formula::Or(parts)
                });
            }
            Some(Keyword::Not) => Formula::Not(Box::new(self.formula()?)),
            Some(Keyword::Imply) => {
                let a = self.formula()?;
                Formula::Imply(Box::new(a), Box::new(self.formula()?))
            }
            Some(kw @ (Keyword::Forall | Keyword::Exists)) => {
                let vars = self.typed_vars()?;
                let depth = self.scope.len();
                self.scope.extend(vars.iter().map(|v| v.name));
                let body = self.formula();
                self.scope.truncate(depth);
                let body = Box::new(body?);
                if kw == Keyword::Forall {
                    Formula::Forall(vars, body)
                } else {
                    Formula::Exists(vars, body)
                }
            }
            Some(Keyword::Eq) => {
                let a = self.word()?;
                let a = self.term(a)?;
                let b = self.word()?;
                Formula::Eq(a, self.term(b)?)
            }
            Some(Keyword::When) => return Err(Defer),
            None => return Ok(Formula::Atom(self.atom(head)?)),
        };
        self.close()?;
        Ok(f)
    }

    /// An effect expression starting at `(`, flattened into `out`.
    fn effects(&mut self, out: &mut Vec<Effect>) -> Read<()> {
        self.open()?;
        let head = self.head()?;
        match keyword(head) {
            Some(Keyword::And) => {
                while !self.at_close() {
                    self.effects(out)?;
                }
                return Ok(());
            }
            Some(Keyword::Not) => {
                self.open()?;
                let inner = self.head()?;
                if keyword(inner).is_some() {
                    return Err(Defer);
                }
                out.push(Effect::Del(self.atom(inner)?));
            }
            Some(Keyword::Forall) => {
                let vars = self.typed_vars()?;
                let depth = self.scope.len();
                self.scope.extend(vars.iter().map(|v| v.name));
                let mut body = Vec::new();
                let read = self.effects(&mut body);
                self.scope.truncate(depth);
                read?;
                out.push(Effect::Forall(vars, body));
            }
            Some(Keyword::When) => {
                let cond = self.formula()?;
                let mut body = Vec::new();
                self.effects(&mut body)?;
                out.push(Effect::When(cond, body));
            }
            Some(_) => return Err(Defer),
            None => {
                out.push(Effect::Add(self.atom(head)?));
                return Ok(());
            }
        }
        self.close()
    }

    /// The bullet the general path skips before an item: digits followed by `.`, or one of
    /// `-`, `*`, `+`, then spaces and tabs. (`•` is not ASCII: deferred later.) A `1)`
    /// bullet defers: the general path's balance pre-scan counts its `)` and rejects it.
    fn bullet(&mut self) -> Read<()> {
        let bytes = self.text.as_bytes();
        let mut i = self.pos;
        while i < self.end && bytes[i].is_ascii_digit() {
            i += 1;
        }
        let marker = if i > self.pos {
            if i < self.end && bytes[i] == b')' {
                return Err(Defer);
            }
            i < self.end && bytes[i] == b'.'
        } else {
            i < self.end && matches!(bytes[i], b'-' | b'*' | b'+')
        };
        if marker {
            self.pos = i + 1;
            while self.pos < self.end && matches!(bytes[self.pos], b' ' | b'\t') {
                self.pos += 1;
            }
        }
        Ok(())
    }

    /// The items of a section body: `item` reads one parenthesised item; the word `None`
    /// (alone) gives nothing.
    fn items(&mut self, mut item: impl FnMut(&mut Self) -> Read<()>) -> Read<()> {
        let mut items = 0usize;
        let mut none = false;
        loop {
            self.skip_space();
            if self.pos == self.end {
                break;
            }
            self.bullet()?;
            self.skip_space();
            match self.peek() {
                None => break,
                Some(b'(') => {
                    item(self)?;
                    items += 1;
                }
                Some(_) => {
                    let t = self.token()?;
                    if t.is_empty() || !t.trim_end_matches(['.', ',']).eq_ignore_ascii_case("none") {
                        return Err(Defer);
                    }
                    none = true;
                }
            }
        }
        if none && items > 0 { Err(Defer) } else { Ok(()) }
    }
}

fn reader(doc: &str, start: usize, end: usize) -> Reader<'_> {
    Reader {
        text: doc,
        pos: start,
        end,
        depth: 0,
        scope: SmallVec::new(),
    }
}

/// The formulas of a precondition body `doc[start..end]`, or `None` to defer.
pub(crate) fn preconditions(doc: &str, start: usize, end: usize) -> Option<Vec<Formula>> {
    let mut r = reader(doc, start, end);
    let mut out = Vec::new();
    r.items(|r| {
        out.push(r.formula()?);
        Ok(())
    })
    .ok()?;
    Some(out)
}

/// The effects of an effect body `doc[start..end]` (`and` flattened), or `None` to defer.
pub(crate) fn effects(doc: &str, start: usize, end: usize) -> Option<Vec<Effect>> {
    let mut r = reader(doc, start, end);
    let mut out = Vec::new();
    r.items(|r| r.effects(&mut out)).ok()?;
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pre(text: &str) -> Option<Vec<Formula>> {
        preconditions(text, 0, text.len())
    }

    fn eff(text: &str) -> Option<Vec<Effect>> {
        effects(text, 0, text.len())
    }

    #[test]
    fn reads_the_common_shapes() {
        let body = "\n\t(VacuumSuction)\n - (forall (?y - thing) (not (OnTopOf ?y green_cylinder)))\n12. (exists (?a ?b - block ?c) (and (on ?a ?b) (not (= ?a ?c))))\n* (imply (Open lid)\n    (or (A) (B x)))";
        let got = pre(body).unwrap();
        let printed: Vec<String> = got.iter().map(|f| f.to_string()).collect();
        assert_eq!(
            printed,
            [
                "(VacuumSuction)",
                "(forall (?y - thing) (not (OnTopOf ?y green_cylinder)))",
                "(exists (?a ?b - block ?c - thing) (and (on ?a ?b) (not (= ?a ?c))))",
                "(imply (Open lid) (or (A) (B x)))",
            ]
        );
        assert_eq!(pre("\tNone\n").unwrap(), vec![]);
        assert_eq!(pre("none.").unwrap(), vec![]);
        let es =
            eff("(and (A) (not (B))) (forall (?x - thing) (when (C ?x) (and (D ?x) (not (E)))))").unwrap();
        assert_eq!(es.len(), 3);
        assert_eq!(
            es[2].to_string(),
            "(forall (?x - thing) (when (C ?x) (and (D ?x) (not (E)))))"
        );
    }

    #[test]
    fn defers_what_it_does_not_read() {
        for text in [
            "(A) ; comment",
            "• (A)",
            "```\n(A)",
            "(A ?free)",
            "(A) prose",
            "None (A)",
            "(A))",
            "((A))",
            "()",
            "(not (A) (B))",
            "(when (A) (B))",
            "(forall () (A))",
            "(forall (- thing) (A))",
            "(forall (?x - (either a b)) (A ?x))",
            "(Ä)",
            "1) (A)",
        ] {
            assert!(pre(text).is_none(), "{text}");
        }
        let deep = "(not ".repeat(100) + "(A)" + &")".repeat(100);
        assert!(pre(&deep).is_none());
        for text in ["(not (and (A)))", "(not A)", "(or (A))", "(= a b)"] {
            assert!(eff(text).is_none(), "{text}");
        }
    }
}
