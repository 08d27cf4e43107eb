//! # nesy-robot
//!
//! The robot protocol (`docs/robot-protocol.md`): how a policy that nesy runs in its sandbox
//! drives a robot outside it. The protocol is JSON-RPC 2.0, one JSON object per line over a
//! TCP or Unix socket, carrying exactly the robot API policies use, plus `hello`, `heartbeat`,
//! `get_tool_pos`, `finish` and `stop`.
//!
//! - [`RobotClient`] is one connection with a heartbeat thread and per-call time limits.
//! - [`Bridge`] answers the sandbox's relayed calls ([`nesy_policy::run_relayed`]) from a
//!   client, after checking each motion against a [`Workspace`] and, optionally, asking the
//!   operator; it logs every call and answer.
//! - [`serve_session`] serves any [`nesy_policy::Episode`] over the protocol, with the
//!   heartbeat watchdog the protocol requires; `nesy robot-server` serves the simulator with it.
//!
//! ```
//! use nesy_robot::{RobotAddress, Workspace};
//!
//! let address: RobotAddress = "unix:/run/robot.sock".parse().unwrap();
//! assert_eq!(address.to_string(), "unix:/run/robot.sock");
//! let box_: Workspace = "0.1,-0.5,0.45,0.8,0.5,1.3".parse().unwrap();
//! assert!(box_.contains([0.4, 0.0, 0.6]));
//! ```

mod address;
mod bridge;
mod client;
mod protocol;
mod safety;
mod server;

pub use address::{AddressError, Listener, RobotAddress};
pub use bridge::{Bridge, Confirm};
pub use client::{ClientFault, ClientOptions, RobotClient};
pub use protocol::{Hello, MAX_MESSAGE_BYTES, PROTOCOL_VERSION, Welcome, codes};
pub use safety::{Workspace, WorkspaceError};
pub use server::{EventLog, ServerOptions, SessionEnd, serve_session};
