//! From s-expressions to formulas and effects, with scope checking.

use smallvec::SmallVec;

use super::sexpr::{SExpr, SKind};
use super::{ParseError, ParseErrorKind};
use crate::atom::is_name_char;
use crate::formula::{AtomPattern, Effect, Formula, Term, TypedVar};
use crate::symbol::Symbol;
use crate::types::ROOT_TYPE;

/// Converts s-expressions of one document into formulas and effects.
pub(crate) struct Converter<'d> {
    doc: &'d str,
    /// PDDL is case-insensitive: in PDDL mode every name is lower-cased.
    lowercase: bool,
    /// Declared predicates and arities; when set, atoms are checked against them.
    predicates: Option<Vec<(Symbol, usize)>>,
}

fn is_name(t: &str) -> bool {
    !t.is_empty() && t.chars().all(is_name_char)
}

impl<'d> Converter<'d> {
    pub(crate) fn new(doc: &'d str, lowercase: bool) -> Self {
        Converter {
            doc,
            lowercase,
            predicates: None,
        }
    }

    /// Checks every atom against declared predicates (PDDL's `:predicates`).
    pub(crate) fn with_predicates(mut self, predicates: Vec<(Symbol, usize)>) -> Self {
        self.predicates = Some(predicates);
        self
    }

    pub(crate) fn err(&self, at: usize, kind: ParseErrorKind, expected: impl Into<String>) -> ParseError {
        ParseError::at(self.doc, at, kind, expected)
    }

    pub(crate) fn name(&self, t: &str) -> Symbol {
        if self.lowercase {
            Symbol::new(&t.to_lowercase())
        } else {
            Symbol::new(t)
        }
    }

    /// A name token (not a variable, not a list).
    pub(crate) fn expect_name(&self, e: &SExpr<'_>, what: &str) -> Result<Symbol, ParseError> {
        match e.kind {
            SKind::Token(t) if is_name(t) => Ok(self.name(t)),
            _ => Err(self.err(e.span.start, ParseErrorKind::Syntax, what.to_string())),
        }
    }

