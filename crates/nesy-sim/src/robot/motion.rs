//! Motion generation: tool-space straight segments sampled into joint paths by IK, timed
//! with the authors' quadratic ease-in/out, and played back one control step at a time.

use nalgebra::{UnitQuaternion, Vector3};

use rapier3d::prelude::{ColliderHandle, Pose};

use crate::api::{ApiError, Direction, Embodiment};
use crate::robot::kinematics::{IkOptions, Iso, OrientationGoal, pointing_rotation};
use crate::robot::planner::{self, PlannerOptions};
use crate::scene::TABLE_TOP;
use crate::world::contact::ContactStop;
use crate::world::geometry::{array_to_na, iso_to_pose};
use crate::world::objects::PartRole;
use crate::world::rng::Stream;
use crate::world::{CONTROL_DT, Sim};

/// The quadratic ease-in/out profile of `docs/benchmark.md` §4: `2t²` below ½, `1 − 2(1 − t)²` above.
pub(crate) fn ease(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    if t < 0.5 {
        2.0 * t * t
    } else {
        1.0 - 2.0 * (1.0 - t) * (1.0 - t)
    }
}

/// Average tool speed of a straight segment (m/s); the eased peak is twice this.
const TOOL_SPEED: f64 = 0.2;
/// Average joint speed (rad/s) bound of a segment.
const JOINT_SPEED: f64 = 0.8;
/// Shortest segment duration (s).
const MIN_SEGMENT: f64 = 0.25;
/// Shortest duration of a `move_parallel` (s): the authors' 80 interpolation steps. Pushes
/// (sweeping) then accelerate gently enough that tall pieces slide instead of tipping.
pub(crate) const PARALLEL_MIN_DURATION: f64 = 0.8;
/// Spacing of IK samples along a straight segment (m).
const SAMPLE_SPACING: f64 = 0.015;
/// Largest joint change (rad) between consecutive samples of a followed line.
const MAX_SAMPLE_JUMP: f64 = 0.3;
/// How many times finer a jumping sample step is tried before the line is given up.
const MAX_SUBDIVISION: usize = 8;
/// Control steps the world runs after a motion so objects come to rest.
pub(crate) const MOTION_SETTLE_STEPS: u32 = 20;
/// Gap (m) a transit keeps between the arm (and what it carries) and every loose object.
const TRANSIT_GAP: f32 = 0.01;
/// Largest joint step (rad) between two configurations checked along a transit.
const CHECK_SPACING: f64 = 0.03;
/// Heights (m) above the tallest loose object at which a detour transit crosses the table.
const DETOUR_HEIGHTS: [f64; 3] = [0.06, 0.12, 0.2];
/// Highest tool position (m above the table) a detour uses; above it the arm runs out of reach.
const DETOUR_CEILING: f64 = 0.55;
/// Distance (rad) the joint-space planner keeps from every joint limit.
const LIMIT_MARGIN: f64 = 0.05;

/// Fractions of the lift clearance tried, longest first, for an approach point next to an
/// object.
const APPROACH_FRACTIONS: [f64; 4] = [1.0, 0.7, 0.45, 0.25];

/// A loose object the arm must not touch on a transit: its colliders' shapes and world poses.
struct Obstacle<'a> {
    part: usize,
    shapes: Vec<(&'a dyn rapier3d::prelude::Shape, Pose)>,
    min: [f32; 3],
    max: [f32; 3],
}

/// A tool pose to reach: position and orientation goal.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ToolGoal {
    /// Tool point position (world).
    pub position: Vector3<f64>,
    /// Tool orientation (world); for the vacuum only its z axis is enforced.
    pub rotation: UnitQuaternion<f64>,
}

impl Sim {
    fn orientation_goal(&self, rotation: UnitQuaternion<f64>) -> OrientationGoal {
        let base_inv = self.base.rotation.inverse();
        match self.scene.embodiment {
            Embodiment::Finger => OrientationGoal::Full(base_inv * rotation),
            Embodiment::Vacuum => OrientationGoal::Axis(base_inv * (rotation * Vector3::z())),
        }
    }

