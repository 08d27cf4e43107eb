//! [`RobotApi`] for [`Sim`]: the paper's perception and action calls with `docs/benchmark.md` §4's
//! defaults, embodiment and feasibility rules, the action budget and the trace.

use nalgebra::{UnitQuaternion, Vector3};

use super::contact::FurnitureSnapshot;
use super::floor::empty_floor_xy;
use super::geometry::{Aabb, array_to_na, yaw_of};
use super::objects::PartRole;
use super::{FLOOR_AABB, HandleGrasp, Sim};
use crate::api::{
    ApiCall, ApiError, ApiValue, Direction, Embodiment, HANDLE_REACH, MAX_FINGER_DEPTH, RobotApi, TraceEntry,
};
use crate::robot::kinematics::IkOptions;
use crate::robot::model::FINGER_OPEN;
use crate::robot::model::PALM_ABOVE_TOOL;
use crate::robot::motion::{MOTION_SETTLE_STEPS, PARALLEL_MIN_DURATION, ToolGoal};
use crate::scene::parts;
use crate::scene::{ObjectKind, TABLE_TOP};

/// How far (m) the finger hand backs off against its last push before it lifts.
const PUSH_BACK_OFF: f64 = 0.015;
/// Control steps for the fingers to open or close (0.04 m at 0.2 m/s takes 20).
const GRIPPER_STEPS: u32 = 25;
/// Distances (m) from a finger's travel, along the closing axis, that the pad passes through
/// on the way down (the pad is about 1 cm thick, and its inner face sits at the travel).
const FINGER_SWEEP: [f64; 3] = [-0.01, 0.0, 0.012];
/// Gap (m) per side between an object and the pads the fingers open to on the way down to it.
/// A hand opened to its full 8 cm for a 3 cm cube landed a pad on a fruit 6 cm away; a real
/// gripper is commanded to the width it needs.
const PRESHAPE_CLEARANCE: f64 = 0.012;
/// Half the width (m) of a finger pad across the closing axis.
const FINGER_HALF_WIDTH: f64 = 0.01;
/// Half the palm's length (m) along the closing axis, and half its width across it.
const PALM_HALF_LENGTH: f64 = 0.1;
const PALM_HALF_WIDTH: f64 = 0.025;
/// Gap (m) the palm keeps above the neighbours under it when the hand comes down.
const PALM_CLEARANCE: f64 = 0.004;
/// How far (m) below an object's top the pads' centre reaches at least, however high the
/// palm must stay.
const MIN_PAD_OVERLAP: f64 = 0.006;
/// Gap (m) a finger wants beside a neighbour's box.
const FINGER_MARGIN: f64 = 0.005;
/// A neighbour counts as beside the object when its top is this much (m) above the object's
/// bottom.
const LEVEL_TOLERANCE: f64 = 0.005;
/// Fractions of the lift clearance tried, largest first, when the full lift is out of reach.
const LIFT_FRACTIONS: [f64; 4] = [1.0, 0.75, 0.5, 0.25];

/// The table-plane footprint of a hand above an object: points at `s` along its closing
/// axis and `t` across it, from the object's centre.
struct Footprint {
    centre: [f64; 3],
    along: Vector3<f64>,
    across: Vector3<f64>,
}

impl Footprint {
    fn new(centre: [f64; 3], rotation: &UnitQuaternion<f64>) -> Footprint {
        Footprint {
            centre,
            along: rotation * Vector3::y(),
            across: rotation * Vector3::x(),
        }
    }

    fn point(&self, s: f64, t: f64) -> [f64; 2] {
        [
            self.centre[0] + self.along.x * s + self.across.x * t,
            self.centre[1] + self.along.y * s + self.across.y * t,
        ]
    }
}

/// The palm's sample points `(s, t)`: nine along its length, three across its width.
fn palm_samples() -> impl Iterator<Item = (f64, f64)> {
    (-4..=4)
        .map(|k| PALM_HALF_LENGTH * f64::from(k) / 4.0)
        .flat_map(|s| [-PALM_HALF_WIDTH, 0.0, PALM_HALF_WIDTH].map(|t| (s, t)))
}

/// Whether the box `n`, widened by [`FINGER_MARGIN`], covers the table point `at`.
fn covers(n: &Aabb, at: [f64; 2]) -> bool {
    (0..2).all(|i| at[i] > n.min[i] - FINGER_MARGIN && at[i] < n.max[i] + FINGER_MARGIN)
}

impl Sim {
    fn known_names(&self) -> String {
        self.names().join(", ")
    }

    /// `floor`, the scene's objects in order as perception names them (parts, with a
    /// fine-grained object's pieces as one), then the robot's own entry.
    pub fn names(&self) -> Vec<String> {
        std::iter::once(parts::FLOOR.to_owned())
            .chain(
                self.perceived_objects()
                    .into_iter()
                    .map(|(name, _)| name.to_owned()),
            )
            .chain(std::iter::once(self.gripper_name().to_owned()))
            .collect()
    }

