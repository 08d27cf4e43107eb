//! The reference responder end to end: an expert demonstration recorded in the simulator,
//! a counterfactual target scene, `nesy_core::adapt::run` driven by `VlmReasoner` over a
//! `VlmClient` whose transport is the oracle, code generation through the same client
//! (nesy-sim's template compiler), and the program executed in the simulator by
//! nesy-policy.

use std::sync::Arc;

use nesy_core::Embodiment;
use nesy_core::Symbol;
use nesy_core::adapt::{AdaptConfig, Demonstration, Outcome, Target, TaskContext, run};
use nesy_core::metrics::SubtaskResult;
use nesy_core::{Tier, Vocabulary};
use nesy_oracle::{OracleNoise, OracleStats, OracleTransport};
use nesy_pipeline::synth::SandboxChecks;
use nesy_policy::{Limits, run_in_process};
use nesy_reasoner::codegen::CodeGenerationRequest;
use nesy_reasoner::{KeyframeList, VlmReasoner};
use nesy_sim::perception::observer::observe;
use nesy_sim::scene::SceneSpec;
use nesy_sim::scene::SubtaskKind;
use nesy_sim::tasks::TaskConfig;
use nesy_sim::tasks::goal::GoalMonitor;
use nesy_sim::world::Sim;
use nesy_vlm::{BackendKind, VlmClient, VlmConfig};

use crate::common::Keyframes;

fn scene(kind: SubtaskKind, obst: u8, embodiment: Embodiment, in_state: bool) -> SceneSpec {
    TaskConfig {
        embodiment_in_state: in_state,
        ..TaskConfig::single(kind, 1, obst, 0, embodiment)
    }
    .generate()
    .unwrap()
    .scene
}

fn objects(sim: &Sim) -> Vec<Symbol> {
    nesy_sim::perception::observer::snapshot(sim)
        .objects
        .iter()
        .map(|o| Symbol::new(&o.name))
        .collect()
}

struct Case {
    kind: SubtaskKind,
    source_obst: u8,
    target_obst: u8,
    source: Embodiment,
    target: Embodiment,
}

struct RunResult {
    outcome: Outcome,
    stats: OracleStats,
    statuses: Vec<SubtaskResult>,
    code: String,
}

async fn adapt_and_execute(case: &Case, noise: OracleNoise, budget: usize) -> RunResult {
    let cross = case.source != case.target;
    let tier = if cross { Tier::Extended } else { Tier::Full };
    // The demonstration.
    let source_scene = scene(case.kind, case.source_obst, case.source, cross);
    let mut sim = Sim::new(&source_scene).unwrap();
    let source_objects = objects(&sim);
    let init = observe(&sim);
    sim.add_hook(Box::new(Keyframes::default()));
    nesy_sim::tasks::experts::run(&mut sim, &source_scene).unwrap();
    let recorded = &sim.hook::<Keyframes>().unwrap().calls;
    let mut states = vec![init];
    states.extend(recorded.iter().map(|(_, s)| s.clone()));
    let keyframes = KeyframeList::default();
    let demo_calls = recorded.iter().map(|(c, _)| Some(c.clone())).collect();
    let demo = Demonstration {
        states,
        task: TaskContext {
            instruction: source_scene.instruction.clone(),
            objects: source_objects,
            tier,
            vocabulary: Vocabulary::default(),
        },
    };
    // The target.
    let target_scene = scene(case.kind, case.target_obst, case.target, cross);
    let target_sim = Sim::new(&target_scene).unwrap();
    let target_objects = objects(&target_sim);
    let target = Target {
        init: observe(&target_sim),
        task: TaskContext {
            instruction: target_scene.instruction.clone(),
            objects: target_objects.clone(),
            tier,
            vocabulary: Vocabulary::default(),
        },
        scene_names: Vec::new(),
        goal: None,
    };
    // The oracle behind the real client and reasoner.
    let oracle = Arc::new(
        OracleTransport::new()
            .unwrap()
            .with_noise(noise, 7)
            .with_demo_calls(demo_calls),
    );
    let client = VlmClient::with_transport(
        &VlmConfig::new(BackendKind::OpenAi, "nesy-oracle"),
        oracle.clone(),
    );
    let mut reasoner = VlmReasoner::new(client)
        .unwrap()
        .with_keyframes(Arc::new(keyframes))
        .with_embodiments(case.source, case.target)
        .with_program_check(Arc::new(SandboxChecks));
    let config = AdaptConfig {
        budget,
        ..AdaptConfig::default()
    };
    let adaptation = run(&mut reasoner, &demo, &target, &config).await.unwrap();
    let mut statuses = Vec::new();
    let mut code = String::new();
    if let Outcome::Adapted { procedure, .. } = &adaptation.outcome {
        let policy = reasoner
            .generate_code(&CodeGenerationRequest {
                instruction: target_scene.instruction.clone(),
                objects: target_objects.iter().map(|o| o.to_string()).collect(),
                procedure: procedure.clone(),
                plan: Vec::new(),
                embodiment: case.target,
                extended: cross,
                tools: false,
                protective_stop: false,
            })
            .await
            .unwrap();
        code = policy.code.clone();
        let mut episode = Sim::new(&target_scene).unwrap();
        GoalMonitor::attach(&mut episode).unwrap();
        let result = run_in_process(&policy.code, Box::new(episode), &Limits::default(), None).unwrap();
        assert!(result.is_ok(), "{:?}\n{}", result.outcome, policy.code);
        statuses = result
            .subtasks
            .unwrap_or_default()
            .into_iter()
            .map(|s| s.status)
            .collect();
    }
    RunResult {
        outcome: adaptation.outcome,
        stats: oracle.stats(),
        statuses,
        code,
    }
}

