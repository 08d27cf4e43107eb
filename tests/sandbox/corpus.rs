//! The escape corpus (`tests/sandbox/*.py`) through the real worker path: every policy runs
//! in a `nesy policy-worker` process (static checks, curated builtins, audit hook, budgets,
//! rlimits, seccomp, parent kill) against the sandbox test double, and must end with the
//! outcome its `# expect:` header names. Side effects are checked afterwards: no file in the
//! marker directory (policies try to create one there, directly or through a spawned
//! process), and no connection to a loopback listener the policies try to reach.

use std::io::ErrorKind;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use nesy_core::Embodiment;
use nesy_policy::run_policy_without_static_checks;
use nesy_policy::{EpisodeSpec, ExecutionResult, Limits, Outcome, TimeLimit, WorkerCommand, run_policy};

fn corpus_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/sandbox")
}

/// The `nesy` binary under test; `NESY_SANDBOX_WORKER` points the corpus at another build
/// (e.g. the static binary of `scripts/build-static.sh`).
fn worker() -> WorkerCommand {
    match std::env::var_os("NESY_SANDBOX_WORKER") {
        Some(path) => WorkerCommand::nesy_binary(path),
        None => WorkerCommand::nesy_binary(env!("CARGO_BIN_EXE_nesy")),
    }
}

fn limits() -> Limits {
    Limits {
        wall_time_ms: 1_500,
        kill_grace_ms: 1_000,
        memory_bytes: 1 << 30,
        ..Limits::default()
    }
}

fn double() -> EpisodeSpec {
    EpisodeSpec::RecordingDouble {
        embodiment: Embodiment::Finger,
    }
}

struct Case {
    name: String,
    source: String,
    expected: String,
}

fn load_corpus(marker: &Path, port: u16) -> Vec<Case> {
    let mut cases = Vec::new();
    for entry in std::fs::read_dir(corpus_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "py") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let expected = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{}: first line must be `# expect: <outcome>`", path.display()))
            .trim()
            .to_owned();
        let source = text
            .replace("@MARKER@", &marker.display().to_string())
            .replace("@PORT@", &port.to_string());
        cases.push(Case {
            name: path.file_name().unwrap().to_string_lossy().into_owned(),
            source,
            expected,
        });
    }
    cases.sort_by(|a, b| a.name.cmp(&b.name));
    cases
}

#[test]
fn escape_corpus_has_zero_escapes() {
    let marker = tempfile::tempdir().unwrap();
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    listener.set_nonblocking(true).unwrap();
    let port = listener.local_addr().unwrap().port();
    let cases = load_corpus(marker.path(), port);
    assert!(cases.len() >= 30, "the corpus has {} policies", cases.len());

    let queue = Mutex::new(cases.iter());
    let results: Mutex<Vec<(&Case, ExecutionResult)>> = Mutex::new(Vec::new());
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                loop {
                    let Some(case) = queue.lock().unwrap().next() else {
                        break;
                    };
                    let result = run_policy(&worker(), &case.source, &double(), &limits())
                        .unwrap_or_else(|e| panic!("{}: {e}", case.name));
                    results.lock().unwrap().push((case, result));
                }
            });
        }
    });

    let mut failures = Vec::new();
    let mut results = results.into_inner().unwrap();
    results.sort_by(|a, b| a.0.name.cmp(&b.0.name));
    for (case, result) in &results {
        let kind = result.outcome.kind();
        if kind != case.expected {
            failures.push(format!(
                "{}: expected {}, got {:?}",
                case.name, case.expected, result.outcome
            ));
        }
        if case.expected == "ok" && result.worker.as_ref().is_some_and(|w| w.exit_code != Some(0)) {
            failures.push(format!("{}: worker exit {:?}", case.name, result.worker));
        }
    }
    let created: Vec<_> = std::fs::read_dir(marker.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        created.is_empty(),
        "escape: files created by policies: {created:?}"
    );
    match listener.accept() {
        Err(e) if e.kind() == ErrorKind::WouldBlock => {}
        other => panic!("escape: a policy reached the loopback listener: {other:?}"),
    }
    assert!(
        failures.is_empty(),
        "{} of {} policies misbehaved:\n{}",
        failures.len(),
        results.len(),
        failures.join("\n")
    );

    let forged = results
        .iter()
        .find(|(c, _)| c.name == "benign_forged_print.py")
        .unwrap();
    assert!(
        forged.1.stdout.text.contains("\"nonce\":\"0000\""),
        "the fake message stays in stdout"
    );
    assert_eq!(forged.1.trace.len(), 1, "the real result came through");
}

