//! The embedded interpreter and the sandbox layers that live inside it.

pub mod abort;
pub mod audit;
pub mod budget;
pub mod builtins;
pub mod convert;
pub mod interpreter;
pub(crate) mod output;
pub mod robot_module;
pub mod session;
