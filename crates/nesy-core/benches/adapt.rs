//! The adaptation loop on real inputs: every recorded `nesy adapt --vlm oracle` run of
//! `tests/adapt_corpus/` replayed through `adapt::run` by a scripted reasoner (see
//! `replay/mod.rs`), so what is measured is nesy-core's symbolic path only — reply parsing,
//! world-model verification (Eq. 3), identification (Eq. 6), patch application and
//! re-verification (Eq. 7–8), trace recording. A second group times the refinement-reply
//! parser alone on each run's recorded patch replies (the embodiment-change runs reply with
//! one patch rewriting the whole procedure, 17–37 KB of text).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use nesy_core::adapt;
use nesy_core::text::parse_refinement_reply;

mod replay;

fn bench(c: &mut Criterion) {
    let runs = replay::load_all();
    let mut group = c.benchmark_group("adapt_replay");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    for run in &runs {
        let inputs = run.inputs();
        group.bench_function(run.scenario.as_str(), |b| {
            // The result (world model, trace) is dropped outside the timed region, as in
            // `nesy adapt`, which times `adapt::run` and keeps its result.
            b.iter_with_large_drop(|| {
                let mut reasoner = run.reasoner();
                black_box(
                    pollster::block_on(adapt::run(
                        &mut reasoner,
                        &inputs.demo,
                        &inputs.target,
                        &inputs.config,
                    ))
                    .expect("recorded run replays"),
                )
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("parse_patch_replies");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    for run in runs.iter().filter(|r| !r.patch_replies.is_empty()) {
        group.bench_function(run.scenario.as_str(), |b| {
            b.iter(|| {
                for reply in &run.patch_replies {
                    let _ = black_box(parse_refinement_reply(black_box(reply)));
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
