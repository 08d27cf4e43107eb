//! Hot paths of the simulator: a pick-and-place call sequence (real-time factor), the
//! three 384² views, and the observer on a 26-part scene.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nesy_sim::api::{Direction, RobotApi};
use nesy_sim::perception::observer::observe;
use nesy_sim::perception::render::{VIEW_SIZE, render_views};
use nesy_sim::scene::SceneSpec;
use nesy_sim::world::Sim;

fn scene(name: &str) -> SceneSpec {
    let path = nesy_testkit::workspace_root()
        .join("fixtures/scenes")
        .join(format!("{name}.json"));
    SceneSpec::from_file(&path).unwrap()
}

/// One cube picked and dropped into the toy box; returns the simulated seconds.
fn pick_and_place(sim: &mut Sim) -> f64 {
    let start = sim.time();
    sim.move_gripper_to("red_cube", Direction::Down, 0.015).unwrap();
    sim.close_gripper().unwrap();
    let c = sim.get_obj_pos("toy_box").unwrap();
    sim.move_to_position([c[0], c[1], 0.6], Direction::Down, 0.12, 0.0)
        .unwrap();
    sim.open_gripper().unwrap();
    sim.time() - start
}

fn benches(c: &mut Criterion) {
    let spec = scene("pick_place_finger");
    let sim_seconds = pick_and_place(&mut Sim::new(&spec).unwrap());
    eprintln!("pick_and_place simulates {sim_seconds:.2} s per iteration");
    let mut group = c.benchmark_group("sim");
    group.sample_size(20);
    group.bench_function("build_world_pick_place_scene", |b| {
        b.iter(|| black_box(Sim::new(&spec).unwrap()))
    });
    group.bench_function("pick_and_place_sequence", |b| {
        b.iter_batched(
            || Sim::new(&spec).unwrap(),
            |mut sim| black_box(pick_and_place(&mut sim)),
            criterion::BatchSize::LargeInput,
        )
    });
    let composite = Sim::new(&scene("composite_all_finger")).unwrap();
    group.bench_function("render_3_views_384_1_thread", |b| {
        b.iter(|| black_box(render_views(&composite, VIEW_SIZE, 1)))
    });
    group.bench_function("render_3_views_384_2_threads", |b| {
        b.iter(|| black_box(render_views(&composite, VIEW_SIZE, 2)))
    });
    group.bench_function("observe_26_parts", |b| b.iter(|| black_box(observe(&composite))));
    group.finish();
}

criterion_group!(sim_benches, benches);
criterion_main!(sim_benches);
