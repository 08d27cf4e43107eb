//! Scripted experts: one per subtask, driving only the public [`RobotApi`] on either
//! embodiment and at every obstruction level. They follow the authors' demo recipes
//! (spec §2, "Demo") adapted to this simulator; the README lists the differences.
//!
//! The experts decide what to do from perception calls (`get_obj_bbox`, ...), not from the
//! generator's obstruction level: a stack is cleared when something rests on a cube, a piece
//! is lifted back to the board when it is in a box, the fruit on the lid is moved away when
//! there is one, and lids and drawers are opened when they are closed.

use crate::api::{ApiError, Direction, Embodiment, RobotApi};
use crate::goal::{EpisodeOutcome, GoalError, GoalMonitor};
use crate::scene::{SceneError, SceneSpec, SubtaskGoal};
use crate::sim::Sim;
use crate::task::SubtaskKind;

/// Why an expert stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{subtask} expert: {step} failed: {error}")]
pub struct ExpertError {
    /// The subtask it was working on.
    pub subtask: SubtaskKind,
    /// The call that failed, e.g. `move_gripper_to(red_cube)`.
    pub step: String,
    /// The robot's answer.
    pub error: ApiError,
}

/// Cells of the toy box the cubes are dropped into (offsets from its centre, m): three
/// along the long side, two across; placed cubes are square to the box (the wrist turns to
/// yaw 0 on the way), so they fit side by side.
pub(crate) const TOY_BOX_CELLS: [[f64; 2]; 6] = [
    [-0.042, -0.022],
    [0.0, -0.022],
    [0.042, -0.022],
    [-0.042, 0.022],
    [0.0, 0.022],
    [0.042, 0.022],
];
/// Fruit drop spots along the hinge box's long side (y offsets, m): fruits are round with a
/// flat base and do not roll aside when dropped onto each other.
pub(crate) const HINGE_SPOTS: [f64; 3] = [-0.06, 0.0, 0.06];
/// Cylinder drop spots in the bottom drawer (x offset, outward y offset from the drawer's
/// centre, m). They are 5 cm or more apart, because a cylinder dropped onto another one tips
/// over and, lying on its side, rolls on without stopping (Rapier has no rolling
/// resistance); and 1.5 cm or more inside the walls, because a cylinder falling 19 cm that
/// clips a wall's top edge is flung out of the drawer.
pub(crate) const DRAWER_SPOTS: [[f64; 2]; 3] = [[-0.035, -0.005], [0.035, -0.005], [0.0, 0.035]];
/// Waypoints of the tool around the hinge axis when opening the lid (degrees from +x in
/// the x–z plane; the closed lid points at 180°, the open one at 90°). A grasped lid follows
/// the tool's angle about the axis, and the handle slips when the tool gets more than
/// 10 cm from it: a single straight move (the authors' recipe) cuts the arc short, and with
/// the tool holding the handle a little above its centre it left the lid short of vertical or
/// lost the handle. Short arcs keep the tool near the handle; the last one is 30° past
/// vertical so the lid stops at its limit (q = 0.8).
pub(crate) const LID_OPENING_ARC: [f64; 3] = [135.0, 90.0, 60.0];
/// Waypoints when closing the lid (the last one is the authors' target, the body's −x top
/// edge).
pub(crate) const LID_CLOSING_ARC: [f64; 2] = [135.0, 180.0];
/// Height above the release point at which a carried object is let go over a container.
const DROP_CLEARANCE: f64 = 0.01;
/// Height of the table top.
const TABLE: f64 = 0.5;
/// Reach (m) of the finger hand's wrist around the tool point when it grasps a drawer
/// handle from above.
const WRIST_CLEARANCE: f64 = 0.07;
/// Half the finger hand's length along the fingers' travel, seen from above (m).
const HAND_HALF_LENGTH: f64 = 0.105;
/// Half the finger hand's width across the fingers' travel, seen from above (m).
const HAND_HALF_WIDTH: f64 = 0.035;
/// Grasps tried on one object before the expert carries on regardless.
const PICK_ATTEMPTS: usize = 3;
/// How far (m) the wrist and forearm trail behind the tool point when the hand grasps a
/// handle pointing sideways.
const FOREARM_REACH: f64 = 0.3;
/// Swings of the lid tried before the expert carries on regardless.
const SWING_ATTEMPTS: usize = 3;
/// Nearest x (m) to the robot's base at which the experts set objects down out of the way.
const COMFORTABLE_MIN_X: f64 = 0.3;

