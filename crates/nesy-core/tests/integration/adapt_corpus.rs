//! Replays every recorded run of `tests/adapt_corpus/` through `adapt::run` and checks that
//! the loop reaches the recorded outcome: same status, same number of proposals, same final
//! procedure. This pins the behaviour the `adapt` bench times.

#[path = "../../benches/replay/mod.rs"]
mod replay;

use nesy_core::adapt::{self, Outcome};

#[test]
fn every_recorded_run_replays_to_its_recorded_outcome() {
    let runs = replay::load_all();
    assert!(runs.len() >= 10, "corpus holds {} runs", runs.len());
    for run in &runs {
        let inputs = run.inputs();
        let mut reasoner = run.reasoner();
        let adaptation = pollster::block_on(adapt::run(
            &mut reasoner,
            &inputs.demo,
            &inputs.target,
            &inputs.config,
        ))
        .unwrap_or_else(|e| panic!("{}: {e}", run.scenario));
        assert!(
            adaptation.world_model.is_verified(),
            "{}: world model",
            run.scenario
        );
        let (outcome, iterations) = match &adaptation.outcome {
            Outcome::Adapted { iterations, .. } => ("adapted", *iterations),
            Outcome::Unresolved { iterations, .. } => ("unresolved", *iterations),
        };
        assert_eq!(outcome, run.expected.outcome, "{}: outcome", run.scenario);
        assert_eq!(
            iterations, run.expected.iterations,
            "{}: iterations",
            run.scenario
        );
        let names: Vec<&str> = adaptation
            .outcome
            .procedure()
            .iter()
            .map(|o| o.name.as_str())
            .collect();
        assert_eq!(names, run.expected.procedure, "{}: procedure", run.scenario);
    }
}
