//! The simulated world: Rapier bodies for the table, pedestal, objects and the robot's
//! links, fixed-step stepping, the kinematic robot driven by forward kinematics, welded
//! grasps, suction, handle-driven articulations, the execution trace and the hooks that the
//! task layer plugs into.
//!
//! - [`Sim`] is the world; it implements [`crate::api::RobotApi`] (in `api_impl`).
//! - `build` builds it from a scene in named steps.
//! - `contact` stops lids and drawers where they meet other furniture, stops the arm there
//!   when the protective stop is on ([`Sim::set_protective_stop`]), and measures how deep
//!   the arm goes into it ([`FurnitureContactProbe`]); [`magnet`] pulls
//!   screws toward a magnetic hook.
//! - [`objects`] builds the benchmark's objects from their kinds; [`geometry`] holds the
//!   boxes and frame conversions; `floor` finds free table spots; `rng` is the seeded
//!   randomness that scene generation and motion planning draw from.

mod api_impl;
mod build;
pub(crate) mod contact;
pub(crate) mod floor;
mod gather;
pub mod geometry;
pub mod magnet;
pub mod objects;
pub(crate) mod rng;

pub use contact::{FURNITURE_TOUCH_DEPTH, FurnitureContact, FurnitureContactProbe};

use std::any::Any;

use nalgebra::Vector3;
use rapier3d::prelude::*;

use crate::api::{Embodiment, HANDLE_REACH, TraceEntry};
use crate::robot::kinematics::{Iso, RobotModel};
use crate::robot::model;
use crate::scene::parts;
use crate::scene::{ObjectKind, SceneSpec, TABLE_TOP};
use geometry::{Aabb, iso_to_pose, pose_to_iso, vec_to_array};
use objects::{JointBuild, PartRole, Pattern};

/// Control period in seconds: one "step" of the hooks, the trace clock and the motion
/// profiles (the authors' Genesis `dt`).
pub const CONTROL_DT: f64 = 0.01;
/// Physics substeps per control step (Rapier runs at 400 Hz).
pub const SUBSTEPS: u32 = 4;
/// The reachable workspace on the table (`docs/benchmark.md` §1, `FLOOR_AABB`): positions
/// the API moves the tool to and free table spots lie inside it.
pub const FLOOR_AABB: Aabb = Aabb {
    min: [0.11, -0.60, -0.01],
    max: [0.73, 0.61, TABLE_TOP],
};

/// Tunables of a simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct SimConfig {
    /// Action calls allowed before [`crate::api::ApiError::BudgetExhausted`].
    pub action_budget: usize,
    /// Control steps run when the scene is built so objects come to rest (not counted in
    /// the clock).
    pub settle_steps: u32,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            action_budget: 200,
            settle_steps: 50,
        }
    }
}

/// Render data attached to every collider (through its index in [`Sim::looks`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// Base colour.
    pub colour: [f32; 3],
    /// Pattern.
    pub pattern: Pattern,
    /// Part index in [`Sim::parts`], or `None` for the table, pedestal and robot.
    pub part: Option<usize>,
    /// Half extents in x and y of a cuboid collider, the frame of its checker pattern.
    pub pattern_half_extent: [f32; 2],
}

/// One named part of the scene (an object or a part of an articulated object).
#[derive(Clone, Debug)]
pub struct Part {
    /// Name used by the API and observer.
    pub name: String,
    /// The scene object it comes from.
    pub kind: ObjectKind,
    /// Index of the scene object.
    pub object: usize,
    /// Role in the rules.
    pub role: PartRole,
    /// Its rigid body.
    pub body: RigidBodyHandle,
    /// Its colliders.
    pub colliders: Vec<ColliderHandle>,
    /// Articulation that moves it, for links and handles.
    pub articulation: Option<usize>,
    /// Yaw offset of the finger grasp relative to the object's yaw.
    pub grasp_yaw: f64,
    /// Yaw of the object frame at build time (articulated parts keep it).
    pub base_yaw: f64,
}

