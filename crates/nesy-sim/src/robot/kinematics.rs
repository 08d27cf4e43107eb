//! The robot's kinematic tree, read from its URDF, with forward kinematics, the geometric
//! Jacobian and a damped-least-squares inverse kinematics with deterministic restarts.
//!
//! Nothing about the Panda is hard-coded here: the chain, joint axes, origins and limits
//! all come from the parsed URDF (`rapier3d_urdf::urdf_rs`).

use nalgebra::{Isometry3, Matrix6, Translation3, UnitQuaternion, Vector3, Vector6};
use nesy_core::rng::SplitMix64;
use rapier3d_urdf::urdf_rs;

/// A rigid transform in f64 (the kinematics' precision).
pub type Iso = Isometry3<f64>;

/// How a link hangs off its parent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointKind {
    /// Rigidly attached.
    Fixed,
    /// Rotates about `axis`.
    Revolute,
    /// Slides along `axis`.
    Prismatic,
}

/// Where a joint's value comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointSource {
    /// Fixed joint: no value.
    None,
    /// Arm degree of freedom `i` (0-based, in URDF chain order).
    Arm(usize),
    /// The gripper opening (one finger's travel), times `multiplier`, plus `offset`.
    Gripper {
        /// URDF `<mimic>` multiplier (1 for the driving finger).
        multiplier: f64,
        /// URDF `<mimic>` offset.
        offset: f64,
    },
}

/// A primitive collision shape from the URDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    /// Full edge lengths.
    Box([f64; 3]),
    /// Radius and length along local z.
    Cylinder {
        /// Radius.
        radius: f64,
        /// Length along z.
        length: f64,
    },
    /// Radius and cylinder length along local z (caps excluded).
    Capsule {
        /// Radius.
        radius: f64,
        /// Length of the cylindrical part along z.
        length: f64,
    },
    /// Radius.
    Sphere(f64),
}

/// One link of the tree, with the joint that attaches it to its parent.
#[derive(Clone, Debug)]
pub struct LinkModel {
    /// URDF link name.
    pub name: String,
    /// Index of the parent link, `None` for the root.
    pub parent: Option<usize>,
    /// URDF name of the joint from the parent (empty for the root).
    pub joint_name: String,
    /// Joint type.
    pub kind: JointKind,
    /// Joint origin in the parent link frame.
    pub origin: Iso,
    /// Unit joint axis in the joint frame.
    pub axis: Vector3<f64>,
    /// Joint limits `(lower, upper)`.
    pub limits: (f64, f64),
    /// Which configuration value drives the joint.
    pub source: JointSource,
    /// Collision primitives with their poses in the link frame.
    pub collisions: Vec<(Primitive, Iso)>,
    /// Mass in kg.
    pub mass: f64,
}

/// Errors while turning a URDF into a [`RobotModel`].
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The XML did not parse.
    #[error("URDF parse error: {0}")]
    Parse(String),
    /// The tree is malformed or lacks something the simulator needs.
    #[error("URDF {robot}: {message}")]
    Invalid {
        /// Robot name.
        robot: String,
        /// What is wrong.
        message: String,
    },
}

/// The kinematic tree of one robot variant.
#[derive(Clone, Debug)]
pub struct RobotModel {
    /// URDF robot name.
    pub name: String,
    /// Links in topological order (parents before children); index 0 is the root.
    pub links: Vec<LinkModel>,
    /// Arm joint limits, in dof order.
    pub arm_limits: Vec<(f64, f64)>,
    /// Gripper travel limits, when the robot has a gripper.
    pub gripper_limits: Option<(f64, f64)>,
    /// Index of the tool link (grasp point or suction tip).
    pub tool_link: usize,
    /// Chain from the root to the tool link (link indices, root first).
    chain: Vec<usize>,
}

fn pose_to_iso(pose: &urdf_rs::Pose) -> Iso {
    let [x, y, z] = pose.xyz.0;
    let [r, p, yaw] = pose.rpy.0;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(r, p, yaw),
    )
}

impl RobotModel {
    /// Parses URDF text and builds the tree rooted at the link that is nobody's child, with
    /// `tool_link` as the end effector. Revolute joints become arm dofs in chain order;
    /// prismatic joints (and their mimics) become the gripper.
    pub fn from_urdf_str(urdf: &str, tool_link: &str) -> Result<Self, ModelError> {
        let robot = urdf_rs::read_from_string(urdf).map_err(|e| ModelError::Parse(e.to_string()))?;
        let mut tree = TreeBuilder::rooted(&robot)?;
        // Breadth-first over joints in file order keeps the dof order deterministic.
        let mut frontier = 0;
        while frontier < tree.links.len() {
            tree.attach_children(frontier)?;
            frontier += 1;
        }
        tree.into_model(tool_link)
    }

