//! Lifted formulas and effects, and their grounding over a typed universe.
//!
//! Formulas are PDDL-style: atoms, `=`, `not`, `and`, `or`, `imply`, `forall` and `exists`
//! over typed variables. Effects add and delete atoms, possibly under `forall` and `when`.
//!
//! Grounding is structural: a variable is a [`Term::Var`] node resolved through a binding
//! environment while walking the parsed tree, so `?x` can never capture `?xy` and no text is
//! ever rewritten. Quantifiers expand over [`Universe::objects_of`] their type, and a type
//! the universe does not know is a [`GroundError`], not an empty (vacuously true) range.

use std::fmt;

use serde::{Deserialize, Serialize};
use smallvec::SmallVec;

use crate::atom::Atom;
use crate::state::State;
use crate::symbol::Symbol;
use crate::types::{TypeError, Universe};

/// An argument of an atom pattern: a variable (`?x`, stored without the `?`) or a constant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Term {
    /// A variable bound by a quantifier or an action parameter.
    Var(Symbol),
    /// An object constant.
    Const(Symbol),
}

impl fmt::Display for Term {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Term::Var(v) => write!(f, "?{v}"),
            Term::Const(c) => write!(f, "{c}"),
        }
    }
}

/// A predicate applied to terms, e.g. `(OnTopOf ?x floor)`.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct AtomPattern {
    /// The predicate.
    pub pred: Symbol,
    /// The arguments.
    pub args: SmallVec<[Term; 3]>,
}

impl AtomPattern {
    /// A pattern with only constant arguments.
    pub fn ground(atom: Atom) -> Self {
        AtomPattern {
            pred: atom.pred(),
            args: atom.args().iter().map(|a| Term::Const(*a)).collect(),
        }
    }

    /// The ground atom, if no argument is a variable.
    pub fn as_atom(&self) -> Option<Atom> {
        let mut args: SmallVec<[Symbol; 3]> = SmallVec::new();
        for t in &self.args {
            match t {
                Term::Const(c) => args.push(*c),
                Term::Var(_) => return None,
            }
        }
        Some(Atom::from_symbols(self.pred, args))
    }

    fn resolve(&self, env: &Bindings) -> Result<Atom, GroundError> {
        let mut args: SmallVec<[Symbol; 3]> = SmallVec::with_capacity(self.args.len());
        for t in &self.args {
            args.push(env.resolve(*t)?);
        }
        Ok(Atom::from_slice(self.pred, &args))
    }
}

impl fmt::Display for AtomPattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}", self.pred)?;
        for a in &self.args {
            write!(f, " {a}")?;
        }
        f.write_str(")")
    }
}

/// A typed variable of a quantifier or parameter list: `?y - thing`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TypedVar {
    /// The variable's name without `?`.
    pub name: Symbol,
    /// Its type.
    pub ty: Symbol,
}

/// Prints a typed variable list the way PDDL writes it: `?a ?b - block ?c - thing`.
pub fn fmt_typed_vars(vars: &[TypedVar]) -> String {
    let mut out = String::new();
    let mut i = 0;
    while i < vars.len() {
        let ty = vars[i].ty;
        let mut j = i;
        while j < vars.len() && vars[j].ty == ty {
            if !out.is_empty() {
                out.push(' ');
            }
            out.push('?');
            out.push_str(vars[j].name.as_str());
            j += 1;
        }
        out.push_str(" - ");
        out.push_str(ty.as_str());
        i = j;
    }
    out
}

/// A first-order formula over atoms.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Formula {
    /// An atom.
    Atom(AtomPattern),
    /// Equality of two terms (`(= ?x ?y)`).
    Eq(Term, Term),
    /// Negation.
    Not(Box<Formula>),
    /// Conjunction; `(and)` is true.
    And(Vec<Formula>),
    /// Disjunction; `(or)` is false.
    Or(Vec<Formula>),
    /// Implication.
    Imply(Box<Formula>, Box<Formula>),
    /// Universal quantification over typed variables.
    Forall(Vec<TypedVar>, Box<Formula>),
    /// Existential quantification over typed variables.
    Exists(Vec<TypedVar>, Box<Formula>),
}

