//! The robot as the experts drive it: the moves every subtask's expert shares (pick, put
//! down, move aside, grasp and release handles, swing the lid), each failing with an
//! [`ExpertError`] that names the call.

use super::ExpertError;
use crate::api::{ApiError, DEFAULT_LIFT_CLEARANCE, Direction, Embodiment, RobotApi};
use crate::perception::observer::CLING_REACH;
use crate::robot::model::{HAND_HALF_LENGTH, HAND_HALF_WIDTH, PALM_ABOVE_TOOL};
use crate::scene::{SubtaskKind, TABLE_TOP, parts};
use crate::tasks::layout::{DROP_CLEARANCE, LID_SWING_MAX_X};

/// Grasps tried on one object before the expert carries on regardless.
const PICK_ATTEMPTS: usize = 3;
/// Nearest x (m) to the robot's base at which the experts set objects down out of the way.
const COMFORTABLE_MIN_X: f64 = 0.3;

/// The robot with the subtask being worked on (for error reports) and the scene's loose
/// objects (the only ones an expert moves aside).
pub(super) struct Hand<'a, R: RobotApi + ?Sized> {
    pub(super) robot: &'a mut R,
    subtask: SubtaskKind,
    pub(super) vacuum: bool,
    loose: &'a [String],
    /// The scene's tools (magnetic hooks) and fine-grained objects (screws).
    tools: Tools<'a>,
    /// The robot's protective stop is on: approaches keep off furniture.
    pub(super) furniture_aware: bool,
}

/// The scene's magnetic hooks and the fine-grained objects only a hook's magnet can move.
#[derive(Clone, Copy, Default)]
pub(super) struct Tools<'a> {
    /// Magnetic hooks.
    pub(super) hooks: &'a [String],
    /// Fine-grained objects (screws).
    pub(super) fine: &'a [String],
}

/// An axis-aligned box as the API returns it: `[min, max]`.
pub(super) type Bbox = [[f64; 3]; 2];

pub(super) fn centre(b: &Bbox) -> [f64; 3] {
    std::array::from_fn(|i| (b[0][i] + b[1][i]) / 2.0)
}

pub(super) fn size(b: &Bbox) -> [f64; 3] {
    std::array::from_fn(|i| b[1][i] - b[0][i])
}

pub(super) fn overlaps_xy(a: &Bbox, b: &Bbox, margin: f64) -> bool {
    (0..2).all(|i| a[0][i] < b[1][i] + margin && b[0][i] < a[1][i] + margin)
}

/// Whether the finger hand, its tool point above `spot` at the API's default angle (the
/// fingers' travel along y), overlaps any of `boxes` seen from above.
fn hand_meets(boxes: &[Bbox], [x, y]: [f64; 2]) -> bool {
    let hand: Bbox = [
        [x - HAND_HALF_WIDTH, y - HAND_HALF_LENGTH, 0.0],
        [x + HAND_HALF_WIDTH, y + HAND_HALF_LENGTH, 0.0],
    ];
    boxes.iter().any(|b| overlaps_xy(b, &hand, 0.0))
}

/// Whether two boxes overlap in all three axes.
pub(super) fn overlaps(a: &Bbox, b: &Bbox) -> bool {
    (0..3).all(|i| a[0][i] < b[1][i] && b[0][i] < a[1][i])
}

impl<'a, R: RobotApi + ?Sized> Hand<'a, R> {
    pub(super) fn new(robot: &'a mut R, subtask: SubtaskKind, loose: &'a [String]) -> Self {
        let vacuum = robot.embodiment() == Embodiment::Vacuum;
        Hand {
            robot,
            subtask,
            vacuum,
            loose,
            tools: Tools::default(),
            furniture_aware: false,
        }
    }

    /// The same hand, knowing the scene's hooks and fine-grained objects.
    pub(super) fn with_tools(mut self, tools: Tools<'a>) -> Self {
        self.tools = tools;
        self
    }

    /// True for a magnetic hook.
    pub(super) fn is_hook(&self, name: &str) -> bool {
        self.tools.hooks.iter().any(|h| h == name)
    }

    /// True for a fine-grained object, which only a hook's magnet moves.
    pub(super) fn is_fine_grained(&self, name: &str) -> bool {
        self.tools.fine.iter().any(|f| f == name)
    }

    /// True for the scene's loose objects (cubes, cylinders, fruits, chess pieces); the
    /// furniture, the table and the robot are never moved aside.
    pub(super) fn is_loose(&self, name: &str) -> bool {
        self.loose.iter().any(|l| l == name) && !self.is_fine_grained(name)
    }

