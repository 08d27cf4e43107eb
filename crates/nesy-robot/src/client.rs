//! The client side of the robot protocol: one connection, a heartbeat thread, and calls that
//! wait for their answer within a time limit.

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use nesy_sim::api::{ApiCall, ApiError, ApiValue};
use serde_json::{Value, json};

use crate::address::{RobotAddress, Stream};
use crate::protocol::{self, Hello, MAX_MESSAGE_BYTES, PROTOCOL_VERSION, Welcome, codes};

/// How a client talks to a robot server.
#[derive(Clone, Debug, PartialEq)]
pub struct ClientOptions {
    /// Time to open the connection.
    pub connect_timeout: Duration,
    /// Longest wait for the answer to one call (a motion included).
    pub call_timeout: Duration,
    /// Interval between heartbeats.
    pub heartbeat_period: Duration,
    /// The speed scale asked for in `hello`, in (0, 1].
    pub speed_scale: f64,
}

impl Default for ClientOptions {
    fn default() -> Self {
        ClientOptions {
            connect_timeout: Duration::from_secs(5),
            call_timeout: Duration::from_secs(60),
            heartbeat_period: Duration::from_millis(500),
            speed_scale: 0.5,
        }
    }
}

/// Why a call got no usable answer. Any of these ends a run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ClientFault {
    /// No answer within the call's time limit.
    #[error("{method}: no answer from {address} within {seconds:.1} s")]
    NoAnswer {
        /// The method.
        method: String,
        /// The server.
        address: String,
        /// The limit.
        seconds: f64,
    },
    /// An answer that is not the protocol.
    #[error("{method}: unreadable answer from {address}: {detail}")]
    BadAnswer {
        /// The method.
        method: String,
        /// The server.
        address: String,
        /// What was wrong with it.
        detail: String,
    },
    /// The connection closed or failed.
    #[error("{method}: the connection to {address} closed: {detail}")]
    Disconnected {
        /// The method.
        method: String,
        /// The server.
        address: String,
        /// What the OS or the server said.
        detail: String,
    },
}

/// How a request's id is made.
#[derive(Clone, Copy)]
enum RequestId {
    /// An integer: the policy's calls and the session's own requests.
    Plain,
    /// `check-N`: a query for nesy's own checks.
    Check,
}

/// What the reader thread delivers for a request id.
type Answer = Result<Result<Value, Value>, String>;

/// Requests waiting for their answers, and whether the connection has failed.
#[derive(Default)]
struct Pending {
    /// Keyed by the request id's JSON text (`17`, `"check-18"`).
    waiting: HashMap<String, mpsc::Sender<Answer>>,
    /// Set once the reader stops: every later call fails with it at once.
    closed: Option<String>,
    /// An answer that matched no request (garbage, or a made-up id), to report at the next call.
    stray: Option<String>,
}

/// A connection to a robot server after a successful `hello`.
pub struct RobotClient {
    address: RobotAddress,
    writer: Arc<Mutex<Stream>>,
    pending: Arc<Mutex<Pending>>,
    next_id: Arc<AtomicU64>,
    options: ClientOptions,
    welcome: Welcome,
    stop_heartbeat: Arc<AtomicBool>,
    heartbeat: Option<JoinHandle<()>>,
    reader: Option<JoinHandle<()>>,
    closer: Stream,
}

impl std::fmt::Debug for RobotClient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RobotClient")
            .field("address", &self.address)
            .field("welcome", &self.welcome)
            .finish_non_exhaustive()
    }
}

