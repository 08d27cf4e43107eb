//! Print → parse is the identity for states, action blocks, procedures, patches, formulas
//! and PDDL.

use crate::common;

use common::*;
use nesy_core::Patch;
use nesy_core::format_procedure;
use nesy_core::pddl::{
    Domain, PlanStep, PredicateDecl, Problem, format_plan, parse_domain, parse_plan, parse_problem,
};
use nesy_core::text::{parse_formula, parse_procedure, parse_refinement_reply, parse_state_list};
use nesy_core::{Formula, TypedVar};
use nesy_core::{Operator, State, Symbol};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn states(seed in any::<u64>()) {
        let s = state(&mut SeedRng::new(seed), 12);
        prop_assert_eq!(parse_state_list(&s.to_string()).unwrap(), s);
    }

    #[test]
    fn formulas(seed in any::<u64>()) {
        let f = formula(&mut SeedRng::new(seed), 4, &mut Vec::new());
        prop_assert_eq!(parse_formula(&f.to_string()).unwrap(), f);
    }

    #[test]
    fn procedures(seed in any::<u64>()) {
        let ops = procedure(&mut SeedRng::new(seed), 4);
        let text = format_procedure(&ops);
        let back = parse_procedure(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(back, ops);
    }

    #[test]
    fn patches(seed in any::<u64>()) {
        let mut rng = SeedRng::new(seed);
        let mut search = procedure(&mut rng, 3);
        if search.is_empty() {
            search.push(operator(&mut rng, "OnlyAction"));
        }
        let patch = Patch { search, replace: procedure(&mut rng, 3) };
        let text = format!("Refinement rationale:\n- because\n\nRefinement patch:\n{patch}\n");
        let reply = parse_refinement_reply(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(reply.patches.len(), 1);
        prop_assert_eq!(&reply.patches[0], &patch);
    }

    #[test]
    fn pddl(seed in any::<u64>()) {
        let mut rng = SeedRng::new(seed);
        let (domain, problem, plan) = random_pddl(&mut rng);
        let text = domain.to_string();
        let d = parse_domain(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&d, &domain);
        let text = problem.to_string();
        let p = parse_problem(&text, &d).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(p, problem);
        prop_assert_eq!(parse_plan(&format_plan(&plan)).unwrap().iter().map(|s| s.to_string()).collect::<Vec<_>>(),
                        plan.iter().map(|s| s.to_string()).collect::<Vec<_>>());
    }
}

fn sym(s: &str) -> Symbol {
    Symbol::new(s)
}

/// A random typed domain over `on/2`, `clear/1`, `free/0`, its problem and a plan.
fn random_pddl(rng: &mut SeedRng) -> (Domain, Problem, Vec<PlanStep>) {
    let block = sym("block");
    let preds = vec![
        PredicateDecl {
            name: sym("on"),
            params: vec![
                TypedVar {
                    name: sym("a"),
                    ty: block,
                },
                TypedVar {
                    name: sym("b"),
                    ty: block,
                },
            ],
        },
        PredicateDecl {
            name: sym("clear"),
            params: vec![TypedVar {
                name: sym("a"),
                ty: block,
            }],
        },
        PredicateDecl {
            name: sym("free"),
            params: vec![],
        },
    ];
    let objects = ["b1", "b2", "b3"];
    let mut actions = Vec::new();
    for (i, name) in ["move", "lift", "drop-it"]
        .iter()
        .enumerate()
        .take(1 + rng.below(3))
    {
        let params: Vec<TypedVar> = (0..1 + i % 2)
            .map(|k| TypedVar {
                name: sym(["p", "q"][k]),
                ty: block,
            })
            .collect();
        let scope: Vec<Symbol> = params.iter().map(|p| p.name).collect();
        let pre: Vec<Formula> = (0..rng.below(3))
            .map(|_| pddl_formula(rng, &scope, &objects, 2))
            .filter(|f| !matches!(f, Formula::And(_)))
            .collect();
        let mut eff = Vec::new();
        for _ in 0..1 + rng.below(3) {
            let atom = pddl_atom(rng, &scope, &objects);
            eff.push(if rng.chance(50) {
                nesy_core::Effect::Add(atom)
            } else {
                nesy_core::Effect::Del(atom)
            });
        }
        if rng.chance(30) {
            let v = TypedVar {
                name: sym("z"),
                ty: block,
            };
            let mut inner = scope.clone();
            inner.push(v.name);
            let cond = pddl_formula(rng, &inner, &objects, 1);
            eff.push(nesy_core::Effect::Forall(
                vec![v],
                vec![nesy_core::Effect::When(
                    cond,
                    vec![nesy_core::Effect::Del(pddl_atom(rng, &inner, &objects))],
                )],
            ));
        }
        actions.push(Operator {
            name: name.to_string(),
            params,
            args: vec![],
            pre: pre.into(),
            eff: eff.into(),
        });
    }
    let domain = Domain {
        name: sym("rand"),
        requirements: vec![":adl".into(), ":typing".into()],
        types: vec![(block, sym("object"))],
        constants: vec![],
        predicates: preds,
        actions,
    };
    let init = State::from_atoms((0..rng.below(5)).map(|_| {
        let a = *rng.pick(&objects);
        let b = *rng.pick(&objects);
        match rng.below(3) {
            0 => nesy_core::Atom::new("on", &[a, b]),
            1 => nesy_core::Atom::new("clear", &[a]),
            _ => nesy_core::Atom::new("free", &[]),
        }
    }));
    let problem = Problem {
        name: sym("p"),
        domain: sym("rand"),
        objects: objects.iter().map(|o| (sym(o), block)).collect(),
        init,
        goal: pddl_formula(rng, &[], &objects, 3),
    };
    let plan = (0..rng.below(4))
        .map(|i| PlanStep {
            action: sym("move"),
            args: vec![sym(rng.word(&objects))],
            line: i + 1,
            column: 1,
        })
        .collect();
    (domain, problem, plan)
}

fn pddl_atom(rng: &mut SeedRng, scope: &[Symbol], objects: &[&'static str]) -> nesy_core::AtomPattern {
    use nesy_core::{AtomPattern, Term};
    let term = |rng: &mut SeedRng| {
        if !scope.is_empty() && rng.chance(60) {
            Term::Var(*rng.pick(scope))
        } else {
            Term::Const(sym(rng.word(objects)))
        }
    };
    match rng.below(3) {
        0 => AtomPattern {
            pred: sym("on"),
            args: [term(rng), term(rng)].into_iter().collect(),
        },
        1 => AtomPattern {
            pred: sym("clear"),
            args: [term(rng)].into_iter().collect(),
        },
        _ => AtomPattern {
            pred: sym("free"),
            args: Default::default(),
        },
    }
}

fn pddl_formula(rng: &mut SeedRng, scope: &[Symbol], objects: &[&'static str], depth: usize) -> Formula {
    if depth == 0 || rng.chance(40) {
        return Formula::Atom(pddl_atom(rng, scope, objects));
    }
    match rng.below(5) {
        0 => Formula::Not(Box::new(pddl_formula(rng, scope, objects, depth - 1))),
        1 => Formula::And(
            (0..1 + rng.below(2))
                .map(|_| pddl_formula(rng, scope, objects, depth - 1))
                .collect(),
        ),
        2 => Formula::Or(
            (0..1 + rng.below(2))
                .map(|_| pddl_formula(rng, scope, objects, depth - 1))
                .collect(),
        ),
        3 => {
            let v = TypedVar {
                name: sym("w"),
                ty: sym("block"),
            };
            let mut inner = scope.to_vec();
            inner.push(v.name);
            Formula::Exists(vec![v], Box::new(pddl_formula(rng, &inner, objects, depth - 1)))
        }
        _ => {
            use nesy_core::Term;
            let t = |rng: &mut SeedRng| {
                if !scope.is_empty() && rng.chance(50) {
                    Term::Var(*rng.pick(scope))
                } else {
                    Term::Const(sym(rng.word(objects)))
                }
            };
            Formula::Eq(t(rng), t(rng))
        }
    }
}
