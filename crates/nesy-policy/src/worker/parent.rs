//! The parent side: spawn the worker, feed it the request, collect its messages and its raw
//! output, and kill it when the wall clock runs out.

use std::ffi::OsString;
use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use super::protocol::{RELAY_FD, RESULT_FD, RelayReply, WorkerEpisode, WorkerMessage, WorkerRequest};
use crate::episode::EpisodeSpec;
use crate::limits::Limits;
use crate::relay::{CallRelay, RelayStop, RobotStopReason};
use crate::result::{CapturedText, ExecutionResult, Outcome, TimeLimit, WorkerReport};
use nesy_core::Embodiment;
use nesy_sim::api::TraceEntry;

/// How to start a worker process.
#[derive(Clone, Debug)]
pub struct WorkerCommand {
    /// The executable (normally the running `nesy` binary).
    pub program: PathBuf,
    /// Arguments selecting the hidden worker subcommand.
    pub args: Vec<OsString>,
}

/// Name of the hidden worker subcommand of `nesy`.
pub const WORKER_SUBCOMMAND: &str = "policy-worker";

impl WorkerCommand {
    /// The running executable, re-executed as `<exe> policy-worker`.
    pub fn current_exe() -> std::io::Result<WorkerCommand> {
        Ok(WorkerCommand::nesy_binary(std::env::current_exe()?))
    }

    /// A given `nesy` binary, e.g. `env!("CARGO_BIN_EXE_nesy")` in tests.
    pub fn nesy_binary(path: impl Into<PathBuf>) -> WorkerCommand {
        WorkerCommand {
            program: path.into(),
            args: vec![WORKER_SUBCOMMAND.into()],
        }
    }
}

/// Why a policy could not be run at all (as opposed to running and failing).
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The worker process could not be started.
    #[error("cannot start the policy worker {program}: {source}")]
    Spawn {
        /// The executable.
        program: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The worker reported that it could not set up the episode.
    #[error("the policy worker could not set up the episode: {0}")]
    Setup(String),
    /// An OS call in the parent failed.
    #[error("policy worker plumbing failed: {0}")]
    Io(#[from] std::io::Error),
}

const RAW_OUTPUT_CAP: usize = 16 * 1024;

fn nonce() -> String {
    let mut bytes = [0u8; 16];
    // SAFETY: getrandom fills the buffer it is given.
    let n = unsafe { libc::getrandom(bytes.as_mut_ptr().cast(), bytes.len(), 0) };
    if n != bytes.len() as isize {
        // Fall back to time and pid; the nonce only has to be unknown to the policy.
        let t = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap_or_default();
        bytes[..8].copy_from_slice(&(t.as_nanos() as u64).to_le_bytes());
        bytes[8..12].copy_from_slice(&std::process::id().to_le_bytes());
    }
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn pipe() -> std::io::Result<(OwnedFd, OwnedFd)> {
    let mut fds = [0; 2];
    // SAFETY: pipe2 writes two descriptors into the array.
    if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: both descriptors are fresh and owned by us.
    Ok(unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) })
}

fn drain_capped(mut reader: impl Read + Send + 'static) -> std::thread::JoinHandle<CapturedText> {
    std::thread::spawn(move || {
        let mut captured = CapturedText::default();
        let mut buf = [0u8; 8192];
        loop {
            match reader.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => captured.push_capped(&String::from_utf8_lossy(&buf[..n]), RAW_OUTPUT_CAP),
            }
        }
        captured
    })
}

/// Runs `source` against the episode `spec` in a fresh worker process under `limits`.
///
/// Every way the policy can end is an `Ok(ExecutionResult)` (see [`Outcome`]); `Err` means
/// the episode could not be set up (bad scene, worker missing).
pub fn run_policy(
    worker: &WorkerCommand,
    source: &str,
    spec: &EpisodeSpec,
    limits: &Limits,
) -> Result<ExecutionResult, RunError> {
    let episode = WorkerEpisode::Built { spec: spec.clone() };
    run(worker, source, episode, limits, true, None)
}

/// Runs `source` in a fresh worker process under `limits` against a robot outside the
/// worker: each call the policy makes is answered by `relay` in this process (see
/// [`CallRelay`]), so the policy keeps every sandbox layer while the bridge talks to the
/// robot. The first robot error ends the run: a later call is not relayed, and the outcome
/// is [`Outcome::RobotStopped`] with [`RobotStopReason::AfterError`].
pub fn run_relayed(
    worker: &WorkerCommand,
    source: &str,
    embodiment: Embodiment,
    limits: &Limits,
    relay: &mut dyn CallRelay,
) -> Result<ExecutionResult, RunError> {
    run(
        worker,
        source,
        WorkerEpisode::Relayed { embodiment },
        limits,
        true,
        Some(relay),
    )
}