impl RobotClient {
    /// Connects, says `hello` and starts the heartbeat. Fails if the server speaks another
    /// protocol or does not accept the speed scale.
    pub fn connect(address: &RobotAddress, options: ClientOptions) -> Result<RobotClient, ClientFault> {
        let fault = |detail: String| ClientFault::Disconnected {
            method: "hello".to_owned(),
            address: address.to_string(),
            detail,
        };
        let stream = address
            .connect(options.connect_timeout)
            .map_err(|e| fault(e.to_string()))?;
        let read_half = stream.try_clone().map_err(|e| fault(e.to_string()))?;
        let closer = stream.try_clone().map_err(|e| fault(e.to_string()))?;
        let pending = Arc::new(Mutex::new(Pending::default()));
        let reader = spawn_reader(read_half, Arc::clone(&pending));
        let mut client = RobotClient {
            address: address.clone(),
            writer: Arc::new(Mutex::new(stream)),
            pending,
            next_id: Arc::new(AtomicU64::new(1)),
            options: options.clone(),
            welcome: Welcome {
                protocol: String::new(),
                robot: String::new(),
                embodiment: nesy_core::Embodiment::Finger,
                heartbeat_timeout_s: 0.0,
                speed_scale: 0.0,
            },
            stop_heartbeat: Arc::new(AtomicBool::new(false)),
            heartbeat: None,
            reader: Some(reader),
            closer,
        };
        let hello = Hello {
            protocol: PROTOCOL_VERSION.to_owned(),
            client: format!("nesy {}", env!("CARGO_PKG_VERSION")),
            heartbeat_period_s: options.heartbeat_period.as_secs_f64(),
            speed_scale: options.speed_scale,
        };
        let params = serde_json::to_value(&hello).unwrap_or(Value::Null);
        let answer = client.request(
            "hello",
            params,
            options.connect_timeout.max(Duration::from_secs(5)),
        )?;
        let bad = |detail: String| ClientFault::BadAnswer {
            method: "hello".to_owned(),
            address: address.to_string(),
            detail,
        };
        let result =
            answer.map_err(|error| bad(format!("the server refused hello: {}", protocol::short(&error))))?;
        let welcome: Welcome = serde_json::from_value(result.clone())
            .map_err(|e| bad(format!("{e} in {}", protocol::short(&result))))?;
        if welcome.protocol != PROTOCOL_VERSION {
            return Err(bad(format!(
                "the server speaks {:?}, expected {PROTOCOL_VERSION:?}",
                welcome.protocol
            )));
        }
        if (welcome.speed_scale - options.speed_scale).abs() > 1e-9 {
            return Err(bad(format!(
                "the robot answered speed scale {} to the {} asked for",
                welcome.speed_scale, options.speed_scale
            )));
        }
        client.welcome = welcome;
        client.heartbeat = Some(client.spawn_heartbeat());
        Ok(client)
    }

    /// What the server said about its robot.
    pub fn welcome(&self) -> &Welcome {
        &self.welcome
    }

    /// The server's address.
    pub fn address(&self) -> &RobotAddress {
        &self.address
    }

    /// Performs one robot API call: the robot's value or its typed error, or a fault.
    pub fn call(&self, call: &ApiCall) -> Result<Result<ApiValue, ApiError>, ClientFault> {
        self.api_call(call, false)
    }

    /// Like [`RobotClient::call`], for a query nesy makes for its own checks rather than for
    /// the policy: its request id is a string `check-N`, so that a server's log can tell it
    /// from the policy's calls.
    pub fn check_call(&self, call: &ApiCall) -> Result<Result<ApiValue, ApiError>, ClientFault> {
        self.api_call(call, true)
    }

    fn api_call(&self, call: &ApiCall, check: bool) -> Result<Result<ApiValue, ApiError>, ClientFault> {
        let (method, params) = protocol::call_request(call);
        let kind = if check { RequestId::Check } else { RequestId::Plain };
        match self.request_as(kind, method, params, self.options.call_timeout)? {
            Ok(result) => protocol::value_from_json(call, &result)
                .map(Ok)
                .map_err(|detail| self.bad(method, detail)),
            Err(error) => self.robot_error(method, &error).map(Err),
        }
    }

    /// The tool tip's position, if the robot reports it (`get_tool_pos`).
    pub fn tool_position(&self) -> Result<Option<[f64; 3]>, ClientFault> {
        let method = "get_tool_pos";
        match self.request(method, json!({}), self.options.call_timeout)? {
            Ok(Value::Null) => Ok(None),
            Ok(value) => {
                let call = ApiCall::GetObjPos {
                    obj_name: String::new(),
                };
                match protocol::value_from_json(&call, &value) {
                    Ok(ApiValue::Vec3(v)) => Ok(Some(v)),
                    _ => Err(self.bad(
                        method,
                        format!("expected [x, y, z] or null, not {}", protocol::short(&value)),
                    )),
                }
            }
            Err(error) => Err(self.bad(method, format!("error {}", protocol::short(&error)))),
        }
    }

