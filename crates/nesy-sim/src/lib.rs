//! # nesy-sim
//!
//! The simulated world in which nesy's code policies run: a Franka Panda (finger gripper
//! or vacuum tool) at a table, the benchmark's objects, the robot API of the paper, and
//! the symbolic observer that turns geometry into `nesy_core::State`.
//!
//! The modules are layers, lowest first:
//!
//! - [`api`]: the robot API contract ([`api::RobotApi`]) that policies and experts call.
//! - [`scene`]: the `scene.json` format, part names and joints, subtask goals.
//! - [`world`]: the Rapier world ([`world::Sim`]) built from a scene; it implements the API.
//! - [`robot`]: the Panda models, kinematics, motion generation and the planner.
//! - [`perception`]: the symbolic observer and the renderer.
//! - [`tasks`]: the benchmark's tasks, goal checks, scripted experts and scenarios.
//! - [`demo`]: recorded demonstrations (MCAP and folders) and the recorder.
//! - [`domain`]: the world's true domain (`assets/pddl/nesy-world.pddl`) and what each of
//!   its schemas does on the robot.
//! - [`codegen`]: the template compiler from symbolic actions to robot-API code.
//!
//! ```
//! use nesy_core::Embodiment;
//! use nesy_sim::api::RobotApi;
//! use nesy_sim::perception::observer::observe;
//! use nesy_sim::scene::SubtaskKind;
//! use nesy_sim::tasks::TaskConfig;
//! use nesy_sim::world::Sim;
//!
//! let task = TaskConfig::single(SubtaskKind::PickPlace, 3, 0, 0, Embodiment::Finger)
//!     .generate()
//!     .unwrap();
//! let mut sim = Sim::new(&task.scene).unwrap();
//! assert!(sim.get_obj_names().contains(&"toy_box".to_owned()));
//! let state = observe(&sim);
//! assert!(state.to_string().contains("(GripperOpen)"));
//! ```

pub mod api;
pub mod codegen;
pub mod demo;
pub mod domain;
pub mod perception;
pub mod robot;
pub mod scene;
pub mod tasks;
pub mod world;

/// The simulator's fingerprint: its version and a hash of its sources and robot models.
/// Anything recorded with the simulator (demonstrations) is keyed by it.
pub const FINGERPRINT: &str = env!("NESY_SIM_FINGERPRINT");