    pub(super) fn fail(&self, step: String, error: ApiError) -> ExpertError {
        ExpertError {
            subtask: self.subtask,
            step,
            error,
        }
    }

    pub(super) fn bbox(&mut self, name: &str) -> Result<Bbox, ExpertError> {
        self.robot
            .get_obj_bbox(name)
            .map_err(|e| self.fail(format!("get_obj_bbox({name})"), e))
    }

    /// Whether every piece of the fine-grained object `pieces` lies against the hook: their
    /// box within [`CLING_REACH`] of the hook's on every side, as a pile on its magnet does.
    pub(super) fn clings_to(&mut self, pieces: &str, hook: &str) -> Result<bool, ExpertError> {
        let (p, h) = (self.bbox(pieces)?, self.bbox(hook)?);
        Ok((0..3).all(|k| p[0][k] >= h[0][k] - CLING_REACH && p[1][k] <= h[1][k] + CLING_REACH))
    }

    /// How far below the tool point a held object's bottom hangs: suction holds it by the
    /// top, the fingers by the middle (the pick depth is half its height).
    pub(super) fn hang(&self, height: f64) -> f64 {
        if self.vacuum { height } else { height / 2.0 }
    }

    pub(super) fn move_to_object(&mut self, name: &str, depth: f64) -> Result<(), ExpertError> {
        self.robot
            .move_gripper_to(name, Direction::Down, depth)
            .map_err(|e| self.fail(format!("move_gripper_to({name}, depth {depth:.3})"), e))
    }

    pub(super) fn move_to(&mut self, pos: [f64; 3], clearance: f64) -> Result<(), ExpertError> {
        self.move_to_turned(pos, clearance, 0.0)
    }

    /// [`Hand::move_to`] with the wrist turned by `angle` (rad) about the vertical.
    pub(super) fn move_to_turned(
        &mut self,
        pos: [f64; 3],
        clearance: f64,
        angle: f64,
    ) -> Result<(), ExpertError> {
        self.robot
            .move_to_position(pos, Direction::Down, clearance, angle)
            .map_err(|e| {
                self.fail(
                    format!("move_to_position(({:.3}, {:.3}, {:.3}))", pos[0], pos[1], pos[2]),
                    e,
                )
            })
    }

    pub(super) fn slide(&mut self, dir: Direction, offset: f64) -> Result<(), ExpertError> {
        self.slide_pointing(dir, offset, Direction::Down)
    }

    /// [`Hand::slide`] with the tool pointing along `pointing`.
    pub(super) fn slide_pointing(
        &mut self,
        dir: Direction,
        offset: f64,
        pointing: Direction,
    ) -> Result<(), ExpertError> {
        self.robot
            .move_parallel(dir, offset, pointing)
            .map_err(|e| self.fail(format!("move_parallel({}, {offset:.3})", dir.as_str()), e))
    }

    pub(super) fn grasp(&mut self) -> Result<(), ExpertError> {
        let (name, result) = if self.vacuum {
            ("activate_vacuum", self.robot.activate_vacuum())
        } else {
            ("close_gripper", self.robot.close_gripper())
        };
        result.map_err(|e| self.fail(format!("{name}()"), e))
    }

    pub(super) fn release(&mut self) -> Result<(), ExpertError> {
        let (name, result) = if self.vacuum {
            ("deactivate_vacuum", self.robot.deactivate_vacuum())
        } else {
            ("open_gripper", self.robot.open_gripper())
        };
        result.map_err(|e| self.fail(format!("{name}()"), e))
    }

    /// Moves to a handle from above and grasps it.
    pub(super) fn grab_handle(&mut self, handle: &str) -> Result<(), ExpertError> {
        self.grab_handle_pointing(handle, Direction::Down)
    }

    /// Moves to a handle with the tool pointing along `pointing` and grasps it.
    pub(super) fn grab_handle_pointing(
        &mut self,
        handle: &str,
        pointing: Direction,
    ) -> Result<(), ExpertError> {
        self.robot
            .move_gripper_to(handle, pointing, 0.0)
            .map_err(|e| self.fail(format!("move_gripper_to({handle}, {})", pointing.as_str()), e))?;
        let (name, result) = if self.vacuum {
            ("attach_vacuum_handle", self.robot.attach_vacuum_handle(handle))
        } else {
            ("grasp_handle", self.robot.grasp_handle(handle))
        };
        result.map_err(|e| self.fail(format!("{name}({handle})"), e))
    }

    pub(super) fn let_go_handle(&mut self) -> Result<(), ExpertError> {
        let (name, result) = if self.vacuum {
            ("detach_vacuum_handle", self.robot.detach_vacuum_handle())
        } else {
            ("release_handle", self.robot.release_handle())
        };
        result.map_err(|e| self.fail(format!("{name}()"), e))
    }

