//! Truncated and garbage input never panics any parser: every prefix of real inputs, and
//! random strings over the characters that matter to the grammars, give `Ok` or a typed
//! error with a position inside the input.

use nesy_core::Atom;
use nesy_core::pddl::{parse_domain, parse_plan, parse_problem};
use nesy_core::text::ParseError;
use nesy_core::text::{
    parse_action_block, parse_effects, parse_formula, parse_induction_reply, parse_procedure,
    parse_refinement_reply, parse_state_list,
};
use proptest::prelude::*;

fn fixture(path: &str) -> String {
    std::fs::read_to_string(nesy_testkit::workspace_root().join("fixtures").join(path)).unwrap()
}

fn check_position(text: &str, e: &ParseError) {
    let lines = text.split('\n').count();
    assert!(
        e.line >= 1 && e.line <= lines.max(1),
        "line {} outside 1..={lines}: {e}",
        e.line
    );
    assert!(e.column >= 1);
}

/// Runs every parser on `text`; none may panic.
fn all_parsers(text: &str) {
    let domain = parse_domain(&fixture("pddl/blocksworld/domain.pddl")).unwrap();
    let results: Vec<Result<(), ParseError>> = vec![
        parse_state_list(text).map(|_| ()),
        parse_procedure(text).map(|_| ()),
        parse_action_block(text).map(|_| ()),
        parse_induction_reply(text).map(|_| ()),
        parse_refinement_reply(text).map(|_| ()),
        parse_formula(text).map(|_| ()),
        parse_effects(text).map(|_| ()),
        parse_domain(text).map(|_| ()),
        parse_problem(text, &domain).map(|_| ()),
        parse_plan(text).map(|_| ()),
    ];
    for e in results.into_iter().filter_map(Result::err) {
        check_position(text, &e);
    }
    let _ = text.parse::<Atom>();
}

#[test]
fn every_prefix_of_real_inputs() {
    let mut inputs = vec![
        fixture("pddl/blocksworld/domain.pddl"),
        fixture("pddl/briefcase/domain.pddl"),
        fixture("pddl/logistics/two-cities.pddl"),
        fixture("pddl/blocksworld/sussman.valid.plan"),
        fixture("responses/procedure-hinge.txt"),
    ];
    for entry in std::fs::read_dir(nesy_testkit::workspace_root().join("fixtures/responses")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "txt") {
            inputs.push(std::fs::read_to_string(path).unwrap());
        }
    }
    for input in &inputs {
        let mut cut = 0;
        while cut <= input.len() {
            if input.is_char_boundary(cut) {
                all_parsers(&input[..cut]);
            }
            cut += 1 + input.len() / 97; // about a hundred prefixes per input keeps this fast
        }
        all_parsers(input);
    }
}

#[test]
fn hostile_shapes() {
    for text in [
        "",
        "\n\n\r\n",
        "(",
        ")",
        ")))(((",
        &"(".repeat(100_000),
        &"(a ".repeat(5_000),
        "<<<<<<< SEARCH",
        "=======\n>>>>>>> REPLACE",
        "<<<<<<< SEARCH\n=======\n>>>>>>> REPLACE\n<<<<<<< SEARCH",
        "Action Semantic:\nPrecondition:\nEffect:",
        "Action Semantic:\n- \u{1F916}\nPrecondition:\n- (\u{00E9}t\u{00E9})\nEffect:\n- (\u{4E2D} ?)",
        "(define",
        "(define (domain d) (:action a :parameters (?x - (either a b)) :effect (p)))",
        "(define (problem p) (:domain d))",
        "- (forall (?x - thing) (P ?x)",
        "\u{0}\u{1}\u{7f}",
        "- Preconditions:\n- Effects:",
        "1.\n2)\n*\n-\n•",
    ] {
        all_parsers(text);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn random_text(text in "[()?\\-* \t\r\n:;=<>a-zA-Z0-9_.`#]{0,200}") {
        all_parsers(&text);
    }

    #[test]
    fn random_unicode(text in "\\PC{0,120}") {
        all_parsers(&text);
    }
}
