//! apply and verify_procedure agree with a naive reference evaluator on random small
//! domains. The reference works on sets of atom strings and resolves variables through an
//! environment map while walking the tree: a different implementation of the same
//! semantics (closed world; conditions evaluated before the action; deletes, then adds).

use crate::common;

use std::collections::{BTreeMap, BTreeSet};

use common::*;
use nesy_core::{AtomPattern, Effect, Formula, Term};
use nesy_core::{ExecError, Operator, State, Symbol, Universe};
use nesy_core::{StepStatus, apply_in, verify_procedure_in};
use proptest::prelude::*;

type Env = BTreeMap<String, String>;

fn atom_text(p: &AtomPattern, env: &Env) -> String {
    let mut s = format!("({}", p.pred);
    for t in &p.args {
        s.push(' ');
        match t {
            Term::Const(c) => s.push_str(c.as_str()),
            Term::Var(v) => s.push_str(&env[v.as_str()]),
        }
    }
    s.push(')');
    s
}

fn term(t: &Term, env: &Env) -> String {
    match t {
        Term::Const(c) => c.to_string(),
        Term::Var(v) => env[v.as_str()].clone(),
    }
}

fn holds(f: &Formula, s: &BTreeSet<String>, env: &Env, objects: &[String]) -> bool {
    match f {
        Formula::Atom(p) => s.contains(&atom_text(p, env)),
        Formula::Eq(a, b) => term(a, env) == term(b, env),
        Formula::Not(x) => !holds(x, s, env, objects),
        Formula::And(xs) => xs.iter().all(|x| holds(x, s, env, objects)),
        Formula::Or(xs) => xs.iter().any(|x| holds(x, s, env, objects)),
        Formula::Imply(a, b) => !holds(a, s, env, objects) || holds(b, s, env, objects),
        Formula::Forall(vs, body) | Formula::Exists(vs, body) => {
            let mut all = true;
            let mut any = false;
            for_all_bindings(
                vs.iter().map(|v| v.name.to_string()).collect(),
                env,
                objects,
                &mut |e| {
                    let v = holds(body, s, e, objects);
                    all &= v;
                    any |= v;
                },
            );
            if matches!(f, Formula::Forall(..)) {
                all
            } else {
                any
            }
        }
    }
}

fn for_all_bindings(vars: Vec<String>, env: &Env, objects: &[String], visit: &mut dyn FnMut(&Env)) {
    if vars.is_empty() {
        visit(env);
        return;
    }
    for o in objects {
        let mut e = env.clone();
        e.insert(vars[0].clone(), o.clone());
        for_all_bindings(vars[1..].to_vec(), &e, objects, visit);
    }
}

fn collect(
    e: &Effect,
    s: &BTreeSet<String>,
    env: &Env,
    objects: &[String],
    adds: &mut BTreeSet<String>,
    dels: &mut BTreeSet<String>,
) {
    match e {
        Effect::Add(p) => {
            adds.insert(atom_text(p, env));
        }
        Effect::Del(p) => {
            dels.insert(atom_text(p, env));
        }
        Effect::Forall(vs, es) => for_all_bindings(
            vs.iter().map(|v| v.name.to_string()).collect(),
            env,
            objects,
            &mut |e2| {
                for x in es {
                    collect(x, s, e2, objects, adds, dels);
                }
            },
        ),
        Effect::When(c, es) => {
            if holds(c, s, env, objects) {
                for x in es {
                    collect(x, s, env, objects, adds, dels);
                }
            }
        }
    }
}

