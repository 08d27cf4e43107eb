//! Figures of the embedded runtime (run with `cargo bench -p nesy-policy --bench runtime`):
//! interpreter start-up in-process, the per-call overhead of a robot API call from Python
//! into Rust against the recording test double (no simulation), measured against the same
//! loop calling a Python builtin, and the cost of one in-process episode.

use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use nesy_core::Embodiment;
use nesy_policy::RecordingRobot;
use nesy_policy::{Limits, run_in_process};

const CALLS: usize = 20_000;

fn run(source: &str) -> Duration {
    let limits = Limits {
        api_calls: CALLS + 10,
        action_calls: CALLS + 10,
        ..Limits::default()
    };
    let t0 = Instant::now();
    let result = run_in_process(
        source,
        Box::new(RecordingRobot::new(Embodiment::Finger)),
        &limits,
        None,
    )
    .unwrap();
    assert!(result.is_ok(), "{:?}", result.outcome);
    t0.elapsed()
}

fn benches(c: &mut Criterion) {
    let startup = nesy_policy::initialize().expect("interpreter starts");
    println!(
        "start-up: interpreter {:.2} ms + runtime preparation {:.2} ms = {:.2} ms",
        startup.interpreter.as_secs_f64() * 1e3,
        startup.prepare.as_secs_f64() * 1e3,
        startup.total().as_secs_f64() * 1e3
    );

    let api = format!("for i in range({CALLS}):\n    gripper_is_open()\n");
    let api_with_args =
        format!("for i in range({CALLS}):\n    move_to_position([0.4, 0.1, 0.6], lift_clearance=0.05)\n");
    let baseline = format!("for i in range({CALLS}):\n    len('')\n");
    let mut group = c.benchmark_group("policy");
    group.sample_size(20);
    group.bench_function("api_call_gripper_is_open", |b| {
        b.iter_custom(|iters| (0..iters).map(|_| run(&api)).sum::<Duration>() / CALLS as u32)
    });
    group.bench_function("api_call_move_to_position", |b| {
        b.iter_custom(|iters| (0..iters).map(|_| run(&api_with_args)).sum::<Duration>() / CALLS as u32)
    });
    group.bench_function("baseline_builtin_call", |b| {
        b.iter_custom(|iters| (0..iters).map(|_| run(&baseline)).sum::<Duration>() / CALLS as u32)
    });
    group.bench_function("episode_in_process_pass", |b| b.iter(|| run("pass")));
    group.finish();
}

criterion_group!(runtime, benches);
criterion_main!(runtime);