    /// The box of the object called `name`, or the error naming every known object.
    pub(super) fn aabb_or_unknown(&self, name: &str) -> Result<Aabb, ApiError> {
        self.object_aabb(name).ok_or_else(|| ApiError::UnknownObject {
            name: name.to_owned(),
            known: self.known_names(),
        })
    }

    /// The part called `name`, for call `call`; a fine-grained object cannot be reached as
    /// one part.
    fn part_or_unknown(&self, name: &str, call: &str) -> Result<usize, ApiError> {
        if !self.pieces_of(name).is_empty() {
            return Err(ApiError::Infeasible {
                call: call.into(),
                target: name.into(),
                reason: "its pieces are too small to grasp one by one; gather them with a magnetic hook"
                    .into(),
            });
        }
        self.part_index(name).ok_or_else(|| ApiError::UnknownObject {
            name: name.to_owned(),
            known: self.known_names(),
        })
    }

    /// Records a call, fires the hooks, and passes the result through.
    fn record<T>(
        &mut self,
        call: ApiCall,
        result: Result<T, ApiError>,
        value: impl FnOnce(&T) -> ApiValue,
    ) -> Result<T, ApiError> {
        let entry = TraceEntry {
            index: self.trace.len(),
            call,
            result: result.as_ref().map(value).map_err(Clone::clone),
            sim_time: self.time(),
        };
        if !self.hooks.is_empty() {
            let mut hooks = std::mem::take(&mut self.hooks);
            for hook in hooks.iter_mut() {
                hook.on_call(self, &entry);
            }
            hooks.append(&mut self.hooks);
            self.hooks = hooks;
        }
        let pause = self.action_pause_steps > 0 && entry.call.is_action() && entry.result.is_ok();
        self.trace.push(entry);
        if pause {
            self.step_idle(self.action_pause_steps);
        }
        result
    }

    /// Runs an action: refuses it if the budget is spent or the embodiment is wrong,
    /// otherwise runs `body`, and records the call either way.
    fn action(
        &mut self,
        call: ApiCall,
        needs: Option<(Embodiment, &str)>,
        body: impl FnOnce(&mut Sim) -> Result<(), ApiError>,
    ) -> Result<(), ApiError> {
        let result = if self.actions_used >= self.config.action_budget {
            Err(ApiError::BudgetExhausted {
                limit: self.config.action_budget,
            })
        } else {
            self.actions_used += 1;
            match needs {
                Some((embodiment, use_instead)) if embodiment != self.scene.embodiment => {
                    Err(ApiError::WrongEmbodiment {
                        call: call.name().to_owned(),
                        embodiment: self.scene.embodiment,
                        use_instead: use_instead.to_owned(),
                    })
                }
                _ => body(self),
            }
        };
        self.record(call, result, |_| ApiValue::None)
    }

    /// Something stacked on a cube or cylinder (`docs/benchmark.md` §4 feasibility rule 2).
    pub fn stacked_on(&self, part: usize) -> Option<usize> {
        let me = self.part_aabb(part);
        self.parts.iter().enumerate().find_map(|(i, p)| {
            if i == part || !matches!(p.kind, ObjectKind::Cube | ObjectKind::Cylinder) {
                return None;
            }
            let other = self.part_aabb(i);
            (other.overlaps_xy(&me, 0.005)
                && other.min[2] >= me.max[2] - 0.004
                && other.min[2] > me.min[2] + 0.004)
                .then_some(i)
        })
    }

    /// The open top drawer covering the bottom drawer's handle of the same cabinet
    /// (`docs/benchmark.md` §4 rule 3).
    pub fn handle_covered_by(&self, part: usize) -> Option<usize> {
        let handle = &self.parts[part];
        if handle.role != PartRole::Handle {
            return None;
        }
        let top = parts::sibling(&handle.name, parts::BOTTOM_DRAWER_HANDLE, parts::TOP_DRAWER)?;
        let top = self.part_index(&top)?;
        (self.parts[top].object == handle.object
            && self.part_aabb(top).overlaps_xy(&self.part_aabb(part), 0.005))
        .then_some(top)
    }

    /// A loose object resting on the articulation's link (it blocks a lid from opening).
    fn blocking_load(&self, articulation: usize) -> Option<usize> {
        let link = self.articulations[articulation].link;
        if !matches!(
            self.articulations[articulation].joint,
            crate::world::objects::JointBuild::Revolute { .. }
        ) {
            return None;
        }
        let lid = self.part_aabb(link);
        self.parts.iter().enumerate().find_map(|(i, p)| {
            if p.role != PartRole::Loose || self.held.is_some_and(|h| h.part == i) {
                return None;
            }
            let a = self.part_aabb(i);
            let gap = a.min[2] - lid.max[2];
            (a.overlaps_xy(&lid, 0.002) && (-0.01..=0.01).contains(&gap)).then_some(i)
        })
    }

    pub(super) fn check_workspace(&self, target: [f64; 3]) -> Result<(), ApiError> {
        let inside = (0..2).all(|i| target[i] >= FLOOR_AABB.min[i] && target[i] <= FLOOR_AABB.max[i]);
        if !inside
            || !(TABLE_TOP - 0.05..=TABLE_TOP + 0.8).contains(&target[2])
            || target.iter().any(|v| !v.is_finite())
        {
            return Err(ApiError::OutOfWorkspace { target });
        }
        Ok(())
    }

