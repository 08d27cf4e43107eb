//! PDDL domains, problems and plans: parsing, printing, and grounding a plan into the
//! operators [`crate::exec::verify_procedure_in`] checks.
//!
//! Supported requirements: `:strips`, `:typing`, `:negative-preconditions`,
//! `:disjunctive-preconditions`, `:equality`, `:existential-preconditions`,
//! `:universal-preconditions`, `:quantified-preconditions`, `:conditional-effects` and
//! `:adl`. Anything else (numeric fluents, durative actions, derived predicates, `either`
//! types) is rejected with a [`ParseErrorKind::Unsupported`] error rather than misread.
//! PDDL is case-insensitive, so every name is lower-cased on input.
//!
//! Plans hold one `(action arg...)` per line; `;` starts a comment, and an optional
//! `time:` prefix and `[duration]` suffix (as planners print them) are accepted.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::atom::Atom;
use crate::formula::{Formula, TypedVar, fmt_typed_vars};
use crate::operator::Operator;
use crate::state::State;
use crate::symbol::Symbol;
use crate::text::sexpr::{SExpr, parse_all, parse_single};
use crate::text::syntax::Converter;
use crate::text::{ParseError, ParseErrorKind};
use crate::types::{TypeError, Universe};

const SUPPORTED_REQUIREMENTS: &[&str] = &[
    ":strips",
    ":typing",
    ":negative-preconditions",
    ":disjunctive-preconditions",
    ":equality",
    ":existential-preconditions",
    ":universal-preconditions",
    ":quantified-preconditions",
    ":conditional-effects",
    ":adl",
];

/// A declared predicate: name and typed parameters.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PredicateDecl {
    /// The predicate.
    pub name: Symbol,
    /// Its parameters.
    pub params: Vec<TypedVar>,
}

/// A PDDL domain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Domain {
    /// The domain's name.
    pub name: Symbol,
    /// Requirement flags as written (lower-cased), e.g. `:typing`.
    pub requirements: Vec<String>,
    /// Declared types with their parents, in declaration order.
    pub types: Vec<(Symbol, Symbol)>,
    /// Domain constants with their types.
    pub constants: Vec<(Symbol, Symbol)>,
    /// Declared predicates.
    pub predicates: Vec<PredicateDecl>,
    /// Action schemas; preconditions are the top-level conjuncts.
    pub actions: Vec<Operator>,
}

/// A PDDL problem.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// The problem's name.
    pub name: Symbol,
    /// The domain it refers to.
    pub domain: Symbol,
    /// Objects with their types.
    pub objects: Vec<(Symbol, Symbol)>,
    /// The initial state.
    pub init: State,
    /// The goal.
    pub goal: Formula,
}

/// One plan step as written.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlanStep {
    /// The action's name.
    pub action: Symbol,
    /// Its arguments.
    pub args: Vec<Symbol>,
    /// 1-based line in the plan file.
    pub line: usize,
    /// 1-based column of the step's `(`.
    pub column: usize,
}

impl fmt::Display for PlanStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}", self.action)?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        f.write_str(")")
    }
}

fn err(doc: &str, at: usize, kind: ParseErrorKind, expected: impl Into<String>) -> ParseError {
    ParseError::at(doc, at, kind, expected)
}

fn keyword_is(e: &SExpr<'_>, kw: &str) -> bool {
    e.token().is_some_and(|t| t.eq_ignore_ascii_case(kw))
}