impl Formula {
    /// The atom `(pred args...)` with constant arguments.
    pub fn atom(atom: Atom) -> Self {
        Formula::Atom(AtomPattern::ground(atom))
    }

    /// `(not f)`.
    pub fn negate(f: Formula) -> Self {
        Formula::Not(Box::new(f))
    }

    /// The top-level conjuncts: `(and a b)` gives `[a, b]`, anything else itself.
    pub fn conjuncts(&self) -> Vec<Formula> {
        match self {
            Formula::And(parts) => parts.iter().flat_map(|p| p.conjuncts()).collect(),
            other => vec![other.clone()],
        }
    }

    /// Every atom pattern the formula mentions, in order (repeats included).
    pub fn patterns<'a>(&'a self, out: &mut Vec<&'a AtomPattern>) {
        match self {
            Formula::Atom(p) => out.push(p),
            Formula::Eq(..) => {}
            Formula::Not(f) | Formula::Forall(_, f) | Formula::Exists(_, f) => f.patterns(out),
            Formula::And(fs) | Formula::Or(fs) => fs.iter().for_each(|f| f.patterns(out)),
            Formula::Imply(a, b) => {
                a.patterns(out);
                b.patterns(out)
            }
        }
    }

    /// Every object constant the formula mentions.
    pub fn constants(&self, out: &mut Vec<Symbol>) {
        match self {
            Formula::Atom(p) => terms_constants(&p.args, out),
            Formula::Eq(a, b) => terms_constants(&[*a, *b], out),
            Formula::Not(f) => f.constants(out),
            Formula::And(fs) | Formula::Or(fs) => fs.iter().for_each(|f| f.constants(out)),
            Formula::Imply(a, b) => {
                a.constants(out);
                b.constants(out)
            }
            Formula::Forall(_, f) | Formula::Exists(_, f) => f.constants(out),
        }
    }

    /// True if no `forall` or `exists` occurs in the formula: its grounding then does not
    /// depend on the universe.
    pub fn is_quantifier_free(&self) -> bool {
        match self {
            Formula::Atom(_) | Formula::Eq(..) => true,
            Formula::Not(f) => f.is_quantifier_free(),
            Formula::And(fs) | Formula::Or(fs) => fs.iter().all(Formula::is_quantifier_free),
            Formula::Imply(a, b) => a.is_quantifier_free() && b.is_quantifier_free(),
            Formula::Forall(..) | Formula::Exists(..) => false,
        }
    }

    /// Grounds the formula over a universe with the given variable bindings.
    pub fn ground(&self, universe: &Universe, env: &mut Bindings) -> Result<Ground, GroundError> {
        Ok(match self {
            Formula::Atom(p) => Ground::Atom(p.resolve(env)?),
            Formula::Eq(a, b) => Ground::constant(env.resolve(*a)? == env.resolve(*b)?),
            Formula::Not(f) => Ground::not(f.ground(universe, env)?),
            Formula::And(fs) => Ground::and(
                fs.iter()
                    .map(|f| f.ground(universe, env))
                    .collect::<Result<_, _>>()?,
            ),
            Formula::Or(fs) => Ground::or(
                fs.iter()
                    .map(|f| f.ground(universe, env))
                    .collect::<Result<_, _>>()?,
            ),
            Formula::Imply(a, b) => Ground::or(vec![
                Ground::not(a.ground(universe, env)?),
                b.ground(universe, env)?,
            ]),
            Formula::Forall(vars, body) => {
                let mut parts = Vec::new();
                for_each_binding(vars, universe, env, &mut |env| {
                    parts.push(body.ground(universe, env)?);
                    Ok(())
                })?;
                Ground::and(parts)
            }
            Formula::Exists(vars, body) => {
                let mut parts = Vec::new();
                for_each_binding(vars, universe, env, &mut |env| {
                    parts.push(body.ground(universe, env)?);
                    Ok(())
                })?;
                Ground::or(parts)
            }
        })
    }

    /// Substitutes constants for free variables, structurally (quantified variables shadow).
    pub fn substitute(&self, bindings: &[(Symbol, Symbol)]) -> Formula {
        let sub_term = |t: &Term| match t {
            Term::Var(v) => bindings
                .iter()
                .rev()
                .find(|(n, _)| n == v)
                .map_or(*t, |(_, c)| Term::Const(*c)),
            Term::Const(_) => *t,
        };
        match self {
            Formula::Atom(p) => Formula::Atom(AtomPattern {
                pred: p.pred,
                args: p.args.iter().map(sub_term).collect(),
            }),
            Formula::Eq(a, b) => Formula::Eq(sub_term(a), sub_term(b)),
            Formula::Not(f) => Formula::Not(Box::new(f.substitute(bindings))),
            Formula::And(fs) => Formula::And(fs.iter().map(|f| f.substitute(bindings)).collect()),
            Formula::Or(fs) => Formula::Or(fs.iter().map(|f| f.substitute(bindings)).collect()),
            Formula::Imply(a, b) => {
                Formula::Imply(Box::new(a.substitute(bindings)), Box::new(b.substitute(bindings)))
            }
            Formula::Forall(vars, body) | Formula::Exists(vars, body) => {
                let inner: Vec<(Symbol, Symbol)> = bindings
                    .iter()
                    .filter(|(n, _)| !vars.iter().any(|v| v.name == *n))
                    .copied()
                    .collect();
                let body = Box::new(body.substitute(&inner));
                if matches!(self, Formula::Forall(..)) {
                    Formula::Forall(vars.clone(), body)
                } else {
                    Formula::Exists(vars.clone(), body)
                }
            }
        }
    }
}