fn assert_full_success(r: &RunResult) {
    assert!(r.outcome.is_adapted(), "{:?}", r.outcome);
    assert!(!r.statuses.is_empty(), "no goal checks ran\n{}", r.code);
    assert!(
        r.statuses.iter().all(|s| *s == SubtaskResult::FullSuccess),
        "{:?}\n{}",
        r.statuses,
        r.code
    );
}

#[tokio::test]
async fn stacked_cube_target_gets_an_unstacking_patch_and_succeeds() {
    let r = adapt_and_execute(
        &Case {
            kind: SubtaskKind::PickPlace,
            source_obst: 0,
            target_obst: 1,
            source: Embodiment::Finger,
            target: Embodiment::Finger,
        },
        OracleNoise::NONE,
        10,
    )
    .await;
    println!("{:?}", r.stats);
    assert_full_success(&r);
    assert!(r.stats.patches >= 1);
}

#[tokio::test]
async fn closed_hinge_lid_target_gets_an_opening_patch_and_succeeds() {
    let r = adapt_and_execute(
        &Case {
            kind: SubtaskKind::PutInHinge,
            source_obst: 0,
            target_obst: 1,
            source: Embodiment::Finger,
            target: Embodiment::Finger,
        },
        OracleNoise::NONE,
        10,
    )
    .await;
    println!("{:?}", r.stats);
    assert_full_success(&r);
}

#[tokio::test]
async fn finger_demo_is_converted_for_the_vacuum_robot() {
    let r = adapt_and_execute(
        &Case {
            kind: SubtaskKind::PickPlace,
            source_obst: 0,
            target_obst: 0,
            source: Embodiment::Finger,
            target: Embodiment::Vacuum,
        },
        OracleNoise::NONE,
        10,
    )
    .await;
    println!("{:?}", r.stats);
    assert_full_success(&r);
}

#[tokio::test]
async fn redundant_lid_opening_is_removed_when_the_target_lid_is_open() {
    let r = adapt_and_execute(
        &Case {
            kind: SubtaskKind::PutInHinge,
            source_obst: 1,
            target_obst: 0,
            source: Embodiment::Finger,
            target: Embodiment::Finger,
        },
        OracleNoise::NONE,
        10,
    )
    .await;
    println!("{:?}", r.stats);
    assert_full_success(&r);
    assert!(
        !r.code.contains("for degrees in [135.0, 90.0, 60.0]"),
        "the lid is opened again:\n{}",
        r.code
    );
}

fn iterations(outcome: &Outcome) -> usize {
    match outcome {
        Outcome::Adapted { iterations, .. } | Outcome::Unresolved { iterations, .. } => *iterations,
    }
}

#[tokio::test]
async fn bad_patches_cost_iterations_but_the_adaptation_still_verifies() {
    let case = Case {
        kind: SubtaskKind::PutInHinge,
        source_obst: 0,
        target_obst: 1,
        source: Embodiment::Finger,
        target: Embodiment::Finger,
    };
    let clean = adapt_and_execute(&case, OracleNoise::NONE, 10).await;
    let noisy = adapt_and_execute(&case, "bad-patch=0.6".parse().unwrap(), 10).await;
    println!("clean {:?}\nnoisy {:?}", clean.stats, noisy.stats);
    assert!(noisy.stats.corrupted_patches >= 1, "{:?}", noisy.stats);
    assert!(iterations(&noisy.outcome) > iterations(&clean.outcome));
    assert_full_success(&noisy);
}

#[tokio::test]
async fn heavy_noise_ends_verified_or_honestly_unresolved() {
    let case = Case {
        kind: SubtaskKind::PickPlace,
        source_obst: 0,
        target_obst: 1,
        source: Embodiment::Finger,
        target: Embodiment::Finger,
    };
    let r = adapt_and_execute(&case, "op-drop=0.1,op-flip=0.1,bad-patch=0.5".parse().unwrap(), 4).await;
    println!("{:?} {:?}", r.stats, r.outcome.is_adapted());
    assert!(r.stats.perturbed_literals > 0);
    match &r.outcome {
        Outcome::Adapted { report, .. } => {
            // Whatever noise did on the way, what is returned as adapted verifies.
            assert!(report.is_valid());
        }
        Outcome::Unresolved { iterations, .. } => assert!(*iterations <= 4),
    }
}
