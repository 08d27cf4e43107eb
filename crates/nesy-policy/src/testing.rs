//! A recording test double of the robot API.
//!
//! [`RecordingRobot`] records every call in a trace exactly like the simulator does, answers
//! perception from a fixed table of objects, checks embodiment and object names, and
//! accepts every action **without moving anything**. It exists to test the interpreter,
//! argument conversion, error mapping and the sandbox; it is not a simulator. Nothing it
//! returns describes a real scene.

use nesy_core::Embodiment;
use nesy_sim::api::{ApiCall, ApiError, ApiValue, Direction, RobotApi, TraceEntry};

use crate::episode::{Episode, EpisodeEnd};

/// A robot that records calls and moves nothing. See the module docs.
#[derive(Clone, Debug)]
pub struct RecordingRobot {
    embodiment: Embodiment,
    objects: Vec<(String, [[f64; 3]; 2])>,
    gripper_open: bool,
    trace: Vec<TraceEntry>,
}

impl RecordingRobot {
    /// A double with three fixed boxes (`red_cube`, `blue_cube`, `toy_box`), `floor` and the
    /// embodiment's own entry (`gripper` or `vacuum_gripper`).
    pub fn new(embodiment: Embodiment) -> RecordingRobot {
        let own = match embodiment {
            Embodiment::Finger => "gripper",
            Embodiment::Vacuum => "vacuum_gripper",
        };
        let objects = vec![
            ("red_cube".to_owned(), [[0.40, -0.10, 0.50], [0.44, -0.06, 0.54]]),
            ("blue_cube".to_owned(), [[0.40, 0.10, 0.50], [0.44, 0.14, 0.54]]),
            ("toy_box".to_owned(), [[0.55, -0.05, 0.50], [0.65, 0.05, 0.56]]),
            ("floor".to_owned(), [[0.0, -1.0, 0.0], [1.0, 1.0, 0.5]]),
            (own.to_owned(), [[0.30, -0.02, 0.80], [0.34, 0.02, 0.90]]),
        ];
        RecordingRobot {
            embodiment,
            objects,
            gripper_open: true,
            trace: Vec::new(),
        }
    }

    fn record<T: Clone>(
        &mut self,
        call: ApiCall,
        result: Result<T, ApiError>,
        value: impl Fn(T) -> ApiValue,
    ) -> Result<T, ApiError> {
        let entry = TraceEntry {
            index: self.trace.len(),
            call,
            result: result.clone().map(value),
            sim_time: 0.0,
        };
        self.trace.push(entry);
        result
    }

    fn bbox(&self, name: &str) -> Result<[[f64; 3]; 2], ApiError> {
        let found = self.objects.iter().find(|(n, _)| n == name);
        found.map(|(_, b)| *b).ok_or_else(|| ApiError::UnknownObject {
            name: name.to_owned(),
            known: self
                .objects
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        })
    }

    fn needs(&self, call: &str, embodiment: Embodiment, use_instead: &str) -> Result<(), ApiError> {
        if self.embodiment == embodiment {
            Ok(())
        } else {
            Err(ApiError::WrongEmbodiment {
                call: call.to_owned(),
                embodiment: self.embodiment,
                use_instead: use_instead.to_owned(),
            })
        }
    }

    fn action(&mut self, call: ApiCall, result: Result<(), ApiError>) -> Result<(), ApiError> {
        self.record(call, result, |()| ApiValue::None)
    }
}

impl Episode for RecordingRobot {
    fn finish(&mut self) -> EpisodeEnd {
        EpisodeEnd::default()
    }
}

impl RobotApi for RecordingRobot {
    fn embodiment(&self) -> Embodiment {
        self.embodiment
    }

    fn trace(&self) -> &[TraceEntry] {
        &self.trace
    }

    fn is_obj_visible(&mut self, obj_name: &str) -> bool {
        let visible = self.objects.iter().any(|(n, _)| n == obj_name);
        let call = ApiCall::IsObjVisible {
            obj_name: obj_name.to_owned(),
        };
        self.record(call, Ok(visible), ApiValue::Bool).unwrap_or(false)
    }

    fn get_obj_names(&mut self) -> Vec<String> {
        let names: Vec<String> = self.objects.iter().map(|(n, _)| n.clone()).collect();
        self.record(ApiCall::GetObjNames, Ok(names), ApiValue::Names)
            .unwrap_or_default()
    }