impl AtomPattern {
    /// The pattern with every constant argument passed through `rename` (variables stay).
    pub fn rename_constants(&self, rename: &impl Fn(Symbol) -> Symbol) -> AtomPattern {
        AtomPattern {
            pred: self.pred,
            args: self
                .args
                .iter()
                .map(|t| match t {
                    Term::Const(c) => Term::Const(rename(*c)),
                    Term::Var(_) => *t,
                })
                .collect(),
        }
    }
}

impl Formula {
    /// The formula with every object constant passed through `rename`: how one asset's
    /// schemas are made from another's whose parts are named differently.
    pub fn rename_constants(&self, rename: &impl Fn(Symbol) -> Symbol) -> Formula {
        let term = |t: &Term| match t {
            Term::Const(c) => Term::Const(rename(*c)),
            Term::Var(_) => *t,
        };
        match self {
            Formula::Atom(p) => Formula::Atom(p.rename_constants(rename)),
            Formula::Eq(a, b) => Formula::Eq(term(a), term(b)),
            Formula::Not(f) => Formula::Not(Box::new(f.rename_constants(rename))),
            Formula::And(fs) => Formula::And(fs.iter().map(|f| f.rename_constants(rename)).collect()),
            Formula::Or(fs) => Formula::Or(fs.iter().map(|f| f.rename_constants(rename)).collect()),
            Formula::Imply(a, b) => Formula::Imply(
                Box::new(a.rename_constants(rename)),
                Box::new(b.rename_constants(rename)),
            ),
            Formula::Forall(vars, body) => {
                Formula::Forall(vars.clone(), Box::new(body.rename_constants(rename)))
            }
            Formula::Exists(vars, body) => {
                Formula::Exists(vars.clone(), Box::new(body.rename_constants(rename)))
            }
        }
    }
}

fn terms_constants(terms: &[Term], out: &mut Vec<Symbol>) {
    for t in terms {
        if let Term::Const(c) = t
            && !out.contains(c)
        {
            out.push(*c);
        }
    }
}