    /// Moves a grasped lid's handle through `arc` (degrees) about the hinge `axis` (x, z)
    /// at distance `reach`, one short move per waypoint.
    pub(super) fn swing_lid(
        &mut self,
        axis: [f64; 2],
        y: f64,
        reach: f64,
        arc: &[f64],
    ) -> Result<(), ExpertError> {
        for angle in arc.iter().map(|a| a.to_radians()) {
            let x = (axis[0] + reach * angle.cos()).min(LID_SWING_MAX_X);
            let target = [x, y, axis[1] + reach * angle.sin()];
            // Keep the wrist as it grasped the handle (fingers across the handle's thin side,
            // turned by 90°): turning it on the way makes the arm leave the straight line, and
            // the tool strays from the handle.
            self.move_to_turned(target, 0.0, std::f64::consts::FRAC_PI_2)?;
        }
        Ok(())
    }

    /// Picks an object from above at half its height; returns its height.
    ///
    /// A grasp that did not take (a round fruit nudged aside by a finger on the way down) is
    /// let go and tried again from the object's new position, up to [`PICK_ATTEMPTS`] times.
    pub(super) fn pick(&mut self, name: &str) -> Result<f64, ExpertError> {
        let mut h = 0.0;
        self.grasp_retrying(name, |expert| {
            h = size(&expert.bbox(name)?)[2];
            expert.move_to_object(name, h / 2.0)
        })?;
        Ok(h)
    }

    /// Runs `approach` and closes the tool on `name`; when the grasp did not take, lets go
    /// and tries again, up to [`PICK_ATTEMPTS`] approaches in all.
    pub(super) fn grasp_retrying(
        &mut self,
        name: &str,
        mut approach: impl FnMut(&mut Self) -> Result<(), ExpertError>,
    ) -> Result<(), ExpertError> {
        for attempt in 1..=PICK_ATTEMPTS {
            approach(self)?;
            self.grasp()?;
            let held = self
                .robot
                .obj_in_gripper(name)
                .map_err(|e| self.fail(format!("obj_in_gripper({name})"), e))?;
            if held || attempt == PICK_ATTEMPTS {
                break;
            }
            self.release()?;
        }
        Ok(())
    }