/// The reference step: `Err(indices of unmet preconditions)` or the next state.
fn reference_apply(
    s: &BTreeSet<String>,
    op: &Operator,
    objects: &[String],
) -> Result<BTreeSet<String>, Vec<usize>> {
    let env = Env::new();
    let unmet: Vec<usize> = op
        .pre
        .iter()
        .enumerate()
        .filter(|(_, f)| !holds(f, s, &env, objects))
        .map(|(i, _)| i)
        .collect();
    if !unmet.is_empty() {
        return Err(unmet);
    }
    let (mut adds, mut dels) = (BTreeSet::new(), BTreeSet::new());
    for e in op.eff.iter() {
        collect(e, s, &env, objects, &mut adds, &mut dels);
    }
    let mut next: BTreeSet<String> = s.difference(&dels).cloned().collect();
    next.extend(adds);
    Ok(next)
}

fn texts(s: &State) -> BTreeSet<String> {
    s.iter().map(|a| a.to_string()).collect()
}

fn universe() -> (Universe, Vec<String>) {
    (
        Universe::of_things(OBJECTS.iter().map(|o| Symbol::new(o))),
        OBJECTS.iter().map(|o| o.to_string()).collect(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn apply_agrees(seed in any::<u64>()) {
        let mut rng = SeedRng::new(seed);
        let (u, objects) = universe();
        let s = state(&mut rng, 10);
        let op = operator(&mut rng, "Op");
        let ours = apply_in(&u, &s, &op);
        match (ours, reference_apply(&texts(&s), &op, &objects)) {
            (Ok(next), Ok(expected)) => prop_assert_eq!(texts(&next), expected),
            (Err(ExecError::Violation(v)), Err(unmet)) => {
                let ours: Vec<String> = v.unmet.iter().map(|u| u.literal.to_string()).collect();
                let theirs: Vec<String> = unmet.iter().map(|&i| op.pre[i].to_string()).collect();
                prop_assert_eq!(ours, theirs);
                // The reported atom truths are the truths in the state.
                for u in &v.unmet {
                    for t in &u.atoms {
                        prop_assert_eq!(t.holds, s.contains(&t.atom));
                    }
                }
            }
            (a, b) => prop_assert!(false, "disagree: ours {:?}, reference {:?}", a, b),
        }
    }

    #[test]
    fn verify_agrees(seed in any::<u64>()) {
        let mut rng = SeedRng::new(seed);
        let (u, objects) = universe();
        let init = state(&mut rng, 10);
        let ops = procedure(&mut rng, 6);
        let goal = formula(&mut rng, 2, &mut Vec::new());
        let report = verify_procedure_in(&u, &init, &ops, Some(&goal));
        let mut s = texts(&init);
        let mut failed = None;
        for (i, op) in ops.iter().enumerate() {
            match reference_apply(&s, op, &objects) {
                Ok(next) => s = next,
                Err(_) => {
                    failed = Some(i);
                    break;
                }
            }
        }
        prop_assert_eq!(report.first_failure, failed);
        prop_assert_eq!(texts(&report.final_state), s.clone());
        if failed.is_none() {
            prop_assert_eq!(report.goal.as_ref().unwrap().satisfied, holds(&goal, &s, &Env::new(), &objects));
        } else {
            let failed_step = matches!(report.steps[failed.unwrap()].status, StepStatus::Failed { .. });
            prop_assert!(failed_step);
        }
    }

    #[test]
    fn with_changes_is_deletes_then_adds(seed in any::<u64>()) {
        let mut rng = SeedRng::new(seed);
        let s = state(&mut rng, 60);
        let mut dels: Vec<nesy_core::Atom> = (0..rng.below(8)).map(|_| ground_atom(&mut rng)).collect();
        let mut adds: Vec<nesy_core::Atom> = (0..rng.below(8)).map(|_| ground_atom(&mut rng)).collect();
        dels.sort();
        dels.dedup();
        adds.sort();
        adds.dedup();
        let mut expected: BTreeSet<String> = texts(&s);
        for d in &dels {
            expected.remove(&d.to_string());
        }
        expected.extend(adds.iter().map(|a| a.to_string()));
        prop_assert_eq!(texts(&s.with_changes(&dels, &adds)), expected);
    }
}
