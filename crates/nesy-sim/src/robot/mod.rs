//! The robot: the two Panda variants and their kinematic model, motion generation along
//! straight tool lines, and the joint-space planner used when no straight route is clear.
//!
//! - [`model`]: the URDFs, tool links, home configuration and mounting pose.
//! - [`kinematics`]: the kinematic tree read from a URDF, forward kinematics, the Jacobian
//!   and inverse kinematics.
//! - `motion`: the robot API's motions on [`crate::world::Sim`]: IK-sampled straight
//!   segments, transit checks against loose objects, detours, eased playback.
//! - `planner`: RRT-Connect in joint space with shortcutting, seeded from the problem.

pub mod kinematics;
pub mod model;
pub(crate) mod motion;
pub(crate) mod planner;
