//! The robot bridge end to end: `nesy run --robot` against `nesy robot-server` (a real
//! separate process serving the simulator) and against scripted servers that fail in each
//! way a robot server can.

use crate::common;

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// A `nesy robot-server` process; killed when dropped.
struct SimServer {
    child: Child,
    address: String,
    log: PathBuf,
    _dir: tempfile::TempDir,
}

impl SimServer {
    fn start(scene: &str) -> SimServer {
        let dir = common::scratch();
        let log = dir.path().join("server.jsonl");
        let mut child = Command::new(env!("CARGO_BIN_EXE_nesy"))
            .current_dir(common::workspace())
            .args([
                "robot-server",
                "--scene",
                scene,
                "--heartbeat-timeout",
                "1.5",
                "--log",
            ])
            .arg(&log)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("starting nesy robot-server");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .expect("the server's first line");
        let address = line
            .trim()
            .strip_prefix("listening on ")
            .unwrap_or_else(|| panic!("unexpected first line {line:?}"))
            .to_owned();
        SimServer {
            child,
            address,
            log,
            _dir: dir,
        }
    }

    /// The server's events so far.
    fn events(&self) -> Vec<Value> {
        std::fs::read_to_string(&self.log)
            .unwrap_or_default()
            .lines()
            .filter_map(|l| serde_json::from_str(l).ok())
            .collect()
    }

    /// The methods of the requests the server received (heartbeats are not logged).
    fn requested_methods(&self) -> Vec<String> {
        self.events()
            .iter()
            .filter(|e| e["event"] == "request")
            .map(|e| e["method"].as_str().unwrap_or_default().to_owned())
            .collect()
    }
}

impl Drop for SimServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `nesy run --robot ADDRESS --robot-run-dir DIR` with `extra`; returns the exit code, the
/// output and the run record (`robot-run.json`), if written.
fn run_on_robot(
    policy: &Path,
    address: &str,
    extra: &[&str],
) -> (Option<i32>, String, Option<Value>, tempfile::TempDir) {
    let dir = common::scratch();
    let run_dir = dir.path().join("robot-run");
    let mut args: Vec<String> = ["run", "--policy"].map(String::from).to_vec();
    args.push(policy.display().to_string());
    args.extend([
        "--robot".to_owned(),
        address.to_owned(),
        "--robot-run-dir".to_owned(),
    ]);
    args.push(run_dir.display().to_string());
    args.extend(extra.iter().map(|a| a.to_string()));
    let output = common::nesy(&args);
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    let record = std::fs::read_to_string(run_dir.join("robot-run.json"))
        .ok()
        .map(|t| serde_json::from_str(&t).expect("robot-run.json is JSON"));
    (output.status.code(), text, record, dir)
}

/// A call and what it returned, without the clock.
fn calls(trace: &Value) -> Vec<Value> {
    trace
        .as_array()
        .expect("a trace")
        .iter()
        .map(|entry| {
            let mut entry = entry.clone();
            let object = entry.as_object_mut().unwrap();
            object.remove("sim_time");
            entry
        })
        .collect()
}

/// A trace's calls as the protocol sends them: `{"method", "params"}`.
fn as_sent(trace: &Value) -> Vec<Value> {
    calls(trace)
        .into_iter()
        .map(|mut entry| {
            let object = entry.as_object_mut().unwrap();
            object.remove("index");
            object.remove("result");
            let method = object.remove("call").unwrap();
            json!({"method": method, "params": entry})
        })
        .collect()
}

fn write_policy(dir: &Path, source: &str) -> PathBuf {
    let path = dir.join("policy.py");
    std::fs::write(&path, source).unwrap();
    path
}