    /// The tool motion of `move_to_position` (no trace entry); `call` names the API call
    /// that moves (`move_to_position` or `move_gripper_to`) in a collision.
    fn do_move_to_position(
        &mut self,
        call: &str,
        pos: [f64; 3],
        pointing: Direction,
        clearance: f64,
        angle: f64,
    ) -> Result<(), ApiError> {
        if !(clearance.is_finite() && clearance >= 0.0 && angle.is_finite()) {
            return Err(ApiError::InvalidArgument {
                call: "move_to_position".into(),
                message: format!("lift_clearance must be ≥ 0 and angle finite, got {clearance} and {angle}"),
            });
        }
        if pointing == Direction::Up {
            return Err(ApiError::InvalidArgument {
                call: "move_to_position".into(),
                message: "pointing_to must be down, left, right, front or back".into(),
            });
        }
        self.check_workspace(pos)?;
        let angle = match self.scene.embodiment {
            Embodiment::Finger => self.nearest_spin(pointing, angle, std::f64::consts::PI),
            Embodiment::Vacuum => 0.0,
        };
        let rotation = Sim::pointing(pointing, angle);
        let dir = array_to_na(pointing.unit());
        let current = self.tool_pose();
        let current_dir = current.rotation * Vector3::z();
        let target = array_to_na(pos);
        let delta = target - current.translation.vector;
        // A move along the approach axis with unchanged pointing needs no clearance.
        let along_axis = delta.norm() > 1e-9 && delta.normalize().cross(&dir).norm() < 0.05;
        let clearance = if current_dir.dot(&dir) > 0.999 && along_axis {
            0.0
        } else {
            clearance
        };
        let mut waypoints = Vec::new();
        // After a push the trailing finger pad stands against the piece, under the overhang
        // of a chess piece's head (the pads push the neck); lifting straight up hooked the
        // head and carried the piece off. Back off against the push first.
        let mut lift_from = current.translation.vector;
        if let Some(push) = self.last_push.take()
            && clearance > 0.0
            && self.held.is_none()
            && self.handle_grasp.is_none()
        {
            lift_from -= array_to_na(push) * PUSH_BACK_OFF;
            waypoints.push(ToolGoal {
                position: lift_from,
                rotation: current.rotation,
            });
        }
        // The move from the lift point (or the start) to the approach point is the free
        // transit the planner keeps clear of loose objects.
        let mut transit = None;
        if clearance > 0.0 {
            if self.moved_since_reset {
                let lift = self.reachable_lift(lift_from, current_dir, &current.rotation, clearance);
                waypoints.push(ToolGoal {
                    position: lift_from - current_dir * lift,
                    rotation: current.rotation,
                });
            }
            transit = Some(waypoints.len());
            let approach = self.clear_approach(
                &ToolGoal {
                    position: target,
                    rotation,
                },
                dir,
                clearance,
            );
            waypoints.push(ToolGoal {
                position: target - dir * approach,
                rotation,
            });
        }
        waypoints.push(ToolGoal {
            position: target,
            rotation,
        });
        let plan = self.plan(&waypoints, pointing, transit)?;
        let executed = self.execute(&plan, MOTION_SETTLE_STEPS);
        self.moved_since_reset = true;
        executed.map_err(|stop| stop.into_error(self, call))
    }

    /// How far the tool backs off along its axis before a transit: the full `clearance`
    /// where the arm reaches that point, else the largest reachable fraction of it. Close to
    /// the base the arm cannot rise as high pointing down (its elbow would have to fold past
    /// its limit), and an object put down there left the hand unable to leave.
    pub(super) fn reachable_lift(
        &self,
        from: Vector3<f64>,
        tool_axis: Vector3<f64>,
        rotation: &UnitQuaternion<f64>,
        clearance: f64,
    ) -> f64 {
        // A single quick solve settles the common case; the planner's full search with
        // restarts only runs when it fails.
        let quick = IkOptions {
            restarts: 1,
            iterations: 60,
            ..IkOptions::default()
        };
        let reaches = |lift: f64| {
            let goal = ToolGoal {
                position: from - tool_axis * lift,
                rotation: *rotation,
            };
            self.ik(&goal, &self.q, &quick).is_some()
                || self.ik(&goal, &self.q, &IkOptions::default()).is_some()
        };
        LIFT_FRACTIONS
            .iter()
            .map(|fraction| clearance * fraction)
            .find(|&lift| reaches(lift))
            .unwrap_or(clearance)
    }

