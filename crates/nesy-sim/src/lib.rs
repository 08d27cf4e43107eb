//! # nesy-sim
//!
//! The simulated world in which nesy's code policies run: a Franka Panda (finger gripper
//! or vacuum tool) at a table, the benchmark's objects, the robot API of the paper, and
//! the symbolic observer that turns geometry into `nesy_core::State`.

pub mod api;