#[test]
fn a_policy_on_the_robot_server_matches_the_same_policy_in_simulation() {
    let root = common::workspace();
    let cases = [
        ("pick_place.py", "pick_place_finger.json"),
        ("drawer.py", "drawer_finger.json"),
        ("hinge.py", "hinge_finger.json"),
        ("sweep.py", "sweep_finger.json"),
        ("pick_place.py", "pick_place_vacuum.json"),
    ];
    for (policy, scene) in cases {
        let policy = root.join("crates/nesy-policy/policies").join(policy);
        let scene = format!("fixtures/scenes/{scene}");
        let local = common::nesy(&[
            "run".into(),
            "--policy".into(),
            policy.display().to_string(),
            "--scene".into(),
            scene.clone(),
            "--json".into(),
        ]);
        let local: Value = serde_json::from_slice(&local.stdout).expect("local JSON result");
        let server = SimServer::start(&scene);
        let (code, text, record, _dir) = run_on_robot(&policy, &server.address, &["--scene", &scene]);
        assert_eq!(code, Some(0), "{scene}: {text}");
        let record = record.expect("a run record");
        let remote = &record["result"];
        assert_eq!(record["dry_run"]["skipped"], false, "{scene}");
        assert_eq!(record["dry_run"]["outcome"], "ok", "{scene}");
        assert_eq!(remote["outcome"], local["outcome"], "{scene}");
        assert_eq!(calls(&remote["trace"]), calls(&local["trace"]), "{scene}");
        assert_eq!(remote["subtasks"], local["subtasks"], "{scene}");
        assert!(
            local["subtasks"].as_array().is_some_and(|s| !s.is_empty()),
            "{scene}: {local}"
        );
        assert_eq!(remote["final_state"], local["final_state"], "{scene}");
        // The bridge's call log holds every call the policy made, in order.
        let log = std::fs::read_to_string(_dir.path().join("robot-run/robot-calls.jsonl")).unwrap();
        let sent: Vec<Value> = log
            .lines()
            .map(|l| serde_json::from_str::<Value>(l).unwrap())
            .filter(|e| e["event"] == "call")
            .map(|e| json!({"method": e["method"], "params": e["params"]}))
            .collect();
        let made = as_sent(&local["trace"]);
        assert_eq!(sent, made, "{scene}");
    }
}

#[test]
fn a_policy_that_fails_its_dry_run_never_reaches_the_robot() {
    let server = SimServer::start("fixtures/scenes/pick_place_finger.json");
    let dir = common::scratch();
    // Valid, runs to its end, but leaves the cubes where they are.
    let policy = write_policy(dir.path(), "open_gripper()\n");
    let (code, text, record, _run) = run_on_robot(
        &policy,
        &server.address,
        &["--scene", "fixtures/scenes/pick_place_finger.json"],
    );
    assert_eq!(code, Some(1), "{text}");
    assert!(
        text.contains("robot: not contacted, the goal checks failed in simulation"),
        "{text}"
    );
    assert!(record.is_none());
    // With --json, standard output is one JSON object saying so.
    let output = common::nesy(&[
        "run".into(),
        "--policy".into(),
        policy.display().to_string(),
        "--scene".into(),
        "fixtures/scenes/pick_place_finger.json".into(),
        "--robot".into(),
        server.address.clone(),
        "--json".into(),
    ]);
    assert_eq!(output.status.code(), Some(1));
    let printed: Value = serde_json::from_slice(&output.stdout).expect("stdout is one JSON object");
    assert_eq!(printed["contacted"], false, "{printed}");
    assert_eq!(printed["dry_run"]["outcome"], "ok", "{printed}");
    std::thread::sleep(Duration::from_millis(200));
    assert!(
        server.events().iter().all(|e| e["event"] != "connected"),
        "{:?}",
        server.events()
    );
}

#[test]
fn a_robot_run_needs_a_scene_or_an_explicit_skip() {
    let dir = common::scratch();
    let policy = write_policy(dir.path(), "open_gripper()\n");
    let (code, text, _, _run) = run_on_robot(&policy, "127.0.0.1:9", &[]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("--robot needs --scene for the dry run"), "{text}");
}

