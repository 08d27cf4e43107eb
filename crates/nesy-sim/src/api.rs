//! The robot API that generated code policies call (the paper's Tables 7–8, with the
//! names, defaults and semantics of the `docs/benchmark.md` §4).
//!
//! [`RobotApi`] is the contract between the simulator, which implements it, and the
//! embedded-Python runtime and scripted experts, which call it. Every call, perception
//! or action, successful or refused, is appended to the implementor's trace as a
//! [`TraceEntry`].

use serde::{Deserialize, Serialize};

pub(crate) use nesy_core::Embodiment;

/// Largest distance (m) between the tool and a handle's centre at which `grasp_handle`
/// (or `attach_vacuum_handle`) takes it, and beyond which a grasped handle slips out
/// (`docs/benchmark.md` §4).
pub const HANDLE_REACH: f64 = 0.1;
/// Deepest `move_gripper_to` depth for the finger gripper (m): the palm's underside is
/// 3.4 cm above the pads' centre, so a deeper target would drive the palm into the object's
/// top (the kinematic arm would crush it). Deeper requests stop here, as a real hand stops on
/// contact.
pub const MAX_FINGER_DEPTH: f64 = 0.027;

/// A world-frame direction in the API's naming, which is inverted compared with ROS:
/// left = −y, right = +y, front = +x, back = −x, up = +z, down = −z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// −y.
    Left,
    /// +y.
    Right,
    /// +x.
    Front,
    /// −x.
    Back,
    /// +z.
    Up,
    /// −z.
    Down,
}

impl Direction {
    /// Every direction, in a fixed order.
    pub const ALL: [Direction; 6] = [
        Direction::Left,
        Direction::Right,
        Direction::Front,
        Direction::Back,
        Direction::Up,
        Direction::Down,
    ];

    /// The API's name for the direction.
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Left => "left",
            Direction::Right => "right",
            Direction::Front => "front",
            Direction::Back => "back",
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }

    /// Parses the API's name (exact, lower case).
    pub fn from_name(name: &str) -> Option<Direction> {
        Direction::ALL.into_iter().find(|d| d.as_str() == name)
    }

    /// Unit vector in the world frame.
    pub fn unit(self) -> [f64; 3] {
        match self {
            Direction::Left => [0.0, -1.0, 0.0],
            Direction::Right => [0.0, 1.0, 0.0],
            Direction::Front => [1.0, 0.0, 0.0],
            Direction::Back => [-1.0, 0.0, 0.0],
            Direction::Up => [0.0, 0.0, 1.0],
            Direction::Down => [0.0, 0.0, -1.0],
        }
    }
}

/// One call of the robot API with its arguments, as recorded in traces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "call", rename_all = "snake_case")]
#[allow(missing_docs)] // variant fields are the API's own parameter names
pub enum ApiCall {
    IsObjVisible {
        obj_name: String,
    },
    GetObjNames,
    GetObjPos {
        obj_name: String,
    },
    GetObjBbox {
        obj_name: String,
    },
    GetObjSize {
        obj_name: String,
    },
    GripperIsOpen,
    ObjInGripper {
        obj_name: String,
    },
    GetEmptyFloorXy {
        obj_name: String,
    },
    MoveGripperTo {
        obj_name: String,
        pointing_to: Direction,
        depth: f64,
    },
    MoveToPosition {
        pos: [f64; 3],
        pointing_to: Direction,
        lift_clearance: f64,
        angle: f64,
    },
    MoveParallel {
        move_dir: Direction,
        offset: f64,
        pointing_to: Direction,
    },
    GraspHandle {
        handle_name: String,
    },
    ReleaseHandle,
    OpenGripper,
    CloseGripper,
    AttachVacuumHandle {
        handle_name: String,
    },
    DetachVacuumHandle,
    ActivateVacuum,
    DeactivateVacuum,
    GatherWithHook {
        obj_name: String,
    },
}

