//! Random generators for property tests, driven by a proptest-chosen seed so failures
//! reproduce. Formulas only use variables bound by an enclosing quantifier.

#![allow(dead_code)]

use nesy_core::rng::SplitMix64;
use nesy_core::{Atom, Operator, State, Symbol};
use nesy_core::{AtomPattern, Effect, Formula, Term, TypedVar};

/// The test generators' source of randomness: nesy-core's SplitMix64 with a few helpers.
pub(crate) struct SeedRng(pub SplitMix64);

impl SeedRng {
    pub(crate) fn new(seed: u64) -> SeedRng {
        SeedRng(SplitMix64::new(seed))
    }

    pub(crate) fn below(&mut self, n: usize) -> usize {
        self.0.below(n)
    }

    pub(crate) fn chance(&mut self, percent: u64) -> bool {
        (self.0.below(100) as u64) < percent
    }

    pub(crate) fn word(&mut self, items: &[&'static str]) -> &'static str {
        items[self.below(items.len())]
    }

    pub(crate) fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Predicates with their arities.
pub(crate) const PREDS: &[(&str, usize)] = &[
    ("OnTopOf", 2),
    ("Open", 1),
    ("GripperOpen", 0),
    ("GripperHolding", 1),
    ("InsideOf", 2),
];
pub(crate) const OBJECTS: &[&str] = &["a", "b", "orange", "hinge_lid"];
/// `x` and `xy` on purpose: a binding of `?x` must never touch `?xy`.
pub(crate) const VARS: &[&str] = &["x", "xy", "y"];

pub(crate) fn ground_atom(rng: &mut SeedRng) -> Atom {
    let (p, n) = *rng.pick(PREDS);
    let args: Vec<&str> = (0..n).map(|_| *rng.pick(OBJECTS)).collect();
    Atom::new(p, &args)
}

pub(crate) fn state(rng: &mut SeedRng, max: usize) -> State {
    let n = rng.below(max + 1);
    State::from_atoms((0..n).map(|_| ground_atom(rng)))
}

fn term(rng: &mut SeedRng, scope: &[Symbol]) -> Term {
    if !scope.is_empty() && rng.chance(50) {
        Term::Var(*rng.pick(scope))
    } else {
        Term::Const(Symbol::new(rng.word(OBJECTS)))
    }
}

pub(crate) fn pattern(rng: &mut SeedRng, scope: &[Symbol]) -> AtomPattern {
    let (p, n) = *rng.pick(PREDS);
    AtomPattern {
        pred: Symbol::new(p),
        args: (0..n).map(|_| term(rng, scope)).collect(),
    }
}

fn vars(rng: &mut SeedRng) -> Vec<TypedVar> {
    let n = 1 + rng.below(2);
    let mut out: Vec<TypedVar> = Vec::new();
    for _ in 0..n {
        let name = Symbol::new(rng.word(VARS));
        if !out.iter().any(|v| v.name == name) {
            out.push(TypedVar {
                name,
                ty: Symbol::new("thing"),
            });
        }
    }
    out
}

pub(crate) fn formula(rng: &mut SeedRng, depth: usize, scope: &mut Vec<Symbol>) -> Formula {
    let leaf = depth == 0 || rng.chance(35);
    if leaf {
        return if rng.chance(10) {
            Formula::Eq(term(rng, scope), term(rng, scope))
        } else {
            Formula::Atom(pattern(rng, scope))
        };
    }
    match rng.below(6) {
        0 => Formula::Not(Box::new(formula(rng, depth - 1, scope))),
        1 => Formula::And(
            (0..rng.below(3))
                .map(|_| formula(rng, depth - 1, scope))
                .collect(),
        ),
        2 => Formula::Or(
            (0..1 + rng.below(2))
                .map(|_| formula(rng, depth - 1, scope))
                .collect(),
        ),
        3 => Formula::Imply(
            Box::new(formula(rng, depth - 1, scope)),
            Box::new(formula(rng, depth - 1, scope)),
        ),
        q => {
            let vs = vars(rng);
            let n = scope.len();
            scope.extend(vs.iter().map(|v| v.name));
            let body = Box::new(formula(rng, depth - 1, scope));
            scope.truncate(n);
            if q == 4 {
                Formula::Forall(vs, body)
            } else {
                Formula::Exists(vs, body)
            }
        }
    }
}

pub(crate) fn effect(rng: &mut SeedRng, depth: usize, scope: &mut Vec<Symbol>) -> Effect {
    if depth == 0 || rng.chance(60) {
        return if rng.chance(50) {
            Effect::Add(pattern(rng, scope))
        } else {
            Effect::Del(pattern(rng, scope))
        };
    }
    if rng.chance(50) {
        let vs = vars(rng);
        let n = scope.len();
        scope.extend(vs.iter().map(|v| v.name));
        let body = (0..1 + rng.below(2))
            .map(|_| effect(rng, depth - 1, scope))
            .collect();
        scope.truncate(n);
        Effect::Forall(vs, body)
    } else {
        let cond = formula(rng, 2, scope);
        Effect::When(
            cond,
            (0..1 + rng.below(2))
                .map(|_| effect(rng, depth - 1, scope))
                .collect(),
        )
    }
}

pub(crate) fn operator(rng: &mut SeedRng, name: &str) -> Operator {
    let pre: Vec<_> = (0..rng.below(4))
        .map(|_| formula(rng, 3, &mut Vec::new()))
        .collect();
    let eff: Vec<_> = (0..1 + rng.below(4))
        .map(|_| effect(rng, 2, &mut Vec::new()))
        .collect();
    Operator::new(name, pre, eff)
}

pub(crate) fn procedure(rng: &mut SeedRng, max: usize) -> Vec<Operator> {
    let names = [
        "MoveGripperToSurroundOrange",
        "GraspOrange",
        "OpenHingeLid",
        "Drop2",
        "LiftA",
    ];
    (0..rng.below(max + 1))
        .map(|_| {
            let name = rng_name(rng, &names);
            operator(rng, name)
        })
        .collect()
}

fn rng_name<'a>(rng: &mut SeedRng, names: &[&'a str]) -> &'a str {
    names[rng.below(names.len())]
}
