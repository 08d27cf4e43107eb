//! Deterministic scripted-reasoner tests of the adaptation loop on the paper's
//! orange/hinge-lid example.

use std::collections::VecDeque;

use super::*;
use crate::atom::Atom;
use crate::predicates::Tier;
use crate::symbol::Symbol;

/// Replays canned replies and records every request.
#[derive(Default)]
struct Scripted {
    induction: VecDeque<String>,
    patches: VecDeque<String>,
    induction_requests: Vec<InductionRequest>,
    patch_requests: Vec<PatchRequest>,
}

impl Reasoner for Scripted {
    async fn induce_operator(&mut self, request: &InductionRequest) -> Result<String, ReasonerError> {
        self.induction_requests.push(request.clone());
        self.induction
            .pop_front()
            .ok_or_else(|| ReasonerError::exhausted("script exhausted (induction)"))
    }

    async fn propose_patch(&mut self, request: &PatchRequest) -> Result<String, ReasonerError> {
        self.patch_requests.push(request.clone());
        self.patches
            .pop_front()
            .ok_or_else(|| ReasonerError::exhausted("script exhausted (patch)"))
    }
}

fn state(atoms: &[&str]) -> State {
    State::from_atoms(atoms.iter().map(|a| a.parse::<Atom>().unwrap()))
}

fn task() -> TaskContext {
    TaskContext {
        instruction: "Put the fruits in the hinge box.".into(),
        objects: ["orange", "hinge_body", "hinge_lid", "floor"]
            .iter()
            .map(|o| Symbol::new(o))
            .collect(),
        tier: Tier::Full,
        vocabulary: Vocabulary::new(),
    }
}

fn demo() -> Demonstration {
    let s0 = state(&["(GripperOpen)", "(OnTopOf orange floor)", "(Open hinge_lid)"]);
    let s1 = state(&[
        "(GripperOpen)",
        "(GripperSurrounding orange)",
        "(OnTopOf orange floor)",
        "(Open hinge_lid)",
    ]);
    let s2 = state(&[
        "(GripperClosed)",
        "(GripperHolding orange)",
        "(OnTopOf orange floor)",
        "(Open hinge_lid)",
    ]);
    let s3 = state(&[
        "(GripperClosed)",
        "(GripperHolding orange)",
        "(OverOf orange hinge_body)",
        "(Open hinge_lid)",
    ]);
    let s4 = state(&[
        "(GripperOpen)",
        "(InsideOf orange hinge_body)",
        "(Open hinge_lid)",
    ]);
    Demonstration {
        states: vec![s0, s1, s2, s3, s4],
        task: task(),
    }
}