/// Splits `(define (KIND name) sections...)` and returns the name and the sections.
fn define<'a>(doc: &'a str, kind: &str) -> Result<(Symbol, Vec<SExpr<'a>>), ParseError> {
    let top = parse_all(doc, 0, doc.len())?;
    let Some(first) = top.first() else {
        return Err(err(
            doc,
            doc.len(),
            ParseErrorKind::Empty,
            format!("`(define ({kind} NAME) ...)`"),
        ));
    };
    if let Some(extra) = top.get(1) {
        return Err(err(
            doc,
            extra.span.start,
            ParseErrorKind::Syntax,
            "end of file after the `(define ...)`",
        ));
    }
    let items = match first.list() {
        Some(items) if items.first().is_some_and(|h| keyword_is(h, "define")) => items,
        _ => {
            return Err(err(
                doc,
                first.span.start,
                ParseErrorKind::Syntax,
                "`(define ...`",
            ));
        }
    };
    let conv = Converter::new(doc, true);
    let header = items.get(1).and_then(|h| h.list());
    let name = match header {
        Some([k, n]) if keyword_is(k, kind) => conv.expect_name(n, &format!("a {kind} name"))?,
        _ => {
            let at = items.get(1).map_or(first.span.end - 1, |h| h.span.start);
            return Err(err(doc, at, ParseErrorKind::Syntax, format!("`({kind} NAME)`")));
        }
    };
    Ok((name, items[2..].to_vec()))
}

fn section_name(doc: &str, s: &SExpr<'_>) -> Result<String, ParseError> {
    match s.list().and_then(|l| l.first()).and_then(|h| h.token()) {
        Some(t) if t.starts_with(':') => Ok(t.to_ascii_lowercase()),
        _ => Err(err(
            doc,
            s.span.start,
            ParseErrorKind::Syntax,
            "a section like `(:predicates ...)`",
        )),
    }
}

/// The predicate names a domain declares, spelt as its `(:predicates ...)` section writes
/// them ([`parse_domain`] reads every name in lower case).
///
/// ```
/// use nesy_core::pddl::declared_predicate_spellings;
///
/// let doc = "(define (domain d) (:predicates (OnMagnet ?x ?h) (Gathered ?x)))";
/// let names: Vec<String> = declared_predicate_spellings(doc)
///     .unwrap()
///     .iter()
///     .map(|s| s.as_str().to_owned())
///     .collect();
/// assert_eq!(names, ["OnMagnet", "Gathered"]);
/// ```
pub fn declared_predicate_spellings(doc: &str) -> Result<Vec<Symbol>, ParseError> {
    let (_, sections) = define(doc, "domain")?;
    let mut names = Vec::new();
    for s in &sections {
        if section_name(doc, s)? == ":predicates" {
            let body = &s.list().unwrap_or(&[])[1..];
            names.extend(
                body.iter()
                    .filter_map(|p| p.list()?.first()?.token())
                    .map(Symbol::new),
            );
        }
    }
    Ok(names)
}

/// Parses a PDDL domain.
pub fn parse_domain(doc: &str) -> Result<Domain, ParseError> {
    let (name, sections) = define(doc, "domain")?;
    let conv = Converter::new(doc, true);
    let mut domain = Domain {
        name,
        requirements: vec![],
        types: vec![],
        constants: vec![],
        predicates: vec![],
        actions: vec![],
    };
    let mut action_exprs = Vec::new();
    for s in &sections {
        let kw = section_name(doc, s)?;
        let body = &s.list().unwrap_or(&[])[1..];
        match kw.as_str() {
            ":requirements" => parse_requirements(doc, body, &mut domain.requirements)?,
            ":types" => parse_types(doc, &conv, body, &mut domain.types)?,
            ":constants" => {
                for (n, t, at) in conv.typed_list(body, false)? {
                    if domain.constants.iter().any(|(c, _)| *c == n) {
                        return Err(duplicate(doc, at, "constant", n));
                    }
                    domain.constants.push((n, t));
                }
            }
            ":predicates" => parse_predicates(doc, &conv, body, &mut domain.predicates)?,
            ":action" => action_exprs.push(s),
            _ => {
                return Err(err(
                    doc,
                    s.span.start + 1,
                    ParseErrorKind::Unsupported,
                    "a supported section (:requirements, :types, :constants, :predicates, :action)",
                ));
            }
        }
    }
    // Types must form a hierarchy.
    let mut universe = Universe::new();
    for (t, parent) in &domain.types {
        universe
            .types
            .declare(*t, *parent)
            .map_err(|e| err(doc, 0, ParseErrorKind::Reference, e.to_string()))?;
    }
    let conv = Converter::new(doc, true).with_predicates(predicate_arities(&domain.predicates));
    for s in action_exprs {
        let action = parse_action(doc, &conv, s, &universe)?;
        if domain.actions.iter().any(|a| a.name == action.name) {
            return Err(duplicate(doc, s.span.start, "action", Symbol::new(&action.name)));
        }
        domain.actions.push(action);
    }
    Ok(domain)
}