    /// Picks a round object (a fruit) with the finger hand turned so that its long side
    /// (≈ 21 cm along the fingers' travel) misses the neighbours: round fruits nudged by the
    /// hand roll away (Rapier has no rolling resistance). The usual wrist angle when it is
    /// clear or both are blocked, or (furniture-aware) when the turned palm would come down
    /// on furniture taller than its underside (the hinge box beside the fruit), else the
    /// wrist turned by 90°. Returns the height.
    pub(super) fn pick_round(&mut self, name: &str) -> Result<f64, ExpertError> {
        if self.vacuum {
            return self.pick(name);
        }
        let me = self.bbox(name)?;
        let c = centre(&me);
        let palm_underside = me[1][2] - size(&me)[2] / 2.0 + PALM_ABOVE_TOOL;
        let mut others = Vec::new();
        let mut furniture = Vec::new();
        for other in self.robot.get_obj_names() {
            if other == name || self.is_fine_grained(&other) || other.ends_with("_handle") {
                continue;
            }
            if [parts::FLOOR, parts::GRIPPER, parts::VACUUM_GRIPPER].contains(&other.as_str()) {
                continue;
            }
            let b = self.bbox(&other)?;
            if self.is_loose(&other) {
                others.push(b);
            } else if b[1][2] > palm_underside {
                furniture.push(b);
            }
        }
        let footprint = |long_x: bool| -> Bbox {
            let (hx, hy) = if long_x {
                (HAND_HALF_LENGTH, HAND_HALF_WIDTH)
            } else {
                (HAND_HALF_WIDTH, HAND_HALF_LENGTH)
            };
            [[c[0] - hx, c[1] - hy, 0.0], [c[0] + hx, c[1] + hy, 0.0]]
        };
        // How deep the deepest neighbour reaches into a footprint (m; ≤ 0 when clear).
        let intrusion = |fp: &Bbox| {
            others
                .iter()
                .map(|b| {
                    (0..2)
                        .map(|i| (b[1][i] - fp[0][i]).min(fp[1][i] - b[0][i]))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        let usual = intrusion(&footprint(false));
        let turned = footprint(true);
        let turned_onto_furniture =
            self.furniture_aware && furniture.iter().any(|f| overlaps_xy(f, &turned, 0.0));
        if usual <= 0.0 || turned_onto_furniture || intrusion(&turned) >= usual {
            return self.pick(name);
        }
        let h = size(&me)[2];
        self.grasp_retrying(name, |expert| {
            let b = expert.bbox(name)?;
            let c = centre(&b);
            expert.move_to_turned(
                [c[0], c[1], b[1][2] - h / 2.0],
                DEFAULT_LIFT_CLEARANCE,
                std::f64::consts::FRAC_PI_2,
            )
        })?;
        Ok(h)
    }

    /// Puts the held object (of height `h`) down with its bottom `lift` above `floor_z` at
    /// `(x, y)`, and lets go.
    pub(super) fn put(&mut self, x: f64, y: f64, floor_z: f64, h: f64, lift: f64) -> Result<(), ExpertError> {
        self.move_to([x, y, floor_z + self.hang(h) + lift], DEFAULT_LIFT_CLEARANCE)?;
        self.release()
    }

    /// Moves an object to a free table spot: `get_empty_floor_xy`'s, unless that is close to
    /// the robot's base, where a top-down reach runs joint 4 into its limit and the planner's
    /// joint-space fallback swings the arm through the scene; then the free spot of
    /// [`Hand::free_spot`].
    pub(super) fn move_aside(&mut self, name: &str) -> Result<(), ExpertError> {
        let h = self.pick(name)?;
        let [x, y] = self
            .robot
            .get_empty_floor_xy(name)
            .map_err(|e| self.fail(format!("get_empty_floor_xy({name})"), e))?;
        // With the protective stop on, the API's spot already keeps the hand off furniture.
        let [x, y] = if x >= COMFORTABLE_MIN_X {
            [x, y]
        } else {
            self.free_spot(name)?.unwrap_or([x, y])
        };
        self.put(x, y, TABLE_TOP, h, DROP_CLEARANCE)
    }

    /// The boxes of the furniture (everything but loose objects, handles, the floor and the
    /// gripper) whose top stands higher than `z`, leaving out `name`.
    fn furniture_above(&mut self, name: &str, z: f64) -> Result<Vec<Bbox>, ExpertError> {
        let mut furniture = Vec::new();
        for other in self.robot.get_obj_names() {
            let skipped = other == name
                || self.is_loose(&other)
                || self.is_fine_grained(&other)
                || other.ends_with("_handle")
                || [parts::FLOOR, parts::GRIPPER, parts::VACUUM_GRIPPER].contains(&other.as_str());
            if skipped {
                continue;
            }
            let b = self.bbox(&other)?;
            if b[1][2] > z {
                furniture.push(b);
            }
        }
        Ok(furniture)
    }

    /// A table spot at x ≥ [`COMFORTABLE_MIN_X`] in the middle strip of the table whose
    /// footprint for `name` keeps 2 cm from every other object (seen via `get_obj_names` and
    /// `get_obj_bbox`), nearest the strip's centre; `None` if there is none.
    pub(super) fn free_spot(&mut self, name: &str) -> Result<Option<[f64; 2]>, ExpertError> {
        let own = size(&self.bbox(name)?);
        let half = [own[0].max(own[1]) / 2.0 + 0.02; 2];
        let mut others = Vec::new();
        for other in self.robot.get_obj_names() {
            if other == name
                || [parts::FLOOR, parts::GRIPPER, parts::VACUUM_GRIPPER].contains(&other.as_str())
            {
                continue;
            }
            others.push(self.bbox(&other)?);
        }
        // A hand that knows its furniture also keeps its own length (the fingers' travel
        // along y) off what stands higher than its palm when it lets go.
        let furniture = if self.furniture_aware && !self.vacuum {
            let palm_underside = TABLE_TOP + self.hang(own[2]) + DROP_CLEARANCE + PALM_ABOVE_TOOL;
            self.furniture_above(name, palm_underside)?
        } else {
            Vec::new()
        };
        let mut best: Option<([f64; 2], f64)> = None;
        for i in 0..=10 {
            for j in 0..=15 {
                let spot = [COMFORTABLE_MIN_X + 0.02 * i as f64, -0.15 + 0.02 * j as f64];
                let footprint: Bbox = [
                    [spot[0] - half[0], spot[1] - half[1], TABLE_TOP],
                    [spot[0] + half[0], spot[1] + half[1], TABLE_TOP + 0.3],
                ];
                if others.iter().any(|b| overlaps_xy(b, &footprint, 0.0)) || hand_meets(&furniture, spot) {
                    continue;
                }
                let cost = (spot[0] - 0.4).abs() + spot[1].abs();
                if best.is_none_or(|(_, c)| cost < c) {
                    best = Some((spot, cost));
                }
            }
        }
        Ok(best.map(|(spot, _)| spot))
    }
}
