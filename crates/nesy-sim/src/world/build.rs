//! Building the world for a scene, in named steps: the static scene (ground, table,
//! pedestal), the scene's objects and their articulations, the robot's links, then the
//! interpenetration check and the initial settle.
//!
//! Bodies and colliders are inserted in a fixed order (static scene, objects in scene order,
//! robot links in URDF order), so Rapier's handles, and with them every simulation, are the
//! same for the same scene.

use nalgebra::Vector3;
use rapier3d::prelude::*;

use super::geometry::iso_to_pose;
use super::objects::{self, JointBuild, PartBuild, PartMotion, PartRole, Pattern};
use super::{Articulation, CONTROL_DT, Look, Part, RobotBodies, SUBSTEPS, Sim, SimConfig};
use crate::robot::kinematics::{Iso, JointKind, Primitive, RobotModel};
use crate::robot::model;
use crate::scene::parts::Joint;
use crate::scene::{ObjectSpec, SceneError, SceneSpec, TABLE_TOP};

/// Continuous collision detection on every dynamic object: a cube dropped into a box or a
/// piece pushed at the end of a fast segment must not tunnel through a 3–4 mm wall.
const DYNAMIC_CCD: bool = true;
/// Rapier's contact prediction distance (m, with the default length unit of 1 m). Below
/// about 5 mm a fruit resting on its rounded edge rocked without end: the contact vanished
/// at each swing's far end and came back with energy, so the fruit never came to rest.
const PREDICTION_DISTANCE: f32 = 0.005;
/// Speed (m/s, of the body's farthest point, solver corrections included) under which a loose
/// object counts as at rest. Rapier's default, 5 cm/s, would put a slowly sliding or tipping
/// object to sleep mid-motion; at 2 mm/s only objects that have stopped sleep (resting
/// contact jitter is far below it).
const SLEEP_SPEED: f32 = 0.002;
/// How long (s) a loose object stays under [`SLEEP_SPEED`] before it sleeps. A sleeping body
/// costs the solver nothing; any contact with a moving body (the arm, a carried or falling
/// object) or a new joint wakes it and its island.
const SLEEP_AFTER: f32 = 1.0;
/// Deepest overlap (m) between two objects, or an object and the table, that a scene may
/// start with.
const MAX_START_OVERLAP: f64 = 0.0015;

/// The Rapier world under construction, with the render data of every collider inserted so
/// far (a collider's `user_data` is its index in `looks`).
struct WorldBuilder {
    world: PhysicsWorld,
    looks: Vec<Look>,
}

/// A plain-coloured look for a collider that belongs to no part.
fn plain(colour: [f32; 3]) -> Look {
    Look {
        colour,
        pattern: Pattern::Plain,
        part: None,
        pattern_half_extent: [0.0; 2],
    }
}

/// A Rapier shape for a URDF primitive, with the rotation that maps the shape's own axis
/// onto the URDF's (parry cylinders run along y, URDF cylinders along z).
fn shape_of(p: &Primitive) -> (SharedShape, Pose) {
    match *p {
        Primitive::Box(s) => (
            SharedShape::cuboid(s[0] as f32 / 2.0, s[1] as f32 / 2.0, s[2] as f32 / 2.0),
            Pose::IDENTITY,
        ),
        Primitive::Cylinder { radius, length } => (
            SharedShape::cylinder(length as f32 / 2.0, radius as f32),
            Pose::from_rotation(Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2)),
        ),
        Primitive::Capsule { radius, length } => (
            SharedShape::capsule_z(length as f32 / 2.0, radius as f32),
            Pose::IDENTITY,
        ),
        Primitive::Sphere(r) => (SharedShape::ball(r as f32), Pose::IDENTITY),
    }
}

