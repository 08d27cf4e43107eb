//! The server side of the robot protocol over any [`Episode`]: `nesy robot-server` serves the
//! simulator with it, and the bridge's tests run against it as a real separate process.
//!
//! One session per connection. Robot calls run one at a time on an executor thread that owns
//! the robot, while the connection's reader keeps answering heartbeats. The watchdog stops
//! the robot when the client has sent nothing for the heartbeat timeout; a closed connection
//! stops it at once. A stopped session executes nothing more.

use std::io::{BufRead, BufReader, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use nesy_policy::Episode;
use nesy_sim::api::RobotApi;
use serde_json::{Value, json};

use crate::address::{Listener, Stream};
use crate::protocol::{self, Hello, MAX_MESSAGE_BYTES, PROTOCOL_VERSION, Welcome, codes};

/// How a server runs its sessions.
#[derive(Clone, Debug, PartialEq)]
pub struct ServerOptions {
    /// The robot's name in `hello`'s answer.
    pub robot_name: String,
    /// After this long without a message from the client, the robot is stopped.
    pub heartbeat_timeout: Duration,
}

impl Default for ServerOptions {
    fn default() -> Self {
        ServerOptions {
            robot_name: "nesy simulator".to_owned(),
            heartbeat_timeout: Duration::from_millis(1500),
        }
    }
}

/// Where a server writes its events: one JSON object per line, `t` in seconds since the
/// log was opened.
#[derive(Clone)]
pub struct EventLog {
    sink: Arc<Mutex<Box<dyn Write + Send>>>,
    opened: Instant,
}

impl std::fmt::Debug for EventLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EventLog").finish_non_exhaustive()
    }
}

impl EventLog {
    /// A log writing to `sink`.
    pub fn new(sink: Box<dyn Write + Send>) -> EventLog {
        EventLog {
            sink: Arc::new(Mutex::new(sink)),
            opened: Instant::now(),
        }
    }

    /// Writes one event: `event` is its name, `fields` its other members.
    pub fn event(&self, event: &str, fields: Value) {
        let mut record =
            json!({"t": (self.opened.elapsed().as_secs_f64() * 1000.0).round() / 1000.0, "event": event});
        if let (Some(record), Value::Object(fields)) = (record.as_object_mut(), fields) {
            record.extend(fields);
        }
        let mut sink = self.sink.lock().unwrap_or_else(|e| e.into_inner());
        let _ = writeln!(sink, "{record}");
        let _ = sink.flush();
    }
}

/// How a session ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SessionEnd {
    /// The client sent `stop`.
    Stopped,
    /// The heartbeat watchdog fired.
    Watchdog,
    /// The connection closed or failed.
    Disconnected,
}

/// Accepts one client and serves it with `robot` until the session ends.
pub fn serve_session(
    listener: &Listener,
    robot: Box<dyn Episode>,
    options: &ServerOptions,
    log: &EventLog,
) -> std::io::Result<SessionEnd> {
    let stream = listener.accept()?;
    log.event("connected", json!({}));
    Ok(Session::new(stream, robot, options, log)?.run())
}

/// What the executor thread is asked to do.
enum Job {
    Call(Value, nesy_sim::api::ApiCall),
    ToolPosition(Value),
    Finish(Value),
}

struct Session<'a> {
    reader: BufReader<Stream>,
    writer: Arc<Mutex<Stream>>,
    closer: Stream,
    robot: Option<Box<dyn Episode>>,
    options: &'a ServerOptions,
    log: &'a EventLog,
    stopped: Arc<AtomicBool>,
    last_heard: Arc<Mutex<Instant>>,
}

impl<'a> Session<'a> {
    fn new(
        stream: Stream,
        robot: Box<dyn Episode>,
        options: &'a ServerOptions,
        log: &'a EventLog,
    ) -> std::io::Result<Self> {
        let reader = BufReader::new(stream.try_clone()?);
        let closer = stream.try_clone()?;
        Ok(Session {
            reader,
            writer: Arc::new(Mutex::new(stream)),
            closer,
            robot: Some(robot),
            options,
            log,
            stopped: Arc::new(AtomicBool::new(false)),
            last_heard: Arc::new(Mutex::new(Instant::now())),
        })
    }