    /// IK for a world tool goal, seeded from `seed`.
    pub(crate) fn ik(&self, goal: &ToolGoal, seed: &[f64], opts: &IkOptions) -> Option<Vec<f64>> {
        let local = self.base.inverse() * nalgebra::Point3::from(goal.position);
        self.robot
            .model
            .solve_ik(local.coords, self.orientation_goal(goal.rotation), seed, opts)
    }

    /// The tool rotation for pointing `dir` with spin `angle`.
    pub(crate) fn pointing(dir: Direction, angle: f64) -> UnitQuaternion<f64> {
        pointing_rotation(array_to_na(dir.unit()), angle)
    }

    /// Of the spins `angle + k·step`, the one whose rotation is closest to the current tool.
    pub(crate) fn nearest_spin(&self, dir: Direction, angle: f64, step: f64) -> f64 {
        self.spins_by_nearness(dir, angle, step)
            .first()
            .copied()
            .unwrap_or(angle)
    }

    /// The spins `angle + k·step` (one full turn), closest to the current tool rotation first.
    pub(crate) fn spins_by_nearness(&self, dir: Direction, angle: f64, step: f64) -> Vec<f64> {
        let current = self.tool_pose().rotation;
        let n = (std::f64::consts::TAU / step).round().max(1.0) as usize;
        let mut spins: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                let spin = crate::world::geometry::wrap_angle(angle + k as f64 * step);
                (spin, Sim::pointing(dir, spin).angle_to(&current))
            })
            .collect();
        // Stable: equally near spins keep their k order.
        spins.sort_by(|a, b| a.1.total_cmp(&b.1));
        spins.into_iter().map(|(spin, _)| spin).collect()
    }

    /// Plans joint paths through the tool waypoints (each reached by IK, nothing moved).
    /// Each segment is a straight tool-space line sampled every 1.5 cm and solved by IK
    /// warm-started along the line; where that fails, the followed part of the line is kept
    /// and the rest is a straight joint interpolation to an IK solution of the waypoint.
    ///
    /// The segment ending at waypoint `transit` (if any) is a free move between two
    /// clearance points. Its swept arm, fingers and carried object are checked against every
    /// loose object; when they would touch one, the transit becomes a detour: straight up to
    /// a height above the tallest loose object, across, and down to the waypoint (the lowest
    /// of [`DETOUR_HEIGHTS`] that is clear). If no detour is clear either, the direct
    /// segment is kept.
    pub(crate) fn plan(
        &self,
        waypoints: &[ToolGoal],
        pointing: Direction,
        transit: Option<usize>,
    ) -> Result<Vec<Vec<Vec<f64>>>, ApiError> {
        // The final goal first, so an unreachable target is reported as such rather than
        // as one of the clearance waypoints in front of it.
        if let Some(last) = waypoints.last()
            && self.ik(last, &self.q, &IkOptions::default()).is_none()
        {
            return Err(ApiError::IkFailed {
                target: [last.position.x, last.position.y, last.position.z],
                pointing_to: pointing,
            });
        }
        let mut segments = Vec::new();
        let mut q_from = self.q.clone();
        let mut pose_from: Iso = self.tool_pose();
        for (i, wp) in waypoints.iter().enumerate() {
            let direct = self.segment(&q_from, &pose_from, wp, pointing)?;
            let route = if transit == Some(i) {
                self.clear_transit(direct, &q_from, &pose_from, wp, pointing)
            } else {
                vec![direct]
            };
            q_from = route
                .last()
                .and_then(|p| p.last())
                .cloned()
                .unwrap_or_else(|| q_from.clone());
            segments.extend(route);
            pose_from = Iso::from_parts(nalgebra::Translation3::from(wp.position), wp.rotation);
        }
        Ok(segments)
    }

    /// One straight tool segment from `(q_from, pose_from)` to `wp`; where the line cannot be
    /// followed to the end, its followed prefix then joint interpolation to an IK solution
    /// of `wp`.
    fn segment(
        &self,
        q_from: &[f64],
        pose_from: &Iso,
        wp: &ToolGoal,
        pointing: Direction,
    ) -> Result<Vec<Vec<f64>>, ApiError> {
        let full = IkOptions::default();
        let quick = IkOptions {
            restarts: 1,
            iterations: 60,
            pos_tol: 5e-4,
            rot_tol: 5e-3,
            ..IkOptions::default()
        };
        let start = pose_from.translation.vector;
        let length = (wp.position - start).norm();
        let n = (length / SAMPLE_SPACING).ceil() as usize;
        let at = |s: f64| ToolGoal {
            position: start + (wp.position - start) * s,
            rotation: pose_from.rotation.slerp(&wp.rotation, s),
        };
        let mut path = vec![q_from.to_vec()];
        let mut seed = q_from.to_vec();
        'line: for i in 1..n {
            // A sample whose joints jump (near a wrist singularity the joints move fast for a
            // short stretch of the line) is approached in finer steps before the line is
            // given up.
            let (s0, s1) = ((i - 1) as f64 / n as f64, i as f64 / n as f64);
            let mut steps = 1;
            loop {
                let mut trial = seed.clone();
                let mut samples = Vec::with_capacity(steps);
                let mut jumped = false;
                for k in 1..=steps {
                    let s = s0 + (s1 - s0) * k as f64 / steps as f64;
                    match self.ik(&at(s), &trial, &quick) {
                        Some(q) if max_delta(&q, &trial) < MAX_SAMPLE_JUMP => {
                            trial = q.clone();
                            samples.push(q);
                        }
                        _ => {
                            jumped = true;
                            break;
                        }
                    }
                }
                if !jumped {
                    seed = trial;
                    path.extend(samples);
                    break;
                }
                if steps >= MAX_SUBDIVISION {
                    break 'line;
                }
                steps *= 2;
            }
        }
        // The waypoint itself, seeded from the end of the line so the branch carries on.
        let q_to = self
            .ik(wp, &seed, &full)
            .or_else(|| self.ik(wp, q_from, &full))
            .ok_or(ApiError::IkFailed {
                target: [wp.position.x, wp.position.y, wp.position.z],
                pointing_to: pointing,
            })?;
        // Where the line cannot be followed to the end, the part that could be followed is
        // kept and only the rest is joint interpolation (the last step of the path): starting
        // the interpolation at the segment's start swung the hand through what it had just
        // let go of (a pushed chess piece, dragged back out of its box by the dipping
        // fingers).
        path.push(q_to);
        Ok(path)
    }

    /// The direct transit if it is clear of loose objects, else the lowest clear detour over
    /// them, else the direct one.
    fn clear_transit(
        &self,
        direct: Vec<Vec<f64>>,
        q_from: &[f64],
        pose_from: &Iso,
        wp: &ToolGoal,
        pointing: Direction,
    ) -> Vec<Vec<Vec<f64>>> {
        // An object already touching the arm where the transit starts (a piece just pushed,
        // say) cannot be avoided by the transit; the others can. Furniture the arm touches at
        // the transit's end (the cabinet whose handle it goes to) cannot be kept clear either.
        let goal_q = direct.last();
        let obstacles: Vec<Obstacle<'_>> = self
            .transit_obstacles()
            .into_iter()
            .filter(|o| self.configuration_is_clear(q_from, std::slice::from_ref(o)))
            .filter(|o| {
                self.parts[o.part].role == PartRole::Loose
                    || goal_q.is_none_or(|q| self.configuration_is_clear(q, std::slice::from_ref(o)))
            })
            .collect();
        if obstacles.is_empty() || self.path_is_clear(&direct, &obstacles) {
            return vec![direct];
        }
        if std::env::var_os("NESY_DEBUG_TRANSIT").is_some() {
            eprintln!("transit to {:?} not clear; detouring", wp.position);
        }
        let tallest = obstacles
            .iter()
            .map(|o| o.max[2] as f64)
            .fold(TABLE_TOP, f64::max);
        // How far the carried object (or the fingertips) reach below the tool point.
        let tool_z = pose_from.translation.vector.z;
        let below = self
            .held
            .map(|h| tool_z - self.part_aabb(h.part).min[2])
            .unwrap_or(0.0)
            .max(0.03);
        let start = pose_from.translation.vector;
        for height in DETOUR_HEIGHTS {
            let z = (tallest + height + below)
                .max(start.z)
                .max(wp.position.z)
                .min(TABLE_TOP + DETOUR_CEILING);
            let up = ToolGoal {
                position: nalgebra::Vector3::new(start.x, start.y, z),
                rotation: pose_from.rotation,
            };
            let across = ToolGoal {
                position: nalgebra::Vector3::new(wp.position.x, wp.position.y, z),
                rotation: wp.rotation,
            };
            let mut route = Vec::new();
            let mut q = q_from.to_vec();
            let mut pose = *pose_from;
            let mut clear = true;
            for goal in [up, across, *wp] {
                let Ok(path) = self.segment(&q, &pose, &goal, pointing) else {
                    if std::env::var_os("NESY_DEBUG_TRANSIT").is_some() {
                        eprintln!("  height {height}: no IK for {:?}", goal.position);
                    }
                    clear = false;
                    break;
                };
                if !self.path_is_clear(&path, &obstacles) {
                    if std::env::var_os("NESY_DEBUG_TRANSIT").is_some() {
                        eprintln!(
                            "  height {height}: {:?} not clear ({} samples)",
                            goal.position,
                            path.len()
                        );
                    }
                    clear = false;
                    break;
                }
                q = path.last().cloned().unwrap_or(q);
                pose = Iso::from_parts(nalgebra::Translation3::from(goal.position), goal.rotation);
                route.push(path);
            }
            if clear {
                return route;
            }
        }
        // No tool-space route is clear (typically the arm is on a branch from which straight
        // lines run joints into their limits, so the segments fell back to joint interpolation
        // through the objects): search joint space for a collision-free path instead.
        if let Some(route) = self.joint_space_transit(&direct, q_from, wp) {
            return vec![route];
        }
        if std::env::var_os("NESY_DEBUG_TRANSIT").is_some() {
            eprintln!("  no clear detour and no joint-space path");
        }
        vec![direct]
    }

    /// A collision-free joint path from `q_from` to an IK solution of `wp` (the direct
    /// transit's own, or one on the home branch), found by [`planner::plan`]. It avoids every
    /// object that is not held, fixed ones included (the search may swing the arm anywhere),
    /// except those already within reach of the arm at either end, and keeps every moving
    /// collider that starts above the table top above it.
    fn joint_space_transit(
        &self,
        direct: &[Vec<f64>],
        q_from: &[f64],
        wp: &ToolGoal,
    ) -> Option<Vec<Vec<f64>>> {
        let mut goals: Vec<Vec<f64>> = direct.last().cloned().into_iter().collect();
        if let Some(q) = self.ik(wp, &crate::robot::model::HOME_ARM, &IkOptions::default())
            && goals.iter().all(|g| max_delta(g, &q) > 1e-3)
        {
            goals.push(q);
        }
        let obstacles: Vec<Obstacle<'_>> = self
            .unheld_obstacles(|_| true)
            .into_iter()
            .filter(|o| {
                let one = std::slice::from_ref(o);
                self.configuration_is_clear(q_from, one)
                    && goals.iter().any(|g| self.configuration_is_clear(g, one))
            })
            .collect();
        // Colliders (in `moving_shapes` order) that start clear of the table and must stay so.
        let above_table: Vec<bool> = self
            .moving_shapes(q_from)
            .iter()
            .map(|(shape, pose)| {
                f64::from(shape.compute_aabb(pose).mins.z) > TABLE_TOP + f64::from(TRANSIT_GAP)
            })
            .collect();
        let is_valid = |q: &[f64]| {
            let moving = self.moving_shapes(q);
            let table_clear = moving.iter().zip(&above_table).all(|((shape, pose), &check)| {
                !check || f64::from(shape.compute_aabb(pose).mins.z) > TABLE_TOP + f64::from(TRANSIT_GAP)
            });
            table_clear && shapes_are_clear(&moving, &obstacles)
        };
        let limits: Vec<(f64, f64)> = self
            .robot
            .model
            .arm_limits
            .iter()
            .map(|&(lo, hi)| (lo + LIMIT_MARGIN, hi - LIMIT_MARGIN))
            .collect();
        // Seeded by the problem itself, so a replayed run plans the same path.
        let seed = q_from
            .iter()
            .chain(wp.position.iter())
            .fold(0u64, |h, v| h.rotate_left(7) ^ v.to_bits());
        let mut rng = Stream::new("motion/joint-space-transit", seed);
        let options = PlannerOptions {
            check_spacing: CHECK_SPACING,
            ..PlannerOptions::default()
        };
        let path = planner::plan(q_from, &goals, &limits, is_valid, &mut rng, &options);
        if std::env::var_os("NESY_DEBUG_TRANSIT").is_some() {
            eprintln!(
                "  joint-space transit ({} goals, {} obstacles): {}",
                goals.len(),
                obstacles.len(),
                path.as_ref()
                    .map_or("none".to_string(), |p| format!("{} configurations", p.len()))
            );
        }
        path
    }

    /// The approach distance for a move to `goal` along `dir` (unit, the pointing): the
    /// longest of `clearance` and its fractions in [`APPROACH_FRACTIONS`] at which the arm
    /// reaches the approach point `goal − dir·c`, and moves straight from it to the goal,
    /// without touching an object or a piece of furniture (those touching the arm now or at
    /// the goal are not counted). An object next to the target (a fruit on a lid beside a
    /// drawer handle, the hinge box beside the cabinet) can leave no room for the full
    /// distance. `clearance` when none is clear.
    pub(crate) fn clear_approach(&self, goal: &ToolGoal, dir: nalgebra::Vector3<f64>, clearance: f64) -> f64 {
        let options = IkOptions::default();
        let goal_q = self.ik(goal, &self.q, &options);
        // Loose objects and furniture alike: the arm passes through fixed walls without
        // contact forces, and a handle approach started inside the hinge box beside the
        // cabinet swept the fruit in it out. What the arm touches now or at the goal (the
        // cabinet whose handle it takes, the board under a piece) cannot be kept clear.
        let obstacles: Vec<Obstacle<'_>> = self
            .unheld_obstacles(|_| true)
            .into_iter()
            .filter(|o| self.configuration_is_clear(&self.q, std::slice::from_ref(o)))
            .filter(|o| {
                goal_q
                    .as_ref()
                    .is_none_or(|q| self.configuration_is_clear(q, std::slice::from_ref(o)))
            })
            .collect();
        if obstacles.is_empty() {
            return clearance;
        }
        for fraction in APPROACH_FRACTIONS {
            let approach = ToolGoal {
                position: goal.position - dir * clearance * fraction,
                rotation: goal.rotation,
            };
            let q = self.ik(&approach, &self.q, &options);
            // The arm at the approach point and along the straight approach to the goal.
            let clear = q.as_ref().is_some_and(|q| {
                let from =
                    Iso::from_parts(nalgebra::Translation3::from(approach.position), approach.rotation);
                self.configuration_is_clear(q, &obstacles)
                    && self
                        .segment(q, &from, goal, Direction::Down)
                        .is_ok_and(|path| self.path_is_clear(&path, &obstacles))
            });
            if std::env::var_os("NESY_DEBUG_TRANSIT").is_some() {
                let hits: Vec<&str> = obstacles
                    .iter()
                    .filter(|o| {
                        q.as_ref()
                            .is_some_and(|q| !self.configuration_is_clear(q, std::slice::from_ref(o)))
                    })
                    .map(|o| self.parts[o.part].name.as_str())
                    .collect();
                eprintln!(
                    "approach {fraction}: ik {} clear {clear} hits at the approach point {hits:?}",
                    q.is_some()
                );
            }
            if clear {
                return clearance * fraction;
            }
        }
        clearance
    }

    /// The objects that are not held and whose role `keep` accepts, with their current shapes
    /// and boxes.
    fn unheld_obstacles(&self, keep: impl Fn(PartRole) -> bool) -> Vec<Obstacle<'_>> {
        let held = self.held.map(|h| h.part);
        self.parts
            .iter()
            .enumerate()
            .filter(|&(i, p)| keep(p.role) && Some(i) != held)
            .map(|(i, p)| {
                let aabb = self.part_aabb(i);
                Obstacle {
                    part: i,
                    shapes: self.collider_shapes(&p.colliders),
                    min: aabb.min.map(|v| v as f32),
                    max: aabb.max.map(|v| v as f32),
                }
            })
            .collect()
    }

    /// The loose objects that are not held and, with the protective stop on, the furniture
    /// (fixed parts, articulated bodies, lids and drawers, by their solid colliders): what a
    /// transit must not touch.
    fn transit_obstacles(&self) -> Vec<Obstacle<'_>> {
        let furniture = self.protective_stop;
        let mut obstacles =
            self.unheld_obstacles(|role| role == PartRole::Loose || (furniture && role.is_furniture()));
        // Furniture by its solid colliders only (a handle's sensor is not in the way).
        for o in &mut obstacles {
            if self.parts[o.part].role != PartRole::Loose {
                o.shapes.clear();
                for &c in &self.parts[o.part].colliders {
                    let collider = &self.world.colliders[c];
                    if !collider.is_sensor() {
                        o.shapes.push((collider.shape(), *collider.position()));
                    }
                }
            }
        }
        obstacles.retain(|o| !o.shapes.is_empty());
        obstacles
    }

    fn collider_shapes(&self, colliders: &[ColliderHandle]) -> Vec<(&dyn rapier3d::prelude::Shape, Pose)> {
        colliders
            .iter()
            .map(|&c| {
                let collider = &self.world.colliders[c];
                (collider.shape(), *collider.position())
            })
            .collect()
    }

    /// Whether the arm, fingers and carried object stay [`TRANSIT_GAP`] away from every
    /// obstacle along the joint path (checked every [`CHECK_SPACING`] rad).
    fn path_is_clear(&self, path: &[Vec<f64>], obstacles: &[Obstacle<'_>]) -> bool {
        let mut previous: Option<&Vec<f64>> = None;
        for q in path {
            let steps = previous.map_or(1, |p| (max_delta(p, q) / CHECK_SPACING).ceil().max(1.0) as usize);
            for k in 1..=steps {
                let t = k as f64 / steps as f64;
                let at: Vec<f64> = match previous {
                    Some(p) => p.iter().zip(q).map(|(a, b)| a + (b - a) * t).collect(),
                    None => q.clone(),
                };
                if !self.configuration_is_clear(&at, obstacles) {
                    return false;
                }
            }
            previous = Some(q);
        }
        true
    }

    fn configuration_is_clear(&self, q: &[f64], obstacles: &[Obstacle<'_>]) -> bool {
        shapes_are_clear(&self.moving_shapes(q), obstacles)
    }

    /// Calls `visit` with each robot collider, its shape and its world pose, the links posed
    /// at `poses` ([`crate::robot::kinematics::RobotModel::link_poses`]).
    pub(crate) fn visit_robot_shapes<'s>(
        &'s self,
        poses: &[Iso],
        mut visit: impl FnMut(ColliderHandle, &'s dyn rapier3d::prelude::Shape, Pose),
    ) {
        for &(li, body) in &self.robot.bodies {
            let link = iso_to_pose(&(self.base * poses[li]));
            for &c in self.world.bodies[body].colliders() {
                let collider = &self.world.colliders[c];
                let local = collider.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
                visit(c, collider.shape(), link * local);
            }
        }
    }

    /// The shapes and world poses of the arm, the gripper and the carried object at `q`.
    fn moving_shapes(&self, q: &[f64]) -> Vec<(&dyn rapier3d::prelude::Shape, Pose)> {
        let poses = self.robot.model.link_poses(q, self.gripper);
        let mut moving: Vec<(&dyn rapier3d::prelude::Shape, Pose)> = Vec::new();
        self.visit_robot_shapes(&poses, |_, shape, pose| moving.push((shape, pose)));
        if let Some(held) = self.held {
            let carrier = iso_to_pose(&(self.base * poses[self.robot.carrier_link]));
            let body = &self.world.bodies[self.parts[held.part].body];
            for &c in body.colliders() {
                let collider = &self.world.colliders[c];
                let local = collider.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
                moving.push((collider.shape(), carrier * held.relative * local));
            }
        }
        moving
    }

    /// Plays planned segments back with eased timing, then settles.
    pub(crate) fn execute(&mut self, segments: &[Vec<Vec<f64>>], settle: u32) -> Result<(), ContactStop> {
        self.execute_at_least(segments, settle, MIN_SEGMENT)
    }

    /// [`Sim::execute`] with a longer shortest segment duration (s).
    pub(crate) fn execute_at_least(
        &mut self,
        segments: &[Vec<Vec<f64>>],
        settle: u32,
        min_segment: f64,
    ) -> Result<(), ContactStop> {
        self.contact_stop = None;
        let at_start = if self.protective_stop {
            self.furniture_overlaps_at_start()
        } else {
            Vec::new()
        };
        for path in segments {
            let (cumulative, total) = path_lengths(path);
            let tool_len = {
                let a = self.robot.model.tool_pose(&path[0]).translation.vector;
                let b = self
                    .robot
                    .model
                    .tool_pose(&path[path.len() - 1])
                    .translation
                    .vector;
                (a - b).norm()
            };
            let joint_len = path.windows(2).map(|w| max_delta(&w[0], &w[1])).sum::<f64>();
            let duration = (tool_len / TOOL_SPEED)
                .max(joint_len / JOINT_SPEED)
                .max(min_segment);
            let steps = (duration / CONTROL_DT).ceil() as usize;
            for k in 1..=steps {
                let s = ease(k as f64 / steps as f64);
                let q = sample_path(path, &cumulative, total, s);
                self.control_step(&q);
                // A protective stop: the arm halts where a driven lid or drawer, a link of
                // the arm or the carried object met furniture.
                if self.protective_stop && self.contact_stop.is_none() {
                    self.contact_stop = self.protective_stop(&at_start);
                }
                if let Some(stop) = self.contact_stop.take() {
                    self.step_idle(settle);
                    self.note_left_asset();
                    return Err(stop);
                }
            }
        }
        self.step_idle(settle);
        self.note_left_asset();
        Ok(())
    }
}

/// Whether every moving shape stays [`TRANSIT_GAP`] away from every obstacle.
fn shapes_are_clear(moving: &[(&dyn rapier3d::prelude::Shape, Pose)], obstacles: &[Obstacle<'_>]) -> bool {
    for (shape, pose) in moving {
        let aabb = shape.compute_aabb(pose);
        for obstacle in obstacles {
            let apart = (0..3).any(|i| {
                aabb.mins[i] > obstacle.max[i] + TRANSIT_GAP || obstacle.min[i] > aabb.maxs[i] + TRANSIT_GAP
            });
            if apart {
                continue;
            }
            for (other, other_pose) in &obstacle.shapes {
                let near = rapier3d::parry::query::distance(pose, *shape, other_pose, *other)
                    .map_or(true, |d| d.distance < TRANSIT_GAP);
                if near {
                    return false;
                }
            }
        }
    }
    true
}

fn max_delta(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Cumulative joint-space arc length at each sample.
fn path_lengths(path: &[Vec<f64>]) -> (Vec<f64>, f64) {
    let mut acc = 0.0;
    let mut cumulative = vec![0.0];
    for w in path.windows(2) {
        acc += w[0]
            .iter()
            .zip(&w[1])
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        cumulative.push(acc);
    }
    (cumulative, acc)
}

/// The configuration at fraction `s` of the path's arc length.
fn sample_path(path: &[Vec<f64>], cumulative: &[f64], total: f64, s: f64) -> Vec<f64> {
    if total <= 0.0 {
        return path[path.len() - 1].clone();
    }
    let d = s * total;
    let i = cumulative.partition_point(|&c| c < d).clamp(1, path.len() - 1);
    let span = cumulative[i] - cumulative[i - 1];
    let t = if span > 0.0 {
        (d - cumulative[i - 1]) / span
    } else {
        1.0
    };
    path[i - 1]
        .iter()
        .zip(&path[i])
        .map(|(a, b)| a + (b - a) * t)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ease_profile() {
        assert_eq!(ease(0.0), 0.0);
        assert_eq!(ease(0.25), 0.125);
        assert_eq!(ease(0.5), 0.5);
        assert_eq!(ease(0.75), 0.875);
        assert_eq!(ease(1.0), 1.0);
    }

    #[test]
    fn path_sampling_is_piecewise_linear() {
        let path = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]];
        let (c, t) = path_lengths(&path);
        assert_eq!(t, 2.0);
        assert_eq!(sample_path(&path, &c, t, 0.25), vec![0.5, 0.0]);
        assert_eq!(sample_path(&path, &c, t, 0.75), vec![1.0, 0.5]);
        assert_eq!(sample_path(&path, &c, t, 1.0), vec![1.0, 1.0]);
    }
}