#[test]
fn a_motion_outside_the_workspace_is_refused_before_it_is_sent() {
    let server = SimServer::start("fixtures/scenes/pick_place_finger.json");
    let dir = common::scratch();
    let policy = write_policy(
        dir.path(),
        "get_obj_names()\nmove_to_position([0.4, 0.0, 0.7])\nmove_to_position([0.95, 0.0, 0.7])\n",
    );
    let (code, text, record, _run) = run_on_robot(&policy, &server.address, &["--skip-dry-run"]);
    assert_eq!(code, Some(1), "{text}");
    let record = record.expect("a run record");
    assert_eq!(record["dry_run"]["skipped"], true);
    let outcome = &record["result"]["outcome"];
    assert_eq!(outcome["kind"], "robot_stopped", "{outcome}");
    assert_eq!(outcome["reason"], "refused", "{outcome}");
    assert_eq!(outcome["call"], "move_to_position(0.95, 0.00, 0.70)", "{outcome}");
    assert!(
        outcome["message"]
            .as_str()
            .unwrap()
            .contains("outside the workspace"),
        "{outcome}"
    );
    std::thread::sleep(Duration::from_millis(300));
    let methods = server.requested_methods();
    assert_eq!(
        methods,
        ["hello", "get_obj_names", "move_to_position", "stop"],
        "{methods:?}"
    );
    // The one move that was sent is the one inside the box.
    let moves: Vec<Value> = server
        .events()
        .into_iter()
        .filter(|e| e["event"] == "request" && e["method"] == "move_to_position")
        .collect();
    assert_eq!(moves[0]["params"]["pos"], json!([0.4, 0.0, 0.7]));

    // With --json, standard output is the run record itself.
    let run_dir = dir.path().join("json-run");
    let output = common::nesy(&[
        "run".into(),
        "--policy".into(),
        policy.display().to_string(),
        "--robot".into(),
        server.address.clone(),
        "--skip-dry-run".into(),
        "--json".into(),
        "--robot-run-dir".into(),
        run_dir.display().to_string(),
    ]);
    assert_eq!(output.status.code(), Some(1));
    let printed: Value = serde_json::from_slice(&output.stdout).expect("stdout is one JSON object");
    let written: Value =
        serde_json::from_str(&std::fs::read_to_string(run_dir.join("robot-run.json")).unwrap()).unwrap();
    assert_eq!(printed, written);
    assert_eq!(printed["contacted"], true);

    // A relative move is checked against the tool position the robot reports.
    let policy = write_policy(dir.path(), "move_parallel('up', 2.0)\n");
    let (code, text, record, _run) = run_on_robot(&policy, &server.address, &["--skip-dry-run"]);
    assert_eq!(code, Some(1), "{text}");
    let outcome = &record.expect("a run record")["result"]["outcome"];
    assert_eq!(outcome["reason"], "refused", "{outcome}");
    assert_eq!(outcome["call"], "move_parallel(up, 2.00)", "{outcome}");
}

/// How a scripted server misbehaves at the first robot call.
#[derive(Clone, Copy, Debug)]
enum Fault {
    RobotError,
    Late,
    Garbage,
    Hangup,
    Silent,
}

/// A one-session server on a free port: answers `hello` and heartbeats, and misbehaves at
/// the first robot call. Returns its address.
fn faulty_server(fault: Fault) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let address = listener.local_addr().unwrap().to_string();
    std::thread::spawn(move || {
        let Ok((stream, _)) = listener.accept() else {
            return;
        };
        let mut writer = stream.try_clone().unwrap();
        let reader = BufReader::new(stream);
        let mut faulted = false;
        for line in reader.lines() {
            let Ok(line) = line else { return };
            let request: Value = serde_json::from_str(&line).unwrap();
            let id = request["id"].clone();
            let method = request["method"].as_str().unwrap_or_default().to_owned();
            let answer = match method.as_str() {
                "hello" => json!({"jsonrpc": "2.0", "id": id, "result": {
                    "protocol": "nesy-robot/1", "robot": "scripted", "embodiment": "finger",
                    "heartbeat_timeout_s": 1.5, "speed_scale": request["params"]["speed_scale"]}}),
                "heartbeat" | "stop" => json!({"jsonrpc": "2.0", "id": id, "result": {}}),
                _ if !faulted => {
                    faulted = true;
                    match fault {
                        Fault::RobotError => json!({"jsonrpc": "2.0", "id": id, "error": {
                            "code": -32000, "message": "blocked",
                            "data": {"kind": "infeasible", "call": method, "target": "red_cube", "reason": "the camera is covered"}}}),
                        Fault::Late => {
                            std::thread::sleep(Duration::from_secs(4));
                            json!({"jsonrpc": "2.0", "id": id, "result": ["floor"]})
                        }
                        Fault::Garbage => {
                            let _ = writer.write_all(b"<html>502 Bad Gateway</html>\n");
                            continue;
                        }
                        Fault::Hangup => return,
                        Fault::Silent => continue,
                    }
                }
                "get_obj_names" => json!({"jsonrpc": "2.0", "id": id, "result": ["floor", "gripper"]}),
                _ => json!({"jsonrpc": "2.0", "id": id, "result": null}),
            };
            if writer.write_all(format!("{answer}\n").as_bytes()).is_err() {
                return;
            }
        }
    });
    address
}