impl ApiCall {
    /// The API function's name, e.g. `move_gripper_to`.
    pub fn name(&self) -> &'static str {
        match self {
            ApiCall::IsObjVisible { .. } => "is_obj_visible",
            ApiCall::GetObjNames => "get_obj_names",
            ApiCall::GetObjPos { .. } => "get_obj_pos",
            ApiCall::GetObjBbox { .. } => "get_obj_bbox",
            ApiCall::GetObjSize { .. } => "get_obj_size",
            ApiCall::GripperIsOpen => "gripper_is_open",
            ApiCall::ObjInGripper { .. } => "obj_in_gripper",
            ApiCall::GetEmptyFloorXy { .. } => "get_empty_floor_xy",
            ApiCall::MoveGripperTo { .. } => "move_gripper_to",
            ApiCall::MoveToPosition { .. } => "move_to_position",
            ApiCall::MoveParallel { .. } => "move_parallel",
            ApiCall::GraspHandle { .. } => "grasp_handle",
            ApiCall::ReleaseHandle => "release_handle",
            ApiCall::OpenGripper => "open_gripper",
            ApiCall::CloseGripper => "close_gripper",
            ApiCall::AttachVacuumHandle { .. } => "attach_vacuum_handle",
            ApiCall::DetachVacuumHandle => "detach_vacuum_handle",
            ApiCall::ActivateVacuum => "activate_vacuum",
            ApiCall::DeactivateVacuum => "deactivate_vacuum",
            ApiCall::GatherWithHook { .. } => "gather_with_hook",
        }
    }

    /// The object or handle the call names (`obj_name` or `handle_name`), if any.
    pub fn object(&self) -> Option<&str> {
        match self {
            ApiCall::IsObjVisible { obj_name }
            | ApiCall::GetObjPos { obj_name }
            | ApiCall::GetObjBbox { obj_name }
            | ApiCall::GetObjSize { obj_name }
            | ApiCall::ObjInGripper { obj_name }
            | ApiCall::GetEmptyFloorXy { obj_name }
            | ApiCall::MoveGripperTo { obj_name, .. }
            | ApiCall::GatherWithHook { obj_name } => Some(obj_name),
            ApiCall::GraspHandle { handle_name } | ApiCall::AttachVacuumHandle { handle_name } => {
                Some(handle_name)
            }
            _ => None,
        }
    }

    /// The call as a short caption: the function and its object, handle or target
    /// (`move_gripper_to(red_cube)`, `move_to_position(0.65, -0.24, 0.67)`, `close_gripper()`).
    pub fn label(&self) -> String {
        let argument = match self {
            ApiCall::MoveToPosition { pos, .. } => format!("{:.2}, {:.2}, {:.2}", pos[0], pos[1], pos[2]),
            ApiCall::MoveParallel { move_dir, offset, .. } => format!("{}, {offset:.2}", move_dir.as_str()),
            other => other.object().unwrap_or_default().to_owned(),
        };
        format!("{}({argument})", self.name())
    }

    /// Makes the call on `robot` with its recorded arguments, returning what the robot
    /// returned: how a recorded trace is replayed.
    pub fn perform(&self, robot: &mut dyn RobotApi) -> Result<ApiValue, ApiError> {
        let done = |r: Result<(), ApiError>| r.map(|()| ApiValue::None);
        match self {
            ApiCall::IsObjVisible { obj_name } => Ok(ApiValue::Bool(robot.is_obj_visible(obj_name))),
            ApiCall::GetObjNames => Ok(ApiValue::Names(robot.get_obj_names())),
            ApiCall::GetObjPos { obj_name } => robot.get_obj_pos(obj_name).map(ApiValue::Vec3),
            ApiCall::GetObjBbox { obj_name } => robot.get_obj_bbox(obj_name).map(ApiValue::Bbox),
            ApiCall::GetObjSize { obj_name } => robot.get_obj_size(obj_name).map(ApiValue::Vec3),
            ApiCall::GripperIsOpen => Ok(ApiValue::Bool(robot.gripper_is_open())),
            ApiCall::ObjInGripper { obj_name } => robot.obj_in_gripper(obj_name).map(ApiValue::Bool),
            ApiCall::GetEmptyFloorXy { obj_name } => robot.get_empty_floor_xy(obj_name).map(ApiValue::Xy),
            ApiCall::MoveGripperTo {
                obj_name,
                pointing_to,
                depth,
            } => done(robot.move_gripper_to(obj_name, *pointing_to, *depth)),
            ApiCall::MoveToPosition {
                pos,
                pointing_to,
                lift_clearance,
                angle,
            } => done(robot.move_to_position(*pos, *pointing_to, *lift_clearance, *angle)),
            ApiCall::MoveParallel {
                move_dir,
                offset,
                pointing_to,
            } => done(robot.move_parallel(*move_dir, *offset, *pointing_to)),
            ApiCall::GraspHandle { handle_name } => done(robot.grasp_handle(handle_name)),
            ApiCall::ReleaseHandle => done(robot.release_handle()),
            ApiCall::OpenGripper => done(robot.open_gripper()),
            ApiCall::CloseGripper => done(robot.close_gripper()),
            ApiCall::AttachVacuumHandle { handle_name } => done(robot.attach_vacuum_handle(handle_name)),
            ApiCall::DetachVacuumHandle => done(robot.detach_vacuum_handle()),
            ApiCall::ActivateVacuum => done(robot.activate_vacuum()),
            ApiCall::DeactivateVacuum => done(robot.deactivate_vacuum()),
            ApiCall::GatherWithHook { obj_name } => done(robot.gather_with_hook(obj_name)),
        }
    }

    /// True for calls that move the robot or change the gripper (they count against the
    /// action budget and, when they succeed, produce a keyframe); false for perception.
    pub fn is_action(&self) -> bool {
        !matches!(
            self,
            ApiCall::IsObjVisible { .. }
                | ApiCall::GetObjNames
                | ApiCall::GetObjPos { .. }
                | ApiCall::GetObjBbox { .. }
                | ApiCall::GetObjSize { .. }
                | ApiCall::GripperIsOpen
                | ApiCall::ObjInGripper { .. }
                | ApiCall::GetEmptyFloorXy { .. }
        )
    }
}