    fn do_move_gripper_to(&mut self, name: &str, pointing: Direction, depth: f64) -> Result<(), ApiError> {
        if name == parts::FLOOR || name == self.gripper_name() {
            return Err(ApiError::Infeasible {
                call: "move_gripper_to".into(),
                target: name.into(),
                reason: "it is not an object the gripper can move to; use move_to_position".into(),
            });
        }
        let part = self.part_or_unknown(name, "move_gripper_to")?;
        let aabb = self.part_aabb(part);
        let p = &self.parts[part];
        let call = "move_gripper_to".to_owned();
        if p.role == PartRole::Loose
            && !(0..2).all(|i| aabb.min[i] >= FLOOR_AABB.min[i] && aabb.max[i] <= FLOOR_AABB.max[i])
        {
            return Err(ApiError::OutOfWorkspace {
                target: aabb.centre(),
            });
        }
        if let Some(on_top) = self.stacked_on(part) {
            return Err(ApiError::Infeasible {
                call,
                target: name.into(),
                reason: format!("{} is stacked on it; move that first", self.parts[on_top].name),
            });
        }
        if let Some(top) = self.handle_covered_by(part) {
            return Err(ApiError::Infeasible {
                call,
                target: name.into(),
                reason: format!("the open {} covers it", self.parts[top].name),
            });
        }
        if !depth.is_finite() {
            return Err(ApiError::InvalidArgument {
                call,
                message: format!("depth must be finite, got {depth}"),
            });
        }
        if !matches!(pointing, Direction::Down | Direction::Left | Direction::Right) {
            return Err(ApiError::InvalidArgument {
                call,
                message: "pointing_to must be down, left or right".into(),
            });
        }
        let is_handle = p.role == PartRole::Handle;
        let asset = p.object;
        let depth = match self.scene.embodiment {
            Embodiment::Vacuum if is_handle => -0.01,
            Embodiment::Vacuum => 0.0,
            // The palm is 3.4 cm above the pads' centre: deeper, it would press on the object.
            Embodiment::Finger => depth.min(MAX_FINGER_DEPTH),
        };
        let dir = pointing.unit();
        let axis = dir.iter().position(|v| v.abs() > 0.5).unwrap_or(2);
        let half = aabb.size()[axis] / 2.0;
        let centre = aabb.centre();
        let mut target: [f64; 3] = std::array::from_fn(|i| centre[i] + (depth - half) * dir[i]);
        let yaw = match self.scene.embodiment {
            Embodiment::Vacuum => 0.0,
            Embodiment::Finger => {
                let (angle, step) = self.finger_grasp_spins(part);
                self.uncrowded_spin(part, pointing, angle, step, target[2])
            }
        };
        // A hand coming down stops where its palm would meet a taller neighbour, as a real
        // one stops on contact (its palm came down on a fruit beside a cube and flung it off
        // the table), as long as the pads still reach a little below the object's top.
        if self.scene.embodiment == Embodiment::Finger && !is_handle {
            let rotation = Sim::pointing(pointing, yaw);
            if pointing == Direction::Down
                && let Some(top) = self.palm_ceiling(part, &rotation)
            {
                let palm_clear = top + PALM_CLEARANCE - PALM_ABOVE_TOOL;
                target[2] = target[2].max(palm_clear.min(aabb.max[2] - MIN_PAD_OVERLAP));
            }
            // The empty open hand narrows to the object on its way (the fingers move while
            // the arm does); `open_gripper` opens it fully again.
            if !self.closed && self.held.is_none() && self.handle_grasp.is_none() {
                self.gripper_target = self.preshape_travel(part, &rotation);
            }
        }
        self.handle_approach = is_handle.then_some(asset);
        let moved = self.do_move_to_position(
            "move_gripper_to",
            target,
            pointing,
            crate::api::DEFAULT_LIFT_CLEARANCE,
            yaw,
        );
        self.handle_approach = None;
        // The hand now rests at the handle, inside its asset's space (the authors' handles
        // stand closer to the face than a Panda hand fits): without grasping, it may leave
        // the way it came, as after letting go of a handle.
        if is_handle && self.protective_stop {
            self.leaving_asset = Some(asset);
        }
        moved
    }