impl WorldBuilder {
    /// An empty world: gravity along −z, [`SUBSTEPS`] physics steps per control step.
    fn new() -> WorldBuilder {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -9.81);
        world.integration_parameters.dt = (CONTROL_DT / SUBSTEPS as f64) as f32;
        // Rapier's contact recycling keeps a pair's contact points while the pair has moved
        // less than 5 cm since its last full update. Against the arm that is wrong by whole
        // objects: a finger pad that had pushed a rook kept its contact through the 15 mm
        // back-off and lifted the rook by it as the hand rose. Every pair is updated every
        // step instead.
        world.integration_parameters.contact_recycling = false;
        // Contacts are predicted 5 mm ahead instead of Rapier's 2 cm (tuned for metre-sized
        // bodies): with every pair updated every step, a 2 cm margin made the narrow phase
        // the largest cost among these centimetre-sized objects. Dropped objects move less
        // than 3 mm per substep and dynamic bodies use CCD, so nothing tunnels.
        world.integration_parameters.normalized_prediction_distance = PREDICTION_DISTANCE;
        WorldBuilder {
            world,
            looks: Vec::new(),
        }
    }

    fn add_collider(
        &mut self,
        builder: ColliderBuilder,
        body: RigidBodyHandle,
        look: Look,
    ) -> ColliderHandle {
        self.looks.push(look);
        self.world
            .insert_collider(builder.user_data((self.looks.len() - 1) as u128), Some(body))
    }

    /// Ground, table and pedestal; returns the table's colliders (the `floor` object).
    fn add_static_scene(&mut self) -> Vec<ColliderHandle> {
        let ground = self.world.insert_body(RigidBodyBuilder::fixed());
        self.add_collider(
            ColliderBuilder::cuboid(3.0, 3.0, 0.05).translation(Vector::new(0.5, 0.0, -0.05)),
            ground,
            plain([0.45, 0.47, 0.5]),
        );
        // The table: x 0..1, y −1..1, from the ground up to the table top.
        let half_height = (TABLE_TOP / 2.0) as f32;
        let table = self.add_collider(
            ColliderBuilder::cuboid(0.5, 1.0, half_height)
                .translation(Vector::new(0.5, 0.0, half_height))
                .friction(objects::FRICTION),
            ground,
            plain([0.78, 0.72, 0.62]),
        );
        // The robot's pedestal, as high as the table.
        self.add_collider(
            ColliderBuilder::cuboid(0.15, 0.2, half_height).translation(Vector::new(-0.05, 0.0, half_height)),
            ground,
            plain([0.3, 0.3, 0.32]),
        );
        vec![table]
    }

    /// Every scene object's parts (in scene order) and the articulations they form.
    fn add_objects(&mut self, scene: &SceneSpec) -> (Vec<Part>, Vec<Articulation>) {
        let mut parts: Vec<Part> = Vec::new();
        let mut articulations: Vec<Articulation> = Vec::new();
        for (oi, spec) in scene.objects.iter().enumerate() {
            let [x, y, z] = spec.pose.position;
            let frame = Pose::from_parts(
                Vector::new(x as f32, y as f32, z as f32),
                Rotation::from_rotation_z(spec.pose.yaw as f32),
            );
            let builds = objects::build_object(spec);
            for build in &builds {
                let part_index = parts.len();
                let (articulation, pose) = match (build.motion, build.joint) {
                    (PartMotion::Articulated, Some(joint)) => {
                        let link_name = match build.rides_on {
                            Some(l) => builds[l].name.as_str(),
                            None => build.name.as_str(),
                        };
                        // Every part of an articulation is expressed in the joint frame at
                        // the closed position (the link's), and starts at its joint position.
                        let joint_frame = frame * build.offset;
                        let ai = articulation_of(
                            &mut articulations,
                            &parts,
                            scene,
                            link_name,
                            part_index,
                            joint,
                            joint_frame,
                        );
                        let a = &mut articulations[ai];
                        a.parts.push(part_index);
                        if build.role == PartRole::Handle {
                            a.handle = Some(part_index);
                        }
                        (Some(ai), joint_frame * objects::joint_motion(joint, a.q))
                    }
                    _ => (None, frame * build.offset),
                };
                let body = self.world.insert_body(body_builder(build, spec).pose(pose));
                if build.motion == PartMotion::Dynamic {
                    let activation = self.world.bodies[body].activation_mut();
                    activation.normalized_linear_threshold = SLEEP_SPEED;
                    activation.time_until_sleep = SLEEP_AFTER;
                }
                let colliders = self.add_part_colliders(build, spec, body, part_index);
                parts.push(Part {
                    name: build.name.clone(),
                    kind: spec.kind,
                    object: oi,
                    role: build.role,
                    body,
                    colliders,
                    articulation,
                    grasp_yaw: build.grasp_yaw,
                    base_yaw: spec.pose.yaw,
                });
            }
        }
        (parts, articulations)
    }

    /// The colliders of one part, with their looks.
    fn add_part_colliders(
        &mut self,
        build: &PartBuild,
        spec: &ObjectSpec,
        body: RigidBodyHandle,
        part_index: usize,
    ) -> Vec<ColliderHandle> {
        let (friction, rule) = objects::friction(spec.kind);
        build
            .shapes
            .iter()
            .map(|shape| {
                let half = shape
                    .shape
                    .as_cuboid()
                    .map(|c| [c.half_extents.x, c.half_extents.y])
                    .unwrap_or([0.0; 2]);
                let builder = ColliderBuilder::new(shape.shape.clone())
                    .position(shape.local)
                    .density(shape.density)
                    .friction(friction)
                    .friction_combine_rule(rule)
                    .sensor(!build.solid);
                self.add_collider(
                    builder,
                    body,
                    Look {
                        colour: shape.colour,
                        pattern: shape.pattern,
                        part: Some(part_index),
                        pattern_half_extent: half,
                    },
                )
            })
            .collect()
    }

    /// The robot's links with colliders, as kinematic bodies at configuration `(q,
    /// gripper)` on `base`.
    fn add_robot(
        &mut self,
        model: RobotModel,
        carrier_link: usize,
        base: &Iso,
        q: &[f64],
        gripper: f64,
    ) -> RobotBodies {
        let poses = model.link_poses(q, gripper);
        let mut bodies = Vec::new();
        let mut gripper_colliders = Vec::new();
        let mut pads = Vec::new();
        for (li, link) in model.links.iter().enumerate() {
            if link.collisions.is_empty() {
                continue;
            }
            let body = self.world.insert_body(
                RigidBodyBuilder::kinematic_position_based()
                    .can_sleep(false)
                    .pose(iso_to_pose(&(base * poses[li]))),
            );
            let is_gripper = li >= carrier_link;
            let colour = if link.name.contains("finger") {
                [0.2, 0.2, 0.22]
            } else if is_gripper {
                [0.85, 0.85, 0.87]
            } else {
                [0.93, 0.93, 0.95]
            };
            for (prim, local) in &link.collisions {
                let (shape, axis) = shape_of(prim);
                let h = self.add_collider(
                    ColliderBuilder::new(shape)
                        .position(iso_to_pose(local) * axis)
                        .friction(objects::FRICTION),
                    body,
                    plain(colour),
                );
                if is_gripper {
                    gripper_colliders.push(h);
                }
            }
            // A finger's pad is its outermost collision primitive along the finger.
            if matches!(link.kind, JointKind::Prismatic)
                && let Some((_, pad)) = link
                    .collisions
                    .iter()
                    .max_by(|a, b| a.1.translation.vector.z.total_cmp(&b.1.translation.vector.z))
            {
                pads.push((li, pad.translation.vector));
            }
            bodies.push((li, body));
        }
        let pads: Option<[(usize, Vector3<f64>); 2]> = match pads.as_slice() {
            [a, b] => Some([*a, *b]),
            _ => None,
        };
        RobotBodies {
            model,
            bodies,
            carrier_link,
            pads,
            gripper_colliders,
        }
    }
}

