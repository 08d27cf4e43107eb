//! Helpers shared by the `nesy adapt` tests.
#![allow(dead_code)]

pub(crate) mod realstyle;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use nesy_sim::demo::{RecordOptions, record_scene, write_mcap_file};
use nesy_sim::scene::SceneSpec;

/// The workspace root.
pub(crate) fn workspace() -> PathBuf {
    nesy_testkit::workspace_root()
}

/// A scratch directory; kept under `$NESY_TEST_KEEP/<random>` when that variable is set
/// (to look at a run's outputs), else removed when dropped.
pub(crate) fn scratch() -> tempfile::TempDir {
    match std::env::var_os("NESY_TEST_KEEP") {
        Some(root) => {
            std::fs::create_dir_all(&root).expect("creating $NESY_TEST_KEEP");
            tempfile::Builder::new()
                .disable_cleanup(true)
                .tempdir_in(root)
                .expect("scratch dir")
        }
        None => tempfile::tempdir().expect("scratch dir"),
    }
}

/// Runs the `nesy` binary with `args`, without any VLM settings from the environment.
pub(crate) fn nesy(args: &[String]) -> Output {
    nesy_with_env(args, &[])
}

/// Runs the `nesy` binary with `args`: its exit code, stdout and stderr.
pub(crate) fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    let output = nesy(&args);
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// Runs `nesy adapt --demo DEMO --target TARGET --vlm VLM --out OUT` followed by `more`: its
/// exit code, stdout and stderr.
pub(crate) fn adapt(
    demo: &Path,
    target: &Path,
    vlm: &str,
    out: &Path,
    more: &[&str],
) -> (Option<i32>, String, String) {
    let (demo, target, out) = (
        demo.display().to_string(),
        target.display().to_string(),
        out.display().to_string(),
    );
    let mut args = vec![
        "adapt", "--demo", &demo, "--target", &target, "--vlm", vlm, "--out", &out,
    ];
    args.extend_from_slice(more);
    run(&args)
}

/// Runs the `nesy` binary with `args` and only the VLM settings of `env` (`(name, value)`).
pub(crate) fn nesy_with_env(args: &[String], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_nesy"));
    command.args(args).current_dir(workspace());
    for (key, _) in std::env::vars() {
        if key.starts_with("NESY_VLM") || key.starts_with("NESY_CASSETTE") || key.ends_with("_API_KEY") {
            command.env_remove(key);
        }
    }
    command.envs(env.iter().copied());
    command.output().expect("running nesy")
}

/// Records the expert's demo of `scene` into `out` (MCAP) with `size`-pixel views.
pub(crate) fn record_demo(scene: &Path, out: &Path, size: u32) {
    let spec = SceneSpec::from_file(scene).expect("scene");
    let recording = record_scene(
        &spec,
        &RecordOptions {
            image_size: size,
            ..RecordOptions::default()
        },
    )
    .expect("recording");
    assert!(recording.expert_error.is_none(), "{:?}", recording.expert_error);
    write_mcap_file(&recording.demo, out).expect("writing the demo");
}

/// An operator-induction reply, in a chatty model's style, derived from the "State
/// difference" section of an induction prompt: the preconditions are the atoms the step
/// removed (they held before it), the effects are the difference. The verifier accepts it.
pub(crate) fn operator_from_diff(user: &str, n: usize) -> String {
    let section = user.rsplit("- State difference:").next().unwrap_or("");
    let mut pre = Vec::new();
    let mut eff = Vec::new();
    for line in section.lines().map(str::trim) {
        if let Some(atom) = line.strip_prefix("(+)") {
            eff.push(atom.trim().to_owned());
        } else if let Some(atom) = line.strip_prefix("(-)") {
            pre.push(atom.trim().to_owned());
            eff.push(format!("(not {})", atom.trim()));
        } else if !line.is_empty() && !pre.is_empty() | !eff.is_empty() {
            break;
        }
    }
    let pre = if pre.is_empty() {
        "None".to_owned()
    } else {
        pre.iter()
            .map(|a| format!("- {a}"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let eff = eff
        .iter()
        .map(|a| format!("- {a}"))
        .collect::<Vec<_>>()
        .join("\n");
    format!(
        "Comparing the two states, I can see what changed.\n\n* Prediction Rationale:\n- The atoms listed as removed held before the step.\n\n* Predicted Action:\nAction Semantic:\n- Demo step {n}\nPrecondition:\n{pre}\nEffect:\n{eff}\n"
    )
}

/// The text of a chat message as a server receives it: a string, or the text parts of a
/// multi-part content joined by newlines.
pub(crate) fn message_text(message: &serde_json::Value) -> String {
    match &message["content"] {
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Array(parts) => parts
            .iter()
            .filter_map(|p| p["text"].as_str())
            .collect::<Vec<_>>()
            .join("\n"),
        _ => String::new(),
    }
}