    fn run(mut self) -> SessionEnd {
        let Some(robot) = self.robot.take() else {
            return SessionEnd::Disconnected;
        };
        let embodiment = robot.embodiment();
        let (jobs, job_rx) = mpsc::channel::<Job>();
        let executor = spawn_executor(
            robot,
            job_rx,
            Arc::clone(&self.writer),
            Arc::clone(&self.stopped),
            self.log.clone(),
        );
        let watchdog_fired = Arc::new(AtomicBool::new(false));
        let session_over = Arc::new(AtomicBool::new(false));
        let watchdog = self.spawn_watchdog(Arc::clone(&watchdog_fired), Arc::clone(&session_over));
        let mut greeted = false;
        let end = loop {
            let mut line = Vec::new();
            match (&mut self.reader)
                .take(MAX_MESSAGE_BYTES + 1)
                .read_until(b'\n', &mut line)
            {
                Ok(0) | Err(_) => break SessionEnd::Disconnected,
                Ok(n) if n as u64 > MAX_MESSAGE_BYTES => {
                    self.reply(
                        &Value::Null,
                        Err(protocol::error_json(
                            codes::INVALID_REQUEST,
                            "message too long",
                            None,
                        )),
                    );
                    break SessionEnd::Disconnected;
                }
                Ok(_) => {}
            }
            *self.last_heard.lock().unwrap_or_else(|e| e.into_inner()) = Instant::now();
            if line.iter().all(u8::is_ascii_whitespace) {
                continue;
            }
            let (id, method, params) = match read_request(&line) {
                Ok(request) => request,
                Err((id, error)) => {
                    self.reply(&id, Err(error));
                    continue;
                }
            };
            if method != "heartbeat" {
                self.log
                    .event("request", json!({"id": id, "method": method, "params": params}));
            }
            match method.as_str() {
                "heartbeat" => self.reply(&id, Ok(json!({}))),
                "hello" => match self.hello(&params, embodiment) {
                    Ok(welcome) => {
                        greeted = true;
                        self.reply(&id, Ok(welcome));
                    }
                    Err(error) => self.reply(&id, Err(error)),
                },
                "stop" => {
                    self.reply(&id, Ok(json!({})));
                    break SessionEnd::Stopped;
                }
                _ if !greeted => self.reply(
                    &id,
                    Err(protocol::error_json(codes::NO_SESSION, "say hello first", None)),
                ),
                _ if self.stopped.load(Ordering::Acquire) => self.reply(
                    &id,
                    Err(protocol::error_json(
                        codes::SESSION_STOPPED,
                        "the robot was stopped",
                        None,
                    )),
                ),
                "get_tool_pos" => {
                    let _ = jobs.send(Job::ToolPosition(id));
                }
                "finish" => {
                    let _ = jobs.send(Job::Finish(id));
                }
                _ => match protocol::call_from_request(&method, &params) {
                    Ok(call) => {
                        let _ = jobs.send(Job::Call(id, call));
                    }
                    Err(detail) => {
                        let known = nesy_policy::api_function_names().contains(&method.as_str());
                        let (code, message) = if known {
                            (codes::INVALID_PARAMS, format!("{method}: {detail}"))
                        } else {
                            (codes::METHOD_NOT_FOUND, format!("no method {method:?}"))
                        };
                        self.reply(&id, Err(protocol::error_json(code, &message, None)));
                    }
                },
            }
        };
        let end = if watchdog_fired.load(Ordering::Acquire) {
            SessionEnd::Watchdog
        } else {
            end
        };
        // Nothing more runs on this robot: the executor finishes the call in hand, if any,
        // and drops the robot.
        self.stopped.store(true, Ordering::Release);
        session_over.store(true, Ordering::Release);
        if end != SessionEnd::Watchdog {
            let reason = match end {
                SessionEnd::Stopped => "the client sent stop",
                _ => "the connection closed",
            };
            self.log.event("stopped", json!({"reason": reason}));
        }
        drop(jobs);
        self.closer.shutdown();
        let _ = executor.join();
        watchdog.thread().unpark();
        let _ = watchdog.join();
        end
    }

    fn hello(&self, params: &Value, embodiment: nesy_core::Embodiment) -> Result<Value, Value> {
        let invalid = |message: String| protocol::error_json(codes::INVALID_PARAMS, &message, None);
        let hello: Hello =
            serde_json::from_value(params.clone()).map_err(|e| invalid(format!("hello: {e}")))?;
        if hello.protocol != PROTOCOL_VERSION {
            return Err(invalid(format!(
                "this server speaks {PROTOCOL_VERSION}, not {}",
                hello.protocol
            )));
        }
        if !(hello.speed_scale > 0.0 && hello.speed_scale <= 1.0) {
            return Err(invalid(format!(
                "speed_scale must be in (0, 1], not {}",
                hello.speed_scale
            )));
        }
        let welcome = Welcome {
            protocol: PROTOCOL_VERSION.to_owned(),
            robot: self.options.robot_name.clone(),
            embodiment,
            heartbeat_timeout_s: self.options.heartbeat_timeout.as_secs_f64(),
            speed_scale: hello.speed_scale,
        };
        Ok(serde_json::to_value(welcome).unwrap_or(Value::Null))
    }