/// Like [`run_policy`] with the static checks (layer 1) off, so tests can show that the
/// worker's own layers hold. Never use it for untrusted code outside such tests.
#[doc(hidden)]
pub fn run_policy_without_static_checks(
    worker: &WorkerCommand,
    source: &str,
    spec: &EpisodeSpec,
    limits: &Limits,
) -> Result<ExecutionResult, RunError> {
    let episode = WorkerEpisode::Built { spec: spec.clone() };
    run(worker, source, episode, limits, false, None)
}

fn run(
    worker: &WorkerCommand,
    source: &str,
    episode: WorkerEpisode,
    limits: &Limits,
    static_checks: bool,
    mut relay: Option<&mut dyn CallRelay>,
) -> Result<ExecutionResult, RunError> {
    let started = Instant::now();
    let nonce = nonce();
    let request = WorkerRequest {
        nonce: nonce.clone(),
        source: source.to_owned(),
        episode,
        limits: limits.clone(),
        static_checks,
    };
    let (read_end, write_end) = pipe()?;
    let answers = match relay {
        Some(_) => Some(pipe()?),
        None => None,
    };
    let mut child = spawn_worker(worker, &write_end, answers.as_ref().map(|(read, _)| read))?;
    drop(write_end);
    let mut answers = answers.map(|(read, write)| {
        drop(read);
        File::from(write)
    });

    let stdout = drain_capped(child.stdout.take().expect("piped"));
    let stderr = drain_capped(child.stderr.take().expect("piped"));
    let mut stdin = child.stdin.take().expect("piped");
    let body = serde_json::to_vec(&request).map_err(std::io::Error::other)?;
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&body);
    });

    let (tx, rx) = mpsc::channel::<WorkerMessage>();
    let reader_nonce = nonce.clone();
    let reader = std::thread::spawn(move || {
        let mut forged = 0usize;
        for line in BufReader::new(File::from(read_end)).lines() {
            let Ok(line) = line else { break };
            match serde_json::from_str::<WorkerMessage>(&line) {
                Ok(message) if message.nonce() == reader_nonce => {
                    if tx.send(message).is_err() {
                        break;
                    }
                }
                _ => forged += 1,
            }
        }
        forged
    });

    let kill_at = started + Duration::from_millis(limits.wall_time_ms + limits.kill_grace_ms);
    let relay = match (relay.as_mut(), answers.as_mut()) {
        (Some(relay), Some(answers)) => Some(Relaying {
            relay: &mut **relay,
            answers,
            first_error: None,
        }),
        _ => None,
    };
    let heard = listen(&rx, &mut child, kill_at, limits, relay);
    drop(answers);
    let status = wait_until(&mut child, kill_at.max(Instant::now()) + Duration::from_secs(2))?;
    let _ = writer.join();
    let _ = reader.join();
    let raw_output = {
        let mut text = stdout.join().unwrap_or_default();
        let err = stderr.join().unwrap_or_default();
        text.push_capped(&err.text, RAW_OUTPUT_CAP);
        text.truncated_bytes += err.truncated_bytes;
        text
    };
    let report = WorkerReport {
        exit_code: status.code(),
        signal: status.signal(),
        raw_output,
        startup_s: heard.startup_s,
    };
    if let Some(message) = heard.setup_error {
        return Err(RunError::Setup(message));
    }
    let wall_time_s = started.elapsed().as_secs_f64();
    if let Some(mut result) = heard.final_result {
        result.wall_time_s = wall_time_s;
        result.worker = Some(report);
        return Ok(result);
    }
    let outcome = if let Some(stop) = heard.robot_stop {
        stop
    } else if heard.killed_by_parent {
        Outcome::Timeout {
            limit: if heard.idle_kill {
                TimeLimit::Idle
            } else {
                TimeLimit::ParentKill
            },
            error: None,
        }
    } else {
        died(&report)
    };
    Ok(ExecutionResult {
        outcome,
        trace: heard.trace,
        stdout: CapturedText::default(),
        stderr: CapturedText::default(),
        wall_time_s,
        subtasks: None,
        final_state: None,
        worker: Some(report),
    })
}