fn induction_reply(name: &str, pre: &[&str], eff: &[&str]) -> String {
    let pre = if pre.is_empty() {
        "None".to_string()
    } else {
        pre.iter()
            .map(|p| format!("- {p}"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let eff = eff
        .iter()
        .map(|p| format!("- {p}"))
        .collect::<Vec<_>>()
        .join("\n");
    format!(
        "* Prediction Rationale:\n- Reasoning about {name}.\n\n* Predicted Action:\nAction Semantic:\n- {name}\nPrecondition:\n{pre}\nEffect:\n{eff}\n"
    )
}

const APPROACH: (&str, &[&str], &[&str]) = (
    "Move gripper to surround orange",
    &["(GripperOpen)", "(forall (?y - thing) (not (GripperHolding ?y)))"],
    &["(GripperSurrounding orange)"],
);
const GRASP: (&str, &[&str], &[&str]) = (
    "Close gripper to grasp orange",
    &["(GripperSurrounding orange)", "(GripperOpen)"],
    &[
        "(GripperClosed)",
        "(GripperHolding orange)",
        "(not (GripperOpen))",
        "(not (GripperSurrounding orange))",
    ],
);
const LIFT: (&str, &[&str], &[&str]) = (
    "Move held orange over hinge body",
    &["(GripperHolding orange)"],
    &["(OverOf orange hinge_body)", "(not (OnTopOf orange floor))"],
);
const DROP: (&str, &[&str], &[&str]) = (
    "Open gripper to drop orange into hinge body",
    &[
        "(GripperHolding orange)",
        "(OverOf orange hinge_body)",
        "(not (Closed hinge_lid))",
    ],
    &[
        "(InsideOf orange hinge_body)",
        "(GripperOpen)",
        "(not (GripperClosed))",
        "(not (GripperHolding orange))",
        "(not (OverOf orange hinge_body))",
    ],
);

fn good_inductions() -> VecDeque<String> {
    [APPROACH, GRASP, LIFT, DROP]
        .iter()
        .map(|(n, p, e)| induction_reply(n, p, e))
        .collect()
}

fn block(name: &str, pre: &[&str], eff: &[&str]) -> String {
    let section = |xs: &[&str]| {
        if xs.is_empty() {
            "\tNone".to_string()
        } else {
            xs.iter().map(|x| format!("\t{x}")).collect::<Vec<_>>().join("\n")
        }
    };
    format!(
        "{name}\n- Preconditions:\n{}\n- Effects:\n{}",
        section(pre),
        section(eff)
    )
}

fn drop_block() -> String {
    block("OpenGripperToDropOrangeIntoHingeBody", DROP.1, DROP.2)
}

fn open_lid_block() -> String {
    block(
        "PushHingeLidOpenWithHeldOrange",
        &["(GripperHolding orange)", "(Closed hinge_lid)"],
        &["(Open hinge_lid)", "(not (Closed hinge_lid))"],
    )
}

fn refinement(search: &str, replace: &str) -> String {
    format!(
        "* Refinement rationale:\n- The lid is closed in the deployment scene.\n\n* Refinement patch:\n```\n<<<<<<< SEARCH\n{search}\n=======\n{replace}\n>>>>>>> REPLACE\n```\n"
    )
}

fn target() -> Target {
    Target {
        init: state(&["(GripperOpen)", "(OnTopOf orange floor)", "(Closed hinge_lid)"]),
        task: task(),
        scene_names: ["floor", "orange", "hinge_body", "hinge_lid", "hinge_handle"]
            .map(Symbol::new)
            .to_vec(),
        goal: None,
    }
}

#[test]
fn world_model_reprediction_with_feedback() {
    let mut r = Scripted::default();
    // Transition 0: first an unparsable reply, then one whose effects miss an atom, then right.
    r.induction.push_back("I think the robot moved.".into());
    r.induction
        .push_back(induction_reply(APPROACH.0, APPROACH.1, &["(GripperClosed)"]));
    r.induction.extend(good_inductions());
    let mut trace = Trace::default();
    let wm = pollster::block_on(construct_world_model(
        &mut r,
        &demo(),
        &AdaptConfig::default(),
        &mut trace,
    ))
    .unwrap();
    assert!(wm.is_verified());
    assert_eq!(wm.procedure.len(), 4);
    assert_eq!(wm.procedure[0].name, "MoveGripperToSurroundOrange");
    assert_eq!(
        wm.goal.to_string(),
        "(and (InsideOf orange hinge_body) (forall (?x - thing) (not (GripperHolding ?x))) (forall (?x - thing) (not (VacuumAttached ?x))))"
    );
    // The second and third requests for transition 0 carry the verifier's feedback.
    assert_eq!(r.induction_requests[1].feedback.len(), 1);
    assert!(matches!(
        r.induction_requests[1].feedback[0].problem,
        Problem::Unparsable { .. }
    ));
    let fb = &r.induction_requests[2].feedback[1];
    let Problem::EffectMismatch { missing, unexpected } = &fb.problem else {
        panic!("{fb:?}")
    };
    assert_eq!(missing, &vec![Atom::new("GripperSurrounding", &["orange"])]);
    assert_eq!(unexpected, &vec![Atom::new("GripperClosed", &[])]);
    assert!(
        fb.message.contains("- (GripperSurrounding orange)"),
        "{}",
        fb.message
    );
    assert_eq!(r.induction_requests[3].step, 1);
    assert_eq!(r.induction_requests[3].diff.added.len(), 2);
}

#[test]
fn world_model_rejects_unmet_preconditions_and_keeps_precondition_free_operators() {
    let mut r = Scripted::default();
    r.induction
        .push_back(induction_reply(APPROACH.0, &["(GripperClosed)"], APPROACH.2));
    r.induction
        .push_back(induction_reply(APPROACH.0, &[], APPROACH.2));
    r.induction.extend(good_inductions().into_iter().skip(1));
    let mut trace = Trace::default();
    let wm = pollster::block_on(construct_world_model(
        &mut r,
        &demo(),
        &AdaptConfig::default(),
        &mut trace,
    ))
    .unwrap();
    assert!(
        wm.procedure[0].pre.is_empty(),
        "an operator without preconditions is kept, not dropped"
    );
    let fb = &r.induction_requests[1].feedback[0];
    assert!(
        matches!(&fb.problem, Problem::PreconditionsUnmet { unmet } if unmet[0].literal.to_string() == "(GripperClosed)")
    );
}

#[test]
fn unverifiable_transition_is_recorded_not_hidden() {
    let mut r = Scripted::default();
    for _ in 0..2 {
        r.induction
            .push_back(induction_reply(APPROACH.0, APPROACH.1, &["(GripperClosed)"]));
    }
    r.induction.extend(good_inductions().into_iter().skip(1));
    let config = AdaptConfig {
        induction_tries: 2,
        ..Default::default()
    };
    let wm = pollster::block_on(construct_world_model(
        &mut r,
        &demo(),
        &config,
        &mut Trace::default(),
    ))
    .unwrap();
    assert_eq!(wm.unverified_steps, vec![0]);
    // Without world-model verification the wrong operator is accepted at once.
    let mut r = Scripted::default();
    r.induction
        .push_back(induction_reply(APPROACH.0, APPROACH.1, &["(GripperClosed)"]));
    r.induction.extend(good_inductions().into_iter().skip(1));
    let config = AdaptConfig {
        ablation: Ablation::NO_WORLD_MODEL,
        ..Default::default()
    };
    let wm = pollster::block_on(construct_world_model(
        &mut r,
        &demo(),
        &config,
        &mut Trace::default(),
    ))
    .unwrap();
    assert!(wm.is_verified());
    assert_eq!(r.induction_requests.len(), 4);
}

#[test]
fn exploration_rejects_bad_proposals_then_adapts() {
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    // 1: unparsable; 2: SEARCH does not match; 3: parses and matches but does not fix the
    // lid; 4: two patches; 5: the fix.
    r.patches
        .push_back("Let me think about the lid... no patch today.".into());
    r.patches.push_back(refinement(
        &block(
            "OpenGripperToDropOrangeIntoHingeBody",
            &["(GripperHolding orange)"],
            DROP.2,
        ),
        &open_lid_block(),
    ));
    r.patches.push_back(refinement(
        &drop_block(),
        &format!(
            "{}\n\n{}",
            block(
                "Wiggle",
                &["(GripperHolding orange)"],
                &["(GripperHolding orange)"]
            ),
            drop_block()
        ),
    ));
    let fix = refinement(
        &drop_block(),
        &format!("{}\n\n{}", open_lid_block(), drop_block()),
    );
    r.patches.push_back(format!("{fix}\n{fix}"));
    r.patches.push_back(fix.clone());
    let adaptation = pollster::block_on(run(&mut r, &demo(), &target(), &AdaptConfig::default())).unwrap();
    let Outcome::Adapted {
        procedure,
        report,
        iterations,
    } = &adaptation.outcome
    else {
        panic!("{:?}", adaptation.outcome)
    };
    assert_eq!(*iterations, 5);
    assert_eq!(procedure.len(), 5);
    assert_eq!(procedure[3].name, "PushHingeLidOpenWithHeldOrange");
    assert!(report.is_valid());

    // The identification example: the drop is the erroneous action, unmet (not (Closed hinge_lid)).
    let first = &r.patch_requests[0];
    assert_eq!(first.kind, ViolationKind::Precondition);
    assert_eq!(first.failing_step, Some(3));
    assert_eq!(
        first.erroneous.as_ref().unwrap().name,
        "OpenGripperToDropOrangeIntoHingeBody"
    );
    assert_eq!(first.unfulfilled_preconditions(), "- (not (Closed hinge_lid))");
    assert!(first.error_state.contains(&Atom::new("Closed", &["hinge_lid"])));
    assert_eq!(first.executed.len(), 3);
    assert!(first.remaining.is_empty());
    // Feedback accumulates for the same violation.
    let kinds: Vec<&Problem> = r.patch_requests[4].feedback.iter().map(|f| &f.problem).collect();
    assert!(matches!(kinds[0], Problem::Unparsable { .. }));
    assert!(matches!(kinds[1], Problem::PatchDidNotApply { .. }));
    assert!(
        matches!(
            kinds[2],
            Problem::NotResolved {
                failing_step: Some(4),
                ..
            }
        ),
        "{:?}",
        kinds[2]
    );
    assert!(matches!(kinds[3], Problem::MultiplePatches { count: 2 }));
    assert!(
        r.patch_requests[4].feedback[1]
            .message
            .contains("closest candidate")
    );

    // The trace records every proposal and serialises.
    let proposals = adaptation
        .trace
        .events
        .iter()
        .filter(|e| matches!(e, TraceEvent::Proposal { .. }))
        .count();
    assert_eq!(proposals, 5);
    let json = serde_json::to_string(&adaptation).unwrap();
    let back: Adaptation = serde_json::from_str(&json).unwrap();
    assert_eq!(back, adaptation);
}

#[test]
fn removal_then_goal_violation_then_budget() {
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    // Removing the erroneous drop resolves that violation but leaves the goal unmet: the
    // orange is not in the box, and it is still held.
    r.patches.push_back(refinement(&drop_block(), ""));
    r.patches.push_back("still no patch".into());
    let config = AdaptConfig {
        budget: 2,
        ..Default::default()
    };
    let adaptation = pollster::block_on(run(&mut r, &demo(), &target(), &config)).unwrap();
    assert_eq!(r.patch_requests[1].kind, ViolationKind::Goal);
    assert_eq!(
        r.patch_requests[1].unfulfilled_preconditions(),
        "- (InsideOf orange hinge_body)\n- (forall (?x - thing) (not (GripperHolding ?x)))"
    );
    assert!(r.patch_requests[1].erroneous.is_none());
    let Outcome::Unresolved {
        best,
        last,
        last_violation,
        iterations,
    } = adaptation.outcome
    else {
        panic!()
    };
    assert_eq!(iterations, 2);
    assert_eq!(last.len(), 3);
    assert_eq!(best.len(), 3, "all three remaining steps apply");
    assert_eq!(last_violation.unwrap().kind, ViolationKind::Goal);
}

#[test]
fn a_reasoner_without_any_proposal_stops_the_loop_unresolved() {
    // No patch scripted: the reasoner says it has none (exhausted) at the first request.
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    let adaptation = pollster::block_on(run(&mut r, &demo(), &target(), &AdaptConfig::default())).unwrap();
    assert_eq!(r.patch_requests.len(), 1, "the same question is not asked again");
    let Outcome::Unresolved {
        iterations,
        last_violation,
        ..
    } = &adaptation.outcome
    else {
        panic!("{:?}", adaptation.outcome)
    };
    assert_eq!(*iterations, 0);
    assert!(last_violation.is_some());
    assert!(
        adaptation.trace.events.iter().any(|e| matches!(
            e,
            TraceEvent::GaveUp { iteration: 0, message } if message.contains("script exhausted")
        )),
        "{:?}",
        adaptation.trace.events
    );
}

#[test]
fn ablations_change_what_is_checked_and_shown() {
    // w/o Eq. 8: the wiggle patch (which does not fix the lid) is accepted.
    let wiggle = refinement(
        &drop_block(),
        &format!(
            "{}\n\n{}",
            block(
                "Wiggle",
                &["(GripperHolding orange)"],
                &["(GripperHolding orange)"]
            ),
            drop_block()
        ),
    );
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    r.patches.push_back(wiggle.clone());
    let config = AdaptConfig {
        budget: 1,
        ablation: Ablation::NO_VERIFICATION,
        ..Default::default()
    };
    let a = pollster::block_on(run(&mut r, &demo(), &target(), &config)).unwrap();
    let Outcome::Unresolved { last, .. } = &a.outcome else {
        panic!()
    };
    assert_eq!(last[3].name, "Wiggle");

    // w/o Eq. 6: the request hides the failure; a fixing patch is still verified and accepted.
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    r.patches.push_back(wiggle.clone());
    r.patches.push_back(refinement(
        &drop_block(),
        &format!("{}\n\n{}", open_lid_block(), drop_block()),
    ));
    let config = AdaptConfig {
        ablation: Ablation::NO_IDENTIFICATION,
        ..Default::default()
    };
    let a = pollster::block_on(run(&mut r, &demo(), &target(), &config)).unwrap();
    assert!(a.outcome.is_adapted());
    assert_eq!(r.patch_requests[0].kind, ViolationKind::Unidentified);
    assert!(r.patch_requests[0].erroneous.is_none() && r.patch_requests[0].unmet.is_empty());
    assert!(matches!(
        r.patch_requests[1].feedback[0].problem,
        Problem::NotResolved { .. }
    ));

    // w/o both: one revision, unchecked.
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    r.patches.push_back(wiggle);
    let config = AdaptConfig {
        ablation: Ablation::NO_IDENTIFICATION_NO_VERIFICATION,
        ..Default::default()
    };
    let a = pollster::block_on(run(&mut r, &demo(), &target(), &config)).unwrap();
    assert!(!a.outcome.is_adapted());
    assert_eq!(r.patch_requests.len(), 1);
}

#[test]
fn a_stated_target_goal_replaces_the_derived_one() {
    let same = |goal: Option<&str>| Target {
        init: demo().states[0].clone(),
        task: task(),
        scene_names: Vec::new(),
        goal: goal.map(|g| crate::text::parse_formula(g).unwrap()),
    };
    // The demonstrated procedure reaches the derived goal from the demo's own start, so
    // nothing is asked; a target that also wants the lid closed is a goal violation the
    // loop must patch, and the world model it returns carries that goal.
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    let a = pollster::block_on(run(&mut r, &demo(), &same(None), &AdaptConfig::default())).unwrap();
    assert!(matches!(a.outcome, Outcome::Adapted { iterations: 0, .. }));
    let stated = "(and (InsideOf orange hinge_body) (Closed hinge_lid))";
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    let a = pollster::block_on(run(&mut r, &demo(), &same(Some(stated)), &AdaptConfig::default())).unwrap();
    assert_eq!(
        a.world_model.goal.to_string(),
        crate::text::parse_formula(stated).unwrap().to_string()
    );
    assert!(matches!(a.outcome, Outcome::Unresolved { .. }), "{:?}", a.outcome);
    assert_eq!(r.patch_requests.len(), 1);
    let unmet = format!("{:?}", r.patch_requests[0]);
    assert!(unmet.contains("Closed") && unmet.contains("hinge_lid"), "{unmet}");
    // Without the goal check no goal is required, stated or not.
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    let config = AdaptConfig {
        goal_check: false,
        ..AdaptConfig::default()
    };
    let a = pollster::block_on(run(&mut r, &demo(), &same(Some(stated)), &config)).unwrap();
    assert!(matches!(a.outcome, Outcome::Adapted { iterations: 0, .. }));
}

#[test]
fn consistent_target_needs_no_patch_and_budget_table() {
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    let same = Target {
        init: demo().states[0].clone(),
        task: task(),
        scene_names: Vec::new(),
        goal: None,
    };
    let a = pollster::block_on(run(&mut r, &demo(), &same, &AdaptConfig::default())).unwrap();
    assert!(matches!(a.outcome, Outcome::Adapted { iterations: 0, .. }));
    assert!(r.patch_requests.is_empty());
}

#[test]
fn goal_excludes_embodiment_atoms() {
    let s0 = state(&["(GripperOpen)", "(FingerGripper)", "(OnTopOf a floor)"]);
    let s1 = state(&[
        "(GripperClosed)",
        "(GripperHolding a)",
        "(FingerGripper)",
        "(Gathered a)",
    ]);
    let s2 = state(&[
        "(GripperClosed)",
        "(GripperHolding a)",
        "(FingerGripper)",
        "(Gathered a)",
        "(InsideOf a box)",
    ]);
    let mut v = Vocabulary::new();
    v.declare(
        "Gathered",
        &["x"],
        crate::predicates::Category::Physics,
        "gathered",
    )
    .unwrap();
    let g = derive_goal(&[s0, s1, s2], &v);
    // The last state holds `a`, so only the vacuum's "nothing attached" joins the goal.
    assert_eq!(
        g.to_string(),
        "(and (Gathered a) (InsideOf a box) (forall (?x - thing) (not (VacuumAttached ?x))))"
    );
}

#[test]
fn an_unreadable_transition_is_numbered_from_one_like_the_reasoners_errors() {
    let mut r = Scripted::default();
    let config = AdaptConfig::default();
    r.induction.extend(std::iter::repeat_n(
        "no operator here".to_string(),
        config.induction_tries,
    ));
    let mut trace = Trace::default();
    let err = pollster::block_on(construct_world_model(&mut r, &demo(), &config, &mut trace)).unwrap_err();
    assert_eq!(
        err,
        AdaptError::NoOperator {
            step: 0,
            attempts: config.induction_tries
        }
    );
    assert!(
        err.to_string()
            .starts_with("no parsable operator for transition 1 "),
        "{err}"
    );
}

#[test]
fn misspelt_names_are_refused_with_the_nearest_known_one_and_re_asked() {
    // A vacuous precondition over a predicate that does not exist would verify: it is
    // refused as unreadable instead, and the second reply is the good one.
    let mut r = Scripted::default();
    r.induction.push_back(induction_reply(
        APPROACH.0,
        &[
            "(GripperOpen)",
            "(forall (?y - thing) (not (gripper_holding ?y)))",
        ],
        APPROACH.2,
    ));
    r.induction.extend(good_inductions());
    let mut trace = Trace::default();
    let wm = pollster::block_on(construct_world_model(
        &mut r,
        &demo(),
        &AdaptConfig::default(),
        &mut trace,
    ))
    .unwrap();
    assert!(wm.is_verified());
    let fb = &r.induction_requests[1].feedback[0];
    assert!(fb.problem.is_unreadable());
    assert!(
        fb.message
            .contains("`gripper_holding` is not a predicate; did you mean `GripperHolding`?"),
        "{}",
        fb.message
    );

    // A patch that names an object the target does not have goes back the same way.
    let mut r = Scripted {
        induction: good_inductions(),
        ..Default::default()
    };
    r.patches.push_back(refinement(
        &drop_block(),
        &format!(
            "{}\n\n{}",
            block(
                "PushHingeLidOpenWithHeldOrange",
                &["(GripperHolding orange)", "(Closed hinge_lidd)"],
                &["(Open hinge_lid)", "(not (Closed hinge_lid))"],
            ),
            drop_block()
        ),
    ));
    r.patches.push_back(refinement(
        &drop_block(),
        &format!("{}\n\n{}", open_lid_block(), drop_block()),
    ));
    let adaptation = pollster::block_on(run(&mut r, &demo(), &target(), &AdaptConfig::default())).unwrap();
    assert!(
        matches!(adaptation.outcome, Outcome::Adapted { .. }),
        "{:?}",
        adaptation.outcome
    );
    let fb = &r.patch_requests[1].feedback[0];
    assert!(
        fb.message
            .contains("`hinge_lidd` is not an object of this task; did you mean `hinge_lid`?"),
        "{}",
        fb.message
    );
}