    /// The robot's end-of-run report (`finish`), as its JSON object.
    pub fn finish(&self) -> Result<Value, ClientFault> {
        match self.request("finish", json!({}), self.options.call_timeout)? {
            Ok(value) => Ok(value),
            Err(error) => Err(self.bad("finish", format!("error {}", protocol::short(&error)))),
        }
    }

    /// Ends the session: sends `stop` (the robot stops and the server closes the session),
    /// stops the heartbeat and closes the connection.
    pub fn close(mut self, reason: &str) {
        let _ = self.request("stop", json!({"reason": reason}), Duration::from_secs(2));
        self.shut();
    }

    fn shut(&mut self) {
        self.stop_heartbeat.store(true, Ordering::Release);
        if let Some(heartbeat) = self.heartbeat.take() {
            heartbeat.thread().unpark();
            let _ = heartbeat.join();
        }
        self.closer.shutdown();
        if let Some(reader) = self.reader.take() {
            let _ = reader.join();
        }
    }

    fn bad(&self, method: &str, detail: String) -> ClientFault {
        ClientFault::BadAnswer {
            method: method.to_owned(),
            address: self.address.to_string(),
            detail,
        }
    }

    /// A robot error's typed form; another error object is a fault.
    fn robot_error(&self, method: &str, error: &Value) -> Result<ApiError, ClientFault> {
        let code = error.get("code").and_then(Value::as_i64);
        let message = error.get("message").and_then(Value::as_str).unwrap_or_default();
        if code == Some(codes::ROBOT_ERROR) {
            let data = error.get("data").cloned().unwrap_or(Value::Null);
            return serde_json::from_value::<ApiError>(data.clone()).map_err(|e| {
                self.bad(
                    method,
                    format!(
                        "robot error data {} is not a typed error: {e}",
                        protocol::short(&data)
                    ),
                )
            });
        }
        Err(self.bad(
            method,
            format!(
                "error {}: {message}",
                code.map(|c| c.to_string()).unwrap_or_else(|| "?".into())
            ),
        ))
    }

    /// Sends one request and waits up to `timeout` for its answer: `Ok(result)` or
    /// `Err(error object)` as the server sent them.
    fn request(
        &self,
        method: &str,
        params: Value,
        timeout: Duration,
    ) -> Result<Result<Value, Value>, ClientFault> {
        self.request_as(RequestId::Plain, method, params, timeout)
    }