    fn reply(&self, id: &Value, outcome: Result<Value, Value>) {
        send(&self.writer, &protocol::response(id, outcome));
    }

    /// Stops the robot and closes the connection when the client has been silent too long.
    fn spawn_watchdog(&self, fired: Arc<AtomicBool>, over: Arc<AtomicBool>) -> std::thread::JoinHandle<()> {
        let last_heard = Arc::clone(&self.last_heard);
        let stopped = Arc::clone(&self.stopped);
        let timeout = self.options.heartbeat_timeout;
        let closer = self.closer.try_clone();
        let log = self.log.clone();
        std::thread::spawn(move || {
            let Ok(closer) = closer else { return };
            while !over.load(Ordering::Acquire) {
                std::thread::park_timeout(Duration::from_millis(20));
                let silent = last_heard.lock().unwrap_or_else(|e| e.into_inner()).elapsed();
                if silent >= timeout && !over.load(Ordering::Acquire) {
                    stopped.store(true, Ordering::Release);
                    fired.store(true, Ordering::Release);
                    log.event(
                        "stopped",
                        json!({"reason": format!("watchdog: no message from the client for {:.2} s", silent.as_secs_f64())}),
                    );
                    closer.shutdown();
                    return;
                }
            }
        })
    }
}

/// Runs robot jobs in order on their own thread, answering each on the connection.
fn spawn_executor(
    mut robot: Box<dyn Episode>,
    jobs: mpsc::Receiver<Job>,
    writer: Arc<Mutex<Stream>>,
    stopped: Arc<AtomicBool>,
    log: EventLog,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        for job in jobs {
            let (id, method, outcome) = match job {
                _ if stopped.load(Ordering::Acquire) => continue,
                Job::Call(id, call) => {
                    let robot_api: &mut dyn RobotApi = &mut *robot;
                    let outcome = call
                        .perform(robot_api)
                        .map(|value| protocol::value_json(&value))
                        .map_err(|error| protocol::robot_error_json(&error));
                    (id, call.name().to_owned(), outcome)
                }
                Job::ToolPosition(id) => (id, "get_tool_pos".to_owned(), Ok(json!(robot.tool_position()))),
                Job::Finish(id) => {
                    let end = robot.finish();
                    (
                        id,
                        "finish".to_owned(),
                        Ok(serde_json::to_value(end).unwrap_or(Value::Null)),
                    )
                }
            };
            let summary = match &outcome {
                Ok(result) => json!({"id": id, "method": method, "result": result}),
                Err(error) => json!({"id": id, "method": method, "error": error}),
            };
            log.event("answer", summary);
            send(&writer, &protocol::response(&id, outcome));
        }
    })
}

fn send(writer: &Mutex<Stream>, message: &Value) {
    if let Ok(mut line) = serde_json::to_vec(message) {
        line.push(b'\n');
        let mut stream = writer.lock().unwrap_or_else(|e| e.into_inner());
        let _ = stream.write_all(&line).and_then(|()| stream.flush());
    }
}

/// One request line: its id, method and params, or the error to answer it with.
fn read_request(line: &[u8]) -> Result<(Value, String, Value), (Value, Value)> {
    let value: Value = serde_json::from_slice(line).map_err(|e| {
        (
            Value::Null,
            protocol::error_json(codes::PARSE_ERROR, &format!("not JSON: {e}"), None),
        )
    })?;
    let id = value.get("id").cloned().unwrap_or(Value::Null);
    let invalid = |message: &str| {
        (
            id.clone(),
            protocol::error_json(codes::INVALID_REQUEST, message, None),
        )
    };
    if value.get("jsonrpc").and_then(Value::as_str) != Some("2.0") {
        return Err(invalid("expected \"jsonrpc\": \"2.0\""));
    }
    if !(id.is_u64() || id.is_string()) {
        return Err(invalid("expected an \"id\" (a number or a string)"));
    }
    let Some(method) = value.get("method").and_then(Value::as_str) else {
        return Err(invalid("expected a \"method\" string"));
    };
    let params = value.get("params").cloned().unwrap_or(Value::Null);
    Ok((id, method.to_owned(), params))
}
