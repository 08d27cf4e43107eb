//! A robot outside the sandbox. In a relayed episode the worker process has no robot of its
//! own: each call the policy makes travels to the parent on the worker's message channel, the
//! parent's [`CallRelay`] answers it (a bridge to a real robot, after its own safety checks),
//! and the answer travels back on a second pipe. The policy keeps every sandbox layer; the
//! worker still opens no socket and no file.

use nesy_core::Embodiment;
use nesy_sim::api::{ApiCall, ApiError, ApiValue, Direction, RobotApi, TraceEntry};
use serde::{Deserialize, Serialize};

use crate::episode::{Episode, EpisodeEnd};

/// Answers the calls of a relayed episode in the parent process ([`crate::run_relayed`]).
///
/// `answer` is called once per robot API call the policy makes, in order, and blocks until
/// the robot has answered. An `Ok(Err(_))` is the robot's own refusal or failure of that call
/// (the policy sees it as the usual `robot.*Error`); an `Err(RelayStop)` ends the run at once:
/// the worker is killed and the outcome is [`crate::Outcome::RobotStopped`].
pub trait CallRelay {
    /// Performs one call on the robot.
    fn answer(&mut self, call: &ApiCall) -> Result<Result<ApiValue, ApiError>, RelayStop>;
    /// Called once after the policy ended (not after a stop or a kill): what the robot
    /// reports at the end (goal checks and observed state, where it has them).
    fn finish(&mut self) -> Result<EpisodeEnd, RelayStop>;
}

/// Why a relayed run was stopped by the parent before the robot answered a call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RobotStopReason {
    /// nesy refused the call before sending it (workspace bounds, speed scale).
    Refused,
    /// The operator declined the call when asked to confirm it.
    Declined,
    /// The policy made another call after the robot had answered one with an error: the first
    /// robot error stops a run on a robot.
    AfterError,
    /// The robot answered with an error a call that cannot fail in the robot API
    /// (`get_obj_names`, `is_obj_visible`, `gripper_is_open`), so the policy could not be told.
    UnexpectedError,
    /// The robot did not answer within the call's time limit.
    NoAnswer,
    /// The robot's answer could not be read (not JSON, not the protocol, a value of the wrong
    /// shape for the call).
    BadAnswer,
    /// The connection to the robot closed or failed.
    Disconnected,
}

impl RobotStopReason {
    /// The reason as its JSON name.
    pub fn as_str(self) -> &'static str {
        match self {
            RobotStopReason::Refused => "refused",
            RobotStopReason::Declined => "declined",
            RobotStopReason::AfterError => "after_error",
            RobotStopReason::UnexpectedError => "unexpected_error",
            RobotStopReason::NoAnswer => "no_answer",
            RobotStopReason::BadAnswer => "bad_answer",
            RobotStopReason::Disconnected => "disconnected",
        }
    }
}

/// True for the calls whose robot-API signature can report an error; the others
/// (`get_obj_names`, `is_obj_visible`, `gripper_is_open`) always return a value.
pub(crate) fn can_report_error(call: &ApiCall) -> bool {
    !matches!(
        call,
        ApiCall::GetObjNames | ApiCall::IsObjVisible { .. } | ApiCall::GripperIsOpen
    )
}

/// A [`CallRelay`] ending the run: why, in words.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}: {message}", reason.as_str())]
pub struct RelayStop {
    /// The kind of stop.
    pub reason: RobotStopReason,
    /// What happened, naming the call and the robot's address where known.
    pub message: String,
}

/// How the worker's relayed robot reaches the parent.
pub(crate) trait RelayLink: Send {
    /// Sends `call` and waits for the robot's answer; `None` if the link closed.
    fn call(&mut self, call: &ApiCall) -> Option<Result<ApiValue, ApiError>>;
    /// Asks for the end-of-episode report; `None` if the link closed.
    fn finish(&mut self) -> Option<EpisodeEnd>;
}

/// The worker's robot in a relayed episode: every call goes over the [`RelayLink`]; the trace
/// is kept here the way the simulator keeps its own (`sim_time` is wall time since the start).
pub(crate) struct RelayedRobot {
    embodiment: Embodiment,
    link: Box<dyn RelayLink>,
    trace: Vec<TraceEntry>,
    started: std::time::Instant,
}

impl RelayedRobot {
    pub(crate) fn new(embodiment: Embodiment, link: Box<dyn RelayLink>) -> RelayedRobot {
        RelayedRobot {
            embodiment,
            link,
            trace: Vec::new(),
            started: std::time::Instant::now(),
        }
    }

    fn relay(&mut self, call: ApiCall) -> Result<ApiValue, ApiError> {
        let result = self.link.call(&call).unwrap_or_else(|| {
            Err(ApiError::Stopped {
                call: call.name().to_owned(),
                reason: "the run was stopped by nesy (the link to the robot closed)".to_owned(),
            })
        });
        self.trace.push(TraceEntry {
            index: self.trace.len(),
            call,
            result: result.clone(),
            sim_time: self.started.elapsed().as_secs_f64(),
        });
        result
    }

    fn action(&mut self, call: ApiCall) -> Result<(), ApiError> {
        let name = call.name();
        match self.relay(call)? {
            ApiValue::None => Ok(()),
            other => Err(wrong_shape(name, &other)),
        }
    }