#[test]
fn every_way_a_robot_server_can_fail_ends_the_run_with_a_typed_outcome() {
    let dir = common::scratch();
    let policy = write_policy(
        dir.path(),
        "names = get_obj_names()\nget_obj_names()\nopen_gripper()\n",
    );
    let cases = [
        (Fault::Late, "no_answer"),
        (Fault::Garbage, "bad_answer"),
        (Fault::Hangup, "disconnected"),
        (Fault::Silent, "no_answer"),
    ];
    for (fault, reason) in cases {
        let address = faulty_server(fault);
        let started = Instant::now();
        let (code, text, record, _run) =
            run_on_robot(&policy, &address, &["--skip-dry-run", "--call-timeout", "1"]);
        assert_eq!(code, Some(1), "{fault:?}: {text}");
        assert!(started.elapsed() < Duration::from_secs(20), "{fault:?}");
        let outcome = &record.unwrap_or_else(|| panic!("{fault:?}: no record: {text}"))["result"]["outcome"];
        assert_eq!(outcome["kind"], "robot_stopped", "{fault:?}: {outcome}");
        assert_eq!(outcome["reason"], reason, "{fault:?}: {outcome}");
        assert_eq!(outcome["call"], "get_obj_names()", "{fault:?}: {outcome}");
        assert!(!text.contains("panicked"), "{fault:?}: {text}");
    }

    // An error to a call that cannot report one ends the run there.
    let address = faulty_server(Fault::RobotError);
    let (code, text, record, _run) = run_on_robot(&policy, &address, &["--skip-dry-run"]);
    assert_eq!(code, Some(1), "{text}");
    let outcome = &record.expect("a run record")["result"]["outcome"];
    assert_eq!(outcome["kind"], "robot_stopped", "{outcome}");
    assert_eq!(outcome["reason"], "unexpected_error", "{outcome}");
    assert_eq!(outcome["call"], "get_obj_names()", "{outcome}");

    // The robot's own error reaches the policy as the usual exception naming the call...
    let asking = write_policy(dir.path(), "p = get_obj_pos('red_cube')\nopen_gripper()\n");
    let address = faulty_server(Fault::RobotError);
    let (code, text, record, _run) = run_on_robot(&asking, &address, &["--skip-dry-run"]);
    assert_eq!(code, Some(1), "{text}");
    let outcome = &record.expect("a run record")["result"]["outcome"];
    assert_eq!(outcome["kind"], "python_error", "{outcome}");
    assert_eq!(outcome["exception"], "robot.InfeasibleError", "{outcome}");
    assert!(
        outcome["message"]
            .as_str()
            .unwrap()
            .starts_with("get_obj_pos(red_cube) is infeasible"),
        "{outcome}"
    );
    assert_eq!(outcome["line"], 1, "{outcome}");

    // ...and a policy that catches it cannot go on: the first robot error ends the run.
    let catching = write_policy(
        dir.path(),
        "try:\n    get_obj_pos('red_cube')\nexcept Exception:\n    pass\nopen_gripper()\n",
    );
    let address = faulty_server(Fault::RobotError);
    let (code, text, record, _run) = run_on_robot(&catching, &address, &["--skip-dry-run"]);
    assert_eq!(code, Some(1), "{text}");
    let outcome = &record.expect("a run record")["result"]["outcome"];
    assert_eq!(outcome["kind"], "robot_stopped", "{outcome}");
    assert_eq!(outcome["reason"], "after_error", "{outcome}");
    assert_eq!(outcome["call"], "open_gripper()", "{outcome}");
}