    /// The connective or quantifier a list head names (case-insensitive), in lower case;
    /// `None` for anything else (a predicate name, a nested list). Allocation-free: every
    /// formula node of a reply goes through here.
    fn keyword(&self, e: &SExpr<'_>) -> Option<&'static str> {
        const KEYWORDS: [&str; 8] = ["and", "or", "not", "imply", "forall", "exists", "when", "="];
        let t = e.token()?;
        KEYWORDS.into_iter().find(|k| t.eq_ignore_ascii_case(k))
    }

    fn term(&self, e: &SExpr<'_>, scope: &[Symbol]) -> Result<Term, ParseError> {
        match e.kind {
            SKind::Token(t) if t.starts_with('?') && is_name(&t[1..]) => {
                let v = self.name(&t[1..]);
                if scope.contains(&v) {
                    Ok(Term::Var(v))
                } else {
                    Err(self.err(
                        e.span.start,
                        ParseErrorKind::UnboundVariable,
                        format!("a bound variable or an object name (`{t}` is not bound by any quantifier or parameter)"),
                    ))
                }
            }
            SKind::Token(t) if is_name(t) => Ok(Term::Const(self.name(t))),
            _ => Err(self.err(
                e.span.start,
                ParseErrorKind::Syntax,
                "an object name or a `?variable`",
            )),
        }
    }

    fn atom(
        &self,
        head: &SExpr<'_>,
        args: &[SExpr<'_>],
        scope: &[Symbol],
    ) -> Result<AtomPattern, ParseError> {
        let pred = self.expect_name(head, "a predicate name")?;
        if let Some(declared) = &self.predicates {
            match declared.iter().find(|(p, _)| *p == pred) {
                None => {
                    return Err(self.err(
                        head.span.start,
                        ParseErrorKind::Reference,
                        format!("a predicate declared in :predicates (`{pred}` is not)"),
                    ));
                }
                Some((_, arity)) if *arity != args.len() => {
                    return Err(self.err(
                        head.span.start,
                        ParseErrorKind::Reference,
                        format!(
                            "{arity} argument(s) for `{pred}`, as declared (found {})",
                            args.len()
                        ),
                    ));
                }
                Some(_) => {}
            }
        }
        let args: SmallVec<[Term; 3]> = args
            .iter()
            .map(|a| self.term(a, scope))
            .collect::<Result<_, _>>()?;
        Ok(AtomPattern { pred, args })
    }

    /// Parses `?a ?b - type ?c` (untyped variables are `thing`).
    pub(crate) fn typed_list(
        &self,
        items: &[SExpr<'_>],
        variables: bool,
    ) -> Result<Vec<(Symbol, Symbol, usize)>, ParseError> {
        let mut out: Vec<(Symbol, Symbol, usize)> = Vec::new();
        let mut pending: Vec<(Symbol, usize)> = Vec::new();
        let mut i = 0;
        while i < items.len() {
            let e = &items[i];
            if e.token() == Some("-") {
                let Some(ty) = items.get(i + 1) else {
                    return Err(self.err(e.span.end, ParseErrorKind::Syntax, "a type name after `-`"));
                };
                if let Some(list) = ty.list() {
                    let either = list
                        .first()
                        .and_then(|h| h.token())
                        .is_some_and(|h| h.eq_ignore_ascii_case("either"));
                    let what = if either {
                        "a single type name (`either` types are not supported)"
                    } else {
                        "a type name"
                    };
                    let kind = if either {
                        ParseErrorKind::Unsupported
                    } else {
                        ParseErrorKind::Syntax
                    };
                    return Err(self.err(ty.span.start, kind, what));
                }
                let ty_sym = self.expect_name(ty, "a type name")?;
                if pending.is_empty() {
                    return Err(self.err(e.span.start, ParseErrorKind::Syntax, "a name before `- type`"));
                }
                out.extend(pending.drain(..).map(|(n, at)| (n, ty_sym, at)));
                i += 2;
                continue;
            }
            let t = e.token().unwrap_or("");
            let name = if variables {
                match t.strip_prefix('?') {
                    Some(v) if is_name(v) => self.name(v),
                    _ => return Err(self.err(e.span.start, ParseErrorKind::Syntax, "a `?variable`")),
                }
            } else if is_name(t) && !t.starts_with('?') {
                self.name(t)
            } else {
                return Err(self.err(e.span.start, ParseErrorKind::Syntax, "a name"));
            };
            pending.push((name, e.span.start));
            i += 1;
        }
        let root = Symbol::new(ROOT_TYPE);
        out.extend(pending.drain(..).map(|(n, at)| (n, root, at)));
        Ok(out)
    }

    fn quantifier_vars(&self, e: &SExpr<'_>) -> Result<Vec<TypedVar>, ParseError> {
        let Some(items) = e.list() else {
            return Err(self.err(
                e.span.start,
                ParseErrorKind::Syntax,
                "a parenthesised variable list like `(?x - thing)`",
            ));
        };
        let vars = self.typed_list(items, true)?;
        if vars.is_empty() {
            return Err(self.err(
                e.span.start,
                ParseErrorKind::Syntax,
                "at least one quantified variable",
            ));
        }
        Ok(vars
            .into_iter()
            .map(|(name, ty, _)| TypedVar { name, ty })
            .collect())
    }

    fn arity_error(&self, e: &SExpr<'_>, kw: &str, expected: &str) -> ParseError {
        self.err(
            e.span.start,
            ParseErrorKind::Syntax,
            format!("`({kw} ...)` with {expected}"),
        )
    }

    /// A formula; `scope` holds the variables bound around it.
    pub(crate) fn formula(&self, e: &SExpr<'_>, scope: &mut Vec<Symbol>) -> Result<Formula, ParseError> {
        let Some(items) = e.list() else {
            return Err(self.err(e.span.start, ParseErrorKind::Syntax, "a formula in parentheses"));
        };
        let Some((head, rest)) = items.split_first() else {
            return Err(self.err(
                e.span.start,
                ParseErrorKind::Syntax,
                "a predicate or connective after `(`",
            ));
        };
        let kw = self.keyword(head);
        match kw {
            Some("and") | Some("or") => {
                let parts = rest
                    .iter()
                    .map(|x| self.formula(x, scope))
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(if kw == Some("and") {
                    Formula::And(parts)
                } else {
                    Formula::Or(parts)
                })
            }
            Some("not") => match rest {
                [x] => Ok(Formula::Not(Box::new(self.formula(x, scope)?))),
                _ => Err(self.arity_error(e, "not", "exactly one formula")),
            },
            Some("imply") => match rest {
                [a, b] => Ok(Formula::Imply(
                    Box::new(self.formula(a, scope)?),
                    Box::new(self.formula(b, scope)?),
                )),
                _ => Err(self.arity_error(e, "imply", "exactly two formulas")),
            },
            Some("forall") | Some("exists") => match rest {
                [vars, body] => {
                    let vars = self.quantifier_vars(vars)?;
                    let depth = scope.len();
                    scope.extend(vars.iter().map(|v| v.name));
                    let body = self.formula(body, scope);
                    scope.truncate(depth);
                    let body = Box::new(body?);
                    Ok(if kw == Some("forall") {
                        Formula::Forall(vars, body)
                    } else {
                        Formula::Exists(vars, body)
                    })
                }
                _ => Err(self.arity_error(e, kw.unwrap_or_default(), "a variable list and one formula")),
            },
            Some("=") => match rest {
                [a, b] => Ok(Formula::Eq(self.term(a, scope)?, self.term(b, scope)?)),
                _ => Err(self.arity_error(e, "=", "exactly two terms")),
            },
            Some("when") => Err(self.err(
                head.span.start,
                ParseErrorKind::Syntax,
                "a formula (`when` is only allowed in effects)",
            )),
            _ => Ok(Formula::Atom(self.atom(head, rest, scope)?)),
        }
    }

    /// An effect expression, flattened: `(and e1 e2)` gives two effects.
    pub(crate) fn effects(&self, e: &SExpr<'_>, scope: &mut Vec<Symbol>) -> Result<Vec<Effect>, ParseError> {
        let Some(items) = e.list() else {
            return Err(self.err(e.span.start, ParseErrorKind::Syntax, "an effect in parentheses"));
        };
        let Some((head, rest)) = items.split_first() else {
            return Err(self.err(
                e.span.start,
                ParseErrorKind::Syntax,
                "an atom, `not`, `and`, `forall` or `when` after `(`",
            ));
        };
        let kw = self.keyword(head);
        match kw {
            Some("and") => {
                let mut out = Vec::new();
                for x in rest {
                    out.extend(self.effects(x, scope)?);
                }
                Ok(out)
            }
            Some("not") => match rest {
                [x] => {
                    let inner = x.list().unwrap_or(&[]);
                    match inner.split_first() {
                        Some((h, args))
                            if !matches!(
                                self.keyword(h),
                                Some("and" | "or" | "not" | "forall" | "exists" | "when" | "imply" | "=")
                            ) =>
                        {
                            Ok(vec![Effect::Del(self.atom(h, args, scope)?)])
                        }
                        _ => Err(self.err(
                            x.span.start,
                            ParseErrorKind::Syntax,
                            "an atom to delete after `not`",
                        )),
                    }
                }
                _ => Err(self.arity_error(e, "not", "exactly one atom")),
            },
            Some("forall") => match rest {
                [vars, body] => {
                    let vars = self.quantifier_vars(vars)?;
                    let depth = scope.len();
                    scope.extend(vars.iter().map(|v| v.name));
                    let body = self.effects(body, scope);
                    scope.truncate(depth);
                    Ok(vec![Effect::Forall(vars, body?)])
                }
                _ => Err(self.arity_error(e, "forall", "a variable list and one effect")),
            },
            Some("when") => match rest {
                [cond, body] => Ok(vec![Effect::When(
                    self.formula(cond, scope)?,
                    self.effects(body, scope)?,
                )]),
                _ => Err(self.arity_error(e, "when", "a condition and one effect")),
            },
            Some("or" | "exists" | "imply" | "=") => Err(self.err(
                head.span.start,
                ParseErrorKind::Syntax,
                "an effect: an atom, `(not atom)`, `and`, `forall` or `when`",
            )),
            _ => Ok(vec![Effect::Add(self.atom(head, rest, scope)?)]),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::text::{parse_effects, parse_formula};

    #[test]
    fn formulas_round_trip_and_scope() {
        for text in [
            "(forall (?y - thing) (not (GripperHolding ?y)))",
            "(not (and (Finegrained black_screws) (not (Gathered black_screws))))",
            "(exists (?a ?b - block) (and (on ?a ?b) (not (= ?a ?b))))",
            "(imply (Open lid) (or (A) (B x)))",
            "(and)",
        ] {
            assert_eq!(parse_formula(text).unwrap().to_string(), text);
        }
        let err = parse_formula("(forall (?x - thing) (P ?xy))").unwrap_err();
        assert!(err.expected.contains("?xy"), "{err}");
        assert_eq!(err.column, 25);
        assert!(parse_formula("(when (A) (B))").is_err());
        assert!(parse_formula("(forall (?x - (either a b)) (P ?x))").is_err());
    }

    #[test]
    fn effects_flatten() {
        let es =
            parse_effects("(and (A) (not (B)) (forall (?x - thing) (when (C ?x) (not (D ?x)))))").unwrap();
        assert_eq!(es.len(), 3);
        assert_eq!(
            es[2].to_string(),
            "(forall (?x - thing) (when (C ?x) (not (D ?x))))"
        );
        assert!(parse_effects("(not (or (A) (B)))").is_err());
    }
}