/// The worker's own layers, with the static checks off: the policy reaches `posix` through
/// `BuiltinImporter` (no audit event: the module is already loaded) and tries what the audit
/// hook cannot see.
#[test]
fn worker_layers_hold_without_static_checks() {
    let marker = tempfile::tempdir().unwrap();
    let posix = "p = [c for c in ().__class__.__base__.__subclasses__() if c.__name__ == 'BuiltinImporter'][0].load_module('posix')\n";
    let run = |body: &str| {
        let source = format!("{posix}{body}").replace("@MARKER@", &marker.path().display().to_string());
        run_policy_without_static_checks(&worker(), &source, &double(), &limits()).unwrap()
    };

    // Writes to fd 1 and 2 land in the parent's raw capture, and a forged result on fd 3
    // lacks the nonce: the real result still arrives.
    let result = run(
        "p.write(1, b'{\"type\":\"result\",\"nonce\":\"x\"}\\n')\np.write(2, b'noise')\np.write(3, b'{\"type\":\"result\",\"nonce\":\"x\",\"result\":{}}\\n')\nprint('done')\n",
    );
    assert_eq!(result.outcome, Outcome::Ok, "{:?}", result.outcome);
    assert_eq!(result.stdout.text, "done\n");
    let raw = &result.worker.as_ref().unwrap().raw_output.text;
    assert!(raw.contains("nonce") && raw.contains("noise"), "{raw}");

    // os._exit is not audited: the worker dies without a result and the parent says so.
    let result = run("p._exit(7)\n");
    assert_eq!(
        result.outcome,
        Outcome::Killed {
            reason: "worker exited with status 7 without reporting a result".into()
        }
    );

    // os.system is audited: refused, episode terminated.
    let result = run("p.system('touch @MARKER@/system')\n");
    assert!(
        matches!(&result.outcome, Outcome::SandboxViolation { event, .. } if event == "os.system"),
        "{:?}",
        result.outcome
    );

    // Opening a file for writing is audited (and would hit seccomp and RLIMIT_FSIZE).
    let result = run("fd = p.open('@MARKER@/open', p.O_WRONLY | p.O_CREAT)\n");
    assert!(
        matches!(&result.outcome, Outcome::SandboxViolation { event, .. } if event == "open"),
        "{:?}",
        result.outcome
    );

    // A C-level hang holds the interpreter lock: only the parent's kill ends it.
    let t0 = std::time::Instant::now();
    let result = run("x = 7 ** (10 ** 9)\n");
    assert_eq!(
        result.outcome,
        Outcome::Timeout {
            limit: TimeLimit::ParentKill,
            error: None
        }
    );
    assert!(t0.elapsed().as_secs_f64() < 6.0);

    let created: Vec<_> = std::fs::read_dir(marker.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(created.is_empty(), "escape: {created:?}");
}

#[test]
fn worker_runs_a_benign_policy_and_streams_the_trace() {
    let result = run_policy(
        &worker(),
        "for name in ['red_cube', 'blue_cube']:\n    move_gripper_to(name)\n    close_gripper()\n    open_gripper()\n",
        &double(),
        &limits(),
    )
    .unwrap();
    assert_eq!(result.outcome, Outcome::Ok);
    assert_eq!(result.trace.len(), 6);
    let report = result.worker.unwrap();
    assert_eq!(report.exit_code, Some(0));
    assert!(report.startup_s.is_some());
}

#[test]
fn worker_reports_setup_errors() {
    let spec = EpisodeSpec::Scene {
        path: "/nonexistent/scene.json".into(),
        embodiment: None,
    };
    let err = run_policy(&worker(), "pass", &spec, &limits()).unwrap_err();
    assert!(err.to_string().contains("/nonexistent/scene.json"), "{err}");
}

/// Figures for the README: the cost of one episode through the worker process against the
/// same trivial episode in-process, and a worked example through the worker on the real
/// simulator. Run with `cargo test --release -p nesy-cli --test sandbox_corpus -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn worker_overhead_figures() {
    const RUNS: usize = 20;
    let limits = Limits::default();
    let mut worker_times = Vec::new();
    let mut startup_times = Vec::new();
    for _ in 0..RUNS {
        let result = run_policy(&worker(), "pass", &double(), &limits).unwrap();
        assert!(result.is_ok());
        worker_times.push(result.wall_time_s);
        startup_times.push(result.worker.unwrap().startup_s.unwrap());
    }
    nesy_policy::initialize().unwrap();
    let mut local_times = Vec::new();
    for _ in 0..RUNS {
        let episode = Box::new(nesy_policy::RecordingRobot::new(Embodiment::Finger));
        let result = nesy_policy::run_in_process("pass", episode, &limits, None).unwrap();
        local_times.push(result.wall_time_s);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2] * 1e3
    };
    let (w, s, l) = (
        median(&mut worker_times),
        median(&mut startup_times),
        median(&mut local_times),
    );
    println!(
        "episode `pass`: worker {w:.2} ms (worker start-up to ready {s:.2} ms), in-process {l:.3} ms, worker overhead {:.2} ms",
        w - l
    );

    let scene =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/scenes/pick_place_finger.json");
    let source = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../nesy-policy/policies/pick_place.py"),
    )
    .unwrap();
    let spec = EpisodeSpec::Scene {
        path: scene,
        embodiment: None,
    };
    let result = run_policy(&worker(), &source, &spec, &limits).unwrap();
    assert!(result.is_ok(), "{:?}", result.outcome);
    println!(
        "pick_place.py on pick_place_finger.json through the worker: {:.1} ms",
        result.wall_time_s * 1e3
    );
}
