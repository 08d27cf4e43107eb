//! The few-shot examples are real: every induction and state-translation example is
//! reproduced by replaying its recorded robot calls in nesy-sim and observing the states,
//! every induced operator verifies against its transition (as the adaptation loop checks
//! replies), and every code example runs in nesy-policy's embedded Python against its scene
//! and leaves the scene in the expected state.

use std::path::PathBuf;

use nesy_core::Embodiment;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::adapt::{TransitionCheck, check_transition};
use nesy_core::{Tier, Vocabulary};
use nesy_policy::{EpisodeFactory, EpisodeSpec, Limits, Outcome, SimEpisodes, run_in_process};
use nesy_reasoner::prompts::examples::{project_operator, project_state};
use nesy_reasoner::prompts::{Prompts, api_docs};
use nesy_sim::api::{ApiCall, ApiError, RobotApi};
use nesy_sim::perception::observer::observe;
use nesy_sim::scene::SceneSpec;
use nesy_sim::world::Sim;

fn prompts_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("prompts")
}

fn scene_path(scene: &str) -> PathBuf {
    prompts_dir().join("examples/scenes").join(scene)
}

fn build(scene: &str, embodiment: Embodiment, in_state: bool) -> Sim {
    let path = scene_path(scene);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut spec = SceneSpec::from_json_str(&text, &path.display().to_string()).unwrap();
    spec.embodiment = embodiment;
    spec.embodiment_in_state = in_state;
    Sim::new(&spec).unwrap_or_else(|e| panic!("{scene}: {e}"))
}

/// Performs one recorded call on the simulator.
fn perform(sim: &mut Sim, call: &ApiCall) -> Result<(), ApiError> {
    match call {
        ApiCall::MoveGripperTo {
            obj_name,
            pointing_to,
            depth,
        } => sim.move_gripper_to(obj_name, *pointing_to, *depth),
        ApiCall::MoveToPosition {
            pos,
            pointing_to,
            lift_clearance,
            angle,
        } => sim.move_to_position(*pos, *pointing_to, *lift_clearance, *angle),
        ApiCall::MoveParallel {
            move_dir,
            offset,
            pointing_to,
        } => sim.move_parallel(*move_dir, *offset, *pointing_to),
        ApiCall::GraspHandle { handle_name } => sim.grasp_handle(handle_name),
        ApiCall::ReleaseHandle => sim.release_handle(),
        ApiCall::OpenGripper => sim.open_gripper(),
        ApiCall::CloseGripper => sim.close_gripper(),
        ApiCall::AttachVacuumHandle { handle_name } => sim.attach_vacuum_handle(handle_name),
        ApiCall::DetachVacuumHandle => sim.detach_vacuum_handle(),
        ApiCall::ActivateVacuum => sim.activate_vacuum(),
        ApiCall::DeactivateVacuum => sim.deactivate_vacuum(),
        other => panic!("example calls are actions, found {other:?}"),
    }
}

fn replay(file: &str, sim: &mut Sim, calls: &[serde_json::Value]) {
    for (i, value) in calls.iter().enumerate() {
        let call: ApiCall = serde_json::from_value(value.clone())
            .unwrap_or_else(|e| panic!("{file}: call {i} is not an ApiCall: {e}"));
        perform(sim, &call).unwrap_or_else(|e| panic!("{file}: call {i} ({}) refused: {e}", call.name()));
    }
}

fn as_toml_array(state: &State) -> String {
    let lines: Vec<String> = state
        .sorted_by_text()
        .iter()
        .map(|a| format!("    \"{a}\","))
        .collect();
    format!("[\n{}\n]", lines.join("\n"))
}

fn scene_objects(sim: &mut Sim) -> Vec<String> {
    let gripper = ["gripper", "vacuum_gripper"];
    sim.get_obj_names()
        .into_iter()
        .filter(|n| !gripper.contains(&n.as_str()))
        .collect()
}