/// Each declared predicate's name and arity, which atoms are checked against.
fn predicate_arities(predicates: &[PredicateDecl]) -> Vec<(Symbol, usize)> {
    predicates.iter().map(|p| (p.name, p.params.len())).collect()
}

/// Reads a `:requirements` section's flags into `requirements`, rejecting any this parser
/// would misread.
fn parse_requirements(
    doc: &str,
    body: &[SExpr<'_>],
    requirements: &mut Vec<String>,
) -> Result<(), ParseError> {
    for r in body {
        let t = r.token().map(|t| t.to_ascii_lowercase()).unwrap_or_default();
        if !SUPPORTED_REQUIREMENTS.contains(&t.as_str()) {
            return Err(err(
                doc,
                r.span.start,
                ParseErrorKind::Unsupported,
                format!("a supported requirement ({})", SUPPORTED_REQUIREMENTS.join(" ")),
            ));
        }
        requirements.push(t);
    }
    Ok(())
}

/// Reads a `:types` section into `types`. A type listed without a parent (read as `thing`)
/// gets `object`, the root type PDDL gives it.
fn parse_types(
    doc: &str,
    conv: &Converter<'_>,
    body: &[SExpr<'_>],
    types: &mut Vec<(Symbol, Symbol)>,
) -> Result<(), ParseError> {
    for (n, t, at) in conv.typed_list(body, false)? {
        if types.iter().any(|(d, _)| *d == n) {
            return Err(duplicate(doc, at, "type", n));
        }
        types.push((
            n,
            if t.as_str() == "thing" {
                Symbol::new("object")
            } else {
                t
            },
        ));
    }
    Ok(())
}

/// Reads a `:predicates` section's declarations into `predicates`.
fn parse_predicates(
    doc: &str,
    conv: &Converter<'_>,
    body: &[SExpr<'_>],
    predicates: &mut Vec<PredicateDecl>,
) -> Result<(), ParseError> {
    for p in body {
        let Some((head, params)) = p.list().and_then(|l| l.split_first()) else {
            return Err(err(
                doc,
                p.span.start,
                ParseErrorKind::Syntax,
                "a predicate declaration `(name ?x ...)`",
            ));
        };
        let name = conv.expect_name(head, "a predicate name")?;
        if predicates.iter().any(|d| d.name == name) {
            return Err(duplicate(doc, head.span.start, "predicate", name));
        }
        let params = conv
            .typed_list(params, true)?
            .into_iter()
            .map(|(name, ty, _)| TypedVar { name, ty })
            .collect();
        predicates.push(PredicateDecl { name, params });
    }
    Ok(())
}

/// A name declared a second time: PDDL has no overloading, and a silent redefinition would
/// verify plans against whichever came last.
fn duplicate(doc: &str, at: usize, what: &str, name: Symbol) -> ParseError {
    err(
        doc,
        at,
        ParseErrorKind::Reference,
        format!("a {what} not declared before (`{name}` is declared twice)"),
    )
}

fn parse_action(
    doc: &str,
    conv: &Converter<'_>,
    s: &SExpr<'_>,
    universe: &Universe,
) -> Result<Operator, ParseError> {
    let items = s.list().unwrap_or(&[]);
    let Some(name_expr) = items.get(1) else {
        return Err(err(
            doc,
            s.span.end.saturating_sub(1),
            ParseErrorKind::Syntax,
            "an action name",
        ));
    };
    let name = conv.expect_name(name_expr, "an action name")?;
    let mut params = Vec::new();
    let mut pre = Vec::new();
    let mut eff = Vec::new();
    let mut seen_effect = false;
    let mut i = 2;
    while i < items.len() {
        let key = items[i].token().map(|t| t.to_ascii_lowercase());
        let Some(value) = items.get(i + 1) else {
            return Err(err(
                doc,
                items[i].span.end,
                ParseErrorKind::Syntax,
                "a value after the keyword",
            ));
        };
        match key.as_deref() {
            Some(":parameters") => {
                let list = value
                    .list()
                    .ok_or_else(|| err(doc, value.span.start, ParseErrorKind::Syntax, "a parameter list"))?;
                for (n, t, at) in conv.typed_list(list, true)? {
                    if !universe.types.contains(t) {
                        return Err(err(
                            doc,
                            at,
                            ParseErrorKind::Reference,
                            format!("a declared type (`{t}` is not)"),
                        ));
                    }
                    params.push(TypedVar { name: n, ty: t });
                }
            }
            Some(":precondition") => {
                let mut scope: Vec<Symbol> = params.iter().map(|p: &TypedVar| p.name).collect();
                let empty = value.list().is_some_and(|l| l.is_empty());
                if !empty {
                    pre = conv.formula(value, &mut scope)?.conjuncts();
                }
            }
            Some(":effect") => {
                let mut scope: Vec<Symbol> = params.iter().map(|p| p.name).collect();
                let empty = value.list().is_some_and(|l| l.is_empty());
                if !empty {
                    eff = conv.effects(value, &mut scope)?;
                }
                seen_effect = true;
            }
            _ => {
                return Err(err(
                    doc,
                    items[i].span.start,
                    ParseErrorKind::Syntax,
                    "`:parameters`, `:precondition` or `:effect`",
                ));
            }
        }
        i += 2;
    }
    if !seen_effect {
        return Err(err(
            doc,
            s.span.end.saturating_sub(1),
            ParseErrorKind::MissingSection,
            "an `:effect`",
        ));
    }
    Ok(Operator {
        name: name.to_string(),
        params,
        args: vec![],
        pre: pre.into(),
        eff: eff.into(),
    })
}

/// Parses a PDDL problem. Atoms and the goal are checked against the domain's predicates.
pub fn parse_problem(doc: &str, domain: &Domain) -> Result<Problem, ParseError> {
    let (name, sections) = define(doc, "problem")?;
    let conv = Converter::new(doc, true).with_predicates(predicate_arities(&domain.predicates));
    let mut dom_name = None;
    let mut objects = Vec::new();
    let mut init = Vec::new();
    let mut goal = None;
    for s in &sections {
        let kw = section_name(doc, s)?;
        let body = &s.list().unwrap_or(&[])[1..];
        match kw.as_str() {
            ":domain" => dom_name = Some(parse_domain_ref(doc, &conv, s, body, domain)?),
            ":requirements" => {}
            ":objects" => parse_objects(doc, &conv, body, domain, &mut objects)?,
            ":init" => parse_init(doc, &conv, body, &mut init)?,
            ":goal" => match body {
                [g] => goal = Some(conv.formula(g, &mut Vec::new())?),
                _ => {
                    return Err(err(
                        doc,
                        s.span.start,
                        ParseErrorKind::Syntax,
                        "`(:goal FORMULA)`",
                    ));
                }
            },
            _ => {
                return Err(err(
                    doc,
                    s.span.start + 1,
                    ParseErrorKind::Unsupported,
                    "a supported section (:domain, :objects, :init, :goal)",
                ));
            }
        }
    }
    let Some(domain_name) = dom_name else {
        return Err(err(
            doc,
            0,
            ParseErrorKind::MissingSection,
            "a `(:domain NAME)` section",
        ));
    };
    let Some(goal) = goal else {
        return Err(err(
            doc,
            doc.len(),
            ParseErrorKind::MissingSection,
            "a `(:goal ...)` section",
        ));
    };
    let problem = Problem {
        name,
        domain: domain_name,
        objects,
        init: State::from_atoms(init),
        goal,
    };
    check_mentioned_objects(doc, domain, &problem)?;
    Ok(problem)
}

/// The name in a `(:domain NAME)` section `s`, which must be `domain`'s.
fn parse_domain_ref(
    doc: &str,
    conv: &Converter<'_>,
    s: &SExpr<'_>,
    body: &[SExpr<'_>],
    domain: &Domain,
) -> Result<Symbol, ParseError> {
    match body {
        [n] => {
            let n = conv.expect_name(n, "the domain name")?;
            if n != domain.name {
                return Err(err(
                    doc,
                    body[0].span.start,
                    ParseErrorKind::Reference,
                    format!("the domain `{}` (the problem names `{n}`)", domain.name),
                ));
            }
            Ok(n)
        }
        _ => Err(err(doc, s.span.start, ParseErrorKind::Syntax, "`(:domain NAME)`")),
    }
}

/// Reads an `:objects` section into `objects`; every type must be `object`, `thing` or one
/// the domain declares.
fn parse_objects(
    doc: &str,
    conv: &Converter<'_>,
    body: &[SExpr<'_>],
    domain: &Domain,
    objects: &mut Vec<(Symbol, Symbol)>,
) -> Result<(), ParseError> {
    for (n, t, at) in conv.typed_list(body, false)? {
        let known =
            t.as_str() == "thing" || t.as_str() == "object" || domain.types.iter().any(|(d, _)| *d == t);
        if !known {
            return Err(err(
                doc,
                at,
                ParseErrorKind::Reference,
                format!("a declared type (`{t}` is not)"),
            ));
        }
        if objects.iter().any(|(o, _)| *o == n) {
            return Err(duplicate(doc, at, "object", n));
        }
        objects.push((n, t));
    }
    Ok(())
}

/// Reads an `:init` section's ground atoms into `init`.
fn parse_init(
    doc: &str,
    conv: &Converter<'_>,
    body: &[SExpr<'_>],
    init: &mut Vec<Atom>,
) -> Result<(), ParseError> {
    for a in body {
        let f = conv.formula(a, &mut Vec::new())?;
        match &f {
            Formula::Atom(p) => init.push(
                p.as_atom()
                    .ok_or_else(|| err(doc, a.span.start, ParseErrorKind::Syntax, "a ground atom"))?,
            ),
            _ => {
                return Err(err(
                    doc,
                    a.span.start,
                    ParseErrorKind::Unsupported,
                    "a ground atom (the initial state lists true atoms only)",
                ));
            }
        }
    }
    Ok(())
}

/// Every constant in init and goal must be an object or a domain constant.
fn check_mentioned_objects(doc: &str, domain: &Domain, problem: &Problem) -> Result<(), ParseError> {
    let universe = domain
        .universe(problem)
        .map_err(|e| err(doc, 0, ParseErrorKind::Reference, e.to_string()))?;
    let mut mentioned = problem.init.objects();
    problem.goal.constants(&mut mentioned);
    if let Some(unknown) = mentioned.iter().find(|o| !universe.contains(**o)) {
        let at = find_token(doc, unknown.as_str()).unwrap_or(0);
        return Err(err(
            doc,
            at,
            ParseErrorKind::Reference,
            format!("a declared object (`{unknown}` is not in :objects)"),
        ));
    }
    Ok(())
}

/// Byte offset of the first whole-token occurrence of `name` (case-insensitive), for
/// pointing at references found after parsing.
fn find_token(doc: &str, name: &str) -> Option<usize> {
    let lower = doc.to_ascii_lowercase();
    let mut from = 0;
    while let Some(i) = lower[from..].find(name) {
        let at = from + i;
        let before = lower[..at].chars().next_back();
        let after = lower[at + name.len()..].chars().next();
        let boundary = |c: Option<char>| c.is_none_or(|c| !crate::atom::is_name_char(c) && c != '?');
        if boundary(before) && boundary(after) {
            return Some(at);
        }
        from = at + name.len().max(1);
    }
    None
}

impl Domain {
    /// The typed universe of a problem: the domain's types, its constants and the problem's
    /// objects.
    pub fn universe(&self, problem: &Problem) -> Result<Universe, TypeError> {
        let mut u = Universe::new();
        for (t, parent) in &self.types {
            u.types.declare(*t, *parent)?;
        }
        for (o, t) in self.constants.iter().chain(&problem.objects) {
            u.add(*o, *t)?;
        }
        Ok(u)
    }

    /// The action schema with this name.
    pub fn action(&self, name: Symbol) -> Option<&Operator> {
        self.actions.iter().find(|a| a.name == name.as_str())
    }
}

/// Parses a plan: one `(action arg...)` per line, `;` comments, optional `N:` prefixes
/// and `[duration]` suffixes.
pub fn parse_plan(doc: &str) -> Result<Vec<PlanStep>, ParseError> {
    let mut steps = Vec::new();
    let mut offset = 0;
    for (line_index, raw) in doc.split('\n').enumerate() {
        let line_start = offset;
        offset += raw.len() + 1;
        let code = raw.split(';').next().unwrap_or("").trim_end_matches('\r');
        let trimmed = code.trim();
        if trimmed.is_empty() {
            continue;
        }
        let mut start = line_start + (code.len() - code.trim_start().len());
        let mut end = line_start + code.trim_end().len();
        // Optional `12:` or `0.001:` time stamp.
        if let Some(colon) = trimmed.find(':') {
            let stamp = &trimmed[..colon];
            if !stamp.is_empty() && stamp.chars().all(|c| c.is_ascii_digit() || c == '.') {
                start += colon + 1;
            }
        }
        // Optional `[duration]` suffix.
        if code.trim_end().ends_with(']')
            && let Some(open) = code.rfind('[')
        {
            end = line_start + open;
        }
        let e = parse_single(doc, start, end)?;
        let items = match e.list() {
            Some(items) if !items.is_empty() => items,
            _ => {
                return Err(err(
                    doc,
                    e.span.start,
                    ParseErrorKind::Syntax,
                    "a plan step `(action arg...)`",
                ));
            }
        };
        let conv = Converter::new(doc, true);
        let action = conv.expect_name(&items[0], "an action name")?;
        let args = items[1..]
            .iter()
            .map(|a| conv.expect_name(a, "an object name"))
            .collect::<Result<_, _>>()?;
        // From this line, not from the document's start: counting from the start for every
        // step made long plans quadratic.
        let line = line_index + 1;
        let column = doc[line_start..e.span.start].chars().count() + 1;
        steps.push(PlanStep {
            action,
            args,
            line,
            column,
        });
    }
    Ok(steps)
}

/// Prints a plan, one step per line.
pub fn format_plan(steps: &[PlanStep]) -> String {
    steps.iter().map(|s| format!("{s}\n")).collect()
}

/// Binds every plan step to its action schema. Unknown actions, wrong argument counts and
/// objects of the wrong type are [`ParseErrorKind::Reference`] errors at the step's
/// position in `plan_text`.
pub fn ground_plan(
    domain: &Domain,
    universe: &Universe,
    steps: &[PlanStep],
    plan_text: &str,
) -> Result<Vec<Operator>, ParseError> {
    let at = |s: &PlanStep| {
        let mut offset = 0;
        for (i, l) in plan_text.split('\n').enumerate() {
            if i + 1 == s.line {
                return offset + l.char_indices().nth(s.column - 1).map_or(0, |(b, _)| b);
            }
            offset += l.len() + 1;
        }
        plan_text.len()
    };
    steps
        .iter()
        .map(|s| {
            let Some(schema) = domain.action(s.action) else {
                return Err(err(
                    plan_text,
                    at(s),
                    ParseErrorKind::Reference,
                    format!(
                        "an action of domain `{}` (`{}` is not one)",
                        domain.name, s.action
                    ),
                ));
            };
            schema
                .instantiate(&s.args, universe)
                .map_err(|e| err(plan_text, at(s), ParseErrorKind::Reference, e.to_string()))
        })
        .collect()
}

fn fmt_objects(list: &[(Symbol, Symbol)]) -> String {
    let vars: Vec<TypedVar> = list.iter().map(|(n, t)| TypedVar { name: *n, ty: *t }).collect();
    fmt_typed_vars(&vars).replace('?', "")
}

impl fmt::Display for Domain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "(define (domain {})", self.name)?;
        if !self.requirements.is_empty() {
            writeln!(f, "  (:requirements {})", self.requirements.join(" "))?;
        }
        if !self.types.is_empty() {
            writeln!(f, "  (:types {})", fmt_objects(&self.types))?;
        }
        if !self.constants.is_empty() {
            writeln!(f, "  (:constants {})", fmt_objects(&self.constants))?;
        }
        f.write_str("  (:predicates")?;
        for p in &self.predicates {
            if p.params.is_empty() {
                write!(f, " ({})", p.name)?;
            } else {
                write!(f, " ({} {})", p.name, fmt_typed_vars(&p.params))?;
            }
        }
        f.write_str(")\n")?;
        for a in &self.actions {
            writeln!(f, "  (:action {}", a.name)?;
            writeln!(f, "    :parameters ({})", fmt_typed_vars(&a.params))?;
            writeln!(f, "    :precondition {}", Formula::And(a.pre.to_vec()))?;
            f.write_str("    :effect (and")?;
            for e in a.eff.iter() {
                write!(f, " {e}")?;
            }
            f.write_str("))\n")?;
        }
        f.write_str(")\n")
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "(define (problem {})", self.name)?;
        writeln!(f, "  (:domain {})", self.domain)?;
        writeln!(f, "  (:objects {})", fmt_objects(&self.objects))?;
        f.write_str("  (:init")?;
        for a in self.init.sorted_by_text() {
            write!(f, " {a}")?;
        }
        f.write_str(")\n")?;
        writeln!(f, "  (:goal {})", self.goal)?;
        f.write_str(")\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exec::verify_procedure_in;

    const DOMAIN: &str = "; blocks\n(define (domain BW)\n (:requirements :strips :typing :negative-preconditions)\n (:types block - object)\n (:predicates (on ?x - block ?y - block) (ontable ?x - block) (clear ?x - block) (holding ?x - block) (handempty))\n (:action pick-up :parameters (?x - block)\n  :precondition (and (clear ?x) (ontable ?x) (handempty))\n  :effect (and (not (ontable ?x)) (not (clear ?x)) (not (handempty)) (holding ?x)))\n (:action stack :parameters (?x ?y - block)\n  :precondition (and (holding ?x) (clear ?y) (not (= ?x ?y)))\n  :effect (and (not (holding ?x)) (not (clear ?y)) (clear ?x) (handempty) (on ?x ?y))))";
    const PROBLEM: &str = "(define (problem p1) (:domain bw) (:objects a b - block)\n (:init (clear a) (clear b) (ontable a) (ontable b) (handempty))\n (:goal (and (on a b))))";

    #[test]
    fn parse_print_and_verify() {
        let d = parse_domain(DOMAIN).unwrap();
        assert_eq!(d.actions.len(), 2);
        assert_eq!(parse_domain(&d.to_string()).unwrap(), d);
        let p = parse_problem(PROBLEM, &d).unwrap();
        assert_eq!(parse_problem(&p.to_string(), &d).unwrap(), p);
        let plan_text = "; plan\n0: (pick-up a) [1]\n(STACK a b)\n";
        let steps = parse_plan(plan_text).unwrap();
        assert_eq!(steps[1].line, 3);
        let u = d.universe(&p).unwrap();
        let ops = ground_plan(&d, &u, &steps, plan_text).unwrap();
        let report = verify_procedure_in(&u, &p.init, &ops, Some(&p.goal));
        assert!(report.is_valid(), "{report:?}");
        let bad = ground_plan(&d, &u, &parse_plan("(stack a)").unwrap(), "(stack a)").unwrap_err();
        assert_eq!(bad.kind, ParseErrorKind::Reference);
    }

    #[test]
    fn a_huge_token_is_not_echoed_in_full() {
        let d = parse_domain(DOMAIN).unwrap();
        let p = parse_problem(PROBLEM, &d).unwrap();
        let u = d.universe(&p).unwrap();
        let plan = format!("({} a)\n", "x".repeat(1_000_000));
        let steps = parse_plan(&plan).unwrap();
        let e = ground_plan(&d, &u, &steps, &plan).unwrap_err();
        assert!(e.to_string().len() < 1_000, "{} bytes", e.to_string().len());
    }

    #[test]
    fn names_declared_twice_are_refused() {
        let twice = |from: &str, to: &str| {
            let text = DOMAIN.replacen(from, to, 1);
            assert_ne!(text, DOMAIN, "{from}");
            parse_domain(&text).unwrap_err()
        };
        let e = twice("(handempty))", "(handempty) (clear ?z - block))");
        assert!(e.to_string().contains("`clear` is declared twice"), "{e}");
        let e = twice(
            "(:types block - object)",
            "(:types block - object block - object)",
        );
        assert!(e.to_string().contains("type"), "{e}");
        let e = twice(
            " (:action stack",
            " (:action pick-up :parameters (?x - block) :precondition (clear ?x) :effect (holding ?x))\n (:action stack",
        );
        assert!(e.to_string().contains("`pick-up` is declared twice"), "{e}");
        let d = parse_domain(DOMAIN).unwrap();
        let e = parse_problem(&PROBLEM.replace("a b - block", "a b a - block"), &d).unwrap_err();
        assert!(e.to_string().contains("`a` is declared twice"), "{e}");
    }

    #[test]
    fn long_plans_parse_in_linear_time_with_their_positions() {
        let lines = 100_000;
        let plan_text: String = (0..lines).map(|i| format!("{i}:  (pick-up b{i})\n")).collect();
        let started = std::time::Instant::now();
        let steps = parse_plan(&plan_text).unwrap();
        assert_eq!(steps.len(), lines);
        let last = steps.last().unwrap();
        assert_eq!((last.line, last.column), (lines, "99999:  ".len() + 1));
        // Quadratic position counting took minutes here.
        assert!(
            started.elapsed() < std::time::Duration::from_secs(20),
            "{:?}",
            started.elapsed()
        );
    }

    #[test]
    fn rejects_with_positions() {
        let err = parse_domain("(define (domain d) (:requirements :fluents))").unwrap_err();
        assert_eq!((err.kind, err.column), (ParseErrorKind::Unsupported, 35));
        let err = parse_domain(&DOMAIN.replace("(holding ?x))", "(holds ?x))")).unwrap_err();
        assert_eq!(err.kind, ParseErrorKind::Reference);
        let d = parse_domain(DOMAIN).unwrap();
        let err = parse_problem(&PROBLEM.replace("(clear b)", "(clear c)"), &d).unwrap_err();
        assert_eq!((err.kind, err.line), (ParseErrorKind::Reference, 2));
    }
}
