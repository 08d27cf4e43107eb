//! Helpers shared by the oracle tests (`oracle_adapt`, `oracle_codegen`, `oracle_domain`).

use nesy_core::state::State;
use nesy_sim::{Sim, SimHook, TraceEntry, observe};

/// Records, after every successful action call, the call (as JSON) and the observed state:
/// the keyframes of a demonstration without the images.
#[derive(Default)]
pub struct Keyframes {
    /// The calls with the state after each.
    pub calls: Vec<(serde_json::Value, State)>,
}

impl SimHook for Keyframes {
    fn on_call(&mut self, sim: &Sim, entry: &TraceEntry) {
        if entry.call.is_action() && entry.result.is_ok() {
            self.calls
                .push((serde_json::to_value(&entry.call).unwrap(), observe(sim)));
        }
    }
}