/// The articulation `link_name` belongs to, created (at the scene's joint position, else the
/// closed one) the first time one of its parts is built; returns its index.
fn articulation_of(
    articulations: &mut Vec<Articulation>,
    parts: &[Part],
    scene: &SceneSpec,
    link_name: &str,
    part_index: usize,
    joint: JointBuild,
    joint_frame: Pose,
) -> usize {
    if let Some(ai) = articulations.iter().position(|a| parts[a.link].name == link_name) {
        return ai;
    }
    let named = Joint::from_name(link_name);
    let q = scene
        .articulations
        .get(link_name)
        .copied()
        .unwrap_or(named.map_or(0.0, Joint::closed));
    articulations.push(Articulation {
        link: part_index,
        handle: None,
        parts: Vec::new(),
        joint,
        frame: joint_frame,
        q,
        limits: named.map_or((0.0, 0.0), Joint::limits),
    });
    articulations.len() - 1
}

/// The rigid body of a part: dynamic for loose objects, fixed for furniture, kinematic for
/// the parts an articulation moves.
fn body_builder(build: &PartBuild, spec: &ObjectSpec) -> RigidBodyBuilder {
    match build.motion {
        PartMotion::Dynamic => RigidBodyBuilder::dynamic()
            .ccd_enabled(DYNAMIC_CCD)
            .angular_damping(objects::angular_damping(spec.kind))
            .can_sleep(true),
        PartMotion::Fixed => RigidBodyBuilder::fixed(),
        PartMotion::Articulated => RigidBodyBuilder::kinematic_position_based().can_sleep(false),
    }
}