/// The robot with the subtask being worked on, for error reports.
struct Hand<'a, R: RobotApi + ?Sized> {
    robot: &'a mut R,
    subtask: SubtaskKind,
    vacuum: bool,
}

type Bbox = [[f64; 3]; 2];

fn centre(b: &Bbox) -> [f64; 3] {
    std::array::from_fn(|i| (b[0][i] + b[1][i]) / 2.0)
}

fn size(b: &Bbox) -> [f64; 3] {
    std::array::from_fn(|i| b[1][i] - b[0][i])
}

fn overlaps_xy(a: &Bbox, b: &Bbox, margin: f64) -> bool {
    (0..2).all(|i| a[0][i] < b[1][i] + margin && b[0][i] < a[1][i] + margin)
}

impl<'a, R: RobotApi + ?Sized> Hand<'a, R> {
    fn new(robot: &'a mut R, subtask: SubtaskKind) -> Self {
        let vacuum = robot.embodiment() == Embodiment::Vacuum;
        Hand {
            robot,
            subtask,
            vacuum,
        }
    }

    fn fail(&self, step: String, error: ApiError) -> ExpertError {
        ExpertError {
            subtask: self.subtask,
            step,
            error,
        }
    }

    fn bbox(&mut self, name: &str) -> Result<Bbox, ExpertError> {
        self.robot
            .get_obj_bbox(name)
            .map_err(|e| self.fail(format!("get_obj_bbox({name})"), e))
    }

    /// How far below the tool point a held object's bottom hangs: suction holds it by the
    /// top, the fingers by the middle (the pick depth is half its height).
    fn hang(&self, height: f64) -> f64 {
        if self.vacuum { height } else { height / 2.0 }
    }

    fn move_to_object(&mut self, name: &str, depth: f64) -> Result<(), ExpertError> {
        self.robot
            .move_gripper_to(name, Direction::Down, depth)
            .map_err(|e| self.fail(format!("move_gripper_to({name}, depth {depth:.3})"), e))
    }

    fn move_to(&mut self, pos: [f64; 3], clearance: f64) -> Result<(), ExpertError> {
        self.move_to_turned(pos, clearance, 0.0)
    }

    /// [`Hand::move_to`] with the wrist turned by `angle` (rad) about the vertical.
    fn move_to_turned(&mut self, pos: [f64; 3], clearance: f64, angle: f64) -> Result<(), ExpertError> {
        self.robot
            .move_to_position(pos, Direction::Down, clearance, angle)
            .map_err(|e| {
                self.fail(
                    format!("move_to_position(({:.3}, {:.3}, {:.3}))", pos[0], pos[1], pos[2]),
                    e,
                )
            })
    }

    fn slide(&mut self, dir: Direction, offset: f64) -> Result<(), ExpertError> {
        self.slide_pointing(dir, offset, Direction::Down)
    }

    /// [`Hand::slide`] with the tool pointing along `pointing`.
    fn slide_pointing(
        &mut self,
        dir: Direction,
        offset: f64,
        pointing: Direction,
    ) -> Result<(), ExpertError> {
        self.robot
            .move_parallel(dir, offset, pointing)
            .map_err(|e| self.fail(format!("move_parallel({}, {offset:.3})", dir.as_str()), e))
    }

