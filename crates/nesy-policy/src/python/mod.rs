//! The embedded interpreter and the sandbox layers that live inside it.

pub(crate) mod abort;
pub(crate) mod audit;
pub(crate) mod budget;
pub(crate) mod builtins;
pub(crate) mod convert;
pub(crate) mod interpreter;
pub(crate) mod output;
pub(crate) mod robot_module;
pub(crate) mod session;