impl fmt::Display for Formula {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fn list(f: &mut fmt::Formatter<'_>, head: &str, parts: &[Formula]) -> fmt::Result {
            write!(f, "({head}")?;
            for p in parts {
                write!(f, " {p}")?;
            }
            f.write_str(")")
        }
        match self {
            Formula::Atom(p) => write!(f, "{p}"),
            Formula::Eq(a, b) => write!(f, "(= {a} {b})"),
            Formula::Not(x) => write!(f, "(not {x})"),
            Formula::And(parts) => list(f, "and", parts),
            Formula::Or(parts) => list(f, "or", parts),
            Formula::Imply(a, b) => write!(f, "(imply {a} {b})"),
            Formula::Forall(vars, body) => write!(f, "(forall ({}) {body})", fmt_typed_vars(vars)),
            Formula::Exists(vars, body) => write!(f, "(exists ({}) {body})", fmt_typed_vars(vars)),
        }
    }
}

impl Serialize for Formula {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Formula {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = <std::borrow::Cow<'de, str>>::deserialize(deserializer)?;
        crate::text::parse_formula(&text).map_err(serde::de::Error::custom)
    }
}

/// An effect: what an action makes true or false.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Effect {
    /// Makes an atom true.
    Add(AtomPattern),
    /// Makes an atom false (`(not (P ...))`).
    Del(AtomPattern),
    /// The inner effects for every binding of the variables.
    Forall(Vec<TypedVar>, Vec<Effect>),
    /// The inner effects if the condition holds in the state before the action.
    When(Formula, Vec<Effect>),
}

