//! `nesy adapt` against a real model: the local llama.cpp server that
//! `scripts/local-model.sh` starts (Gemma 3 270M, Q4_K_M). Ignored by default; `.ci/run`
//! starts the server and runs it with `--ignored`, and so can anyone:
//!
//! ```text
//! eval "$(scripts/local-model.sh)"
//! cargo test -p nesy-cli --test integration real_model -- --ignored
//! ```
//!
//! What the model says is not checked, only what must hold whatever it says: the run ends
//! with a typed outcome and exit code 0 or 1, within a time limit; every call it made is in
//! the cassette it recorded; and replaying that cassette offline reproduces the outcome and
//! the run files, timings aside. Once with template code generation, once with the model's.
//! The loop's budgets are small (two induction tries, two patch proposals) so that a run
//! takes minutes on two cores.

use crate::common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

/// How long one run may take before it counts as a hang.
const RUN_LIMIT: Duration = Duration::from_secs(900);

/// The local server's settings, as `scripts/local-model.sh` prints them.
fn server_settings() -> Vec<(String, String)> {
    let names = ["NESY_VLM_BACKEND", "NESY_VLM_BASE_URL", "NESY_VLM_MODEL"];
    let settings: Vec<(String, String)> = names
        .iter()
        .filter_map(|name| std::env::var(name).ok().map(|v| (name.to_string(), v)))
        .collect();
    assert_eq!(
        settings.len(),
        names.len(),
        "the real-model test needs a running model server: run `eval \"$(scripts/local-model.sh)\"` first \
         (it installs llama.cpp's server and Gemma 3 270M once, then starts it)"
    );
    settings
}

/// Runs `nesy` with `args` and `env`, killing it after [`RUN_LIMIT`]. Returns the exit code
/// and the output.
fn run_limited(args: &[String], env: &[(String, String)]) -> (i32, String) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_nesy"));
    command
        .args(args)
        .current_dir(common::workspace())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (key, _) in std::env::vars() {
        if key.starts_with("NESY_VLM") || key.starts_with("NESY_CASSETTE") {
            command.env_remove(key);
        }
    }
    command.envs(env.iter().map(|(k, v)| (k.as_str(), v.as_str())));
    let mut child = command.spawn().expect("starting nesy");
    let started = Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("waiting for nesy") {
            let output = child.wait_with_output().expect("reading nesy's output");
            let text = format!(
                "{}{}",
                String::from_utf8_lossy(&output.stdout),
                String::from_utf8_lossy(&output.stderr)
            );
            // A signal (a panic's abort, a crash) has no code: report it as such.
            return (status.code().unwrap_or(-1), text);
        }
        if started.elapsed() > RUN_LIMIT {
            let _ = child.kill();
            panic!("nesy {args:?} did not finish within {RUN_LIMIT:?}");
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// A run file with what legitimately differs between a live run and its replay taken out:
/// times, latencies, where each answer came from (live or replayed), and the run's own
/// directory.
fn comparable(run: &Path, name: &str) -> String {
    let path = run.join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let Ok(text) = String::from_utf8(bytes.clone()) else {
        // Pictures of the scene: compared byte for byte.
        return format!("{} bytes, {:x?}", bytes.len(), &bytes[..bytes.len().min(64)]) + &checksum(&bytes);
    };
    let text = text.replace(&run.display().to_string(), "<run>");
    if path.extension().is_some_and(|e| e == "json") {
        let mut value: Value = serde_json::from_str(&text).unwrap();
        strip_times(&mut value);
        serde_json::to_string_pretty(&value).unwrap()
    } else {
        // Prose reports print times as "12.3 s" or "45 ms".
        text.lines()
            .filter(|line| {
                !line.chars().any(|c| c.is_ascii_digit()) || !(line.contains(" s") || line.contains("ms"))
            })
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// A checksum of `bytes` (FNV-1a), enough to tell two files apart in a test.
fn checksum(bytes: &[u8]) -> String {
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3)
    });
    format!(" fnv {hash:016x}")
}

