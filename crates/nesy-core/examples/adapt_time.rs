//! Per-run symbolic time of the recorded adaptation runs (`tests/adapt_corpus/`), split as
//! `nesy adapt` splits it (Table 9): world-model construction until the first patch request,
//! then the adaptation loop. The scripted reasoner returns recorded replies, so the time is
//! nesy-core's symbolic work only. Prints, per run, the minimum over `--reps` repetitions
//! (default 101) of each part (the least-disturbed repetition: on a shared 2-core machine
//! the median includes waits for a core) and the medians of the adaptation part and of the
//! whole, as a markdown table.
//! The last two columns are the part of the symbolic time spent parsing the model's replies
//! (every recorded reply parsed once, as the loop does), measured separately the same way,
//! and within it the part spent on the refinement (patch) replies, which the adaptation
//! column includes.
//!
//! `cargo run --release -p nesy-core --example adapt_time [-- --reps N] [--only SCENARIO]`

#[path = "../benches/replay/mod.rs"]
mod replay;

use std::time::{Duration, Instant};

use nesy_core::adapt;
use nesy_core::text::{parse_induction_reply, parse_refinement_reply};

fn median(mut v: Vec<Duration>) -> f64 {
    v.sort();
    v[v.len() / 2].as_secs_f64() * 1e3
}

fn min(v: &[Duration]) -> f64 {
    v.iter().min().map_or(0.0, |d| d.as_secs_f64() * 1e3)
}

fn main() {
    let mut reps = 101;
    let mut only: Option<String> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--reps" => {
                reps = args
                    .next()
                    .and_then(|n| n.parse().ok())
                    .filter(|&n: &usize| n > 0)
                    .unwrap_or_else(|| {
                        eprintln!("--reps expects a positive integer");
                        std::process::exit(2)
                    })
            }
            "--only" => only = args.next(),
            other => {
                eprintln!("unknown argument {other}; usage: adapt_time [--reps N] [--only SCENARIO]");
                std::process::exit(2)
            }
        }
    }
    println!(
        "| run | transitions | proposals | outcome | world model ms (min) | adaptation ms (min) | adaptation ms (median) | symbolic ms (min) | symbolic ms (median) | of which reply parsing ms (min) | of which patch replies ms (min) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let (mut all_wm, mut all_ad) = (Vec::new(), Vec::new());
    let runs = replay::load_all();
    for run in runs
        .iter()
        .filter(|r| only.as_ref().is_none_or(|o| r.scenario.contains(o.as_str())))
    {
        let inputs = run.inputs();
        let (mut wm, mut ad, mut total) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..reps {
            let mut reasoner = run.reasoner();
            let started = Instant::now();
            let result = pollster::block_on(adapt::run(
                &mut reasoner,
                &inputs.demo,
                &inputs.target,
                &inputs.config,
            ))
            .expect("recorded run replays");
            let elapsed = started.elapsed();
            std::hint::black_box(result);
            let split = reasoner.first_patch.map_or(elapsed, |at| at - started);
            wm.push(split);
            ad.push(elapsed - split);
            total.push(elapsed);
        }
        let (mut parsing, mut patch_parsing) = (Vec::new(), Vec::new());
        for _ in 0..reps {
            let started = Instant::now();
            for reply in &run.induction_replies {
                let _ = std::hint::black_box(parse_induction_reply(reply));
            }
            let patches_started = Instant::now();
            for reply in &run.patch_replies {
                let _ = std::hint::black_box(parse_refinement_reply(reply));
            }
            patch_parsing.push(patches_started.elapsed());
            parsing.push(started.elapsed());
        }
        let (parsing, patch_parsing) = (min(&parsing), min(&patch_parsing));
        let ad_median = median(ad.clone());
        let (wm, ad, total_min, total) = (min(&wm), min(&ad), min(&total), median(total));
        all_wm.push(wm);
        all_ad.push(ad);
        println!(
            "| {} | {} | {} | {} | {wm:.3} | {ad:.3} | {ad_median:.3} | {total_min:.3} | {total:.3} | {parsing:.3} | {patch_parsing:.3} |",
            run.scenario,
            run.induction_replies.len(),
            run.patch_replies.len(),
            run.expected.outcome,
        );
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    println!(
        "\nminimum over {reps} repetitions: world model mean {:.3} ms, max {:.3} ms; adaptation mean {:.3} ms, max {:.3} ms ({} runs)",
        mean(&all_wm),
        max(&all_wm),
        mean(&all_ad),
        max(&all_ad),
        all_wm.len()
    );
}