#[test]
fn induction_examples_are_observed_transitions_their_operators_explain() {
    let prompts = Prompts::load().unwrap();
    let vocabulary = Vocabulary::new();
    assert!(prompts.induction_examples().len() >= 5);
    for example in prompts.induction_examples() {
        let file = example.file;
        let mut sim = build(&example.scene, example.embodiment, true);
        assert_eq!(scene_objects(&mut sim), example.objects, "{file}: objects");
        replay(file, &mut sim, &example.setup);
        let previous = observe(&sim);
        replay(file, &mut sim, std::slice::from_ref(&example.action));
        let current = observe(&sim);
        assert_eq!(
            previous,
            example.previous,
            "{file}: the scene now gives this previous state:\n{}",
            as_toml_array(&previous)
        );
        assert_eq!(
            current,
            example.current,
            "{file}: the scene now gives this current state:\n{}",
            as_toml_array(&current)
        );
        let objects: Vec<Symbol> = example.objects.iter().map(|o| Symbol::new(o)).collect();
        check_transition(
            &previous,
            &current,
            &example.operator,
            &objects,
            TransitionCheck::Exact,
        )
        .unwrap_or_else(|p| panic!("{file}: the example operator does not verify: {p:?}"));
        // Projected onto each tier that shows it, the example still verifies.
        let tiers: &[Tier] = if example.extended_only {
            &[Tier::Extended]
        } else {
            &[Tier::Full, Tier::Extended]
        };
        for &tier in tiers {
            let (p, c) = (
                project_state(&previous, &vocabulary, tier),
                project_state(&current, &vocabulary, tier),
            );
            let op = project_operator(&example.operator, &vocabulary, tier);
            check_transition(&p, &c, &op, &objects, TransitionCheck::Exact)
                .unwrap_or_else(|e| panic!("{file} in tier {tier}: {e:?}"));
            let embodiment_atoms = ["FingerGripper", "VacuumSuction"];
            let mentions = |s: &State| s.iter().any(|a| embodiment_atoms.contains(&a.pred().as_str()));
            assert_eq!(mentions(&p), tier == Tier::Extended, "{file} in tier {tier}");
        }
    }
}

#[test]
fn state_examples_are_observed_states() {
    let prompts = Prompts::load().unwrap();
    assert!(!prompts.state_examples().is_empty());
    for example in prompts.state_examples() {
        let file = example.file;
        let mut sim = build(&example.scene, example.embodiment, false);
        assert_eq!(scene_objects(&mut sim), example.objects, "{file}: objects");
        replay(file, &mut sim, &example.setup);
        let observed = observe(&sim);
        let given = State::from_atoms(example.known.iter().chain(example.answer.iter()).copied());
        assert_eq!(
            observed,
            given,
            "{file}: the scene now gives\n{}",
            as_toml_array(&observed)
        );
        assert!(
            example.known.iter().all(|a| !example.answer.contains(a)),
            "{file}: the answer repeats a known atom"
        );
    }
}

fn run_code_example(embodiment: Embodiment) {
    let prompts = Prompts::load().unwrap();
    let examples = prompts.code_examples(embodiment);
    assert_eq!(examples.len(), 5, "pick, box grid, hinge, drawer, sweep");
    let other: &[&str] = match embodiment {
        Embodiment::Finger => &api_docs::VACUUM_FUNCTIONS,
        Embodiment::Vacuum => &api_docs::FINGER_ONLY_FUNCTIONS,
    };
    for example in examples {
        let file = example.file;
        // Never mix end effectors, not even in a comment.
        for name in other {
            assert!(!example.code.contains(name), "{file} uses {name}");
        }
        for name in &example.summary {
            assert_eq!(
                nesy_core::text::normalize_action_name(name).as_deref(),
                Some(name.as_str()),
                "{file}: summary names are action names"
            );
        }
        let mut sim = build(&example.scene, embodiment, false);
        assert_eq!(scene_objects(&mut sim), example.objects, "{file}: objects");

        let spec = EpisodeSpec::Scene {
            path: scene_path(&example.scene),
            embodiment: Some(embodiment),
        };
        let episode = SimEpisodes.build(&spec).unwrap();
        let result = run_in_process(&example.code, episode, &Limits::default(), None).unwrap();
        assert_eq!(
            result.outcome,
            Outcome::Ok,
            "{file}: {:#?}\n{}",
            result.outcome,
            result.stdout.text
        );
        for entry in &result.trace {
            assert!(
                entry.result.is_ok(),
                "{file}: call {} {} was refused: {:?}",
                entry.index,
                entry.call.name(),
                entry.result
            );
        }
        let state = result.final_state.expect("the simulator reports its final state");
        let text = state.to_string();
        for atom in &example.expect {
            assert!(
                text.lines().any(|l| l.trim_start_matches("- ") == atom),
                "{file}: expected {atom} after the run, state:\n{text}"
            );
        }
    }
}

#[test]
fn finger_code_examples_run_in_the_simulator() {
    run_code_example(Embodiment::Finger);
}

#[test]
fn vacuum_code_examples_run_in_the_simulator() {
    run_code_example(Embodiment::Vacuum);
}
