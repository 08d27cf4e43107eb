//! Runs the scripted expert on a chosen list of benchmark scenes (scenario id and side) and
//! prints one line per scene: the quick loop for re-checking the scenes a full
//! `nesy scenarios sweep` reported as failures.
//!
//! ```text
//! cargo run --release -p nesy-sim --example scenario_batch -- [--threads N] ID:SIDE ...
//! cargo run --release -p nesy-sim --example scenario_batch -- [--threads N] --report SWEEP.jsonl
//! cargo run --release -p nesy-sim --example scenario_batch -- [--threads N] --all
//! ```
//!
//! `SIDE` is `source` or `target`. With `--report`, the scenes are the failures listed in a
//! sweep report (lines whose `full_success` is false). The suite is the generated one
//! (`scenario::generate_suite`, identical to `fixtures/benchmark/`).

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use nesy_sim::demo::run_expert;
use nesy_sim::tasks::scenario::{Scenario, Side, generate_suite, scenarios};

fn side_of(name: &str) -> Side {
    match name {
        "source" => Side::Source,
        "target" => Side::Target,
        other => panic!("side must be source or target, got {other:?}"),
    }
}

/// The failed scenes of a sweep report (JSON lines with `scenario`, `side`, `full_success`).
fn failures(path: &str) -> Vec<(String, Side)> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {path}: {e}"));
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .filter_map(|line| {
            let v: serde_json::Value =
                serde_json::from_str(line).unwrap_or_else(|e| panic!("{path}: bad line {line:?}: {e}"));
            if v["full_success"].as_bool() == Some(true) {
                return None;
            }
            let id = v["scenario"].as_str().expect("scenario id").to_owned();
            Some((id, side_of(v["side"].as_str().expect("side"))))
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut threads = 2usize;
    let mut wanted: Vec<(String, Side)> = Vec::new();
    let all = scenarios(&generate_suite());
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--threads" => {
                threads = args[i + 1].parse().expect("--threads expects a number");
                i += 1;
            }
            "--all" => {
                for s in &all {
                    wanted.push((s.id.clone(), Side::Source));
                    wanted.push((s.id.clone(), Side::Target));
                }
            }
            "--report" => {
                wanted.extend(failures(&args[i + 1]));
                i += 1;
            }
            item => {
                let (id, side) = item.split_once(':').expect("scenes are ID:SIDE");
                wanted.push((id.to_owned(), side_of(side)));
            }
        }
        i += 1;
    }
    let jobs: Vec<(&Scenario, Side)> = wanted
        .iter()
        .map(|(id, side)| {
            let s = all
                .iter()
                .find(|s| &s.id == id)
                .unwrap_or_else(|| panic!("no scenario {id}"));
            (s, *side)
        })
        .collect();
    let next = AtomicUsize::new(0);
    let ok = AtomicUsize::new(0);
    let displaced = AtomicUsize::new(0);
    let out = Mutex::new(());
    let started = Instant::now();
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            scope.spawn(|| {
                while let Some(&(s, side)) = jobs.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let task = s.generate(side).expect("scenario generates");
                    let run = run_expert(&task.scene).expect("scene builds");
                    let results: Vec<&str> = run.outcome.subtasks.iter().map(|o| o.result.as_str()).collect();
                    let kinds: Vec<String> = task.scene.goals.iter().map(|g| g.kind().to_string()).collect();
                    if run.full_success() {
                        ok.fetch_add(1, Ordering::Relaxed);
                    }
                    let _guard = out.lock().unwrap();
                    println!(
                        "{} {} {:<6} {} {:?} {:?}{}",
                        if run.full_success() { "OK  " } else { "FAIL" },
                        s.id,
                        side.as_str(),
                        task.scene.embodiment.as_str(),
                        kinds,
                        results,
                        run.expert_error.map(|e| format!(" -- {e}")).unwrap_or_default()
                    );
                    if !run.outcome.displaced.is_empty() {
                        displaced.fetch_add(1, Ordering::Relaxed);
                        println!("     displaced at the end: {}", run.outcome.displaced.join(", "));
                    }
                }
            });
        }
    });
    println!(
        "{}/{} full_success in {:.1} s; {} end with a latched object displaced",
        ok.load(Ordering::Relaxed),
        jobs.len(),
        started.elapsed().as_secs_f64(),
        displaced.load(Ordering::Relaxed)
    );
}