impl Effect {
    /// Every atom pattern the effect (and any `when` condition) mentions, in order.
    pub fn patterns<'a>(&'a self, out: &mut Vec<&'a AtomPattern>) {
        match self {
            Effect::Add(p) | Effect::Del(p) => out.push(p),
            Effect::Forall(_, es) => es.iter().for_each(|e| e.patterns(out)),
            Effect::When(c, es) => {
                c.patterns(out);
                es.iter().for_each(|e| e.patterns(out));
            }
        }
    }

    /// Every object constant the effect mentions.
    pub fn constants(&self, out: &mut Vec<Symbol>) {
        match self {
            Effect::Add(p) | Effect::Del(p) => terms_constants(&p.args, out),
            Effect::Forall(_, es) => es.iter().for_each(|e| e.constants(out)),
            Effect::When(c, es) => {
                c.constants(out);
                es.iter().for_each(|e| e.constants(out));
            }
        }
    }

    /// True if no `forall` occurs in the effect or its `when` conditions: its grounding then
    /// does not depend on the universe.
    pub fn is_quantifier_free(&self) -> bool {
        match self {
            Effect::Add(_) | Effect::Del(_) => true,
            Effect::Forall(..) => false,
            Effect::When(cond, effects) => {
                cond.is_quantifier_free() && effects.iter().all(Effect::is_quantifier_free)
            }
        }
    }

    /// Grounds the effect into `out`, expanding `forall` and resolving `when` conditions.
    pub fn ground(
        &self,
        universe: &Universe,
        env: &mut Bindings,
        condition: Option<&Ground>,
        out: &mut GroundEffects,
    ) -> Result<(), GroundError> {
        match self {
            Effect::Add(p) | Effect::Del(p) => {
                let atom = p.resolve(env)?;
                let add = matches!(self, Effect::Add(_));
                match condition {
                    None if add => out.adds.push(atom),
                    None => out.dels.push(atom),
                    Some(c) => out.conditional.push(ConditionalEffect {
                        condition: c.clone(),
                        atom,
                        add,
                    }),
                }
            }
            Effect::Forall(vars, effects) => {
                for_each_binding(vars, universe, env, &mut |env| {
                    for e in effects {
                        e.ground(universe, env, condition, out)?;
                    }
                    Ok(())
                })?;
            }
            Effect::When(cond, effects) => {
                let c = cond.ground(universe, env)?;
                let c = match condition {
                    Some(outer) => Ground::and(vec![outer.clone(), c]),
                    None => c,
                };
                match c {
                    Ground::False => {}
                    Ground::True => {
                        for e in effects {
                            e.ground(universe, env, None, out)?;
                        }
                    }
                    c => {
                        for e in effects {
                            e.ground(universe, env, Some(&c), out)?;
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Substitutes constants for free variables, structurally.
    pub fn substitute(&self, bindings: &[(Symbol, Symbol)]) -> Effect {
        let sub_atom = |p: &AtomPattern| match Formula::Atom(p.clone()).substitute(bindings) {
            Formula::Atom(p) => p,
            _ => unreachable!("substituting an atom yields an atom"),
        };
        match self {
            Effect::Add(p) => Effect::Add(sub_atom(p)),
            Effect::Del(p) => Effect::Del(sub_atom(p)),
            Effect::Forall(vars, es) => {
                let inner: Vec<(Symbol, Symbol)> = bindings
                    .iter()
                    .filter(|(n, _)| !vars.iter().any(|v| v.name == *n))
                    .copied()
                    .collect();
                Effect::Forall(vars.clone(), es.iter().map(|e| e.substitute(&inner)).collect())
            }
            Effect::When(c, es) => Effect::When(
                c.substitute(bindings),
                es.iter().map(|e| e.substitute(bindings)).collect(),
            ),
        }
    }
}

impl Effect {
    /// The effect with every object constant passed through `rename`
    /// ([`Formula::rename_constants`]).
    pub fn rename_constants(&self, rename: &impl Fn(Symbol) -> Symbol) -> Effect {
        match self {
            Effect::Add(p) => Effect::Add(p.rename_constants(rename)),
            Effect::Del(p) => Effect::Del(p.rename_constants(rename)),
            Effect::Forall(vars, es) => Effect::Forall(
                vars.clone(),
                es.iter().map(|e| e.rename_constants(rename)).collect(),
            ),
            Effect::When(c, es) => Effect::When(
                c.rename_constants(rename),
                es.iter().map(|e| e.rename_constants(rename)).collect(),
            ),
        }
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fn body(f: &mut fmt::Formatter<'_>, es: &[Effect]) -> fmt::Result {
            if es.len() == 1 {
                write!(f, "{}", es[0])
            } else {
                f.write_str("(and")?;
                for e in es {
                    write!(f, " {e}")?;
                }
                f.write_str(")")
            }
        }
        match self {
            Effect::Add(p) => write!(f, "{p}"),
            Effect::Del(p) => write!(f, "(not {p})"),
            Effect::Forall(vars, es) => {
                write!(f, "(forall ({}) ", fmt_typed_vars(vars))?;
                body(f, es)?;
                f.write_str(")")
            }
            Effect::When(c, es) => {
                write!(f, "(when {c} ")?;
                body(f, es)?;
                f.write_str(")")
            }
        }
    }
}

impl Serialize for Effect {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Effect {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = <std::borrow::Cow<'de, str>>::deserialize(deserializer)?;
        crate::text::parse_effect(&text).map_err(serde::de::Error::custom)
    }
}

/// Variable bindings during grounding: a stack, innermost binding last, so inner
/// quantifiers shadow outer ones.
#[derive(Debug, Clone, Default)]
pub struct Bindings {
    stack: Vec<(Symbol, Symbol)>,
}

impl Bindings {
    /// No bindings.
    pub fn new() -> Self {
        Self::default()
    }

    /// Bindings for parameters.
    pub fn from_pairs(pairs: impl IntoIterator<Item = (Symbol, Symbol)>) -> Self {
        Bindings {
            stack: pairs.into_iter().collect(),
        }
    }

    /// The constant a term denotes.
    pub fn resolve(&self, term: Term) -> Result<Symbol, GroundError> {
        match term {
            Term::Const(c) => Ok(c),
            Term::Var(v) => self
                .stack
                .iter()
                .rev()
                .find(|(n, _)| *n == v)
                .map(|(_, c)| *c)
                .ok_or_else(|| GroundError::UnboundVariable {
                    name: format!("?{v}"),
                }),
        }
    }
}

fn for_each_binding(
    vars: &[TypedVar],
    universe: &Universe,
    env: &mut Bindings,
    visit: &mut dyn FnMut(&mut Bindings) -> Result<(), GroundError>,
) -> Result<(), GroundError> {
    let Some((first, rest)) = vars.split_first() else {
        return visit(env);
    };
    for object in universe.objects_of(first.ty)? {
        env.stack.push((first.name, object));
        let r = for_each_binding(rest, universe, env, visit);
        env.stack.pop();
        r?;
    }
    Ok(())
}

/// Why a formula or effect cannot be grounded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum GroundError {
    /// A quantifier or parameter ranges over a type the universe does not declare.
    #[error(transparent)]
    Type(#[from] TypeError),
    /// A variable is used outside any quantifier or parameter list that binds it.
    #[error("variable {name} is not bound by any quantifier or parameter")]
    UnboundVariable {
        /// The variable, with its `?`.
        name: String,
    },
    /// A lifted operator was applied without arguments, or with the wrong number.
    #[error("action `{action}` takes {expected} argument(s), got {found}")]
    WrongArgumentCount {
        /// The action.
        action: String,
        /// Its parameter count.
        expected: usize,
        /// The arguments given.
        found: usize,
    },
    /// An argument is not an object of the parameter's type.
    #[error("argument `{object}` of action `{action}` is not an object of type `{ty}`")]
    BadArgument {
        /// The action.
        action: String,
        /// The argument.
        object: String,
        /// The parameter's type.
        ty: String,
    },
}

/// A ground formula: quantifiers expanded, equality decided, atoms interned.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Ground {
    /// Always true.
    True,
    /// Always false.
    False,
    /// A ground atom.
    Atom(Atom),
    /// Negation.
    Not(Box<Ground>),
    /// Conjunction (non-empty, no constants inside).
    And(Vec<Ground>),
    /// Disjunction (non-empty, no constants inside).
    Or(Vec<Ground>),
}

impl Ground {
    fn constant(value: bool) -> Ground {
        if value { Ground::True } else { Ground::False }
    }

    fn not(g: Ground) -> Ground {
        match g {
            Ground::True => Ground::False,
            Ground::False => Ground::True,
            Ground::Not(inner) => *inner,
            g => Ground::Not(Box::new(g)),
        }
    }

    fn and(parts: Vec<Ground>) -> Ground {
        // The common case (a quantifier's instances, all atoms or negated atoms) is already
        // simplified: keep the vector instead of copying it.
        if parts.len() > 1
            && parts
                .iter()
                .all(|p| matches!(p, Ground::Atom(_) | Ground::Not(_) | Ground::Or(_)))
        {
            return Ground::And(parts);
        }
        let mut out = Vec::with_capacity(parts.len());
        for p in parts {
            match p {
                Ground::True => {}
                Ground::False => return Ground::False,
                Ground::And(inner) => out.extend(inner),
                p => out.push(p),
            }
        }
        match out.len() {
            0 => Ground::True,
            1 => out.pop().unwrap_or(Ground::True),
            _ => Ground::And(out),
        }
    }

    fn or(parts: Vec<Ground>) -> Ground {
        if parts.len() > 1
            && parts
                .iter()
                .all(|p| matches!(p, Ground::Atom(_) | Ground::Not(_) | Ground::And(_)))
        {
            return Ground::Or(parts);
        }
        let mut out = Vec::with_capacity(parts.len());
        for p in parts {
            match p {
                Ground::False => {}
                Ground::True => return Ground::True,
                Ground::Or(inner) => out.extend(inner),
                p => out.push(p),
            }
        }
        match out.len() {
            0 => Ground::False,
            1 => out.pop().unwrap_or(Ground::False),
            _ => Ground::Or(out),
        }
    }

    /// Truth in a state (closed world).
    pub fn holds(&self, state: &State) -> bool {
        match self {
            Ground::True => true,
            Ground::False => false,
            Ground::Atom(a) => state.contains(a),
            Ground::Not(g) => !g.holds(state),
            Ground::And(gs) => gs.iter().all(|g| g.holds(state)),
            Ground::Or(gs) => gs.iter().any(|g| g.holds(state)),
        }
    }

    /// Truth under an arbitrary atom oracle (used by the planner's bitset states).
    pub fn holds_with(&self, truth: &impl Fn(Atom) -> bool) -> bool {
        match self {
            Ground::True => true,
            Ground::False => false,
            Ground::Atom(a) => truth(*a),
            Ground::Not(g) => !g.holds_with(truth),
            Ground::And(gs) => gs.iter().all(|g| g.holds_with(truth)),
            Ground::Or(gs) => gs.iter().any(|g| g.holds_with(truth)),
        }
    }

    /// The atoms whose truth values decide this formula's value in `state`, with those
    /// values: for a false conjunction the atoms of its false parts, for a false
    /// disjunction the atoms of every part, and so on.
    pub fn explain(&self, state: &State, out: &mut Vec<AtomTruth>) {
        match self {
            Ground::True | Ground::False => {}
            Ground::Atom(a) => {
                let truth = AtomTruth {
                    atom: *a,
                    holds: state.contains(a),
                };
                if !out.contains(&truth) {
                    out.push(truth);
                }
            }
            Ground::Not(g) => g.explain(state, out),
            Ground::And(gs) => {
                if self.holds(state) {
                    gs.iter().for_each(|g| g.explain(state, out));
                } else {
                    gs.iter()
                        .filter(|g| !g.holds(state))
                        .for_each(|g| g.explain(state, out));
                }
            }
            Ground::Or(gs) => {
                if let Some(g) = gs.iter().find(|g| g.holds(state)) {
                    g.explain(state, out);
                } else {
                    gs.iter().for_each(|g| g.explain(state, out));
                }
            }
        }
    }

    /// Every atom in the formula.
    pub fn atoms(&self, out: &mut Vec<Atom>) {
        match self {
            Ground::True | Ground::False => {}
            Ground::Atom(a) => out.push(*a),
            Ground::Not(g) => g.atoms(out),
            Ground::And(gs) | Ground::Or(gs) => gs.iter().for_each(|g| g.atoms(out)),
        }
    }
}

/// A ground atom with its truth value in some state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct AtomTruth {
    /// The atom.
    pub atom: Atom,
    /// Whether it holds.
    pub holds: bool,
}

impl fmt::Display for AtomTruth {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} is {}",
            self.atom,
            if self.holds { "true" } else { "false" }
        )
    }
}

