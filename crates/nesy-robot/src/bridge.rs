//! The bridge: answers a relayed policy's calls from a robot server, after nesy's own checks,
//! and logs every call and answer to the run directory.

use std::fs::File;
use std::io::Write;
use std::time::Instant;

use nesy_policy::{CallRelay, EpisodeEnd, RelayStop, RobotStopReason};
use nesy_sim::api::{ApiCall, ApiError, ApiValue};
use serde_json::{Value, json};

use crate::client::{ClientFault, RobotClient};
use crate::protocol;
use crate::safety::Workspace;

/// Asks the operator whether to send a call; `true` sends it.
pub type Confirm = Box<dyn FnMut(&ApiCall) -> bool + Send>;

/// A [`CallRelay`] to a robot server. Before a motion is sent, its target is checked against
/// the [`Workspace`] (a relative move against the tool position the robot reports, a move to
/// an object against the object's reported position); with a [`Confirm`] hook, the operator
/// is asked before each call. Every call, check and answer goes to the call log as one JSON
/// line.
pub struct Bridge {
    client: RobotClient,
    workspace: Workspace,
    confirm: Option<Confirm>,
    log: File,
    started: Instant,
    sent: usize,
}

impl std::fmt::Debug for Bridge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Bridge")
            .field("client", &self.client)
            .field("workspace", &self.workspace)
            .finish_non_exhaustive()
    }
}

impl Bridge {
    /// A bridge over a connected client, logging to `log` (the run's `robot-calls.jsonl`).
    pub fn new(client: RobotClient, workspace: Workspace, log: File) -> Bridge {
        let mut bridge = Bridge {
            client,
            workspace,
            confirm: None,
            log,
            started: Instant::now(),
            sent: 0,
        };
        let welcome = serde_json::to_value(bridge.client.welcome()).unwrap_or(Value::Null);
        let address = bridge.client.address().to_string();
        bridge.record(json!({"event": "connected", "address": address, "welcome": welcome, "workspace": {"min": workspace.min, "max": workspace.max}}));
        bridge
    }

    /// Asks `confirm` before every call.
    pub fn with_confirmation(mut self, confirm: Confirm) -> Bridge {
        self.confirm = Some(confirm);
        self
    }

    /// How many calls reached the robot.
    pub fn calls_sent(&self) -> usize {
        self.sent
    }

    /// Ends the session (the robot stops) and closes the log.
    pub fn close(mut self, reason: &str) {
        self.record(json!({"event": "closed", "reason": reason}));
        self.client.close(reason);
    }

    fn record(&mut self, mut entry: Value) {
        entry["t"] = json!((self.started.elapsed().as_secs_f64() * 1000.0).round() / 1000.0);
        let _ = writeln!(self.log, "{entry}");
    }

    fn fault(&mut self, call: &str, fault: ClientFault) -> RelayStop {
        let reason = match fault {
            ClientFault::NoAnswer { .. } => RobotStopReason::NoAnswer,
            ClientFault::BadAnswer { .. } => RobotStopReason::BadAnswer,
            ClientFault::Disconnected { .. } => RobotStopReason::Disconnected,
        };
        let stop = RelayStop {
            reason,
            message: fault.to_string(),
        };
        self.record(
            json!({"event": "stopped", "call": call, "reason": reason.as_str(), "message": stop.message}),
        );
        stop
    }

    /// The point a motion will take the tool to, where nesy can know it before sending.
    fn target(&mut self, call: &ApiCall) -> Result<Option<[f64; 3]>, RelayStop> {
        match call {
            ApiCall::MoveToPosition { pos, .. } => Ok(Some(*pos)),
            ApiCall::MoveParallel { move_dir, offset, .. } => {
                let tool = self
                    .client
                    .tool_position()
                    .map_err(|f| self.fault("get_tool_pos", f))?;
                self.record(json!({"event": "check", "query": "get_tool_pos", "value": tool}));
                let Some(tool) = tool else {
                    return Err(self.refuse(
                        call,
                        "the robot does not report its tool position, so a relative move cannot be checked against the workspace".to_owned(),
                    ));
                };
                let unit = move_dir.unit();
                Ok(Some([0, 1, 2].map(|i| tool[i] + unit[i] * offset)))
            }
            ApiCall::MoveGripperTo { obj_name, .. } => {
                let query = ApiCall::GetObjPos {
                    obj_name: obj_name.clone(),
                };
                let answer = self
                    .client
                    .check_call(&query)
                    .map_err(|f| self.fault("get_obj_pos", f))?;
                let value = match &answer {
                    Ok(value) => protocol::value_json(value),
                    Err(error) => json!({"error": error}),
                };
                self.record(
                    json!({"event": "check", "query": "get_obj_pos", "obj_name": obj_name, "value": value}),
                );
                // An object the robot does not know is its to refuse.
                Ok(match answer {
                    Ok(ApiValue::Vec3(pos)) => Some(pos),
                    _ => None,
                })
            }
            _ => Ok(None),
        }
    }

    fn refuse(&mut self, call: &ApiCall, message: String) -> RelayStop {
        let (method, params) = protocol::call_request(call);
        self.record(json!({"event": "refused", "method": method, "params": params, "message": message}));
        RelayStop {
            reason: RobotStopReason::Refused,
            message,
        }
    }
}

impl CallRelay for Bridge {
    fn answer(&mut self, call: &ApiCall) -> Result<Result<ApiValue, ApiError>, RelayStop> {
        if call.is_action()
            && let Some(target) = self.target(call)?
            && !self.workspace.contains(target)
        {
            let message = format!(
                "{} would take the tool to ({:.3}, {:.3}, {:.3}), outside the workspace ({}); not sent",
                call.label(),
                target[0],
                target[1],
                target[2],
                self.workspace
            );
            return Err(self.refuse(call, message));
        }
        if let Some(confirm) = self.confirm.as_mut()
            && !confirm(call)
        {
            let message = format!("the operator declined {}", call.label());
            let (method, params) = protocol::call_request(call);
            self.record(json!({"event": "declined", "method": method, "params": params}));
            return Err(RelayStop {
                reason: RobotStopReason::Declined,
                message,
            });
        }
        let (method, params) = protocol::call_request(call);
        self.record(json!({"event": "call", "index": self.sent, "method": method, "params": params}));
        self.sent += 1;
        let answer = self.client.call(call).map_err(|f| self.fault(method, f))?;
        let logged = match &answer {
            Ok(value) => json!({"event": "answer", "method": method, "result": protocol::value_json(value)}),
            Err(error) => json!({"event": "answer", "method": method, "error": error}),
        };
        self.record(logged);
        Ok(answer)
    }

    fn finish(&mut self) -> Result<EpisodeEnd, RelayStop> {
        let report = self.client.finish().map_err(|f| self.fault("finish", f))?;
        self.record(json!({"event": "finish", "report": report}));
        // A robot without goal checks or a world model has nothing to report.
        if report.is_null() {
            return Ok(EpisodeEnd::default());
        }
        serde_json::from_value::<EpisodeEnd>(report.clone()).map_err(|e| {
            let fault = ClientFault::BadAnswer {
                method: "finish".to_owned(),
                address: self.client.address().to_string(),
                detail: format!(
                    "expected null or {{\"subtasks\": [...] or null, \"final_state\": [...] or null}}: {e}"
                ),
            };
            self.fault("finish", fault)
        })
    }
}