    fn request_as(
        &self,
        kind: RequestId,
        method: &str,
        params: Value,
        timeout: Duration,
    ) -> Result<Result<Value, Value>, ClientFault> {
        let number = self.next_id.fetch_add(1, Ordering::Relaxed);
        let id = match kind {
            RequestId::Plain => json!(number),
            RequestId::Check => json!(format!("check-{number}")),
        };
        let key = id.to_string();
        let (tx, rx) = mpsc::channel();
        {
            let mut pending = self.pending.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(detail) = pending.stray.take() {
                return Err(self.bad(method, detail));
            }
            if let Some(detail) = &pending.closed {
                return Err(self.disconnected(method, detail.clone()));
            }
            pending.waiting.insert(key.clone(), tx);
        }
        if let Err(err) = send(&self.writer, &protocol::request(id, method, params)) {
            self.forget(&key);
            return Err(self.disconnected(method, err.to_string()));
        }
        let answer = rx.recv_timeout(timeout);
        self.forget(&key);
        match answer {
            Ok(Ok(outcome)) => Ok(outcome),
            Ok(Err(detail)) => {
                let pending = self.pending.lock().unwrap_or_else(|e| e.into_inner());
                if pending.closed.as_deref() == Some(detail.as_str()) {
                    Err(self.disconnected(method, detail))
                } else {
                    Err(self.bad(method, detail))
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => Err(ClientFault::NoAnswer {
                method: method.to_owned(),
                address: self.address.to_string(),
                seconds: timeout.as_secs_f64(),
            }),
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                Err(self.disconnected(method, "the reader stopped".to_owned()))
            }
        }
    }

    fn forget(&self, key: &str) {
        self.pending
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .waiting
            .remove(key);
    }

    fn disconnected(&self, method: &str, detail: String) -> ClientFault {
        ClientFault::Disconnected {
            method: method.to_owned(),
            address: self.address.to_string(),
            detail,
        }
    }

    fn spawn_heartbeat(&self) -> JoinHandle<()> {
        let writer = Arc::clone(&self.writer);
        let stop = Arc::clone(&self.stop_heartbeat);
        let ids = Arc::clone(&self.next_id);
        let period = self.options.heartbeat_period;
        std::thread::spawn(move || {
            while !stop.load(Ordering::Acquire) {
                let id = ids.fetch_add(1, Ordering::Relaxed);
                // The answer matches no waiting request and is dropped by the reader.
                if send(&writer, &protocol::request(json!(id), "heartbeat", json!({}))).is_err() {
                    return;
                }
                std::thread::park_timeout(period);
            }
        })
    }
}

impl Drop for RobotClient {
    fn drop(&mut self) {
        self.shut();
    }
}

fn send(writer: &Mutex<Stream>, message: &Value) -> std::io::Result<()> {
    let mut line = serde_json::to_vec(message).map_err(std::io::Error::other)?;
    line.push(b'\n');
    let mut stream = writer.lock().unwrap_or_else(|e| e.into_inner());
    stream.write_all(&line)?;
    stream.flush()
}

/// Reads answers and hands each to the request waiting for it. Answers to heartbeats and to
/// requests that timed out match no waiting request and are dropped; a line that is not a
/// JSON-RPC response fails the request waiting (or the next one).
fn spawn_reader(stream: Stream, pending: Arc<Mutex<Pending>>) -> JoinHandle<()> {
    std::thread::spawn(move || {
        let mut reader = BufReader::new(stream);
        let closed = loop {
            let mut line = Vec::new();
            match (&mut reader)
                .take(MAX_MESSAGE_BYTES + 1)
                .read_until(b'\n', &mut line)
            {
                Ok(0) => break "the server closed the connection".to_owned(),
                Err(err) => break err.to_string(),
                Ok(n) if n as u64 > MAX_MESSAGE_BYTES => {
                    break format!("an answer longer than {MAX_MESSAGE_BYTES} bytes");
                }
                Ok(_) => {}
            }
            if line.iter().all(u8::is_ascii_whitespace) {
                continue;
            }
            let mut pending = pending.lock().unwrap_or_else(|e| e.into_inner());
            match read_response(&line) {
                Ok((key, outcome)) => {
                    if let Some(waiter) = pending.waiting.remove(&key) {
                        let _ = waiter.send(Ok(outcome));
                    }
                }
                Err(detail) => fail_waiting(&mut pending, detail),
            }
        };
        let mut pending = pending.lock().unwrap_or_else(|e| e.into_inner());
        pending.closed = Some(closed.clone());
        for (_, waiter) in pending.waiting.drain() {
            let _ = waiter.send(Err(closed.clone()));
        }
    })
}

/// Fails the waiting requests with `detail`, or keeps it for the next one.
fn fail_waiting(pending: &mut Pending, detail: String) {
    if pending.waiting.is_empty() {
        pending.stray = Some(detail);
    } else {
        for (_, waiter) in pending.waiting.drain() {
            let _ = waiter.send(Err(detail.clone()));
        }
    }
}

/// One response line: its id and its result or error object.
fn read_response(line: &[u8]) -> Result<(String, Result<Value, Value>), String> {
    let text = String::from_utf8_lossy(line);
    let value: Value = serde_json::from_str(text.trim()).map_err(|e| {
        format!(
            "not JSON ({e}): {}",
            protocol::short(&Value::String(text.trim().to_owned()))
        )
    })?;
    let Some(object) = value.as_object() else {
        return Err(format!("not a JSON-RPC response: {}", protocol::short(&value)));
    };
    let id = object
        .get("id")
        .filter(|id| id.is_u64() || id.is_string())
        .map(Value::to_string);
    let version = object.get("jsonrpc").and_then(Value::as_str);
    match (id, version, object.get("result"), object.get("error")) {
        (Some(id), Some("2.0"), Some(result), None) => Ok((id, Ok(result.clone()))),
        (Some(id), Some("2.0"), None, Some(error)) if error.is_object() => Ok((id, Err(error.clone()))),
        _ => Err(format!(
            "not a JSON-RPC 2.0 response with an id and a result or an error: {}",
            protocol::short(&value)
        )),
    }
}