    fn get_obj_pos(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError> {
        let result = self.bbox(obj_name).map(|[lo, hi]| {
            let mut c = [
                (lo[0] + hi[0]) / 2.0,
                (lo[1] + hi[1]) / 2.0,
                (lo[2] + hi[2]) / 2.0,
            ];
            if obj_name == "floor" {
                c[2] = 0.5;
            }
            c
        });
        self.record(
            ApiCall::GetObjPos {
                obj_name: obj_name.to_owned(),
            },
            result,
            ApiValue::Vec3,
        )
    }

    fn get_obj_bbox(&mut self, obj_name: &str) -> Result<[[f64; 3]; 2], ApiError> {
        let result = self.bbox(obj_name);
        self.record(
            ApiCall::GetObjBbox {
                obj_name: obj_name.to_owned(),
            },
            result,
            ApiValue::Bbox,
        )
    }

    fn get_obj_size(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError> {
        let result = self
            .bbox(obj_name)
            .map(|[lo, hi]| [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]]);
        self.record(
            ApiCall::GetObjSize {
                obj_name: obj_name.to_owned(),
            },
            result,
            ApiValue::Vec3,
        )
    }

    fn gripper_is_open(&mut self) -> bool {
        let open = self.gripper_open;
        self.record(ApiCall::GripperIsOpen, Ok(open), ApiValue::Bool)
            .unwrap_or(true)
    }

    fn obj_in_gripper(&mut self, obj_name: &str) -> Result<bool, ApiError> {
        let result = self.bbox(obj_name).map(|_| false);
        self.record(
            ApiCall::ObjInGripper {
                obj_name: obj_name.to_owned(),
            },
            result,
            ApiValue::Bool,
        )
    }

    fn get_empty_floor_xy(&mut self, obj_name: &str) -> Result<[f64; 2], ApiError> {
        let result = self.bbox(obj_name).map(|_| [0.3, 0.0]);
        self.record(
            ApiCall::GetEmptyFloorXy {
                obj_name: obj_name.to_owned(),
            },
            result,
            ApiValue::Xy,
        )
    }

    fn move_gripper_to(
        &mut self,
        obj_name: &str,
        pointing_to: Direction,
        depth: f64,
    ) -> Result<(), ApiError> {
        let result = self.bbox(obj_name).map(|_| ());
        let call = ApiCall::MoveGripperTo {
            obj_name: obj_name.to_owned(),
            pointing_to,
            depth,
        };
        self.action(call, result)
    }

    fn move_to_position(
        &mut self,
        pos: [f64; 3],
        pointing_to: Direction,
        lift_clearance: f64,
        angle: f64,
    ) -> Result<(), ApiError> {
        let call = ApiCall::MoveToPosition {
            pos,
            pointing_to,
            lift_clearance,
            angle,
        };
        self.action(call, Ok(()))
    }

    fn move_parallel(
        &mut self,
        move_dir: Direction,
        offset: f64,
        pointing_to: Direction,
    ) -> Result<(), ApiError> {
        let result = if offset > 0.0 {
            Ok(())
        } else {
            Err(ApiError::InvalidArgument {
                call: "move_parallel".into(),
                message: format!("offset must be positive, got {offset}"),
            })
        };
        self.action(
            ApiCall::MoveParallel {
                move_dir,
                offset,
                pointing_to,
            },
            result,
        )
    }

    fn grasp_handle(&mut self, handle_name: &str) -> Result<(), ApiError> {
        let result = self.needs("grasp_handle", Embodiment::Finger, "attach_vacuum_handle");
        self.action(
            ApiCall::GraspHandle {
                handle_name: handle_name.to_owned(),
            },
            result,
        )
    }

    fn release_handle(&mut self) -> Result<(), ApiError> {
        let result = self.needs("release_handle", Embodiment::Finger, "detach_vacuum_handle");
        self.action(ApiCall::ReleaseHandle, result)
    }

    fn open_gripper(&mut self) -> Result<(), ApiError> {
        let result = self.needs("open_gripper", Embodiment::Finger, "deactivate_vacuum");
        if result.is_ok() {
            self.gripper_open = true;
        }
        self.action(ApiCall::OpenGripper, result)
    }

    fn close_gripper(&mut self) -> Result<(), ApiError> {
        let result = self.needs("close_gripper", Embodiment::Finger, "activate_vacuum");
        if result.is_ok() {
            self.gripper_open = false;
        }
        self.action(ApiCall::CloseGripper, result)
    }

    fn attach_vacuum_handle(&mut self, handle_name: &str) -> Result<(), ApiError> {
        let result = self.needs("attach_vacuum_handle", Embodiment::Vacuum, "grasp_handle");
        self.action(
            ApiCall::AttachVacuumHandle {
                handle_name: handle_name.to_owned(),
            },
            result,
        )
    }

    fn detach_vacuum_handle(&mut self) -> Result<(), ApiError> {
        let result = self.needs("detach_vacuum_handle", Embodiment::Vacuum, "release_handle");
        self.action(ApiCall::DetachVacuumHandle, result)
    }

    fn activate_vacuum(&mut self) -> Result<(), ApiError> {
        let result = self.needs("activate_vacuum", Embodiment::Vacuum, "close_gripper");
        if result.is_ok() {
            self.gripper_open = false;
        }
        self.action(ApiCall::ActivateVacuum, result)
    }

    fn deactivate_vacuum(&mut self) -> Result<(), ApiError> {
        let result = self.needs("deactivate_vacuum", Embodiment::Vacuum, "open_gripper");
        if result.is_ok() {
            self.gripper_open = true;
        }
        self.action(ApiCall::DeactivateVacuum, result)
    }

    fn gather_with_hook(&mut self, obj_name: &str) -> Result<(), ApiError> {
        let result = self.bbox(obj_name).map(|_| ());
        self.action(
            ApiCall::GatherWithHook {
                obj_name: obj_name.to_owned(),
            },
            result,
        )
    }
}