/// A one-dof joint of an articulated asset, driven by the simulator.
#[derive(Clone, Debug)]
pub struct Articulation {
    /// The moving link part (`hinge_lid`, `top_drawer`, `bottom_drawer`).
    pub link: usize,
    /// Its handle part.
    pub handle: Option<usize>,
    /// Every part that moves with the joint.
    pub parts: Vec<usize>,
    /// Joint type.
    pub joint: JointBuild,
    /// World pose of the joint frame at the closed position; the moving parts' colliders
    /// are expressed in it.
    pub frame: Pose,
    /// Joint position, benchmark convention.
    pub q: f64,
    /// Limits.
    pub limits: (f64, f64),
}

/// An object welded to the hand or the suction tool.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Held {
    pub part: usize,
    /// Object pose relative to the carrier link.
    pub relative: Pose,
}

/// A grasped handle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HandleGrasp {
    pub part: usize,
    pub articulation: usize,
    /// Tool position and joint position when grasped.
    pub tool0: Vector3<f64>,
    pub q0: f64,
    /// Handle centre in the moving joint frame.
    pub handle_local: Vector,
}

/// Something that wants to watch the simulation: goal checks every N steps, keyframe
/// recorders after every call. Hooks receive the simulator read-only. They must be `Send`
/// so the simulator can move between threads (e.g. into a Python runtime's worker).
pub trait SimHook: Any + Send {
    /// Run [`SimHook::on_step`] every this many control steps (`None`: never).
    fn step_interval(&self) -> Option<u64> {
        None
    }
    /// Called after every `step_interval`-th control step.
    fn on_step(&mut self, _sim: &Sim) {}
    /// Called after every API call (perception and action, successful or refused) with
    /// its trace entry; keyframe recorders keep `entry.call.is_action() &&
    /// entry.result.is_ok()`.
    fn on_call(&mut self, _sim: &Sim, _entry: &TraceEntry) {}
}

/// The robot's links in the world.
pub(crate) struct RobotBodies {
    pub model: RobotModel,
    /// (link index, body) for links with colliders.
    pub bodies: Vec<(usize, RigidBodyHandle)>,
    /// Link that carries held objects.
    pub carrier_link: usize,
    /// Pad centres (link index, point in link frame) of the two fingers.
    pub pads: Option<[(usize, Vector3<f64>); 2]>,
    /// Colliders of the hand and fingers or the suction tool (the `gripper` object).
    pub gripper_colliders: Vec<ColliderHandle>,
}

/// The simulator. Implements [`crate::api::RobotApi`].
pub struct Sim {
    pub(crate) world: PhysicsWorld,
    pub(crate) scene: SceneSpec,
    pub(crate) config: SimConfig,
    pub(crate) parts: Vec<Part>,
    pub(crate) articulations: Vec<Articulation>,
    pub(crate) looks: Vec<Look>,
    pub(crate) table_colliders: Vec<ColliderHandle>,
    pub(crate) robot: RobotBodies,
    pub(crate) base: Iso,
    /// Commanded (and, being kinematic, actual) arm joints.
    pub(crate) q: Vec<f64>,
    /// Finger travel (each finger), actual and target.
    pub(crate) gripper: f64,
    pub(crate) gripper_target: f64,
    /// Fingers closed (finger robot) or suction on (vacuum robot).
    pub(crate) closed: bool,
    pub(crate) held: Option<Held>,
    pub(crate) handle_grasp: Option<HandleGrasp>,
    pub(crate) trace: Vec<TraceEntry>,
    pub(crate) actions_used: usize,
    pub(crate) steps: u64,
    pub(crate) moved_since_reset: bool,
    /// Unit direction of the last `move_parallel` the open, empty finger hand made sideways
    /// (a push), until the next `move_to_position` backs off from it.
    pub(crate) last_push: Option<[f64; 3]>,
    pub(crate) hooks: Vec<Box<dyn SimHook>>,
    /// Control steps the robot holds still after each successful action (see
    /// [`Sim::set_action_pause`]).
    pub(crate) action_pause_steps: u32,
    /// Set when a link the arm drives met other furniture during the current motion; the
    /// motion ends at the next control step.
    pub(crate) contact_stop: Option<contact::ContactStop>,
    /// The scene object (index) whose handle the current `move_gripper_to` reaches for;
    /// the protective stop lets the hand meet that asset's lid, drawer and body on the way
    /// (see [`Sim::protective_stop`]).
    pub(crate) handle_approach: Option<usize>,
    /// The scene object (index) whose handle the hand let go of (or lost), until the arm
    /// no longer overlaps it: the hand leaves it the way it came.
    pub(crate) leaving_asset: Option<usize>,
    /// Whether motions end at furniture ([`Sim::set_protective_stop`]).
    pub(crate) protective_stop: bool,
    /// Pairs of moving links (part indices) of different assets where the first, open,
    /// stands in the way of the second's opening; found once when the scene is built.
    pub(crate) blocking: Vec<(usize, usize)>,
}

