//! Helpers shared by the responder's tests (`adapt`, `codegen`, `domain`).

use nesy_core::State;
use nesy_sim::api::{ApiCall, TraceEntry};
use nesy_sim::perception::observer::observe;
use nesy_sim::world::{Sim, SimHook};

/// Records, after every successful action call, the call and the observed state:
/// the keyframes of a demonstration without the images.
#[derive(Default)]
pub(crate) struct Keyframes {
    /// The calls with the state after each.
    pub calls: Vec<(ApiCall, State)>,
}

impl SimHook for Keyframes {
    fn on_call(&mut self, sim: &Sim, entry: &TraceEntry) {
        if entry.call.is_action() && entry.result.is_ok() {
            self.calls.push((entry.call.clone(), observe(sim)));
        }
    }
}