    /// Of the finger grasp spins `angle + k·step`, the one nearest the current tool whose
    /// hand comes down to `tool_z` clear of every other loose object; when every spin touches
    /// one, the spin whose tallest touched neighbour is lowest. Two parts of the hand can hit
    /// a neighbour: the open fingers, beside the object at its own level (a cube grasped with
    /// one finger on its neighbour too drags the neighbour along), and the 20 cm long palm,
    /// above any neighbour taller than the grasp (a two-cube stack beside the object is
    /// knocked over).
    fn uncrowded_spin(&self, part: usize, pointing: Direction, angle: f64, step: f64, tool_z: f64) -> f64 {
        let spins = self.spins_by_nearness(pointing, angle, step);
        let Some(&nearest) = spins.first() else {
            return angle;
        };
        if pointing != Direction::Down {
            return nearest;
        }
        let object = self.part_aabb(part);
        let neighbours = self.loose_neighbours(part);
        let palm_z = tool_z + PALM_ABOVE_TOOL;
        // How bad a spin is: the height of the tallest neighbour the hand would touch (a
        // tower knocked over scatters more than a single cube nudged), or 0 when none.
        let crowding = |spin: f64| {
            let rotation = Sim::pointing(pointing, spin);
            let footprint = Footprint::new(object.centre(), &rotation);
            let travel = self.preshape_travel(part, &rotation);
            // The tallest neighbour that `reaches` the hand's sample point at `s` along the
            // closing axis and `t` across it.
            let touched = |s: f64, t: f64, reaches: &dyn Fn(&Aabb) -> bool| {
                let at = footprint.point(s, t);
                neighbours
                    .iter()
                    .filter(|n| reaches(n) && covers(n, at))
                    .map(|n| n.max[2] - TABLE_TOP)
                    .fold(0.0, f64::max)
            };
            let beside = |n: &Aabb| n.max[2] > object.min[2] + LEVEL_TOLERANCE && n.min[2] < object.max[2];
            let under_palm = |n: &Aabb| n.max[2] > palm_z;
            let fingers = FINGER_SWEEP
                .iter()
                .flat_map(|&d| [travel + d, -(travel + d)])
                .flat_map(|s| [-FINGER_HALF_WIDTH, 0.0, FINGER_HALF_WIDTH].map(|t| (s, t)))
                .map(|(s, t)| touched(s, t, &beside))
                .fold(0.0, f64::max);
            let palm = palm_samples()
                .map(|(s, t)| touched(s, t, &under_palm))
                .fold(0.0, f64::max);
            f64::max(fingers, palm)
        };
        // With the protective stop on (a robot that knows its furniture): how far the hand,
        // its open fingers or the wrist would press into furniture on the way down to the
        // grasp (a piece beside the cabinet: the 20 cm palm turned toward it
        // goes through the drawer front), 0 when clear. It outranks crowding: a neighbour is
        // nudged, furniture stops the arm. Even a touch counts: the fingers narrow to the
        // object while the arm moves, so on the way down they stand wider than at the grasp.
        let centre = object.centre();
        let furniture = self.protective_stop.then(|| self.furniture_snapshot());
        let into_furniture = |spin: f64| {
            let Some(furniture) = &furniture else {
                return 0.0;
            };
            self.descent_into_furniture(
                furniture,
                part,
                [centre[0], centre[1]],
                tool_z,
                Sim::pointing(pointing, spin),
            )
        };
        let scored: Vec<(f64, f64, f64)> = spins
            .iter()
            .map(|&spin| (spin, into_furniture(spin), crowding(spin)))
            .collect();
        if std::env::var_os("NESY_DEBUG_TRANSIT").is_some() {
            eprintln!(
                "grasp spins of {} (spin, into furniture, crowding): {scored:?}",
                self.parts[part].name
            );
        }
        // Clear of furniture, then the least crowded; among equals, the nearest (min_by keeps
        // the first).
        scored
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.2.total_cmp(&b.2)))
            .map_or(nearest, |&(spin, _, _)| spin)
    }

    /// The finger hand's grasp spins of `part` as it lies now: `angle + k·step` for every
    /// integer `k` (a box or cylinder from either pair of faces, anything else one way round).
    pub(crate) fn finger_grasp_spins(&self, part: usize) -> (f64, f64) {
        let p = &self.parts[part];
        let object_yaw = match p.role {
            PartRole::Loose => yaw_of(&self.part_pose(part).rotation),
            _ => p.base_yaw,
        };
        let step = match p.kind {
            ObjectKind::Cube | ObjectKind::Cylinder if p.role == PartRole::Loose => {
                std::f64::consts::FRAC_PI_2
            }
            _ => std::f64::consts::PI,
        };
        (object_yaw + p.grasp_yaw, step)
    }

    /// How far (m) the arm, hand or open fingers would press into `furniture` on the way down
    /// to take `part` with the tool at `xy` and height `tool_z` in orientation `rotation`,
    /// checked at the heights of [`DESCENT_CHECK_HEIGHTS`] from the top down (0 when clear).
    pub(crate) fn descent_into_furniture(
        &self,
        furniture: &FurnitureSnapshot<'_>,
        part: usize,
        xy: [f64; 2],
        tool_z: f64,
        rotation: UnitQuaternion<f64>,
    ) -> f64 {
        let travel = self.preshape_travel(part, &rotation);
        let mut seed = self.q.clone();
        let mut deepest = 0.0_f64;
        for lift in DESCENT_CHECK_HEIGHTS.iter().rev() {
            let goal = ToolGoal {
                position: Vector3::new(xy[0], xy[1], tool_z + lift),
                rotation,
            };
            if let Some(q) = self.ik(&goal, &seed, &IkOptions::default()) {
                deepest = deepest.max(furniture.arm_depth_at(&q, travel));
                seed = q;
            }
        }
        deepest
    }

    /// The highest top of the loose objects (other than `part` and a held one) under the
    /// palm of a hand above `part` with tool orientation `rotation`, if any.
    fn palm_ceiling(&self, part: usize, rotation: &UnitQuaternion<f64>) -> Option<f64> {
        let footprint = Footprint::new(self.part_aabb(part).centre(), rotation);
        let points: Vec<[f64; 2]> = palm_samples().map(|(s, t)| footprint.point(s, t)).collect();
        self.loose_neighbours(part)
            .into_iter()
            .filter(|n| points.iter().any(|&at| covers(n, at)))
            .map(|n| n.max[2])
            .reduce(f64::max)
    }

    /// The boxes of the loose objects other than `part` and the held one: what a hand coming
    /// down to `part` can meet.
    fn loose_neighbours(&self, part: usize) -> Vec<Aabb> {
        let held = self.held.map(|h| h.part);
        (0..self.parts.len())
            .filter(|&i| i != part && Some(i) != held && self.parts[i].role == PartRole::Loose)
            .map(|i| self.part_aabb(i))
            .collect()
    }

    fn do_move_parallel(&mut self, dir: Direction, offset: f64) -> Result<(), ApiError> {
        if dir == Direction::Down {
            return Err(ApiError::InvalidArgument {
                call: "move_parallel".into(),
                message: "move_dir must be left, right, front, back or up".into(),
            });
        }
        if !(offset.is_finite() && offset > 0.0) {
            return Err(ApiError::InvalidArgument {
                call: "move_parallel".into(),
                message: format!("offset must be > 0, got {offset}"),
            });
        }
        let current = self.tool_pose();
        let target = current.translation.vector + array_to_na(dir.unit()) * offset;
        self.check_workspace([target.x, target.y, target.z])?;
        let plan = self.plan(
            &[ToolGoal {
                position: target,
                rotation: current.rotation,
            }],
            dir,
            None,
        )?;
        let executed = self.execute_at_least(&plan, MOTION_SETTLE_STEPS, PARALLEL_MIN_DURATION);
        self.moved_since_reset = true;
        executed.map_err(|stop| stop.into_error(self, "move_parallel"))?;
        let sideways = dir != Direction::Up;
        let empty_fingers =
            self.scene.embodiment == Embodiment::Finger && self.held.is_none() && self.handle_grasp.is_none();
        self.last_push = (sideways && empty_fingers).then(|| dir.unit());
        Ok(())
    }

    /// Width of a part across the fingers (along the hand's y axis).
    fn width_across_fingers(&self, part: usize) -> f64 {
        self.width_along(part, &self.carrier_pose().rotation)
    }

    /// Width of a part along the y axis of a frame turned by `rotation` (the closing axis of
    /// a hand with that orientation).
    fn width_along(&self, part: usize, rotation: &rapier3d::prelude::Rotation) -> f64 {
        let frame_inv =
            rapier3d::prelude::Pose::from_parts(rapier3d::prelude::Vector::ZERO, *rotation).inverse();
        let aabb = self.parts[part].colliders.iter().fold(Aabb::EMPTY, |acc, &c| {
            let collider = &self.world.colliders[c];
            acc.union(&Aabb::from_parry(
                &collider.shape().compute_aabb(&(frame_inv * *collider.position())),
            ))
        });
        aabb.size()[1]
    }

    /// The finger travel the open hand takes on its way down to `part` with tool orientation
    /// `rotation`: the part's half-width across the pads plus [`PRESHAPE_CLEARANCE`], at most
    /// fully open.
    fn preshape_travel(&self, part: usize, rotation: &UnitQuaternion<f64>) -> f64 {
        let r = rotation.coords;
        let rotation = rapier3d::prelude::Rotation::from_xyzw(r.x as f32, r.y as f32, r.z as f32, r.w as f32);
        (self.width_along(part, &rotation) / 2.0 + PRESHAPE_CLEARANCE).min(FINGER_OPEN)
    }

    fn close_fingers(&mut self) {
        self.closed = true;
        let mut target = 0.0;
        if let Some(grasp) = self.handle_grasp {
            target = (self.width_across_fingers(grasp.part) / 2.0).min(FINGER_OPEN);
        } else if self.held.is_none() {
            // Of the loose objects between the pads, the one nearest the pads' midpoint: the
            // first in scene order (the authors' rule) could be a neighbour whose box merely
            // grazes the pad line, and the fingers then carried off a cube next to the fruit
            // they closed on.
            let mid = self
                .pad_centres()
                .map(|[a, b]| std::array::from_fn::<f64, 3, _>(|k| (a[k] + b[k]) / 2.0));
            let candidate = (0..self.parts.len())
                .filter(|&i| self.parts[i].role == PartRole::Loose && self.part_in_gripper(i))
                .min_by(|&i, &j| {
                    let d = |p: usize| {
                        let c = self.part_aabb(p).centre();
                        mid.map_or(0.0, |m| (0..3).map(|k| (c[k] - m[k]).powi(2)).sum::<f64>())
                    };
                    d(i).total_cmp(&d(j)).then(i.cmp(&j))
                });
            if let Some(i) = candidate {
                let width = self.width_across_fingers(i);
                if width <= 2.0 * FINGER_OPEN + 1e-3 {
                    target = width / 2.0;
                    self.weld(i);
                } else {
                    // Wider than the opening: the fingers stop on it and nothing is held.
                    target = self.gripper;
                }
            }
        }
        self.gripper_target = target;
        self.step_idle(GRIPPER_STEPS);
    }

    fn open_fingers(&mut self) {
        self.unweld();
        self.closed = false;
        self.gripper_target = if self.scene.embodiment == Embodiment::Finger {
            FINGER_OPEN
        } else {
            0.0
        };
        self.step_idle(GRIPPER_STEPS + MOTION_SETTLE_STEPS);
    }

    fn suction_on(&mut self) {
        self.closed = true;
        if self.held.is_none() && self.handle_grasp.is_none() {
            let point = self.suction_point();
            if let Some(i) = (0..self.parts.len())
                .find(|&i| self.parts[i].role == PartRole::Loose && self.part_aabb(i).contains_point(point))
            {
                self.weld(i);
            }
        }
        self.step_idle(GRIPPER_STEPS);
    }

    fn do_grasp_handle(&mut self, name: &str, call: &str) -> Result<(), ApiError> {
        let part = self.part_or_unknown(name, call)?;
        let infeasible = |reason: String| ApiError::Infeasible {
            call: call.into(),
            target: name.into(),
            reason,
        };
        let Some(articulation) = self.parts[part]
            .articulation
            .filter(|_| self.parts[part].role == PartRole::Handle)
        else {
            return Err(infeasible("it is not a handle".into()));
        };
        if let Some(h) = self.held {
            return Err(infeasible(format!(
                "the gripper is holding {}",
                self.parts[h.part].name
            )));
        }
        if let Some(top) = self.handle_covered_by(part) {
            return Err(infeasible(format!("the open {} covers it", self.parts[top].name)));
        }
        let tool = self.tool_pose().translation.vector;
        let distance = (tool - array_to_na(self.part_aabb(part).centre())).norm();
        if distance > HANDLE_REACH {
            return Err(infeasible(format!(
                "it is {distance:.3} m from the gripper (reach {HANDLE_REACH} m); move_gripper_to it first"
            )));
        }
        if let Some(load) = self.blocking_load(articulation) {
            return Err(infeasible(format!(
                "{} rests on {} and blocks it",
                self.parts[load].name, self.parts[self.articulations[articulation].link].name
            )));
        }
        let a = &self.articulations[articulation];
        let moving = a.frame * crate::world::objects::joint_motion(a.joint, a.q);
        let c = self.part_aabb(part).centre();
        let handle_local = moving.inverse_transform_point(rapier3d::prelude::Vector::new(
            c[0] as f32,
            c[1] as f32,
            c[2] as f32,
        ));
        self.handle_grasp = Some(HandleGrasp {
            part,
            articulation,
            tool0: tool,
            q0: a.q,
            handle_local,
        });
        match self.scene.embodiment {
            Embodiment::Finger => self.close_fingers(),
            Embodiment::Vacuum => self.suction_on(),
        }
        Ok(())
    }

    fn do_release_handle(&mut self) {
        self.leaving_asset = self
            .handle_grasp
            .map(|grasp| self.articulation_asset(grasp.articulation));
        self.handle_grasp = None;
        self.open_fingers();
    }
}

