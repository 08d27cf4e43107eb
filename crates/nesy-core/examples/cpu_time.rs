//! Per-operation **CPU time** of the benchmark workloads, read from `/proc/self/stat`
//! (user + system ticks) over loops of at least two CPU seconds each.
//!
//! Criterion reports wall-clock time, which on a shared machine (other builds running)
//! includes time the process spent waiting for a core. This measures the cost itself; it
//! complements the criterion figures and does not replace them. Linux only.
//!
//! Usage: `cargo run --release -p nesy-core --example cpu_time`

#[path = "../benches/workload/mod.rs"]
mod workload;

use std::hint::black_box;
use std::time::Instant;

use nesy_core::format_procedure;
use nesy_core::planner::{PlannerConfig, plan};
use nesy_core::text::parse_procedure;
use nesy_core::{CompiledProcedure, implicit_universe};

/// Process CPU time in seconds (user + system), with the kernel's tick resolution.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat (Linux only)");
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')').expect("stat format") + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap();
    ticks / 100.0 // USER_HZ is 100 on Linux
}

fn measure(label: &str, mut f: impl FnMut()) {
    let (cpu0, wall0) = (cpu_seconds(), Instant::now());
    let mut n = 0u64;
    while cpu_seconds() - cpu0 < 2.0 {
        for _ in 0..50 {
            f();
        }
        n += 50;
    }
    let cpu = (cpu_seconds() - cpu0) / n as f64;
    let wall = wall0.elapsed().as_secs_f64() / n as f64;
    let show = |s: f64| {
        if s < 1e-3 {
            format!("{:.3} µs", s * 1e6)
        } else {
            format!("{:.3} ms", s * 1e3)
        }
    };
    println!(
        "{label:<44} cpu {:>12}   wall {:>12}   ({n} iterations)",
        show(cpu),
        show(wall)
    );
}

fn main() {
    let state = workload::state_200();
    let op = workload::operator_20();
    let universe = implicit_universe(&state, std::slice::from_ref(&op), None);
    let compiled = op.compile(&universe).unwrap();
    measure("apply 20-literal operator, 200-atom state", || {
        black_box(compiled.apply(black_box(&state), &op).unwrap());
    });

    let ops = workload::procedure_116();
    let goal = workload::goal_116();
    let universe = implicit_universe(&state, &ops, Some(&goal));
    let procedure = CompiledProcedure::new(&universe, &ops, Some(&goal));
    measure("verify 116-step procedure (compiled)", || {
        black_box(procedure.verify(black_box(&state)));
    });

    let text = format_procedure(&ops);
    measure("parse 116-action procedure text", || {
        black_box(parse_procedure(black_box(&text)).unwrap());
    });

    let (domain, problem) = workload::blocksworld_10();
    let u = domain.universe(&problem).unwrap();
    measure("plan 10-block blocksworld (GBFS, h_FF)", || {
        black_box(
            plan(
                &domain.actions,
                &u,
                &problem.init,
                &problem.goal,
                &PlannerConfig::default(),
            )
            .unwrap(),
        );
    });
}
