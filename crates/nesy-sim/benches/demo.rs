//! The scenario suite and demo files: generating all 440 scenario pairs (880 scenes), and
//! writing/reading the medium composite fixture demo as MCAP. Recording a demo end to end
//! is timed by `nesy record` (it prints simulation and rendering time per keyframe).

use std::hint::black_box;
use std::io::Cursor;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use nesy_sim::demo::mcap_format;
use nesy_sim::tasks::scenario;

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("demo");
    group.sample_size(20);
    group.bench_function("generate_440_scenario_pairs", |b| {
        b.iter(|| {
            let files = scenario::generate_suite();
            let mut objects = 0;
            for s in scenario::scenarios(&files) {
                let scenes = s.scenes().unwrap();
                objects += scenes.source.scene.objects.len() + scenes.target.scene.objects.len();
            }
            black_box(objects)
        })
    });
    let path = nesy_testkit::workspace_root().join("fixtures/demos/composite_medium/demo.mcap");
    let bytes = std::fs::read(&path).unwrap();
    let demo = mcap_format::read_mcap_bytes(&bytes, Path::new("demo.mcap")).unwrap();
    group.bench_function("read_mcap_composite_medium", |b| {
        b.iter(|| black_box(mcap_format::read_mcap_bytes(&bytes, Path::new("demo.mcap")).unwrap()))
    });
    group.bench_function("write_mcap_composite_medium", |b| {
        b.iter(|| black_box(mcap_format::write_mcap(&demo, Cursor::new(Vec::new())).unwrap()))
    });
    group.finish();
}

criterion_group!(demo_benches, benches);
criterion_main!(demo_benches);
