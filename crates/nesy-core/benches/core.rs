//! The four figures of the issue: apply, verify, parse, plan.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nesy_core::format_procedure;
use nesy_core::planner::{PlannerConfig, plan};
use nesy_core::text::parse_procedure;
use nesy_core::{CompiledProcedure, implicit_universe, verify_procedure};
use nesy_core::{Universe, apply_in};

mod workload;

fn bench(c: &mut Criterion) {
    let state = workload::state_200();
    let op = workload::operator_20();
    let universe = implicit_universe(&state, std::slice::from_ref(&op), None);
    let compiled = op.compile(&universe).unwrap();
    c.bench_function("apply_20_literals_200_atoms/compiled", |b| {
        b.iter(|| black_box(compiled.apply(black_box(&state), &op).unwrap()))
    });
    c.bench_function("apply_20_literals_200_atoms/from_operator", |b| {
        b.iter(|| black_box(apply_in(&universe, black_box(&state), &op).unwrap()))
    });

    let ops = workload::procedure_116();
    let goal = workload::goal_116();
    assert!(verify_procedure(&state, &ops, Some(&goal)).is_valid());
    let universe: Universe = implicit_universe(&state, &ops, Some(&goal));
    let compiled = CompiledProcedure::new(&universe, &ops, Some(&goal));
    assert!(compiled.verify(&state).is_valid());
    c.bench_function("verify_116_steps/compiled", |b| {
        b.iter(|| black_box(compiled.verify(black_box(&state))))
    });
    c.bench_function("verify_116_steps/from_operators", |b| {
        b.iter(|| black_box(verify_procedure(black_box(&state), &ops, Some(&goal))))
    });

    let text = format_procedure(&ops);
    assert_eq!(parse_procedure(&text).unwrap().len(), 116);
    c.bench_function("parse_116_action_procedure", |b| {
        b.iter(|| black_box(parse_procedure(black_box(&text)).unwrap()))
    });

    let (domain, problem) = workload::blocksworld_10();
    let u = domain.universe(&problem).unwrap();
    let cfg = PlannerConfig::default();
    let found = plan(&domain.actions, &u, &problem.init, &problem.goal, &cfg).unwrap();
    eprintln!(
        "blocksworld-10: plan of {} steps, {} states expanded",
        found.steps.len(),
        found.expanded
    );
    let mut group = c.benchmark_group("plan_blocksworld_10");
    group.sample_size(10);
    group.bench_function("gbfs_hff", |b| {
        b.iter(|| black_box(plan(&domain.actions, &u, &problem.init, &problem.goal, &cfg).unwrap()))
    });
    group.finish();

    // A high-complexity scene of the benchmark over nesy's world domain, with and without
    // preferred operators (the peer: one open list).
    let root = nesy_testkit::workspace_root();
    let world = nesy_core::pddl::parse_domain(
        &std::fs::read_to_string(root.join("assets/pddl/nesy-world.pddl")).unwrap(),
    )
    .unwrap();
    let scene = nesy_core::pddl::parse_problem(
        &std::fs::read_to_string(root.join("fixtures/planning/obst_high_01_s1.pddl")).unwrap(),
        &world,
    )
    .unwrap();
    let u = world.universe(&scene).unwrap();
    let mut group = c.benchmark_group("plan_nesy_world_obst_high_01_s1");
    group.sample_size(10);
    for (name, preferred_operators) in [("gbfs_hff_preferred", true), ("gbfs_hff_single_queue", false)] {
        let cfg = PlannerConfig {
            preferred_operators,
            time_limit: None,
            max_expansions: 2_000_000,
            ..PlannerConfig::default()
        };
        let found = plan(&world.actions, &u, &scene.init, &scene.goal, &cfg).unwrap();
        eprintln!(
            "obst_high_01_s1 ({name}): plan of {} steps, {} states expanded",
            found.steps.len(),
            found.expanded
        );
        group.bench_function(name, |b| {
            b.iter(|| black_box(plan(&world.actions, &u, &scene.init, &scene.goal, &cfg).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
