//! The worker side: read the request, lock the process down, run the episode, report.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::fd::FromRawFd;
use std::process::ExitCode;
use std::time::Instant;

use super::protocol::{
    MAX_RELAY_LINE_BYTES, MAX_REQUEST_BYTES, RELAY_FD, RESULT_FD, RelayReply, WorkerEpisode, WorkerMessage,
    WorkerRequest,
};
use super::{limits, seccomp};
use crate::episode::{Episode, EpisodeEnd, EpisodeFactory};
use crate::python::session::TraceSink;
use crate::relay::{RelayLink, RelayedRobot};
use crate::runner;
use nesy_sim::api::{ApiCall, ApiError, ApiValue};

/// Shared writer for the result channel (the trace sink and the final message use it).
#[derive(Clone)]
struct Channel(std::sync::Arc<std::sync::Mutex<File>>);

impl Channel {
    fn send(&self, message: &WorkerMessage) {
        if let Ok(mut line) = serde_json::to_vec(message) {
            line.push(b'\n');
            if let Ok(mut file) = self.0.lock() {
                let _ = file.write_all(&line);
            }
        }
    }
}

/// Entry point of the hidden worker subcommand. Reads a worker request from stdin,
/// builds the episode with `factory`, runs it and reports on fd 3. Never returns normally
/// after the episode: it exits without finalising the interpreter.
pub fn worker_main(factory: &dyn EpisodeFactory) -> ExitCode {
    let started = Instant::now();
    // SAFETY: getppid has no preconditions.
    limits::die_with_parent(unsafe { libc::getppid() });
    if !is_pipe(RESULT_FD) {
        eprintln!("nesy policy-worker: fd {RESULT_FD} is not a pipe; this command is started by `nesy run`");
        return ExitCode::from(2);
    }
    // SAFETY: fd 3 is an open pipe (checked above) handed to us by the parent; we own it.
    let channel = Channel(std::sync::Arc::new(std::sync::Mutex::new(unsafe {
        File::from_raw_fd(RESULT_FD)
    })));

    let mut raw = Vec::new();
    if let Err(err) = std::io::stdin().take(MAX_REQUEST_BYTES).read_to_end(&mut raw) {
        eprintln!("nesy policy-worker: cannot read the request: {err}");
        return ExitCode::from(2);
    }
    let request: WorkerRequest = match serde_json::from_slice(&raw) {
        Ok(request) => request,
        Err(err) => {
            eprintln!("nesy policy-worker: malformed request: {err}");
            return ExitCode::from(2);
        }
    };
    drop(raw);
    redirect_stdin_to_null();
    let nonce = request.nonce.clone();
    let fail = |message: String| {
        channel.send(&WorkerMessage::Error {
            nonce: nonce.clone(),
            message,
        });
        ExitCode::from(1)
    };

    let cpu_seconds = (request.limits.wall_time_ms + request.limits.kill_grace_ms).div_ceil(1000) + 1;
    if let Err(err) = limits::before_startup(request.limits.memory_bytes, cpu_seconds) {
        return fail(format!("cannot set resource limits: {err}"));
    }
    let episode: Box<dyn Episode> = match &request.episode {
        WorkerEpisode::Built { spec } => match factory.build(spec) {
            Ok(episode) => episode,
            Err(err) => return fail(err.to_string()),
        },
        WorkerEpisode::Relayed { embodiment } => {
            if !is_pipe(RELAY_FD) {
                return fail(format!(
                    "a relayed episode needs the parent's answers on fd {RELAY_FD}"
                ));
            }
            // SAFETY: fd 4 is an open pipe (checked above) handed to us by the parent; we own it.
            let answers = BufReader::new(unsafe { File::from_raw_fd(RELAY_FD) });
            let link = PipeLink {
                channel: channel.clone(),
                nonce: nonce.clone(),
                answers,
            };
            Box::new(RelayedRobot::new(*embodiment, Box::new(link)))
        }
    };
    if let Err(err) = crate::python::interpreter::initialize() {
        return fail(err.to_string());
    }
    if let Err(err) = limits::after_startup() {
        return fail(format!("cannot set resource limits: {err}"));
    }
    if let Err(err) = seccomp::install() {
        return fail(format!("cannot install the seccomp filter: {err}"));
    }
    channel.send(&WorkerMessage::Ready {
        nonce: nonce.clone(),
        startup_s: started.elapsed().as_secs_f64(),
    });

    let sink_channel = channel.clone();
    let sink_nonce = nonce.clone();
    let sink: TraceSink = Box::new(move |entry| {
        sink_channel.send(&WorkerMessage::Trace {
            nonce: sink_nonce.clone(),
            entry: entry.clone(),
        });
    });
    let ran = if request.static_checks {
        runner::run_in_process(&request.source, episode, &request.limits, Some(sink))
    } else {
        runner::run_in_process_without_static_checks(&request.source, episode, &request.limits, Some(sink))
    };
    match ran {
        Ok(result) => channel.send(&WorkerMessage::Result {
            nonce,
            result: Box::new(result),
        }),
        Err(err) => return fail(err.to_string()),
    }
    let _ = std::io::stdout().flush();
    let _ = std::io::stderr().flush();
    // Skip interpreter finalisation: nothing the policy left behind runs after its episode.
    // SAFETY: terminating the process.
    unsafe { libc::_exit(0) }
}

/// True if `fd` is an open pipe.
fn is_pipe(fd: i32) -> bool {
    // SAFETY: fstat on a descriptor number we only inspect.
    unsafe {
        let mut st: libc::stat = std::mem::zeroed();
        libc::fstat(fd, &mut st) == 0 && (st.st_mode & libc::S_IFMT) == libc::S_IFIFO
    }
}

/// A relayed episode's link to the parent: calls out on the message channel, answers back on
/// [`RELAY_FD`].
struct PipeLink {
    channel: Channel,
    nonce: String,
    answers: BufReader<File>,
}

impl PipeLink {
    fn read_reply(&mut self) -> Option<RelayReply> {
        let mut line = String::new();
        let read = (&mut self.answers)
            .take(MAX_RELAY_LINE_BYTES)
            .read_line(&mut line)
            .ok()?;
        if read == 0 {
            return None;
        }
        serde_json::from_str(&line).ok()
    }
}

impl RelayLink for PipeLink {
    fn call(&mut self, call: &ApiCall) -> Option<Result<ApiValue, ApiError>> {
        self.channel.send(&WorkerMessage::Call {
            nonce: self.nonce.clone(),
            call: call.clone(),
        });
        match self.read_reply()? {
            RelayReply::Call { result } => Some(result),
            RelayReply::Finish { .. } => None,
        }
    }

    fn finish(&mut self) -> Option<EpisodeEnd> {
        self.channel.send(&WorkerMessage::Finish {
            nonce: self.nonce.clone(),
        });
        match self.read_reply()? {
            RelayReply::Finish { end } => Some(end),
            RelayReply::Call { .. } => None,
        }
    }
}

fn redirect_stdin_to_null() {
    // SAFETY: open/dup2/close on descriptors we own.
    unsafe {
        let fd = libc::open(c"/dev/null".as_ptr(), libc::O_RDONLY | libc::O_CLOEXEC);
        if fd >= 0 {
            libc::dup2(fd, 0);
            libc::close(fd);
        } else {
            libc::close(0);
        }
    }
}