/// One conditional effect after grounding.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConditionalEffect {
    /// Evaluated in the state before the action.
    pub condition: Ground,
    /// The atom added or deleted.
    pub atom: Atom,
    /// True for an add, false for a delete.
    pub add: bool,
}

/// Ground effects: unconditional adds and deletes, then conditional ones.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct GroundEffects {
    /// Unconditional adds.
    pub adds: Vec<Atom>,
    /// Unconditional deletes.
    pub dels: Vec<Atom>,
    /// Conditional adds and deletes.
    pub conditional: Vec<ConditionalEffect>,
}

impl GroundEffects {
    /// Sorts and de-duplicates the unconditional lists (required by [`State::with_changes`]).
    pub fn normalize(&mut self) {
        self.adds.sort_unstable();
        self.adds.dedup();
        self.dels.sort_unstable();
        self.dels.dedup();
    }

    /// Applies the effects to `state` with PDDL semantics: conditions are evaluated in
    /// `state`, then every delete is applied before every add.
    pub fn apply(&self, state: &State) -> State {
        if self.conditional.is_empty() {
            return state.with_changes(&self.dels, &self.adds);
        }
        let mut adds = self.adds.clone();
        let mut dels = self.dels.clone();
        for c in &self.conditional {
            if c.condition.holds(state) {
                if c.add {
                    adds.push(c.atom)
                } else {
                    dels.push(c.atom)
                }
            }
        }
        adds.sort_unstable();
        adds.dedup();
        dels.sort_unstable();
        dels.dedup();
        state.with_changes(&dels, &adds)
    }
}