impl Sim {
    /// Builds the world for a validated scene with default settings.
    pub fn new(scene: &SceneSpec) -> Result<Sim, SceneError> {
        Sim::with_config(scene, SimConfig::default())
    }

    /// Reads, validates and builds a scene file.
    pub fn from_file(path: &std::path::Path) -> Result<Sim, SceneError> {
        Sim::new(&SceneSpec::from_file(path)?).map_err(|e| e.with_origin(&path.display().to_string()))
    }

    /// Builds the world for a scene, checks that no two objects interpenetrate, and lets
    /// the objects settle for `config.settle_steps` control steps.
    pub fn with_config(scene: &SceneSpec, config: SimConfig) -> Result<Sim, SceneError> {
        scene.validate()?;
        let mut builder = WorldBuilder::new();
        let table_colliders = builder.add_static_scene();
        let (parts, articulations) = builder.add_objects(scene);

        let model = model::load_model(scene.embodiment)
            .map_err(|e| SceneError::invalid("embodiment", "a loadable robot model", e.to_string()))?;
        let (_, _, carrier) = model::variant(scene.embodiment);
        let carrier_link = model.link_index(carrier).unwrap_or(model.tool_link);
        let base = model::base_pose();
        let q = model::HOME_ARM.to_vec();
        let gripper = if model.gripper_limits.is_some() {
            model::FINGER_OPEN
        } else {
            0.0
        };
        let robot = builder.add_robot(model, carrier_link, &base, &q, gripper);

        let mut sim = Sim {
            world: builder.world,
            scene: scene.clone(),
            config,
            parts,
            articulations,
            looks: builder.looks,
            table_colliders,
            robot,
            base,
            q,
            gripper,
            gripper_target: gripper,
            closed: false,
            held: None,
            handle_grasp: None,
            trace: Vec::new(),
            actions_used: 0,
            steps: 0,
            moved_since_reset: false,
            last_push: None,
            hooks: Vec::new(),
            action_pause_steps: 0,
            contact_stop: None,
            handle_approach: None,
            leaving_asset: None,
            protective_stop: scene.protective_stop,
            blocking: Vec::new(),
        };
        sim.check_interpenetration()?;
        sim.blocking = sim.articulation_blocking();
        for _ in 0..sim.config.settle_steps {
            sim.physics_control_step(&sim.q.clone(), &sim.q.clone());
        }
        Ok(sim)
    }

    /// Fails if colliders of two different scene objects (or an object and the table)
    /// overlap by more than [`MAX_START_OVERLAP`].
    fn check_interpenetration(&mut self) -> Result<(), SceneError> {
        // One zero-length step fills the broad phase so contacts can be queried.
        let dt = self.world.integration_parameters.dt;
        self.world.integration_parameters.dt = 0.0;
        self.world.step();
        self.world.integration_parameters.dt = dt;
        let owner = |sim: &Sim, c: ColliderHandle| -> Option<usize> {
            if sim.table_colliders.contains(&c) {
                return Some(usize::MAX);
            }
            let look = sim.looks[sim.world.colliders[c].user_data as usize];
            look.part.map(|p| sim.parts[p].object)
        };
        let mut worst: Option<(f64, usize, usize)> = None;
        for pair in self.world.narrow_phase.contact_pairs() {
            let (Some(a), Some(b)) = (owner(self, pair.collider1), owner(self, pair.collider2)) else {
                continue;
            };
            if a == b {
                continue;
            }
            for manifold in pair.manifolds() {
                for point in &manifold.points {
                    let depth = -(point.dist as f64);
                    if depth > MAX_START_OVERLAP && worst.is_none_or(|(d, _, _)| depth > d) {
                        worst = Some((depth, a.min(b), a.max(b)));
                    }
                }
            }
        }
        let Some((depth, a, b)) = worst else {
            return Ok(());
        };
        let name = |i: usize| {
            if i == usize::MAX {
                "the table".to_owned()
            } else {
                format!("objects[{i}] ({})", self.scene.objects[i].name)
            }
        };
        let (path, other) = if b == usize::MAX {
            (a, name(b))
        } else {
            (b, name(a))
        };
        Err(SceneError::invalid(
            format!("objects[{path}].pose"),
            "a pose that does not interpenetrate other objects",
            format!(
                "{} overlapping {other} by {:.1} mm",
                self.scene.objects[path].name,
                depth * 1000.0
            ),
        ))
    }
}
