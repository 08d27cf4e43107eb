//! Helpers shared by the responder's tests (`adapt`, `codegen`, `domain`).

use nesy_core::state::State;
use nesy_sim::{ApiCall, Sim, SimHook, TraceEntry, observe};

/// Records, after every successful action call, the call and the observed state:
/// the keyframes of a demonstration without the images.
#[derive(Default)]
pub struct Keyframes {
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