    fn vec3(&mut self, call: ApiCall) -> Result<[f64; 3], ApiError> {
        let name = call.name();
        match self.relay(call)? {
            ApiValue::Vec3(v) => Ok(v),
            other => Err(wrong_shape(name, &other)),
        }
    }

    fn boolean(&mut self, call: ApiCall) -> Result<bool, ApiError> {
        let name = call.name();
        match self.relay(call)? {
            ApiValue::Bool(b) => Ok(b),
            other => Err(wrong_shape(name, &other)),
        }
    }
}

/// The bridge checks each answer's shape before relaying it, so this only guards the worker
/// against a parent that did not.
fn wrong_shape(call: &str, value: &ApiValue) -> ApiError {
    ApiError::Stopped {
        call: call.to_owned(),
        reason: format!("the robot answered with a value of the wrong shape ({value:?})"),
    }
}

impl RobotApi for RelayedRobot {
    fn embodiment(&self) -> Embodiment {
        self.embodiment
    }

    fn trace(&self) -> &[TraceEntry] {
        &self.trace
    }

    fn is_obj_visible(&mut self, obj_name: &str) -> bool {
        let call = ApiCall::IsObjVisible {
            obj_name: obj_name.to_owned(),
        };
        self.boolean(call).unwrap_or(false)
    }

    fn get_obj_names(&mut self) -> Vec<String> {
        match self.relay(ApiCall::GetObjNames) {
            Ok(ApiValue::Names(names)) => names,
            _ => Vec::new(),
        }
    }

    fn get_obj_pos(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError> {
        self.vec3(ApiCall::GetObjPos {
            obj_name: obj_name.to_owned(),
        })
    }

    fn get_obj_bbox(&mut self, obj_name: &str) -> Result<[[f64; 3]; 2], ApiError> {
        let call = ApiCall::GetObjBbox {
            obj_name: obj_name.to_owned(),
        };
        match self.relay(call)? {
            ApiValue::Bbox(b) => Ok(b),
            other => Err(wrong_shape("get_obj_bbox", &other)),
        }
    }

    fn get_obj_size(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError> {
        self.vec3(ApiCall::GetObjSize {
            obj_name: obj_name.to_owned(),
        })
    }

    fn gripper_is_open(&mut self) -> bool {
        self.boolean(ApiCall::GripperIsOpen).unwrap_or(false)
    }

    fn obj_in_gripper(&mut self, obj_name: &str) -> Result<bool, ApiError> {
        self.boolean(ApiCall::ObjInGripper {
            obj_name: obj_name.to_owned(),
        })
    }

    fn get_empty_floor_xy(&mut self, obj_name: &str) -> Result<[f64; 2], ApiError> {
        let call = ApiCall::GetEmptyFloorXy {
            obj_name: obj_name.to_owned(),
        };
        match self.relay(call)? {
            ApiValue::Xy(xy) => Ok(xy),
            other => Err(wrong_shape("get_empty_floor_xy", &other)),
        }
    }

    fn move_gripper_to(
        &mut self,
        obj_name: &str,
        pointing_to: Direction,
        depth: f64,
    ) -> Result<(), ApiError> {
        self.action(ApiCall::MoveGripperTo {
            obj_name: obj_name.to_owned(),
            pointing_to,
            depth,
        })
    }

    fn move_to_position(
        &mut self,
        pos: [f64; 3],
        pointing_to: Direction,
        lift_clearance: f64,
        angle: f64,
    ) -> Result<(), ApiError> {
        self.action(ApiCall::MoveToPosition {
            pos,
            pointing_to,
            lift_clearance,
            angle,
        })
    }

    fn move_parallel(
        &mut self,
        move_dir: Direction,
        offset: f64,
        pointing_to: Direction,
    ) -> Result<(), ApiError> {
        self.action(ApiCall::MoveParallel {
            move_dir,
            offset,
            pointing_to,
        })
    }

    fn grasp_handle(&mut self, handle_name: &str) -> Result<(), ApiError> {
        self.action(ApiCall::GraspHandle {
            handle_name: handle_name.to_owned(),
        })
    }

    fn release_handle(&mut self) -> Result<(), ApiError> {
        self.action(ApiCall::ReleaseHandle)
    }

    fn open_gripper(&mut self) -> Result<(), ApiError> {
        self.action(ApiCall::OpenGripper)
    }

    fn close_gripper(&mut self) -> Result<(), ApiError> {
        self.action(ApiCall::CloseGripper)
    }

    fn attach_vacuum_handle(&mut self, handle_name: &str) -> Result<(), ApiError> {
        self.action(ApiCall::AttachVacuumHandle {
            handle_name: handle_name.to_owned(),
        })
    }

    fn detach_vacuum_handle(&mut self) -> Result<(), ApiError> {
        self.action(ApiCall::DetachVacuumHandle)
    }

    fn activate_vacuum(&mut self) -> Result<(), ApiError> {
        self.action(ApiCall::ActivateVacuum)
    }

    fn deactivate_vacuum(&mut self) -> Result<(), ApiError> {
        self.action(ApiCall::DeactivateVacuum)
    }

    fn gather_with_hook(&mut self, obj_name: &str) -> Result<(), ApiError> {
        self.action(ApiCall::GatherWithHook {
            obj_name: obj_name.to_owned(),
        })
    }
}

impl Episode for RelayedRobot {
    fn finish(&mut self) -> EpisodeEnd {
        self.link.finish().unwrap_or_default()
    }
}
