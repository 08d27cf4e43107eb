//! # nesy-policy
//!
//! Runs untrusted, model-written Python code policies in an embedded CPython against
//! nesy-sim's robot API, inside a layered sandbox.
