//! Runs the scripted experts over many generated tasks and reports the success rate and the
//! cause of every failure.
//!
//! ```text
//! cargo run --release -p nesy-sim --example expert_sweep -- [--variants N] [--composites N] [--threads N]
//! ```
//!
//! Single subtasks: both embodiments × four subtasks × obstruction 0–2 × multi 0–2 ×
//! `--variants` variants (default 3, i.e. 216 tasks). Composites: `--composites` random
//! tasks (default 40) at the benchmark's complexities (2 subtasks at multi 0, 3 at multi 1,
//! all 4 at multi 2), random obstruction levels and embodiments.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use nesy_sim::Embodiment;
use nesy_sim::scene::SubtaskKind;
use nesy_sim::tasks::experts::run_scene;
use nesy_sim::tasks::{SubtaskConfig, TaskConfig};
use nesy_sim::world::rng::Stream;

fn arg(args: &[String], name: &str, default: usize) -> usize {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .map(|v| {
            v.parse()
                .unwrap_or_else(|_| panic!("{name} expects a number, got {v:?}"))
        })
        .unwrap_or(default)
}

fn describe(config: &TaskConfig) -> String {
    let parts: Vec<String> = config
        .subtasks
        .iter()
        .map(|s| format!("{} v{} o{} m{}", s.kind, s.variant, s.obst_level, s.multi_level))
        .collect();
    format!(
        "{} ep{} [{}]",
        config.embodiment,
        config.episode,
        parts.join(", ")
    )
}

fn singles(variants: u64) -> Vec<TaskConfig> {
    let mut out = Vec::new();
    for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
        for kind in SubtaskKind::ALL {
            for obst_level in 0..3 {
                for multi_level in 0..3 {
                    for variant in 0..variants {
                        out.push(TaskConfig::single(
                            kind,
                            variant,
                            obst_level,
                            multi_level,
                            embodiment,
                        ));
                    }
                }
            }
        }
    }
    out
}

fn composites(count: usize) -> Vec<TaskConfig> {
    let mut rng = Stream::new("expert_sweep/composites", 0);
    (0..count)
        .map(|episode| {
            let n = 2 + episode % 3;
            let multi_level = (n - 2) as u8;
            let mut kinds = SubtaskKind::ALL.to_vec();
            rng.shuffle(&mut kinds);
            kinds.truncate(n);
            let subtasks = kinds
                .into_iter()
                .map(|kind| SubtaskConfig {
                    kind,
                    variant: rng.next_u64() % 1000,
                    obst_level: rng.index(3) as u8,
                    multi_level,
                })
                .collect();
            TaskConfig {
                subtasks,
                episode: episode as u64,
                embodiment: if rng.index(2) == 0 {
                    Embodiment::Finger
                } else {
                    Embodiment::Vacuum
                },
                embodiment_in_state: false,
            }
        })
        .collect()
}

/// One task's result: its index in the config list, why it failed (if it did), simulated
/// seconds and action calls.
type Row = (usize, Option<String>, f64, usize);

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let variants = arg(&args, "--variants", 3) as u64;
    let composite_count = arg(&args, "--composites", 40);
    let threads = arg(&args, "--threads", 1).max(1);
    let mut configs = singles(variants);
    configs.extend(composites(composite_count));

    let started = Instant::now();
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Row>> = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(config) = configs.get(i) else { break };
                    let result = config
                        .generate()
                        .map_err(|e| format!("generation: {e}"))
                        .and_then(|task| run_scene(&task.scene).map_err(|e| format!("setup: {e}")));
                    let row = match result {
                        Ok(episode) => (i, episode.failure(), episode.sim_time, episode.actions),
                        Err(e) => (i, Some(e), 0.0, 0),
                    };
                    if let Some(why) = &row.1 {
                        println!("FAIL {}: {why}", describe(config));
                    }
                    results.lock().unwrap_or_else(|e| e.into_inner()).push(row);
                }
            });
        }
    });
    let wall = started.elapsed().as_secs_f64();
    let results = results.into_inner().unwrap_or_else(|e| e.into_inner());

    println!(
        "\n{:<10} {:<18} {:>6} {:>6}",
        "embodiment", "subtask", "tasks", "full"
    );
    for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
        for kind in SubtaskKind::ALL {
            let rows: Vec<_> = results
                .iter()
                .filter(|r| {
                    let c = &configs[r.0];
                    c.subtasks.len() == 1 && c.subtasks[0].kind == kind && c.embodiment == embodiment
                })
                .collect();
            let ok = rows.iter().filter(|r| r.1.is_none()).count();
            println!(
                "{:<10} {:<18} {:>6} {:>6}",
                embodiment.to_string(),
                kind.as_str(),
                rows.len(),
                ok
            );
        }
    }
    let composite_rows: Vec<_> = results
        .iter()
        .filter(|r| configs[r.0].subtasks.len() > 1)
        .collect();
    let composite_ok = composite_rows.iter().filter(|r| r.1.is_none()).count();
    println!(
        "{:<10} {:<18} {:>6} {:>6}",
        "mixed",
        "composites",
        composite_rows.len(),
        composite_ok
    );
    let ok = results.iter().filter(|r| r.1.is_none()).count();
    let sim_time: f64 = results.iter().map(|r| r.2).sum();
    let actions: usize = results.iter().map(|r| r.3).sum();
    println!(
        "\n{ok}/{} full_success ({:.1}%); {actions} actions, {sim_time:.0} s simulated in {wall:.1} s wall \
         on {threads} thread(s)",
        results.len(),
        100.0 * ok as f64 / results.len().max(1) as f64,
    );
}