/// What a successful call returned.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", content = "value", rename_all = "snake_case")]
pub enum ApiValue {
    /// Actions return nothing.
    None,
    /// `is_obj_visible`, `gripper_is_open`, `obj_in_gripper`.
    Bool(bool),
    /// `get_obj_names`.
    Names(Vec<String>),
    /// `get_obj_pos`, `get_obj_size`.
    Vec3([f64; 3]),
    /// `get_obj_bbox`: `[min, max]`.
    Bbox([[f64; 3]; 2]),
    /// `get_empty_floor_xy`.
    Xy([f64; 2]),
}

/// Why the robot refused or failed a call. Refused calls do not move the robot; a motion
/// stopped by contact ([`ApiError::Collision`]) ends where it stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ApiError {
    /// A finger-gripper call on the vacuum robot or the reverse.
    #[error("{call}() is not available on the {embodiment} robot; use {use_instead}() instead")]
    WrongEmbodiment {
        /// The refused call.
        call: String,
        /// The robot's embodiment.
        embodiment: Embodiment,
        /// The equivalent call for this embodiment.
        use_instead: String,
    },
    /// No object of that name in the scene.
    #[error("unknown object {name:?}; known objects: {known}")]
    UnknownObject {
        /// The name that was asked for.
        name: String,
        /// Comma-separated list of scene objects.
        known: String,
    },
    /// The call is physically infeasible now (something stacked on the object, a handle
    /// covered by an open drawer, a handle too far away, ...).
    #[error("{call}({target}) is infeasible: {reason}")]
    Infeasible {
        /// The refused call.
        call: String,
        /// The object or position it was aimed at.
        target: String,
        /// Why.
        reason: String,
    },
    /// The target lies outside the reachable workspace.
    #[error("target ({:.3}, {:.3}, {:.3}) is outside the reachable workspace", target[0], target[1], target[2])]
    OutOfWorkspace {
        /// World-frame target position.
        target: [f64; 3],
    },
    /// No joint configuration within limits reaches the target pose.
    #[error("no inverse-kinematics solution reaches ({:.3}, {:.3}, {:.3}) pointing {pointing_to:?}", target[0], target[1], target[2])]
    IkFailed {
        /// World-frame target position of the tool tip.
        target: [f64; 3],
        /// Requested approach direction.
        pointing_to: Direction,
    },
    /// An argument is out of range (non-positive offset, unsupported direction, ...).
    #[error("invalid argument to {call}(): {message}")]
    InvalidArgument {
        /// The call.
        call: String,
        /// What was wrong.
        message: String,
    },
    /// `get_empty_floor_xy` found no free spot.
    #[error("no empty floor position for {obj_name}")]
    NoEmptySpace {
        /// The object to be placed.
        obj_name: String,
    },
    /// The motion was stopped by contact, as a real arm's protective stop ends it: a lid or
    /// drawer the robot was moving ran into another piece of furniture. Unlike refusals,
    /// the robot has moved: it stays where it stopped, still holding the handle.
    #[error("{call}() was stopped by contact: {moving} ran into {obstacle}")]
    Collision {
        /// The call whose motion stopped.
        call: String,
        /// The part that was being moved.
        moving: String,
        /// The part it ran into.
        obstacle: String,
    },
    /// The episode's budget of action calls is used up.
    #[error("action budget of {limit} calls exhausted")]
    BudgetExhausted {
        /// The budget.
        limit: usize,
    },
    /// A robot reached through the robot protocol stopped the motion on its own account
    /// (a protective or emergency stop, an operator, its controller) and stays where it
    /// stopped. The simulator never answers this.
    #[error("{call}() was stopped by the robot: {reason}")]
    Stopped {
        /// The call whose motion stopped.
        call: String,
        /// What the robot said.
        reason: String,
    },
    /// A robot reached through the robot protocol did not complete the motion within its
    /// own time limit. The simulator never answers this.
    #[error("{call}() did not complete on the robot within {seconds:.1} s")]
    TimedOut {
        /// The call that did not complete.
        call: String,
        /// The robot's limit, in seconds.
        seconds: f64,
    },
}