/// Heights (m) above a grasp at which a spin's hand is checked against furniture: the
/// vertical approach from [`crate::api::DEFAULT_LIFT_CLEARANCE`] above down to the grasp.
const DESCENT_CHECK_HEIGHTS: [f64; 4] = [0.0, 0.04, 0.08, crate::api::DEFAULT_LIFT_CLEARANCE];

const FINGER_ONLY: Embodiment = Embodiment::Finger;
const VACUUM_ONLY: Embodiment = Embodiment::Vacuum;

impl RobotApi for Sim {
    fn embodiment(&self) -> Embodiment {
        self.scene.embodiment
    }

    fn trace(&self) -> &[TraceEntry] {
        &self.trace
    }

    fn is_obj_visible(&mut self, obj_name: &str) -> bool {
        let visible = self.names().iter().any(|n| n == obj_name);
        let call = ApiCall::IsObjVisible {
            obj_name: obj_name.into(),
        };
        self.record(call, Ok(visible), |v| ApiValue::Bool(*v))
            .unwrap_or(false)
    }

    fn get_obj_names(&mut self) -> Vec<String> {
        let names = self.names();
        self.record(ApiCall::GetObjNames, Ok(names), |n| ApiValue::Names(n.clone()))
            .unwrap_or_default()
    }

