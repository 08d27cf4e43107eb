//! The benchmark workloads, shared by the criterion benches and the workload exporter
//! that feeds `scripts/bench_py_executor.py` the very same inputs.

#![allow(dead_code)]

use nesy_core::pddl::{Domain, Problem, parse_domain, parse_problem};
use nesy_core::text::parse_action_block;
use nesy_core::{Atom, Formula, Operator, State};

/// A 200-atom state over 60 objects.
pub(crate) fn state_200() -> State {
    let mut atoms = vec![Atom::new("GripperOpen", &[])];
    for i in 0..60 {
        let o = format!("obj{i}");
        let next = format!("obj{}", (i + 1) % 60);
        atoms.push(Atom::new("OnTopOf", &[&o, "floor"]));
        atoms.push(Atom::new("Visible", &[&o]));
        atoms.push(Atom::new("Near", &[&o, &next]));
    }
    for i in 0..19 {
        atoms.push(Atom::new("Marked", &[&format!("obj{i}"), "floor"]));
    }
    let s = State::from_atoms(atoms);
    assert_eq!(s.len(), 200);
    s
}

/// An operator of 20 literals: 10 preconditions (7 positive, 3 negative) and 10 effects
/// (5 adds, 5 deletes), all applicable in [`state_200`].
pub(crate) fn operator_20() -> Operator {
    let mut text = String::from("TwentyLiteralAction\n- Preconditions:\n");
    for i in 0..7 {
        text.push_str(&format!("\t(Near obj{} obj{})\n", i * 5, i * 5 + 1));
    }
    for i in 0..3 {
        text.push_str(&format!("\t(not (InsideOf obj{i} box))\n"));
    }
    text.push_str("- Effects:\n");
    for i in 0..5 {
        text.push_str(&format!("\t(InsideOf obj{i} box)\n"));
    }
    for i in 0..5 {
        text.push_str(&format!("\t(not (OnTopOf obj{i} floor))\n"));
    }
    parse_action_block(&text).expect("workload operator parses")
}

/// A 116-step procedure (58 grasp/place pairs) valid from [`state_200`], in the style of
/// induced operators: quantified preconditions over every object and negative literals.
pub(crate) fn procedure_116() -> Vec<Operator> {
    let mut ops = Vec::new();
    for k in 0..58 {
        let grasp = format!(
            "CloseGripperToGraspObj{k}\n- Preconditions:\n\t(GripperOpen)\n\t(forall (?y - thing) (not (GripperHolding ?y)))\n\t(Visible obj{k})\n\t(OnTopOf obj{k} floor)\n\t(not (InsideOf obj{k} box))\n- Effects:\n\t(GripperHolding obj{k})\n\t(GripperClosed)\n\t(not (GripperOpen))\n\t(not (OnTopOf obj{k} floor))"
        );
        let place = format!(
            "OpenGripperToDropObj{k}IntoBox\n- Preconditions:\n\t(GripperHolding obj{k})\n\t(GripperClosed)\n\t(not (Closed box))\n- Effects:\n\t(InsideOf obj{k} box)\n\t(GripperOpen)\n\t(not (GripperClosed))\n\t(not (GripperHolding obj{k}))"
        );
        ops.push(parse_action_block(&grasp).expect("grasp parses"));
        ops.push(parse_action_block(&place).expect("place parses"));
    }
    ops
}

/// The goal of the procedure: every object in the box.
pub(crate) fn goal_116() -> Formula {
    Formula::And(
        (0..58)
            .map(|k| Formula::atom(Atom::new("InsideOf", &[&format!("obj{k}"), "box"])))
            .collect(),
    )
}

pub(crate) const BLOCKSWORLD: &str = include_str!("../../../../fixtures/pddl/blocksworld/domain.pddl");

/// A 10-block instance: two towers of five, to be rebuilt as one tower in another order.
pub(crate) fn blocksworld_10() -> (Domain, Problem) {
    let domain = parse_domain(BLOCKSWORLD).expect("domain parses");
    let problem = parse_problem(
        "(define (problem bw10) (:domain blocksworld)
          (:objects b1 b2 b3 b4 b5 b6 b7 b8 b9 b10 - block)
          (:init (handempty)
                 (ontable b1) (on b2 b1) (on b3 b2) (on b4 b3) (on b5 b4) (clear b5)
                 (ontable b6) (on b7 b6) (on b8 b7) (on b9 b8) (on b10 b9) (clear b10))
          (:goal (and (on b1 b6) (on b6 b2) (on b2 b7) (on b7 b3) (on b3 b8) (on b8 b4) (on b4 b9) (on b9 b5) (on b5 b10))))",
        &domain,
    )
    .expect("problem parses");
    (domain, problem)
}