impl Sim {
    /// The scene this world was built from.
    pub fn scene(&self) -> &SceneSpec {
        &self.scene
    }

    /// The settings.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// Simulated time since the scene settled, in seconds.
    pub fn time(&self) -> f64 {
        self.steps as f64 * CONTROL_DT
    }

    /// Control steps since the scene settled.
    pub fn step_count(&self) -> u64 {
        self.steps
    }

    /// The parts (named objects) in scene order.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// The articulated joints.
    pub fn articulations(&self) -> &[Articulation] {
        &self.articulations
    }

    /// Index of the part called `name`.
    pub fn part_index(&self, name: &str) -> Option<usize> {
        self.parts.iter().position(|p| p.name == name)
    }

    /// The name perception gives a part: its own, except for the pieces of a fine-grained
    /// object (`black_screws_3`), which are all perceived as that object (`black_screws`).
    pub fn perceived_name(&self, part: usize) -> &str {
        let p = &self.parts[part];
        if p.kind.is_fine_grained() {
            &self.scene.objects[p.object].name
        } else {
            &p.name
        }
    }

    /// Every object as perception names it, in part order, with its parts: a fine-grained
    /// object's pieces together, one part for every other object.
    pub fn perceived_objects(&self) -> Vec<(&str, Vec<usize>)> {
        let mut objects: Vec<(&str, Vec<usize>)> = Vec::with_capacity(self.parts.len());
        for i in 0..self.parts.len() {
            let name = self.perceived_name(i);
            match objects.iter_mut().find(|(n, _)| *n == name) {
                Some((_, parts)) => parts.push(i),
                None => objects.push((name, vec![i])),
            }
        }
        objects
    }

    /// The pieces of the fine-grained object called `name` (none when no such object).
    pub fn pieces_of(&self, name: &str) -> Vec<usize> {
        (0..self.parts.len())
            .filter(|&i| self.parts[i].kind.is_fine_grained() && self.perceived_name(i) == name)
            .collect()
    }

    /// World AABB of several parts together.
    pub fn parts_aabb(&self, parts: &[usize]) -> Aabb {
        parts
            .iter()
            .fold(Aabb::EMPTY, |acc, &p| acc.union(&self.part_aabb(p)))
    }

    /// World AABB of a part.
    pub fn part_aabb(&self, part: usize) -> Aabb {
        self.colliders_aabb(&self.parts[part].colliders)
    }

    pub(crate) fn colliders_aabb(&self, colliders: &[ColliderHandle]) -> Aabb {
        colliders.iter().fold(Aabb::EMPTY, |acc, &c| {
            let collider = &self.world.colliders[c];
            let pose = match collider.parent() {
                Some(b) => {
                    *self.world.bodies[b].position()
                        * *collider.position_wrt_parent().unwrap_or(&Pose::IDENTITY)
                }
                None => *collider.position(),
            };
            acc.union(&Aabb::from_parry(&collider.shape().compute_aabb(&pose)))
        })
    }