    fn get_obj_pos(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError> {
        let result = self.aabb_or_unknown(obj_name).map(|a| {
            let mut c = a.centre();
            if obj_name == parts::FLOOR {
                c[2] = TABLE_TOP;
            }
            c
        });
        self.record(
            ApiCall::GetObjPos {
                obj_name: obj_name.into(),
            },
            result,
            |v| ApiValue::Vec3(*v),
        )
    }

    fn get_obj_bbox(&mut self, obj_name: &str) -> Result<[[f64; 3]; 2], ApiError> {
        let result = self.aabb_or_unknown(obj_name).map(|a| [a.min, a.max]);
        self.record(
            ApiCall::GetObjBbox {
                obj_name: obj_name.into(),
            },
            result,
            |v| ApiValue::Bbox(*v),
        )
    }

    fn get_obj_size(&mut self, obj_name: &str) -> Result<[f64; 3], ApiError> {
        let result = self.aabb_or_unknown(obj_name).map(|a| a.size());
        self.record(
            ApiCall::GetObjSize {
                obj_name: obj_name.into(),
            },
            result,
            |v| ApiValue::Vec3(*v),
        )
    }

    fn gripper_is_open(&mut self) -> bool {
        let open = !self.closed;
        self.record(ApiCall::GripperIsOpen, Ok(open), |v| ApiValue::Bool(*v))
            .unwrap_or(true)
    }

    fn obj_in_gripper(&mut self, obj_name: &str) -> Result<bool, ApiError> {
        let pieces = self.pieces_of(obj_name);
        let result = if pieces.is_empty() {
            self.part_or_unknown(obj_name, "obj_in_gripper")
                .map(|p| self.part_in_gripper(p))
        } else {
            Ok(pieces.iter().any(|&p| self.part_in_gripper(p)))
        };
        self.record(
            ApiCall::ObjInGripper {
                obj_name: obj_name.into(),
            },
            result,
            |v| ApiValue::Bool(*v),
        )
    }

    fn get_empty_floor_xy(&mut self, obj_name: &str) -> Result<[f64; 2], ApiError> {
        let result = self
            .part_or_unknown(obj_name, "get_empty_floor_xy")
            .and_then(|p| {
                empty_floor_xy(self, p).ok_or(ApiError::NoEmptySpace {
                    obj_name: obj_name.into(),
                })
            });
        self.record(
            ApiCall::GetEmptyFloorXy {
                obj_name: obj_name.into(),
            },
            result,
            |v| ApiValue::Xy(*v),
        )
    }

    fn move_gripper_to(
        &mut self,
        obj_name: &str,
        pointing_to: Direction,
        depth: f64,
    ) -> Result<(), ApiError> {
        let call = ApiCall::MoveGripperTo {
            obj_name: obj_name.into(),
            pointing_to,
            depth,
        };
        self.action(call, None, |sim| {
            sim.do_move_gripper_to(obj_name, pointing_to, depth)
        })
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
        self.action(call, None, |sim| {
            sim.do_move_to_position("move_to_position", pos, pointing_to, lift_clearance, angle)
        })
    }

    fn move_parallel(
        &mut self,
        move_dir: Direction,
        offset: f64,
        pointing_to: Direction,
    ) -> Result<(), ApiError> {
        let call = ApiCall::MoveParallel {
            move_dir,
            offset,
            pointing_to,
        };
        self.action(call, None, |sim| sim.do_move_parallel(move_dir, offset))
    }

    fn grasp_handle(&mut self, handle_name: &str) -> Result<(), ApiError> {
        let call = ApiCall::GraspHandle {
            handle_name: handle_name.into(),
        };
        self.action(call, Some((FINGER_ONLY, "attach_vacuum_handle")), |sim| {
            sim.do_grasp_handle(handle_name, "grasp_handle")
        })
    }

    fn release_handle(&mut self) -> Result<(), ApiError> {
        self.action(
            ApiCall::ReleaseHandle,
            Some((FINGER_ONLY, "detach_vacuum_handle")),
            |sim| {
                sim.do_release_handle();
                Ok(())
            },
        )
    }

    fn open_gripper(&mut self) -> Result<(), ApiError> {
        self.action(
            ApiCall::OpenGripper,
            Some((FINGER_ONLY, "deactivate_vacuum")),
            |sim| {
                sim.open_fingers();
                Ok(())
            },
        )
    }

    fn close_gripper(&mut self) -> Result<(), ApiError> {
        self.action(
            ApiCall::CloseGripper,
            Some((FINGER_ONLY, "activate_vacuum")),
            |sim| {
                sim.close_fingers();
                Ok(())
            },
        )
    }

    fn attach_vacuum_handle(&mut self, handle_name: &str) -> Result<(), ApiError> {
        let call = ApiCall::AttachVacuumHandle {
            handle_name: handle_name.into(),
        };
        self.action(call, Some((VACUUM_ONLY, "grasp_handle")), |sim| {
            sim.do_grasp_handle(handle_name, "attach_vacuum_handle")
        })
    }

    fn detach_vacuum_handle(&mut self) -> Result<(), ApiError> {
        self.action(
            ApiCall::DetachVacuumHandle,
            Some((VACUUM_ONLY, "release_handle")),
            |sim| {
                sim.do_release_handle();
                Ok(())
            },
        )
    }

    fn activate_vacuum(&mut self) -> Result<(), ApiError> {
        self.action(
            ApiCall::ActivateVacuum,
            Some((VACUUM_ONLY, "close_gripper")),
            |sim| {
                sim.suction_on();
                Ok(())
            },
        )
    }

    fn deactivate_vacuum(&mut self) -> Result<(), ApiError> {
        self.action(
            ApiCall::DeactivateVacuum,
            Some((VACUUM_ONLY, "open_gripper")),
            |sim| {
                sim.open_fingers();
                Ok(())
            },
        )
    }

    fn gather_with_hook(&mut self, obj_name: &str) -> Result<(), ApiError> {
        let call = ApiCall::GatherWithHook {
            obj_name: obj_name.into(),
        };
        self.action(call, None, |sim| sim.do_gather_with_hook(obj_name))
    }
}