/// Starts the worker process with the result channel's write end as its fd 3 (and, for a
/// relayed episode, the answers' read end as its fd 4), in its own process group, killed with
/// its parent.
fn spawn_worker(
    worker: &WorkerCommand,
    write_end: &OwnedFd,
    answers: Option<&OwnedFd>,
) -> Result<Child, RunError> {
    let write_raw = write_end.as_raw_fd();
    let answers_raw = answers.map(|fd| fd.as_raw_fd());
    let parent_pid = std::process::id() as libc::pid_t;
    let mut command = Command::new(&worker.program);
    command
        .args(&worker.args)
        .env_clear()
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        command.pre_exec(move || {
            if libc::dup2(write_raw, RESULT_FD) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            if let Some(raw) = answers_raw
                && libc::dup2(raw, RELAY_FD) < 0
            {
                return Err(std::io::Error::last_os_error());
            }
            libc::setpgid(0, 0);
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL, 0, 0, 0);
            if libc::getppid() != parent_pid {
                libc::_exit(1);
            }
            Ok(())
        });
    }
    command.spawn().map_err(|source| RunError::Spawn {
        program: worker.program.clone(),
        source,
    })
}

/// What the worker said on its channel before it finished or was killed.
struct Heard {
    trace: Vec<TraceEntry>,
    startup_s: Option<f64>,
    final_result: Option<ExecutionResult>,
    setup_error: Option<String>,
    killed_by_parent: bool,
    idle_kill: bool,
    /// Set when the relay stopped the run.
    robot_stop: Option<Outcome>,
}

/// A relayed episode's side of the parent: the relay and the pipe its answers go back on.
struct Relaying<'a> {
    relay: &'a mut dyn CallRelay,
    answers: &'a mut File,
    /// The first call the robot answered with an error, and the error.
    first_error: Option<String>,
}

impl Relaying<'_> {
    /// Answers one call, or says why the run stops here.
    fn call(&mut self, call: &nesy_sim::api::ApiCall) -> Result<(), Box<Outcome>> {
        let label = call.label();
        if let Some(first) = &self.first_error {
            return Err(robot_stopped(
                &label,
                RelayStop {
                    reason: RobotStopReason::AfterError,
                    message: format!(
                        "not sent: the robot already answered {first}, and its first error ends the run"
                    ),
                },
            ));
        }
        let result = self
            .relay
            .answer(call)
            .map_err(|stop| robot_stopped(&label, stop))?;
        if let Err(error) = &result {
            if !crate::relay::can_report_error(call) {
                return Err(robot_stopped(
                    &label,
                    RelayStop {
                        reason: RobotStopReason::UnexpectedError,
                        message: format!(
                            "the robot answered with an error ({error}), which this call cannot report to the policy"
                        ),
                    },
                ));
            }
            self.first_error = Some(format!("{label} with an error ({error})"));
        }
        self.reply(&RelayReply::Call { result }, &label)
    }

    /// Asks the robot for its end-of-episode report.
    fn finish(&mut self) -> Result<(), Box<Outcome>> {
        let end = self
            .relay
            .finish()
            .map_err(|stop| robot_stopped("finish", stop))?;
        self.reply(&RelayReply::Finish { end }, "finish")
    }

    fn reply(&mut self, reply: &RelayReply, label: &str) -> Result<(), Box<Outcome>> {
        let mut line = serde_json::to_vec(reply).map_err(|e| internal(label, &e.to_string()))?;
        line.push(b'\n');
        self.answers
            .write_all(&line)
            .map_err(|e| internal(label, &format!("the worker is gone: {e}")))
    }
}

fn robot_stopped(call: &str, stop: RelayStop) -> Box<Outcome> {
    Box::new(Outcome::RobotStopped {
        call: call.to_owned(),
        reason: stop.reason,
        message: stop.message,
    })
}

fn internal(call: &str, message: &str) -> Box<Outcome> {
    Box::new(Outcome::Killed {
        reason: format!("relaying {call} failed: {message}"),
    })
}