    /// Number of arm degrees of freedom.
    pub fn arm_dofs(&self) -> usize {
        self.arm_limits.len()
    }

    /// Index of the link called `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }

    fn joint_value(&self, link: &LinkModel, q: &[f64], gripper: f64) -> f64 {
        match link.source {
            JointSource::None => 0.0,
            JointSource::Arm(i) => q[i],
            JointSource::Gripper { multiplier, offset } => gripper * multiplier + offset,
        }
    }

    fn joint_motion(link: &LinkModel, value: f64) -> Iso {
        match link.kind {
            JointKind::Fixed => Iso::identity(),
            JointKind::Revolute => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(link.axis), value),
            ),
            JointKind::Prismatic => {
                Isometry3::from_parts(Translation3::from(link.axis * value), UnitQuaternion::identity())
            }
        }
    }

    /// Poses of every link in the base frame.
    pub fn link_poses(&self, q: &[f64], gripper: f64) -> Vec<Iso> {
        let mut poses: Vec<Iso> = Vec::with_capacity(self.links.len());
        for link in &self.links {
            let local = link.origin * Self::joint_motion(link, self.joint_value(link, q, gripper));
            let pose = match link.parent {
                Some(p) => poses[p] * local,
                None => local,
            };
            poses.push(pose);
        }
        poses
    }

    /// Pose of the tool link in the base frame.
    pub fn tool_pose(&self, q: &[f64]) -> Iso {
        let mut pose = Iso::identity();
        for &i in &self.chain {
            let link = &self.links[i];
            pose = pose * link.origin * Self::joint_motion(link, self.joint_value(link, q, 0.0));
        }
        pose
    }

    /// Pose of link `name` in the base frame, walking only its own chain.
    pub fn pose_of(&self, name: &str, q: &[f64], gripper: f64) -> Option<Iso> {
        let mut i = self.link_index(name)?;
        let mut pose = Iso::identity();
        loop {
            let link = &self.links[i];
            pose = link.origin * Self::joint_motion(link, self.joint_value(link, q, gripper)) * pose;
            match link.parent {
                Some(p) => i = p,
                None => return Some(pose),
            }
        }
    }

    /// Tool pose and the 6×n geometric Jacobian (linear rows first) in the base frame.
    pub fn tool_jacobian(&self, q: &[f64]) -> (Iso, Vec<Vector6<f64>>) {
        let mut pose = Iso::identity();
        let mut axes: Vec<(Vector3<f64>, Vector3<f64>)> = Vec::with_capacity(self.arm_dofs());
        for &i in &self.chain {
            let link = &self.links[i];
            pose *= link.origin;
            if let JointSource::Arm(_) = link.source {
                axes.push((pose.rotation * link.axis, pose.translation.vector));
            }
            pose *= Self::joint_motion(link, self.joint_value(link, q, 0.0));
        }
        let tip = pose.translation.vector;
        let columns = axes
            .into_iter()
            .map(|(z, p)| {
                let lin = z.cross(&(tip - p));
                Vector6::new(lin.x, lin.y, lin.z, z.x, z.y, z.z)
            })
            .collect();
        (pose, columns)
    }

    /// Clamps an arm configuration into the joint limits.
    pub fn clamp(&self, q: &mut [f64]) {
        for (v, &(lo, hi)) in q.iter_mut().zip(&self.arm_limits) {
            *v = v.clamp(lo, hi);
        }
    }

    /// True if every arm value is within its limits (with a tiny tolerance).
    pub fn within_limits(&self, q: &[f64]) -> bool {
        q.iter()
            .zip(&self.arm_limits)
            .all(|(v, &(lo, hi))| *v >= lo - 1e-9 && *v <= hi + 1e-9)
    }
}

/// The tree as [`RobotModel::from_urdf_str`] grows it from the root, with the arm and
/// gripper limits found so far.
struct TreeBuilder<'a> {
    /// The parsed URDF.
    robot: &'a urdf_rs::Robot,
    /// Links added so far, parents before children.
    links: Vec<LinkModel>,
    /// Limits of the revolute joints added so far, in dof order.
    arm_limits: Vec<(f64, f64)>,
    /// Limits of the driving finger, once found.
    gripper_limits: Option<(f64, f64)>,
    /// The unmimicked prismatic joint, which every other prismatic joint must mimic.
    driving_finger: Option<String>,
}

