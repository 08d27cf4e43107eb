//! Helpers shared by the integration tests.
#![allow(dead_code)]

use nesy_sim::perception::observer::observe;
use nesy_sim::world::Sim;

/// Builds the world of a scene fixture.
pub(crate) fn load(name: &str) -> Sim {
    Sim::from_file(&nesy_testkit::scene_fixture(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Asserts that the observed state holds every `present` atom and none of `absent`.
#[track_caller]
pub(crate) fn expect(sim: &Sim, step: &str, present: &[&str], absent: &[&str]) {
    let state = observe(sim).to_string();
    let atoms: Vec<&str> = state.lines().map(|l| l.trim_start_matches("- ")).collect();
    for p in present {
        assert!(atoms.contains(p), "after {step}: expected {p} in\n{state}");
    }
    for a in absent {
        assert!(!atoms.contains(a), "after {step}: did not expect {a} in\n{state}");
    }
}