    /// World AABB of a named object: a part, a fine-grained object (its pieces' union),
    /// `floor` (the table) or `gripper` / `vacuum_gripper` (hand and fingers, or the suction
    /// tool).
    pub fn object_aabb(&self, name: &str) -> Option<Aabb> {
        if let Some(i) = self.part_index(name) {
            return Some(self.part_aabb(i));
        }
        match name {
            parts::FLOOR => Some(self.colliders_aabb(&self.table_colliders)),
            n if n == self.gripper_name() => Some(self.colliders_aabb(&self.robot.gripper_colliders)),
            n => {
                let pieces = self.pieces_of(n);
                (!pieces.is_empty()).then(|| self.parts_aabb(&pieces))
            }
        }
    }

    /// Linear velocity of a part's body (m/s).
    pub fn part_velocity(&self, part: usize) -> [f64; 3] {
        vec_to_array(self.world.bodies[self.parts[part].body].linvel())
    }

    /// Linear velocity of a named part.
    pub fn object_velocity(&self, name: &str) -> Option<[f64; 3]> {
        self.part_index(name).map(|i| self.part_velocity(i))
    }

    /// Pose (position, yaw) of a part's body.
    pub fn part_pose(&self, part: usize) -> Iso {
        pose_to_iso(self.world.bodies[self.parts[part].body].position())
    }

    /// Joint position of an articulated part (`hinge_lid`, `top_drawer`, `bottom_drawer`).
    pub fn articulation_q(&self, name: &str) -> Option<f64> {
        self.articulations
            .iter()
            .find(|a| self.parts[a.link].name == name)
            .map(|a| a.q)
    }

    /// The arm's joint positions.
    pub fn arm_joints(&self) -> &[f64] {
        &self.q
    }

    /// Finger travel (each finger, m); 0 for the vacuum robot.
    pub fn finger_travel(&self) -> f64 {
        self.gripper
    }

    /// The robot's embodiment.
    pub fn robot_embodiment(&self) -> Embodiment {
        self.scene.embodiment
    }

