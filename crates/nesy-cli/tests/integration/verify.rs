//! `nesy verify` against the bundled PDDL fixtures: verdicts must match the ones VAL gave
//! (recorded in `fixtures/pddl/expected.json`), and bad input must exit 2 with a location.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fixtures() -> PathBuf {
    nesy_testkit::workspace_root().join("fixtures/pddl")
}

fn nesy(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nesy"))
        .args(args)
        .output()
        .expect("run nesy")
}

fn verify(domain: &Path, problem: &Path, plan: &Path, json: bool) -> Output {
    let mut args = vec![
        "verify",
        "--domain",
        domain.to_str().unwrap(),
        "--problem",
        problem.to_str().unwrap(),
        "--plan",
        plan.to_str().unwrap(),
    ];
    if json {
        args.push("--json");
    }
    nesy(&args)
}

#[test]
fn verdicts_match_val() {
    let root = fixtures();
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("expected.json")).unwrap()).unwrap();
    let cases = expected["cases"].as_array().unwrap();
    assert!(cases.len() >= 15);
    for case in cases {
        let path = |k: &str| root.join(case[k].as_str().unwrap());
        let out = verify(&path("domain"), &path("problem"), &path("plan"), true);
        let stdout = String::from_utf8_lossy(&out.stdout);
        let name = case["plan"].as_str().unwrap();
        let verdict: serde_json::Value = serde_json::from_str(&stdout)
            .unwrap_or_else(|e| panic!("{name}: {e}\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr)));
        match case["verdict"].as_str().unwrap() {
            "valid" => {
                assert_eq!(out.status.code(), Some(0), "{name}: {stdout}");
                assert_eq!(verdict["valid"], true, "{name}");
                assert_eq!(verdict["goal_satisfied"], true, "{name}");
            }
            "unmet_precondition" => {
                assert_eq!(out.status.code(), Some(1), "{name}");
                assert_eq!(verdict["failure"]["step"], case["step"], "{name}: {stdout}");
                let ours: Vec<&str> = verdict["failure"]["unmet"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_str().unwrap())
                    .collect();
                for advice in case["val_advice"].as_array().unwrap() {
                    assert!(
                        ours.contains(&advice.as_str().unwrap()),
                        "{name}: VAL advises {advice}, we report {ours:?}"
                    );
                }
            }
            "goal_not_satisfied" => {
                assert_eq!(out.status.code(), Some(1), "{name}");
                assert!(verdict["failure"].is_null(), "{name}");
                assert_eq!(verdict["goal_satisfied"], false, "{name}");
                let ours: Vec<&str> = verdict["unmet_goal"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_str().unwrap())
                    .collect();
                for advice in case["val_advice"].as_array().unwrap() {
                    assert!(
                        ours.contains(&advice.as_str().unwrap()),
                        "{name}: VAL advises {advice}, we report {ours:?}"
                    );
                }
            }
            other => panic!("unknown verdict {other}"),
        }
    }
}

#[test]
fn text_output_is_readable() {
    let bw = fixtures().join("blocksworld");
    let out = verify(
        &bw.join("domain.pddl"),
        &bw.join("sussman.pddl"),
        &bw.join("sussman.valid.plan"),
        false,
    );
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(
        String::from_utf8_lossy(&out.stdout).trim(),
        "Plan valid: 6 step(s) executed, goal satisfied."
    );
    let out = verify(
        &bw.join("domain.pddl"),
        &bw.join("sussman.pddl"),
        &bw.join("sussman.unmet.plan"),
        false,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1));
    assert!(text.contains("step 1 (pick-up a) (plan line 2)"), "{text}");
    assert!(text.contains("- (clear a)   ((clear a) is false)"), "{text}");
    let out = verify(
        &bw.join("domain.pddl"),
        &bw.join("sussman.pddl"),
        &bw.join("sussman.goal.plan"),
        false,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("goal is not satisfied") && text.contains("- (on b c)"),
        "{text}"
    );
}