fn strip_times(value: &mut Value) {
    const ORIGIN_COUNTS: [&str; 3] = ["live_calls", "replayed_calls", "offline_calls"];
    match value {
        Value::Object(map) => {
            map.retain(|key, _| {
                !(key.ends_with("_s")
                    || key.ends_with("_ms")
                    || key.ends_with("_ms_total")
                    || key.contains("latency")
                    || ORIGIN_COUNTS.contains(&key.as_str()))
            });
            map.values_mut().for_each(strip_times);
        }
        Value::Array(items) => items.iter_mut().for_each(strip_times),
        _ => {}
    }
}

/// The attempts a run's calls made (retries included), from its summary or its failure
/// record: each one reached the server and is in the cassette, with its response or, when
/// it got none, its failure.
fn attempts_made(run: &Path) -> u64 {
    let file = ["summary.json", "failure.json"]
        .iter()
        .map(|name| run.join(name))
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("{} holds neither summary.json nor failure.json", run.display()));
    let value: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let total = value
        .pointer("/usage/total/attempts")
        .or_else(|| value.pointer("/calls/total/attempts"));
    total
        .and_then(Value::as_u64)
        .unwrap_or_else(|| panic!("{}: no attempt count", file.display()))
}

fn adapt_args(codegen: &str, out: &Path, vlm: Option<String>, record: Option<&Path>) -> Vec<String> {
    let mut args: Vec<String> = [
        "adapt",
        "--demo",
        "fixtures/demos/adapt-realstyle",
        "--target",
        "fixtures/demos/adapt-realstyle/target.json",
        "--states",
        "observed",
        "--codegen",
        codegen,
        "--execute",
        "--induction-tries",
        "2",
        "--budget",
        "2",
        "--out",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.push(out.display().to_string());
    if let Some(vlm) = vlm {
        args.extend(["--vlm".to_string(), vlm]);
    }
    if let Some(record) = record {
        args.extend(["--record".to_string(), record.display().to_string()]);
    }
    args
}

fn live_then_replayed(codegen: &str) {
    let settings = server_settings();
    let scratch = common::scratch();
    let live = scratch.path().join("live");
    let replayed = scratch.path().join("replayed");
    let cassette = scratch.path().join("calls.json");

    let (code, output) = run_limited(&adapt_args(codegen, &live, None, Some(&cassette)), &settings);
    eprintln!("live run ({codegen} code generation), exit {code}:\n{output}");
    assert!(
        code == 0 || code == 1,
        "exit code {code}, not an outcome:\n{output}"
    );
    assert!(!output.contains("panicked"), "{output}");
    let first_line = output
        .lines()
        .find(|l| l.starts_with("nesy adapt: "))
        .unwrap_or_default();
    let outcomes = [
        "SUCCEEDED",
        "UNRESOLVED",
        "CODEGEN_FAILED",
        "EXECUTION_FAILED",
        "NO_USABLE_REPLY",
        "REQUEST_REFUSED",
    ];
    assert!(
        outcomes.iter().any(|o| first_line.contains(o)),
        "no typed outcome in {first_line:?}:\n{output}"
    );

    let recorded = nesy_vlm::CassetteFile::load(&cassette).expect("the run recorded a cassette");
    assert_eq!(
        recorded.interactions.len() as u64,
        attempts_made(&live),
        "every attempt the run made is in its cassette"
    );

    let replay = format!("replay:{}", cassette.display());
    let (replay_code, replay_output) = run_limited(&adapt_args(codegen, &replayed, Some(replay), None), &[]);
    assert_eq!(
        replay_code, code,
        "the replay ends as the live run did:\n{replay_output}"
    );
    let mut files: Vec<String> = std::fs::read_dir(&live)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    for name in &files {
        assert_eq!(
            comparable(&replayed, name),
            comparable(&live, name),
            "{name} differs between the live run and its replay"
        );
    }
}

#[test]
#[ignore = "needs the local model server (scripts/local-model.sh); .ci/run starts it"]
fn a_real_model_run_ends_in_an_outcome_and_replays_identically_with_template_code() {
    live_then_replayed("template");
}

#[test]
#[ignore = "needs the local model server (scripts/local-model.sh); .ci/run starts it"]
fn a_real_model_run_ends_in_an_outcome_and_replays_identically_with_model_code() {
    live_then_replayed("vlm");
}