impl<'a> TreeBuilder<'a> {
    /// An error naming the robot.
    fn invalid(&self, message: String) -> ModelError {
        ModelError::Invalid {
            robot: self.robot.name.clone(),
            message,
        }
    }

    /// A tree holding only the root: the one link that is nobody's child.
    fn rooted(robot: &'a urdf_rs::Robot) -> Result<Self, ModelError> {
        let mut tree = TreeBuilder {
            robot,
            links: Vec::new(),
            arm_limits: Vec::new(),
            gripper_limits: None,
            driving_finger: None,
        };
        let children: std::collections::HashSet<&str> =
            robot.joints.iter().map(|j| j.child.link.as_str()).collect();
        let roots: Vec<&urdf_rs::Link> = robot
            .links
            .iter()
            .filter(|l| !children.contains(l.name.as_str()))
            .collect();
        let [root] = roots.as_slice() else {
            return Err(tree.invalid(format!("expected exactly one root link, found {}", roots.len())));
        };
        let collisions = collisions_of(root).map_err(|m| tree.invalid(m))?;
        tree.links.push(LinkModel {
            name: root.name.clone(),
            parent: None,
            joint_name: String::new(),
            kind: JointKind::Fixed,
            origin: Iso::identity(),
            axis: Vector3::z(),
            limits: (0.0, 0.0),
            source: JointSource::None,
            collisions,
            mass: root.inertial.mass.value,
        });
        Ok(tree)
    }

    /// Appends the links hanging off link `parent`, in the file order of their joints.
    fn attach_children(&mut self, parent: usize) -> Result<(), ModelError> {
        let robot = self.robot;
        let parent_name = self.links[parent].name.clone();
        for joint in robot.joints.iter().filter(|j| j.parent.link == parent_name) {
            let link = robot
                .links
                .iter()
                .find(|l| l.name == joint.child.link)
                .ok_or_else(|| {
                    self.invalid(format!(
                        "joint {} names missing link {}",
                        joint.name, joint.child.link
                    ))
                })?;
            let axis = Vector3::from(joint.axis.xyz.0);
            let axis = if axis.norm() > 0.0 {
                axis.normalize()
            } else {
                Vector3::z()
            };
            let limits = (joint.limit.lower, joint.limit.upper);
            let (kind, source) = self.joint_drive(joint, limits)?;
            let collisions = collisions_of(link).map_err(|m| self.invalid(m))?;
            self.links.push(LinkModel {
                name: link.name.clone(),
                parent: Some(parent),
                joint_name: joint.name.clone(),
                kind,
                origin: pose_to_iso(&joint.origin),
                axis,
                limits,
                source,
                collisions,
                mass: link.inertial.mass.value,
            });
        }
        Ok(())
    }

    /// The joint's kind and what drives it: a revolute joint becomes the next arm dof, a
    /// prismatic one a finger.
    fn joint_drive(
        &mut self,
        joint: &urdf_rs::Joint,
        limits: (f64, f64),
    ) -> Result<(JointKind, JointSource), ModelError> {
        match joint.joint_type {
            urdf_rs::JointType::Fixed => Ok((JointKind::Fixed, JointSource::None)),
            urdf_rs::JointType::Revolute => {
                self.arm_limits.push(limits);
                Ok((JointKind::Revolute, JointSource::Arm(self.arm_limits.len() - 1)))
            }
            urdf_rs::JointType::Prismatic => Ok((JointKind::Prismatic, self.finger_source(joint, limits)?)),
            ref other => Err(self.invalid(format!("joint {} has unsupported type {other:?}", joint.name))),
        }
    }

    /// A prismatic joint's source: the first unmimicked one is the driving finger and sets
    /// the gripper's limits; the others must mimic it.
    fn finger_source(
        &mut self,
        joint: &urdf_rs::Joint,
        limits: (f64, f64),
    ) -> Result<JointSource, ModelError> {
        match &joint.mimic {
            Some(m) => {
                if self.driving_finger.as_deref() != Some(m.joint.as_str()) {
                    return Err(self.invalid(format!(
                        "joint {} mimics {}, which is not the driving finger",
                        joint.name, m.joint
                    )));
                }
                Ok(JointSource::Gripper {
                    multiplier: m.multiplier.unwrap_or(1.0),
                    offset: m.offset.unwrap_or(0.0),
                })
            }
            None => {
                if self.driving_finger.is_some() {
                    return Err(self.invalid("more than one unmimicked prismatic joint".into()));
                }
                self.driving_finger = Some(joint.name.clone());
                self.gripper_limits = Some(limits);
                Ok(JointSource::Gripper {
                    multiplier: 1.0,
                    offset: 0.0,
                })
            }
        }
    }