#[test]
fn bad_input_exits_2_with_location() {
    let dir = tempfile::tempdir().unwrap();
    let bw = fixtures().join("blocksworld");
    let bad_plan = dir.path().join("bad.plan");
    std::fs::write(&bad_plan, "(pick-up a)\n(stack a b\n").unwrap();
    let out = verify(
        &bw.join("domain.pddl"),
        &bw.join("sussman.pddl"),
        &bad_plan,
        false,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.plan:2:11: expected `)` to close the `(` opened at line 2, column 1"),
        "{err}"
    );

    std::fs::write(&bad_plan, "(pick-up a)\n(fly a b)\n").unwrap();
    let out = verify(
        &bw.join("domain.pddl"),
        &bw.join("sussman.pddl"),
        &bad_plan,
        false,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad.plan:2:1:") && err.contains("`fly` is not one"),
        "{err}"
    );

    std::fs::write(&bad_plan, "(stack a z)\n").unwrap();
    let out = verify(
        &bw.join("domain.pddl"),
        &bw.join("sussman.pddl"),
        &bad_plan,
        false,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`z`"));

    let bad_domain = dir.path().join("domain.pddl");
    std::fs::write(
        &bad_domain,
        "(define (domain d)\n  (:requirements :durative-actions))",
    )
    .unwrap();
    let out = verify(
        &bad_domain,
        &bw.join("sussman.pddl"),
        &bw.join("sussman.valid.plan"),
        false,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("domain.pddl:2:18:"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let out = verify(
        &dir.path().join("missing.pddl"),
        &bw.join("sussman.pddl"),
        &bw.join("sussman.valid.plan"),
        false,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.pddl"));
}

/// `nesy scenarios pddl --domain-out` for a scene with two cabinets: the domain names each
/// cabinet's schemas and the `Blocks` precondition, nesy-core's planner solves the problem in
/// it, and `nesy verify` accepts the plan.
#[test]
fn a_scene_with_two_cabinets_gets_a_domain_a_planner_and_val_accept() {
    let dir = crate::common::scratch();
    let (domain, problem, plan) = (
        dir.path().join("domain.pddl"),
        dir.path().join("problem.pddl"),
        dir.path().join("plan.txt"),
    );
    let out = nesy(&[
        "scenarios",
        "pddl",
        "family_drawers_00_s0",
        "--out",
        problem.to_str().unwrap(),
        "--domain-out",
        domain.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let domain_text = std::fs::read_to_string(&domain).unwrap();
    assert!(
        domain_text.contains("(:action open-side-bottom-drawer"),
        "{domain_text}"
    );
    assert!(domain_text.contains("(Blocks ?a ?b - thing)"), "{domain_text}");
    let parsed = nesy_core::pddl::parse_domain(&domain_text).expect("the domain parses");
    let parsed_problem = nesy_core::pddl::parse_problem(&std::fs::read_to_string(&problem).unwrap(), &parsed)
        .expect("the problem parses");
    let universe = parsed.universe(&parsed_problem).unwrap();
    let found = nesy_core::planner::plan(
        &parsed.actions,
        &universe,
        &parsed_problem.init,
        &parsed_problem.goal,
        &nesy_core::planner::PlannerConfig::default(),
    )
    .expect("a plan");
    // One `(action args)` per line, as VAL reads plans.
    let text: String = found
        .steps
        .iter()
        .map(|s| match s.display_name() {
            name if name.starts_with('(') => format!("{name}\n"),
            name => format!("({name})\n"),
        })
        .collect();
    std::fs::write(&plan, &text).unwrap();
    let checked = verify(&domain, &problem, &plan, false);
    assert_eq!(
        checked.status.code(),
        Some(0),
        "{text}\n{}",
        String::from_utf8_lossy(&checked.stdout)
    );
}
