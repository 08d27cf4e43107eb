//! The published real-model comparison (`bench/runs/2026-12-05-gemma3-270m/`) re-scored
//! offline: one scenario's units, every method, replayed from the committed cassettes, give
//! the committed records again (timings aside). The whole run replays the same way; this
//! slice keeps the check within the test suite's time.

use crate::common;

use std::collections::BTreeMap;
use std::path::Path;

use serde_json::Value;

const RUN: &str = "bench/runs/2026-12-05-gemma3-270m";
const SLICE: &str = "obst_low_02_s0";

/// The records of `scenario` in a run's results, by variant, without what measures time or
/// place or depends on the responder (the configuration hash names it).
fn records(run: &Path, scenario: &str) -> BTreeMap<String, Value> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(run.join("results")).unwrap().flatten() {
        for line in std::fs::read_to_string(entry.path()).unwrap().lines() {
            let mut record: Value = serde_json::from_str(line).unwrap();
            if record["scenario"] != scenario {
                continue;
            }
            for volatile in ["finished_at", "artifacts", "config_hash"] {
                record.as_object_mut().unwrap().remove(volatile);
            }
            let effort = record["effort"].as_object_mut().unwrap();
            effort.retain(|k, _| !k.ends_with("_s") && k != "time" && k != "cost_usd");
            out.insert(record["variant"].as_str().unwrap().to_owned(), record);
        }
    }
    out
}

#[test]
fn the_published_real_model_run_replays_to_its_records() {
    let root = common::workspace();
    let published = root.join(RUN);
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(published.join("manifest.json")).unwrap()).unwrap();
    let variants: Vec<&str> = manifest["variants"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["id"].as_str().unwrap())
        .collect();
    let expected = records(&published, SLICE);
    assert_eq!(expected.len(), variants.len(), "the slice is complete in the published run");

    let scratch = common::scratch();
    let run = scratch.path().join("replay");
    let args: Vec<String> = [
        "bench",
        "run",
        &run.display().to_string(),
        "--vlm",
        &format!("replay:{}", published.join("cassettes").display()),
        "--methods",
        &variants.join(","),
        "--scenarios",
        SLICE,
        "--seed",
        &manifest["run_seed"].to_string(),
        "--observation",
        manifest["settings"]["observation"].as_str().unwrap(),
        "--demos",
        &scratch.path().join("demos").display().to_string(),
        "--no-report",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let output = common::nesy(&args);
    assert_eq!(
        output.status.code(),
        Some(0),
        "{}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    let replayed = records(&run, SLICE);
    for (variant, record) in &expected {
        assert_eq!(replayed.get(variant), Some(record), "{SLICE}/{variant}");
    }
}