    /// The name the robot goes by in the object list.
    pub fn gripper_name(&self) -> &'static str {
        match self.scene.embodiment {
            Embodiment::Finger => parts::GRIPPER,
            Embodiment::Vacuum => parts::VACUUM_GRIPPER,
        }
    }

    /// True while the fingers are closed or the suction is on.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Name of the object welded to the hand or tool.
    pub fn held_object(&self) -> Option<&str> {
        self.held.map(|h| self.parts[h.part].name.as_str())
    }

    /// Name of the grasped handle.
    pub fn grasped_handle(&self) -> Option<&str> {
        self.handle_grasp.map(|g| self.parts[g.part].name.as_str())
    }

    /// Render data per collider (indexed by the collider's `user_data`).
    pub fn looks(&self) -> &[Look] {
        &self.looks
    }

    /// The Rapier world (read-only), e.g. for ray casting.
    pub fn physics(&self) -> &PhysicsWorld {
        &self.world
    }

    /// Registers a hook; it runs until removed.
    pub fn add_hook(&mut self, hook: Box<dyn SimHook>) {
        self.hooks.push(hook);
    }

    /// Makes the robot hold still for `control_steps` after every successful action, the
    /// world stepping on meanwhile: the pause a person makes between the steps of a
    /// demonstration, so that a video of it shows each step's result at rest. Recording a
    /// demonstration video sets it; it is 0 otherwise.
    pub fn set_action_pause(&mut self, control_steps: u32) {
        self.action_pause_steps = control_steps;
    }

    /// Turns the protective stop on or off. On, a motion that presses a link of the arm or the
    /// carried object into furniture deeper than a touch ends there with
    /// [`crate::api::ApiError::Collision`] naming both, as a real arm's collision reflex ends
    /// it (the rule and its one exemption, for the authors' proximity-grasped handles, are in
    /// `world/contact.rs`). With it on the robot also moves as one that knows its furniture:
    /// opening fingers stop at furniture, a finger grasp's wrist spin is chosen clear of it
    /// along the descent, and transits keep clear of it. Off, the kinematic arm passes
    /// through furniture (only [`crate::world::FurnitureContactProbe`] says how deep it went)
    /// and moves exactly as it did before the stop existed, so recorded runs replay.
    ///
    /// A world starts with the setting of its scene ([`SceneSpec::protective_stop`], off
    /// unless the scene turns it on).
    ///
    /// ```
    /// use nesy_core::Embodiment;
    /// use nesy_sim::api::{ApiError, Direction, RobotApi};
    /// use nesy_sim::scene::SubtaskKind;
    /// use nesy_sim::tasks::TaskConfig;
    /// use nesy_sim::world::Sim;
    ///
    /// let task = TaskConfig::single(SubtaskKind::PutInPrismatic, 2, 0, 0, Embodiment::Finger)
    ///     .generate()
    ///     .unwrap();
    /// let mut sim = Sim::new(&task.scene).unwrap();
    /// sim.set_protective_stop(true);
    /// // Straight down into the middle of the drawer cabinet, from above its top.
    /// let [min, max] = sim.get_obj_bbox("drawer_body").unwrap();
    /// let (x, y) = ((min[0] + max[0]) / 2.0, (min[1] + max[1]) / 2.0);
    /// sim.move_to_position([x, y, max[2] + 0.1], Direction::Down, 0.0, 0.0).unwrap();
    /// let err = sim
    ///     .move_to_position([x, y, (min[2] + max[2]) / 2.0], Direction::Down, 0.0, 0.0)
    ///     .unwrap_err();
    /// assert!(matches!(&err, ApiError::Collision { obstacle, .. } if obstacle == "drawer_body"));
    ///
    /// // Without the stop the same descent goes through the cabinet's top.
    /// let mut sim = Sim::new(&task.scene).unwrap();
    /// sim.move_to_position([x, y, max[2] + 0.1], Direction::Down, 0.0, 0.0).unwrap();
    /// sim.move_to_position([x, y, (min[2] + max[2]) / 2.0], Direction::Down, 0.0, 0.0).unwrap();
    /// ```
    pub fn set_protective_stop(&mut self, on: bool) {
        self.protective_stop = on;
    }

    /// Removes and returns every hook.
    pub fn take_hooks(&mut self) -> Vec<Box<dyn SimHook>> {
        std::mem::take(&mut self.hooks)
    }

    /// The first registered hook of type `T`.
    pub fn hook<T: SimHook>(&self) -> Option<&T> {
        self.hooks
            .iter()
            .find_map(|h| (&**h as &dyn Any).downcast_ref::<T>())
    }

    /// Every call so far.
    pub fn trace_entries(&self) -> &[TraceEntry] {
        &self.trace
    }

    /// Action calls made so far (counted against the budget).
    pub fn actions_used(&self) -> usize {
        self.actions_used
    }

    /// Steps the world with the robot holding still (e.g. the post-run settle).
    pub fn step_idle(&mut self, control_steps: u32) {
        for _ in 0..control_steps {
            let q = self.q.clone();
            self.control_step(&q);
        }
    }

    /// World pose of robot link `li` for arm joints `q` and finger travel `g`.
    pub(crate) fn link_world(&self, q: &[f64], g: f64, li: usize) -> Iso {
        self.base
            * self
                .robot
                .model
                .pose_of(&self.robot.model.links[li].name, q, g)
                .unwrap_or_else(Iso::identity)
    }

    /// World pose of the tool point (pad centre or suction tip).
    pub fn tool_pose(&self) -> Iso {
        self.base * self.robot.model.tool_pose(&self.q)
    }

    /// Runs one control step: moves the arm from its current joints to `q_next`
    /// (interpolated over the substeps), the fingers toward their target, held objects and
    /// grasped articulations along, then runs due hooks.
    pub(crate) fn control_step(&mut self, q_next: &[f64]) {
        let q_prev = self.q.clone();
        self.physics_control_step(&q_prev, q_next);
        self.steps += 1;
        if !self.hooks.is_empty() {
            let mut hooks = std::mem::take(&mut self.hooks);
            for hook in hooks.iter_mut() {
                if let Some(n) = hook.step_interval()
                    && n > 0
                    && self.steps.is_multiple_of(n)
                {
                    hook.on_step(self);
                }
            }
            hooks.append(&mut self.hooks);
            self.hooks = hooks;
        }
    }

    fn physics_control_step(&mut self, q_prev: &[f64], q_next: &[f64]) {
        // Fingers move at up to 0.2 m/s (the URDF velocity limit).
        let max_finger_step = 0.2 * CONTROL_DT;
        let g_prev = self.gripper;
        let mut g_next = g_prev + (self.gripper_target - g_prev).clamp(-max_finger_step, max_finger_step);
        // With the protective stop on, opening fingers stop at furniture, as a real gripper's
        // do (a cube let go of by the toy box's wall): the fingers are kinematic and nothing
        // else would stop them.
        if self.protective_stop && g_next > g_prev && self.robot.model.gripper_limits.is_some() {
            let furniture = self.furniture_snapshot();
            let before = furniture.fingers_depth_at(q_prev, g_prev);
            let after = furniture.fingers_depth_at(q_next, g_next);
            if after > before.max(contact::FURNITURE_TOUCH_DEPTH) {
                g_next = g_prev;
            }
        }
        for sub in 1..=SUBSTEPS {
            let s = sub as f64 / SUBSTEPS as f64;
            let q: Vec<f64> = q_prev.iter().zip(q_next).map(|(a, b)| a + (b - a) * s).collect();
            let g = g_prev + (g_next - g_prev) * s;
            self.drive_robot(&q, g);
            self.apply_magnets();
            self.world.step();
        }
        self.q = q_next.to_vec();
        self.gripper = g_next;
    }

    /// Sets the next kinematic poses of the robot, the held object and any grasped
    /// articulation for configuration `(q, g)`.
    fn drive_robot(&mut self, q: &[f64], g: f64) {
        let poses = self.robot.model.link_poses(q, g);
        for &(li, body) in &self.robot.bodies {
            let pose = iso_to_pose(&(self.base * poses[li]));
            self.world.bodies[body].set_next_kinematic_position(pose);
        }
        let carrier = iso_to_pose(&(self.base * poses[self.robot.carrier_link]));
        if let Some(held) = self.held {
            let body = self.parts[held.part].body;
            self.world.bodies[body].set_next_kinematic_position(carrier * held.relative);
        }
        if let Some(grasp) = self.handle_grasp {
            let tool = (self.base * poses[self.robot.model.tool_link]).translation.vector;
            let wanted = self.follow_handle(&grasp, tool);
            let (q_joint, stop) = self.travel_until_contact(grasp.articulation, wanted);
            self.set_articulation(grasp.articulation, q_joint);
            if stop.is_some() {
                self.contact_stop = self.contact_stop.or(stop);
                // The hand stops up to one substep past the point of contact; the handle
                // stays where the link stopped, so the grasp is re-anchored there (else the
                // next motion would first have to make up that millimetre against the
                // obstacle, even when it backs away from it).
                if let Some(g) = self.handle_grasp.as_mut() {
                    g.tool0 = tool;
                    g.q0 = q_joint;
                }
            }
            // Like the authors' controller, a handle left more than the reach behind (the
            // joint at its limit while the hand moves on) slips out of the grasp.
            let a = &self.articulations[grasp.articulation];
            let centre = (a.frame * objects::joint_motion(a.joint, a.q)) * grasp.handle_local;
            let gap = (tool - Vector3::new(centre.x as f64, centre.y as f64, centre.z as f64)).norm();
            if gap > HANDLE_REACH {
                self.leaving_asset = Some(self.articulation_asset(grasp.articulation));
                self.handle_grasp = None;
                self.closed = false;
                self.gripper_target = if self.robot.model.gripper_limits.is_some() {
                    model::FINGER_OPEN
                } else {
                    0.0
                };
            }
        }
    }

    /// The joint position that keeps a grasped handle with the tool.
    fn follow_handle(&self, grasp: &HandleGrasp, tool: Vector3<f64>) -> f64 {
        let a = &self.articulations[grasp.articulation];
        let frame = pose_to_iso(&a.frame);
        let q = match a.joint {
            JointBuild::Prismatic => {
                let open_dir = frame.rotation * Vector3::new(0.0, -1.0, 0.0);
                grasp.q0 + (tool - grasp.tool0).dot(&open_dir)
            }
            JointBuild::Revolute { .. } => {
                let axis = frame.rotation * Vector3::y();
                let origin = frame.translation.vector;
                let flat = |p: Vector3<f64>| {
                    let r = p - origin;
                    r - axis * r.dot(&axis)
                };
                let (r0, r1) = (flat(grasp.tool0), flat(tool));
                if r0.norm() < 1e-6 || r1.norm() < 1e-6 {
                    a.q
                } else {
                    grasp.q0 + r0.cross(&r1).dot(&axis).atan2(r0.dot(&r1))
                }
            }
        };
        q.clamp(a.limits.0, a.limits.1)
    }

    /// Moves an articulation (its parts' kinematic bodies) to joint position `q`.
    pub(crate) fn set_articulation(&mut self, ai: usize, q: f64) {
        let a = &mut self.articulations[ai];
        a.q = q.clamp(a.limits.0, a.limits.1);
        let pose = a.frame * objects::joint_motion(a.joint, a.q);
        for &p in &a.parts {
            let body = self.parts[p].body;
            self.world.bodies[body].set_next_kinematic_position(pose);
        }
    }

    /// World pose of the link that carries held objects.
    pub(crate) fn carrier_pose(&self) -> Pose {
        iso_to_pose(&self.link_world(&self.q, self.gripper, self.robot.carrier_link))
    }

    /// Welds a loose part to the carrier link (it becomes kinematic and follows).
    pub(crate) fn weld(&mut self, part: usize) {
        let body = self.parts[part].body;
        let relative = self.carrier_pose().inverse() * *self.world.bodies[body].position();
        let rb = &mut self.world.bodies[body];
        rb.set_body_type(RigidBodyType::KinematicPositionBased, true);
        self.held = Some(Held { part, relative });
    }

    /// Releases the welded part (it becomes dynamic again, at rest).
    pub(crate) fn unweld(&mut self) {
        if let Some(held) = self.held.take() {
            let rb = &mut self.world.bodies[self.parts[held.part].body];
            rb.set_body_type(RigidBodyType::Dynamic, true);
            rb.set_linvel(Vector::ZERO, true);
            rb.set_angvel(Vector::ZERO, true);
        }
    }

    /// Pad centres of the finger gripper in the world, at the current configuration.
    pub(crate) fn pad_centres(&self) -> Option<[[f64; 3]; 2]> {
        let pads = self.robot.pads?;
        Some(pads.map(|(li, p)| {
            let w = self.link_world(&self.q, self.gripper, li) * nalgebra::Point3::from(p);
            [w.x, w.y, w.z]
        }))
    }

    /// The point whose containment means "under the suction cup": 1.1 cm past the tip.
    pub(crate) fn suction_point(&self) -> [f64; 3] {
        let tool = self.tool_pose();
        let p = tool * nalgebra::Point3::new(0.0, 0.0, 0.01075);
        [p.x, p.y, p.z]
    }

    /// True if the part is in the grasp region (between the pads, or under the cup).
    pub fn part_in_gripper(&self, part: usize) -> bool {
        let aabb = self.part_aabb(part);
        match self.scene.embodiment {
            Embodiment::Finger => match self.pad_centres() {
                Some([a, b]) => aabb.intersects_segment(a, b),
                None => false,
            },
            Embodiment::Vacuum => aabb.contains_point(self.suction_point()),
        }
    }
}