    /// The finished model: finds the tool link and its chain from the root, which must
    /// hold every arm dof.
    fn into_model(self, tool_link: &str) -> Result<RobotModel, ModelError> {
        let links = &self.links;
        let tool = links
            .iter()
            .position(|l| l.name == tool_link)
            .ok_or_else(|| self.invalid(format!("no link named {tool_link}")))?;
        let mut chain = vec![tool];
        while let Some(p) = links[*chain.last().unwrap_or(&0)].parent {
            chain.push(p);
        }
        chain.reverse();
        let arm_in_chain = chain
            .iter()
            .filter(|&&i| matches!(links[i].source, JointSource::Arm(_)))
            .count();
        if arm_in_chain != self.arm_limits.len() || self.arm_limits.is_empty() {
            return Err(self.invalid(format!(
                "the tool chain holds {arm_in_chain} of {} revolute joints",
                self.arm_limits.len()
            )));
        }
        Ok(RobotModel {
            name: self.robot.name.clone(),
            links: self.links,
            arm_limits: self.arm_limits,
            gripper_limits: self.gripper_limits,
            tool_link: tool,
            chain,
        })
    }
}

fn collisions_of(link: &urdf_rs::Link) -> Result<Vec<(Primitive, Iso)>, String> {
    link.collision
        .iter()
        .map(|c| {
            let shape = match &c.geometry {
                urdf_rs::Geometry::Box { size } => Primitive::Box(size.0),
                urdf_rs::Geometry::Cylinder { radius, length } => Primitive::Cylinder {
                    radius: *radius,
                    length: *length,
                },
                urdf_rs::Geometry::Capsule { radius, length } => Primitive::Capsule {
                    radius: *radius,
                    length: *length,
                },
                urdf_rs::Geometry::Sphere { radius } => Primitive::Sphere(*radius),
                urdf_rs::Geometry::Mesh { filename, .. } => {
                    return Err(format!(
                        "link {} uses mesh {filename}; only primitives are supported",
                        link.name
                    ));
                }
            };
            Ok((shape, pose_to_iso(&c.origin)))
        })
        .collect()
}

/// What the tool's orientation must satisfy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OrientationGoal {
    /// The full rotation (finger gripper: approach axis and finger direction).
    Full(UnitQuaternion<f64>),
    /// Only the tool's z axis (suction tool: symmetric about its axis).
    Axis(Vector3<f64>),
}

/// Inverse-kinematics tolerances and effort.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkOptions {
    /// Position tolerance in metres.
    pub pos_tol: f64,
    /// Orientation tolerance in radians.
    pub rot_tol: f64,
    /// Iterations per attempt.
    pub iterations: usize,
    /// Attempts (the seed plus deterministic restarts).
    pub restarts: usize,
    /// Damping factor λ of the least-squares step.
    pub damping: f64,
}

impl Default for IkOptions {
    fn default() -> Self {
        IkOptions {
            pos_tol: 2e-4,
            rot_tol: 2e-3,
            iterations: 120,
            restarts: 40,
            damping: 0.02,
        }
    }
}

/// Position and orientation error of `pose` against the goal (6-vector, linear first).
fn pose_error(pose: &Iso, target: &Vector3<f64>, goal: &OrientationGoal) -> Vector6<f64> {
    let dp = target - pose.translation.vector;
    let dr = match goal {
        OrientationGoal::Full(want) => {
            let delta = want * pose.rotation.inverse();
            delta.scaled_axis()
        }
        OrientationGoal::Axis(want) => {
            let z = pose.rotation * Vector3::z();
            let c = z.cross(want);
            let s = c.norm();
            if s < 1e-12 {
                if z.dot(want) > 0.0 {
                    Vector3::zeros()
                } else {
                    pose.rotation * Vector3::x() * std::f64::consts::PI
                }
            } else {
                c / s * s.atan2(z.dot(want))
            }
        }
    };
    Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z)
}

/// Splits a 6-error into (position norm, rotation norm).
fn error_norms(e: &Vector6<f64>) -> (f64, f64) {
    (e.fixed_rows::<3>(0).norm(), e.fixed_rows::<3>(3).norm())
}