    fn grasp(&mut self) -> Result<(), ExpertError> {
        let (name, result) = if self.vacuum {
            ("activate_vacuum", self.robot.activate_vacuum())
        } else {
            ("close_gripper", self.robot.close_gripper())
        };
        result.map_err(|e| self.fail(format!("{name}()"), e))
    }

    fn release(&mut self) -> Result<(), ExpertError> {
        let (name, result) = if self.vacuum {
            ("deactivate_vacuum", self.robot.deactivate_vacuum())
        } else {
            ("open_gripper", self.robot.open_gripper())
        };
        result.map_err(|e| self.fail(format!("{name}()"), e))
    }

    /// Moves to a handle from above and grasps it.
    fn grab_handle(&mut self, handle: &str) -> Result<(), ExpertError> {
        self.grab_handle_pointing(handle, Direction::Down)
    }

    /// Moves to a handle with the tool pointing along `pointing` and grasps it.
    fn grab_handle_pointing(&mut self, handle: &str, pointing: Direction) -> Result<(), ExpertError> {
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

    fn let_go_handle(&mut self) -> Result<(), ExpertError> {
        let (name, result) = if self.vacuum {
            ("detach_vacuum_handle", self.robot.detach_vacuum_handle())
        } else {
            ("release_handle", self.robot.release_handle())
        };
        result.map_err(|e| self.fail(format!("{name}()"), e))
    }

    /// Moves a grasped lid's handle through `arc` (degrees) about the hinge `axis` (x, z)
    /// at distance `reach`, one short move per waypoint.
    fn swing_lid(&mut self, axis: [f64; 2], y: f64, reach: f64, arc: &[f64]) -> Result<(), ExpertError> {
        for angle in arc.iter().map(|a| a.to_radians()) {
            // At the far offsets the hinge is 2 cm inside the workspace's +x edge (spec §1
            // FLOOR_AABB); the last waypoint then comes in along x, still past vertical.
            let x = (axis[0] + reach * angle.cos()).min(crate::sim::FLOOR_AABB.max[0] - 0.005);
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
    fn pick(&mut self, name: &str) -> Result<f64, ExpertError> {
        let mut h = 0.0;
        self.grasp_retrying(name, |expert| {
            h = size(&expert.bbox(name)?)[2];
            expert.move_to_object(name, h / 2.0)
        })?;
        Ok(h)
    }

    /// Runs `approach` and closes the tool on `name`; when the grasp did not take, lets go
    /// and tries again, up to [`PICK_ATTEMPTS`] approaches in all.
    fn grasp_retrying(
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
    /// clear or both are blocked, else the wrist turned by 90°. Returns the height.
    fn pick_round(&mut self, name: &str) -> Result<f64, ExpertError> {
        if self.vacuum {
            return self.pick(name);
        }
        let me = self.bbox(name)?;
        let c = centre(&me);
        let mut others = Vec::new();
        for other in self.robot.get_obj_names() {
            if other != name && !is_fixture(&other) {
                others.push(self.bbox(&other)?);
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
        if usual <= 0.0 || intrusion(&footprint(true)) >= usual {
            return self.pick(name);
        }
        let h = size(&me)[2];
        self.grasp_retrying(name, |expert| {
            let b = expert.bbox(name)?;
            let c = centre(&b);
            expert.move_to_turned(
                [c[0], c[1], b[1][2] - h / 2.0],
                crate::api::DEFAULT_LIFT_CLEARANCE,
                std::f64::consts::FRAC_PI_2,
            )
        })?;
        Ok(h)
    }

    /// Puts the held object (of height `h`) down with its bottom `lift` above `floor_z` at
    /// `(x, y)`, and lets go.
    fn put(&mut self, x: f64, y: f64, floor_z: f64, h: f64, lift: f64) -> Result<(), ExpertError> {
        self.move_to(
            [x, y, floor_z + self.hang(h) + lift],
            crate::api::DEFAULT_LIFT_CLEARANCE,
        )?;
        self.release()
    }

    /// Moves an object to a free table spot: `get_empty_floor_xy`'s, unless that is close to
    /// the robot's base, where a top-down reach runs joint 4 into its limit and the planner's
    /// joint-space fallback swings the arm through the scene; then the free spot of
    /// [`Hand::free_spot`].
    fn move_aside(&mut self, name: &str) -> Result<(), ExpertError> {
        let h = self.pick(name)?;
        let [x, y] = self
            .robot
            .get_empty_floor_xy(name)
            .map_err(|e| self.fail(format!("get_empty_floor_xy({name})"), e))?;
        let [x, y] = if x >= COMFORTABLE_MIN_X {
            [x, y]
        } else {
            self.free_spot(name)?.unwrap_or([x, y])
        };
        self.put(x, y, TABLE, h, DROP_CLEARANCE)
    }

    /// A table spot at x ≥ [`COMFORTABLE_MIN_X`] in the middle strip of the table whose
    /// footprint for `name` keeps 2 cm from every other object (seen via `get_obj_names` and
    /// `get_obj_bbox`), nearest the strip's centre; `None` if there is none.
    fn free_spot(&mut self, name: &str) -> Result<Option<[f64; 2]>, ExpertError> {
        let own = size(&self.bbox(name)?);
        let half = [own[0].max(own[1]) / 2.0 + 0.02; 2];
        let mut others = Vec::new();
        for other in self.robot.get_obj_names() {
            if other == name || other == "floor" || other.contains("gripper") {
                continue;
            }
            others.push(self.bbox(&other)?);
        }
        let mut best: Option<([f64; 2], f64)> = None;
        for i in 0..=10 {
            for j in 0..=15 {
                let spot = [COMFORTABLE_MIN_X + 0.02 * i as f64, -0.15 + 0.02 * j as f64];
                let footprint: Bbox = [
                    [spot[0] - half[0], spot[1] - half[1], TABLE],
                    [spot[0] + half[0], spot[1] + half[1], TABLE + 0.3],
                ];
                if others.iter().any(|b| overlaps_xy(b, &footprint, 0.0)) {
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

/// Why an expert episode could not be run at all.
#[derive(Debug, thiserror::Error)]
pub enum EpisodeError {
    /// The scene does not build.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The goals cannot be checked.
    #[error(transparent)]
    Goal(#[from] GoalError),
}

/// One expert run on a scene, judged by the goal checks.
#[derive(Debug)]
pub struct ExpertEpisode {
    /// The goal checks' verdict after the post-run settle.
    pub outcome: EpisodeOutcome,
    /// Why the expert stopped early, if it did.
    pub error: Option<ExpertError>,
    /// Robot API action calls made.
    pub actions: usize,
    /// Simulated time at the end of the episode (s).
    pub sim_time: f64,
}

impl ExpertEpisode {
    /// The expert finished and every subtask is `full_success`.
    pub fn full_success(&self) -> bool {
        self.error.is_none() && self.outcome.full_success()
    }

    /// Why the episode is not a full success (`None` when it is).
    pub fn failure(&self) -> Option<String> {
        match &self.error {
            Some(e) => Some(format!("{e} ({})", self.outcome.summary())),
            None if !self.outcome.full_success() => Some(format!(
                "{}; achieved {:?}",
                self.outcome.summary(),
                self.outcome.achieved_sequence
            )),
            None => None,
        }
    }
}

/// Builds the scene, runs the experts of all its goals with goal checks attached, and
/// finishes the episode (spec §7's settle and final call).
pub fn run_scene(scene: &SceneSpec) -> Result<ExpertEpisode, EpisodeError> {
    let mut sim = Sim::new(scene)?;
    let monitor = GoalMonitor::attach(&mut sim)?;
    let error = run(&mut sim, &scene.goals).err();
    let outcome = monitor.finish(&mut sim);
    Ok(ExpertEpisode {
        outcome,
        error,
        actions: sim.actions_used(),
        sim_time: sim.time(),
    })
}

/// Runs the expert of every goal of the scene, in order.
pub fn run<R: RobotApi + ?Sized>(robot: &mut R, goals: &[SubtaskGoal]) -> Result<(), ExpertError> {
    for goal in goals {
        run_subtask(robot, goal)?;
    }
    Ok(())
}

/// Runs the expert of one subtask.
pub fn run_subtask<R: RobotApi + ?Sized>(robot: &mut R, goal: &SubtaskGoal) -> Result<(), ExpertError> {
    let mut hand = Hand::new(robot, goal.kind());
    match goal {
        SubtaskGoal::PickPlace { objects, container } => pick_place(&mut hand, objects, container),
        SubtaskGoal::Sweep { placements } => {
            let pairs: Vec<(&str, &str)> = placements
                .iter()
                .map(|p| (p.object.as_str(), p.container.as_str()))
                .collect();
            sweep(&mut hand, &pairs)
        }
        SubtaskGoal::PutInHinge {
            objects,
            container,
            lid,
        } => put_in_hinge(&mut hand, objects, container, lid),
        SubtaskGoal::PutInPrismatic { objects, drawer } => put_in_prismatic(&mut hand, objects, drawer),
    }
}

/// Cubes into the box in label order; whatever rests on a cube is moved to the table first,
/// top down.
fn pick_place<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    cubes: &[String],
    container: &str,
) -> Result<(), ExpertError> {
    for (k, cube) in cubes.iter().enumerate() {
        loop {
            let me = hand.bbox(cube)?;
            let mut above = Vec::new();
            for other in cubes.iter().filter(|c| *c != cube) {
                let b = hand.bbox(other)?;
                if overlaps_xy(&b, &me, 0.005) && b[0][2] >= me[1][2] - 0.004 {
                    above.push((b[0][2], other.clone()));
                }
            }
            // The highest one first.
            let Some((_, top)) = above.into_iter().max_by(|a, b| a.0.total_cmp(&b.0)) else {
                break;
            };
            hand.move_aside(&top)?;
        }
        let h = hand.pick(cube)?;
        let b = hand.bbox(container)?;
        let c = centre(&b);
        let cell = TOY_BOX_CELLS[k % TOY_BOX_CELLS.len()];
        hand.put(c[0] + cell[0], c[1] + cell[1], b[1][2], h, DROP_CLEARANCE)?;
    }
    Ok(())
}

/// Pieces pushed (finger) or carried (suction) across into their boxes; a piece found in a
/// box is first lifted back onto the board at its x.
fn sweep<R: RobotApi + ?Sized>(hand: &mut Hand<'_, R>, pieces: &[(&str, &str)]) -> Result<(), ExpertError> {
    let board = hand.bbox("board")?;
    let board_y = centre(&board)[1];
    for &(piece, home) in pieces {
        let b = hand.bbox(piece)?;
        // By the piece's centre: a box's floor lies only 3 mm below the board's top, and a
        // piece in a box whose bounding box grazed the board's edge passed for one on the
        // board; pushed from the box, it caught the step and toppled.
        let c = centre(&b);
        let on_board =
            b[0][2] >= board[1][2] - 0.005 && (0..2).all(|i| (board[0][i]..=board[1][i]).contains(&c[i]));
        if !on_board {
            let h = hand.pick(piece)?;
            let x = centre(&b)[0];
            hand.put(x, board_y, board[1][2], h, DROP_CLEARANCE)?;
        }
        let h = size(&hand.bbox(piece)?)[2];
        hand.move_to_object(piece, h / 1.3)?;
        if hand.vacuum {
            hand.grasp()?;
        }
        let py = centre(&hand.bbox(piece)?)[1];
        let by = centre(&hand.bbox(home)?)[1];
        let dir = if py > by {
            Direction::Left
        } else {
            Direction::Right
        };
        hand.slide(dir, (py - by).abs() + 0.02)?;
        if hand.vacuum {
            hand.release()?;
        }
    }
    Ok(())
}

/// Fruits into the hinge box: a fruit on the lid is moved to the table, a closed lid is
/// opened by its handle, the fruits are dropped in along the box, the lid is closed.
fn put_in_hinge<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    fruits: &[String],
    body: &str,
    lid: &str,
) -> Result<(), ExpertError> {
    let lid_box = hand.bbox(lid)?;
    for fruit in fruits {
        let b = hand.bbox(fruit)?;
        if overlaps_xy(&b, &lid_box, 0.0) && (b[0][2] - lid_box[1][2]).abs() < 0.01 {
            hand.move_aside(fruit)?;
        }
    }
    // The hinge runs along y at the body's +x top edge (the box is never turned).
    let b = hand.bbox(body)?;
    let axis = [b[1][0], b[1][2]];
    let y = centre(&lid_box)[1];
    let reach = size(&lid_box)[0].max(size(&lid_box)[2]);
    // A closed lid lies flat (1 cm thick); an open one stands up.
    if size(&lid_box)[2] < 0.05 {
        swing_until(hand, lid, axis, y, reach, &LID_OPENING_ARC, true)?;
    }
    for (k, fruit) in fruits.iter().enumerate() {
        let h = hand.pick_round(fruit)?;
        let b = hand.bbox(body)?;
        let c = centre(&b);
        hand.put(c[0], c[1] + HINGE_SPOTS[k % HINGE_SPOTS.len()], b[1][2], h, 0.03)?;
    }
    swing_until(hand, lid, axis, y, reach, &LID_CLOSING_ARC, false)
}

/// Swings the lid through `arc` by its handle until it is open (`open`) or closed, up to
/// [`SWING_ATTEMPTS`] times. A waypoint the arm cannot reach along a straight line falls back
/// to joint interpolation, on which the tool strays from the arc and the grasped lid follows
/// it back (a closing swing at the +y far slot left the lid at q = 0.29); the next swing
/// starts from another arm pose and lid angle.
fn swing_until<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    lid: &str,
    axis: [f64; 2],
    y: f64,
    reach: f64,
    arc: &[f64],
    open: bool,
) -> Result<(), ExpertError> {
    for _ in 0..SWING_ATTEMPTS {
        hand.grab_handle("hinge_handle")?;
        hand.swing_lid(axis, y, reach, arc)?;
        hand.let_go_handle()?;
        // The closed lid lies flat (1 cm); the open one stands about 11 cm tall (10 cm
        // is q ≈ 0.32, the observer's Open).
        let height = size(&hand.bbox(lid)?)[2];
        if (open && height > 0.1) || (!open && height < 0.03) {
            break;
        }
    }
    Ok(())
}

/// Whether `name` is one of the benchmark's fixed assets (or their parts), which the
/// experts never move aside.
fn is_fixture(name: &str) -> bool {
    name == "floor"
        || name == "board"
        || name.contains("gripper")
        || name.contains("drawer")
        || name.starts_with("hinge_")
        || name.ends_with("_box")
        || name.ends_with("_handle")
}

/// Moves to the table the loose objects the arm would knock on its way to grasp `handle`
/// pointing along `pointing`. From above, the wrist passes within [`WRIST_CLEARANCE`] of the
/// handle in x and y (over the cabinet's front edge, where a cylinder may stand); pointing
/// sideways, the wrist and forearm trail up to [`FOREARM_REACH`] behind the handle (over the
/// hinge box's lid, where a fruit may lie).
fn clear_handle_approach<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    handle: &str,
    pointing: Direction,
) -> Result<(), ExpertError> {
    let h = hand.bbox(handle)?;
    let c = centre(&h);
    let corridor: Bbox = match pointing {
        Direction::Down => [
            [c[0] - WRIST_CLEARANCE, c[1] - WRIST_CLEARANCE, h[1][2] + 0.02],
            [c[0] + WRIST_CLEARANCE, c[1] + WRIST_CLEARANCE, h[1][2] + 0.4],
        ],
        _ => {
            let back = -pointing.unit()[1] * FOREARM_REACH;
            [
                [c[0] - WRIST_CLEARANCE, c[1].min(c[1] + back), c[2] - 0.03],
                [c[0] + WRIST_CLEARANCE, c[1].max(c[1] + back), c[2] + 0.3],
            ]
        }
    };
    for name in hand.robot.get_obj_names() {
        if is_fixture(&name) {
            continue;
        }
        let b = hand.bbox(&name)?;
        let inside = (0..3).all(|i| b[0][i] < corridor[1][i] && corridor[0][i] < b[1][i]);
        if inside {
            hand.move_aside(&name)?;
        }
    }
    Ok(())
}

/// Cylinders into the bottom drawer: an open top drawer (which covers the bottom handle) is
/// closed, a closed bottom drawer opened, the cylinders dropped in, the drawer closed.
fn put_in_prismatic<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    cylinders: &[String],
    drawer: &str,
) -> Result<(), ExpertError> {
    let body = hand.bbox("drawer_body")?;
    let body_y = centre(&body)[1];
    let handle_y = centre(&hand.bbox("bottom_drawer_handle")?)[1];
    // Drawers open toward the side their handles are on.
    let (open_dir, close_dir, outward) = if handle_y < body_y {
        (Direction::Left, Direction::Right, -1.0)
    } else {
        (Direction::Right, Direction::Left, 1.0)
    };
    let is_open = |b: &Bbox| {
        if outward < 0.0 {
            b[0][1] < body[0][1] - 0.03
        } else {
            b[1][1] > body[1][1] + 0.03
        }
    };
    let travel = size(&hand.bbox(drawer)?)[1] * 0.85;
    // Toward the cabinet: the pointing that keeps the hand in front of the handle.
    let sideways = if outward < 0.0 {
        Direction::Right
    } else {
        Direction::Left
    };
    // The open top drawer is closed with the tool pointing at the cabinet: from above, the
    // finger hand, wide along the bar, swept cylinders off the cabinet top on the way in.
    if is_open(&hand.bbox("top_drawer")?) {
        clear_handle_approach(hand, "top_drawer_handle", sideways)?;
        hand.grab_handle_pointing("top_drawer_handle", sideways)?;
        hand.slide_pointing(close_dir, travel, sideways)?;
        hand.let_go_handle()?;
    }
    // The bottom handle: the fingers from above, as in the authors' demo; the suction tool
    // pointing at the cabinet, because from above its wrist (6 cm above the tip and wider
    // than the 2.5 cm between the handle and the cabinet face) pushed cylinders standing at
    // the cabinet's front edge down through its top.
    let pointing = if hand.vacuum { sideways } else { Direction::Down };
    if !is_open(&hand.bbox(drawer)?) {
        clear_handle_approach(hand, "bottom_drawer_handle", pointing)?;
        hand.grab_handle_pointing("bottom_drawer_handle", pointing)?;
        hand.slide_pointing(open_dir, travel, pointing)?;
        hand.let_go_handle()?;
        hand.slide_pointing(Direction::Up, 0.05, pointing)?;
    }
    for (k, cylinder) in cylinders.iter().enumerate() {
        let h = hand.pick(cylinder)?;
        let b = hand.bbox(drawer)?;
        let (c, s) = (centre(&b), size(&b));
        // Released high enough that the hand clears the cylinders still on the cabinet.
        let [dx, dy] = DRAWER_SPOTS[k % DRAWER_SPOTS.len()];
        let x = c[0] + dx;
        let y = c[1] + dy * outward;
        hand.move_to([x, y, c[2] + s[2] + h + 0.05], crate::api::DEFAULT_LIFT_CLEARANCE)?;
        hand.release()?;
    }
    clear_handle_approach(hand, "bottom_drawer_handle", pointing)?;
    hand.grab_handle_pointing("bottom_drawer_handle", pointing)?;
    hand.slide_pointing(close_dir, travel, pointing)?;
    hand.let_go_handle()
}