/// Collects the worker's messages until its result, its error, the end of the channel, the
/// wall-clock limit `kill_at`, or the idle limit, killing its process group at a limit.
fn listen(
    rx: &mpsc::Receiver<WorkerMessage>,
    child: &mut Child,
    kill_at: Instant,
    limits: &Limits,
    mut relay: Option<Relaying<'_>>,
) -> Heard {
    // The watchdog inside the worker stops an idle policy that still runs bytecode; one stuck
    // in C code holds the interpreter lock, so the parent also kills a worker that has sent
    // nothing (no `Ready`, no API call) for the idle limit plus the grace.
    let idle_grace = Duration::from_millis(limits.idle_ms.saturating_add(limits.kill_grace_ms));
    let mut last_heard = Instant::now();
    let mut idle_kill = false;
    let mut trace = Vec::new();
    let mut startup_s = None;
    let mut final_result = None;
    let mut setup_error = None;
    let mut killed_by_parent = false;
    let mut robot_stop = None;
    loop {
        let now = Instant::now();
        let idle_at = last_heard + idle_grace;
        if now >= kill_at || now >= idle_at {
            kill_group(child);
            killed_by_parent = true;
            idle_kill = now < kill_at;
            break;
        }
        match rx.recv_timeout(kill_at.min(idle_at) - now) {
            Ok(WorkerMessage::Ready { startup_s: s, .. }) => {
                startup_s = Some(s);
                last_heard = Instant::now();
            }
            Ok(WorkerMessage::Trace { entry, .. }) => {
                trace.push(entry);
                last_heard = Instant::now();
            }
            Ok(WorkerMessage::Call { call, .. }) => {
                let answered = match relay.as_mut() {
                    Some(relay) => relay.call(&call),
                    None => Err(internal(call.name(), "the worker asked for a robot outside it")),
                };
                // The time the robot took is not the policy's idle time.
                last_heard = Instant::now();
                if let Err(outcome) = answered {
                    kill_group(child);
                    robot_stop = Some(*outcome);
                    break;
                }
            }
            Ok(WorkerMessage::Finish { .. }) => {
                let answered = match relay.as_mut() {
                    Some(relay) => relay.finish(),
                    None => Err(internal("finish", "the worker asked for a robot outside it")),
                };
                last_heard = Instant::now();
                if let Err(outcome) = answered {
                    kill_group(child);
                    robot_stop = Some(*outcome);
                    break;
                }
            }
            Ok(WorkerMessage::Result { result, .. }) => {
                final_result = Some(*result);
                break;
            }
            Ok(WorkerMessage::Error { message, .. }) => {
                setup_error = Some(message);
                break;
            }
            Err(mpsc::RecvTimeoutError::Timeout) => continue,
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    Heard {
        trace,
        startup_s,
        final_result,
        setup_error,
        killed_by_parent,
        idle_kill,
        robot_stop,
    }
}

/// Classifies a worker that ended without a result.
fn died(report: &WorkerReport) -> Outcome {
    let out_of_memory = report.raw_output.text.contains("memory allocation of")
        || report.raw_output.text.contains("MemoryError")
        || report.raw_output.text.contains("Cannot allocate memory");
    match report.signal {
        Some(libc::SIGXCPU) => Outcome::Timeout {
            limit: TimeLimit::CpuTime,
            error: None,
        },
        Some(libc::SIGABRT) if out_of_memory => Outcome::Memory { error: None },
        Some(signal) => Outcome::Killed {
            reason: format!("worker killed by signal {} ({signal})", signal_name(signal)),
        },
        None if out_of_memory => Outcome::Memory { error: None },
        None => Outcome::Killed {
            reason: format!(
                "worker exited with status {} without reporting a result",
                report
                    .exit_code
                    .map(|c| c.to_string())
                    .unwrap_or_else(|| "?".into())
            ),
        },
    }
}

fn signal_name(signal: i32) -> &'static str {
    match signal {
        libc::SIGKILL => "SIGKILL",
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGABRT => "SIGABRT",
        libc::SIGXFSZ => "SIGXFSZ",
        libc::SIGSYS => "SIGSYS",
        libc::SIGBUS => "SIGBUS",
        libc::SIGTERM => "SIGTERM",
        libc::SIGPIPE => "SIGPIPE",
        _ => "signal",
    }
}

fn kill_group(child: &mut Child) {
    let pid = child.id() as libc::pid_t;
    // SAFETY: signalling the worker's own process group (it called setpgid(0, 0)).
    unsafe {
        libc::kill(-pid, libc::SIGKILL);
    }
    let _ = child.kill();
}

fn wait_until(child: &mut Child, deadline: Instant) -> std::io::Result<std::process::ExitStatus> {
    loop {
        if let Some(status) = child.try_wait()? {
            return Ok(status);
        }
        if Instant::now() >= deadline {
            kill_group(child);
            return child.wait();
        }
        std::thread::sleep(Duration::from_millis(1));
    }
}
