//! # nesy-sim
//!
//! The simulated world in which nesy's code policies run: a Franka Panda (finger gripper
//! or vacuum tool) at a table, the benchmark's objects, the robot API of the paper, and
//! the symbolic observer that turns geometry into `nesy_core::State`.
//!
//! Entry points: [`scene::SceneSpec`] (the `scene.json` format), [`Sim`] (the world; it
//! implements [`api::RobotApi`]), [`observer::observe`] and [`render::render_views`].

pub mod api;
mod api_impl;
pub mod codegen;
pub mod demo;
pub mod expert;
pub mod floor;
pub mod geometry;
pub mod goal;
pub mod kinematics;
pub mod motion;
pub mod objects;
pub mod observer;
pub mod planner;
pub mod render;
pub mod rng;
pub mod robot;
pub mod scenario;
pub mod scene;
pub mod sim;
pub mod task;

pub use api::{ApiCall, ApiError, ApiValue, Direction, Embodiment, RobotApi, TraceEntry};
pub use api_impl::HANDLE_REACH;
pub use observer::observe;
pub use scene::{SceneError, SceneSpec};
pub use sim::{Sim, SimConfig, SimHook};