impl RobotModel {
    /// Solves for an arm configuration within limits that puts the tool at `target` with
    /// the orientation goal. The first attempt starts from `seed`, later ones from the
    /// seed perturbed and from deterministic pseudo-random configurations. Among converged
    /// attempts, the one closest to `seed` wins (so motions stay short).
    pub fn solve_ik(
        &self,
        target: Vector3<f64>,
        goal: OrientationGoal,
        seed: &[f64],
        opts: &IkOptions,
    ) -> Option<Vec<f64>> {
        let n = self.arm_dofs();
        // Restart seeds from a fixed stream, so IK never depends on global randomness.
        let mut rng = SplitMix64::new(0x5EED_0F1C);
        let mut best: Option<(f64, Vec<f64>)> = None;
        for attempt in 0..opts.restarts.max(1) {
            let mut q: Vec<f64> = match attempt {
                0 => seed.to_vec(),
                a if a < 6 => seed
                    .iter()
                    .zip(&self.arm_limits)
                    .map(|(v, (lo, hi))| v + (rng.unit() - 0.5) * 0.5 * (hi - lo) * (a as f64 / 6.0))
                    .collect(),
                _ => self
                    .arm_limits
                    .iter()
                    .map(|(lo, hi)| lo + rng.unit() * (hi - lo))
                    .collect(),
            };
            self.clamp(&mut q);
            if let Some(sol) = self.dls(&mut q, &target, &goal, opts) {
                let dist: f64 = sol
                    .iter()
                    .zip(seed)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                if best.as_ref().is_none_or(|(d, _)| dist < *d) {
                    best = Some((dist, sol));
                }
                // A solution near the seed is as good as it gets.
                if dist < 0.5 || attempt >= 8 {
                    break;
                }
            }
            debug_assert_eq!(q.len(), n);
        }
        best.map(|(_, q)| q)
    }

    /// Damped least squares from `q`; returns the converged configuration.
    fn dls(
        &self,
        q: &mut [f64],
        target: &Vector3<f64>,
        goal: &OrientationGoal,
        opts: &IkOptions,
    ) -> Option<Vec<f64>> {
        let n = self.arm_dofs();
        let lambda2 = opts.damping * opts.damping;
        for _ in 0..opts.iterations {
            let (pose, cols) = self.tool_jacobian(q);
            let err = pose_error(&pose, target, goal);
            let (ep, er) = error_norms(&err);
            if ep < opts.pos_tol && er < opts.rot_tol {
                return Some(q.to_vec());
            }
            // Axis-only goals leave the spin about the tool axis free.
            let project = match goal {
                OrientationGoal::Axis(_) => {
                    let z = pose.rotation * Vector3::z();
                    Some(nalgebra::Matrix3::identity() - z * z.transpose())
                }
                OrientationGoal::Full(_) => None,
            };
            let cols: Vec<Vector6<f64>> = cols
                .into_iter()
                .map(|c| match project {
                    Some(p) => {
                        let w = p * Vector3::new(c[3], c[4], c[5]);
                        Vector6::new(c[0], c[1], c[2], w.x, w.y, w.z)
                    }
                    None => c,
                })
                .collect();
            // Limit the step so large errors do not throw the arm across its range.
            let mut e = err;
            let lin = e.fixed_rows::<3>(0).norm();
            if lin > 0.1 {
                let s = 0.1 / lin;
                e[0] *= s;
                e[1] *= s;
                e[2] *= s;
            }
            let ang = e.fixed_rows::<3>(3).norm();
            if ang > 0.5 {
                let s = 0.5 / ang;
                e[3] *= s;
                e[4] *= s;
                e[5] *= s;
            }
            let mut jjt = Matrix6::<f64>::zeros();
            for c in &cols {
                jjt += c * c.transpose();
            }
            for i in 0..6 {
                jjt[(i, i)] += lambda2;
            }
            let y = jjt.cholesky()?.solve(&e);
            for (j, c) in cols.iter().enumerate().take(n) {
                q[j] += c.dot(&y);
            }
            self.clamp(q);
        }
        let (pose, _) = self.tool_jacobian(q);
        let (ep, er) = error_norms(&pose_error(&pose, target, goal));
        (ep < opts.pos_tol && er < opts.rot_tol).then(|| q.to_vec())
    }
}

/// The orientation of a tool whose z axis points along `dir` (a unit vector), spun by
/// `angle` about it. For `dir = −z` this is `Rz(angle)·Rx(π)`, the authors' convention.
pub fn pointing_rotation(dir: Vector3<f64>, angle: f64) -> UnitQuaternion<f64> {
    let down = Vector3::new(0.0, 0.0, -1.0);
    let base = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    let align = UnitQuaternion::rotation_between(&down, &dir)
        .unwrap_or_else(|| UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI));
    align * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle) * base
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pointing_down_is_rz_rx() {
        let r = pointing_rotation(Vector3::new(0.0, 0.0, -1.0), 0.3);
        let want = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3)
            * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
        assert!(r.angle_to(&want) < 1e-12);
    }
}