/// Starts `nesy run --robot` on a long policy against `server` and waits until the server has
/// served a few of its calls.
fn long_run(server: &SimServer, dir: &Path) -> Child {
    let policy = write_policy(dir, "for i in range(4000):\n    get_obj_names()\n");
    let child = Command::new(env!("CARGO_BIN_EXE_nesy"))
        .current_dir(common::workspace())
        .arg("run")
        .arg("--policy")
        .arg(&policy)
        .args(["--robot", &server.address, "--skip-dry-run", "--robot-run-dir"])
        .arg(dir.join("run"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(30);
    while server.requested_methods().len() < 20 {
        assert!(
            Instant::now() < deadline,
            "the run did not start: {:?}",
            server.events()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

/// Waits for the server's `stopped` event; returns it and how long it took.
fn wait_for_stop(server: &SimServer, since: Instant) -> (Value, Duration) {
    loop {
        if let Some(stop) = server.events().into_iter().find(|e| e["event"] == "stopped") {
            return (stop, since.elapsed());
        }
        assert!(
            since.elapsed() < Duration::from_secs(10),
            "no stop: {:?}",
            server.events()
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn the_server_stops_the_robot_when_nesy_dies_or_hangs() {
    // Killed: the connection closes, and the server stops at once.
    let server = SimServer::start("fixtures/scenes/pick_place_finger.json");
    let dir = common::scratch();
    let mut nesy = long_run(&server, dir.path());
    let killed = Instant::now();
    nesy.kill().unwrap();
    let _ = nesy.wait();
    let (stop, took) = wait_for_stop(&server, killed);
    assert!(took < Duration::from_millis(1500), "{took:?}: {stop}");

    // Hung (stopped, so its socket stays open): the heartbeat watchdog stops the robot within
    // its timeout.
    let server = SimServer::start("fixtures/scenes/pick_place_finger.json");
    let mut nesy = long_run(&server, dir.path());
    let hung = Instant::now();
    // The shell's own `kill`: minimal systems may have no kill executable.
    let stopped = Command::new("sh")
        .args(["-c", &format!("kill -STOP {}", nesy.id())])
        .status()
        .unwrap();
    assert!(stopped.success());
    let (stop, took) = wait_for_stop(&server, hung);
    assert!(stop["reason"].as_str().unwrap().starts_with("watchdog"), "{stop}");
    assert!(took < Duration::from_millis(1500 + 700), "{took:?}: {stop}");
    let _ = nesy.kill();
    let _ = nesy.wait();
}

#[test]
fn the_quick_start_adaptation_runs_on_the_robot_server_after_its_dry_run() {
    let server = SimServer::start("fixtures/demos/adapt-realstyle/target.json");
    let dir = common::scratch();
    let out = dir.path().join("adapt");
    let (code, stdout, stderr) = common::adapt(
        Path::new("fixtures/demos/adapt-realstyle"),
        Path::new("fixtures/demos/adapt-realstyle/target.json"),
        "replay:fixtures/cassettes/adapt-realstyle.json",
        &out,
        &["--execute", "--robot", &server.address],
    );
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(stdout.contains("  robot     ok at tcp://"), "{stdout}");
    let record: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("robot/robot-run.json")).unwrap()).unwrap();
    let execution: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("execution.json")).unwrap()).unwrap();
    assert_eq!(record["dry_run"]["outcome"], "ok");
    let dry = execution["result"]
        .get("trace")
        .or(execution.get("trace"))
        .expect("the dry run's trace");
    assert_eq!(calls(&record["result"]["trace"]), calls(dry));
    assert_eq!(
        record["result"]["subtasks"][0]["status"], "full_success",
        "{record}"
    );
}

#[test]
fn the_python_example_server_logs_exactly_the_calls_the_policy_made() {
    let root = common::workspace();
    let dir = common::scratch();
    let log = dir.path().join("calls.jsonl");
    let mut server = Command::new("python3")
        .current_dir(&root)
        .env("PYTHONPATH", root.join("python/src"))
        .args([
            "-m",
            "nesy.examples.logging_robot",
            "--listen",
            "127.0.0.1:0",
            "--once",
            "--scene",
        ])
        .arg("fixtures/scenes/pick_place_finger.json")
        .arg("--log")
        .arg(&log)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("python3 runs the example server");
    let mut line = String::new();
    BufReader::new(server.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let address = line
        .trim()
        .strip_prefix("listening on ")
        .expect("the address")
        .to_owned();
    let policy = root.join("crates/nesy-policy/policies/pick_place.py");
    let (code, text, record, _run) = run_on_robot(&policy, &address, &["--skip-dry-run"]);
    let _ = server.wait();
    assert_eq!(code, Some(0), "{text}");
    let trace = &record.expect("a run record")["result"]["trace"];
    let made = as_sent(trace);
    let logged: Vec<Value> = std::fs::read_to_string(&log)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap())
        .filter(|e| e["event"] == "call" && e.get("check").is_none())
        .filter(|e| !matches!(e["method"].as_str(), Some("finish" | "get_tool_pos")))
        .map(|e| json!({"method": e["method"], "params": e["params"]}))
        .collect();
    assert!(made.len() > 10, "{made:?}");
    assert_eq!(logged, made);
}

#[test]
fn a_slow_motion_on_the_robot_is_not_idle_time() {
    let dir = common::scratch();
    let policy = write_policy(dir.path(), "get_obj_names()\nopen_gripper()\n");
    // The first call takes 4 s on this robot, four times the idle limit.
    let address = faulty_server(Fault::Late);
    let (code, text, record, _run) = run_on_robot(
        &policy,
        &address,
        &["--skip-dry-run", "--call-timeout", "10", "--idle-timeout", "1"],
    );
    assert_eq!(code, Some(0), "{text}");
    let result = &record.expect("a run record")["result"];
    assert_eq!(result["outcome"]["kind"], "ok", "{result}");
    assert_eq!(result["trace"].as_array().unwrap().len(), 2, "{result}");
}

/// Runs a command on a pseudo-terminal, answering each `[y/N]` prompt with the next of the
/// comma-separated answers in argv[1]; prints what the terminal showed and exits as the
/// command did.
const ANSWER_ON_A_TERMINAL: &str = r#"
import os, pty, sys, time
answers = sys.argv[1].split(",")
pid, fd = pty.fork()
if pid == 0:
    os.execvp(sys.argv[2], sys.argv[2:])
shown, deadline = b"", time.time() + 60
while time.time() < deadline:
    try:
        chunk = os.read(fd, 4096)
    except OSError:
        break
    if not chunk:
        break
    shown += chunk
    while answers and b"[y/N]" in shown:
        shown = shown.replace(b"[y/N]", b"[answered]", 1)
        os.write(fd, (answers.pop(0) + "\n").encode())
_, status = os.waitpid(pid, 0)
sys.stdout.write(shown.decode(errors="replace"))
sys.exit(os.waitstatus_to_exitcode(status))
"#;

#[test]
fn with_confirm_each_call_waits_for_the_operator() {
    let server = SimServer::start("fixtures/scenes/pick_place_finger.json");
    let dir = common::scratch();
    let driver = dir.path().join("answer.py");
    std::fs::write(&driver, ANSWER_ON_A_TERMINAL).unwrap();
    let policy = write_policy(dir.path(), "get_obj_names()\nopen_gripper()\nclose_gripper()\n");
    let run_dir = dir.path().join("run");
    let output = Command::new("python3")
        .current_dir(common::workspace())
        .arg(&driver)
        .arg("y,n")
        .arg(env!("CARGO_BIN_EXE_nesy"))
        .arg("run")
        .arg("--policy")
        .arg(&policy)
        .args([
            "--robot",
            &server.address,
            "--skip-dry-run",
            "--confirm",
            "--robot-run-dir",
        ])
        .arg(&run_dir)
        .output()
        .expect("python3 runs the terminal driver");
    let shown = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{shown}");
    assert!(
        shown.contains("send get_obj_names() to the robot? [answered] y"),
        "{shown}"
    );
    assert!(
        shown.contains("send open_gripper() to the robot? [answered] n"),
        "{shown}"
    );
    let record: Value =
        serde_json::from_str(&std::fs::read_to_string(run_dir.join("robot-run.json")).unwrap()).unwrap();
    let outcome = &record["result"]["outcome"];
    assert_eq!(outcome["reason"], "declined", "{outcome}");
    assert_eq!(outcome["call"], "open_gripper()", "{outcome}");
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(server.requested_methods(), ["hello", "get_obj_names", "stop"]);

    // Without a terminal there is no one to ask: refused before anything is sent.
    let output = Command::new("setsid")
        .current_dir(common::workspace())
        .arg("--wait")
        .arg(env!("CARGO_BIN_EXE_nesy"))
        .arg("run")
        .arg("--policy")
        .arg(&policy)
        .args([
            "--robot",
            &server.address,
            "--skip-dry-run",
            "--confirm",
            "--robot-run-dir",
        ])
        .arg(dir.path().join("run2"))
        .stdin(Stdio::null())
        .output()
        .expect("setsid runs nesy without a controlling terminal");
    let text = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{text}");
    assert!(text.contains("--confirm asks on the terminal"), "{text}");
}