/// One entry of an execution trace.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TraceEntry {
    /// Position in the trace, from 0.
    pub index: usize,
    /// The call and its arguments (defaults filled in).
    #[serde(flatten)]
    pub call: ApiCall,
    /// What it returned or why it was refused.
    pub result: Result<ApiValue, ApiError>,
    /// Simulated time in seconds when the call returned.
    pub sim_time: f64,
}

/// Default `depth` of `move_gripper_to`.
pub const DEFAULT_DEPTH: f64 = 0.01;
/// Default `lift_clearance` of `move_to_position`.
pub const DEFAULT_LIFT_CLEARANCE: f64 = 0.12;

/// The robot API. Implemented by the simulator; called by scripted experts and by the
/// embedded-Python policy runtime.
///
/// Perception calls take `&mut self` too, because every call is traced.
pub trait RobotApi {
    /// The robot's embodiment.
    fn embodiment(&self) -> Embodiment;
    /// Every call so far, in order.
    fn trace(&self) -> &[TraceEntry];

    /// True if `obj_name` is in the scene's object list.
    fn is_obj_visible(&mut self, obj_name: &str) -> bool;
    /// All object names, in scene order (the robot's own entry last).
    fn get_obj_names(&mut self) -> Vec<String>;
    /// Centre of the object's axis-aligned bounding box (`floor` reports z = 0.5).
    fn get_obj_pos(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError>;
    /// The object's world AABB as `[min, max]`.
    fn get_obj_bbox(&mut self, obj_name: &str) -> Result<[[f64; 3]; 2], ApiError>;
    /// The AABB's extents.
    fn get_obj_size(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError>;
    /// True if the fingers are open (finger robot) or suction is off (vacuum robot).
    fn gripper_is_open(&mut self) -> bool;
    /// True if the object is in the grasp region (between the finger pads, or under the
    /// suction tip).
    fn obj_in_gripper(&mut self, obj_name: &str) -> Result<bool, ApiError>;
    /// A free table position, in the search region of `docs/benchmark.md` §4, for placing `obj_name`.
    fn get_empty_floor_xy(&mut self, obj_name: &str) -> Result<[f64; 2], ApiError>;

    /// Moves the tool to the object: `depth` below its top surface when pointing down.
    fn move_gripper_to(&mut self, obj_name: &str, pointing_to: Direction, depth: f64)
    -> Result<(), ApiError>;
    /// Moves the tool tip to `pos` with a lift/approach clearance; `angle` is the yaw
    /// about the approach axis.
    fn move_to_position(
        &mut self,
        pos: [f64; 3],
        pointing_to: Direction,
        lift_clearance: f64,
        angle: f64,
    ) -> Result<(), ApiError>;
    /// Translates the tool by `offset` metres in `move_dir` (left/right/front/back/up),
    /// keeping its orientation.
    fn move_parallel(
        &mut self,
        move_dir: Direction,
        offset: f64,
        pointing_to: Direction,
    ) -> Result<(), ApiError>;
    /// Grasps a handle within reach (finger robot).
    fn grasp_handle(&mut self, handle_name: &str) -> Result<(), ApiError>;
    /// Releases the grasped handle and opens the gripper (finger robot).
    fn release_handle(&mut self) -> Result<(), ApiError>;
    /// Opens the fingers, releasing any held object (finger robot).
    fn open_gripper(&mut self) -> Result<(), ApiError>;
    /// Closes the fingers, grasping what is between the pads (finger robot).
    fn close_gripper(&mut self) -> Result<(), ApiError>;
    /// Vacuum counterpart of [`RobotApi::grasp_handle`].
    fn attach_vacuum_handle(&mut self, handle_name: &str) -> Result<(), ApiError>;
    /// Vacuum counterpart of [`RobotApi::release_handle`].
    fn detach_vacuum_handle(&mut self) -> Result<(), ApiError>;
    /// Vacuum counterpart of [`RobotApi::close_gripper`]: attaches what is under the tip.
    fn activate_vacuum(&mut self) -> Result<(), ApiError>;
    /// Vacuum counterpart of [`RobotApi::open_gripper`].
    fn deactivate_vacuum(&mut self) -> Result<(), ApiError>;
    /// With a magnetic hook held, sweeps its magnet low over the pieces of the fine-grained
    /// object `obj_name` (screws) and lifts again; the magnet pulls the pieces it passes
    /// within reach of, so that they cling to it and travel with the hook (both robots).
    fn gather_with_hook(&mut self, obj_name: &str) -> Result<(), ApiError>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trace_entry_json_shape() {
        let e = TraceEntry {
            index: 3,
            call: ApiCall::MoveGripperTo {
                obj_name: "red_cube".into(),
                pointing_to: Direction::Down,
                depth: 0.015,
            },
            result: Ok(ApiValue::None),
            sim_time: 1.25,
        };
        let json = serde_json::to_value(&e).unwrap();
        assert_eq!(json["call"], "move_gripper_to");
        assert_eq!(json["obj_name"], "red_cube");
        assert_eq!(json["pointing_to"], "down");
        let back: TraceEntry = serde_json::from_value(json).unwrap();
        assert_eq!(back, e);
        let refused = TraceEntry {
            index: 4,
            call: ApiCall::CloseGripper,
            result: Err(ApiError::WrongEmbodiment {
                call: "close_gripper".into(),
                embodiment: Embodiment::Vacuum,
                use_instead: "activate_vacuum".into(),
            }),
            sim_time: 1.25,
        };
        let text = refused.result.as_ref().unwrap_err().to_string();
        assert_eq!(
            text,
            "close_gripper() is not available on the vacuum robot; use activate_vacuum() instead"
        );
        let back: TraceEntry = serde_json::from_str(&serde_json::to_string(&refused).unwrap()).unwrap();
        assert_eq!(back, refused);
    }

    #[test]
    fn directions_round_trip() {
        for d in Direction::ALL {
            assert_eq!(Direction::from_name(d.as_str()), Some(d));
        }
        assert_eq!(Direction::from_name("sideways"), None);
    }
}
