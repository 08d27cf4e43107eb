//! Running a benchmark: the manifest first, then every pending unit of this shard, each in
//! two phases — (A) the method's specification and its code, (B) execution in the
//! simulator — with one result line appended per unit as it finishes.
//!
//! Running the same command again resumes: units with a final record are skipped, units
//! whose last record is retryable (transport errors, interruptions) or that have none run
//! again. Demos come from the [`DemoCache`](crate::demos::DemoCache); each scenario's demo and target scene are
//! loaded once per process and shared by the variants that run on it.
//!
//! Concurrency: `jobs` units run at once; the CPU-bound stages (recording, building and
//! rendering scenes, executing policies) share `cpu_jobs` slots, and model calls share
//! `model_jobs` slots across all units. When a scenario's first unit starts, the next
//! scenario's demo is recorded (or loaded) ahead, so a free slot never waits on one
//! scenario's recording.

mod config;
mod reexec;
mod schedule;
mod shared;
mod unit;

pub use config::{
    BenchProgress, Prepared, Quiet, ResponderSetup, RunConfig, RunSummary, StopSignal, default_run_id,
    describe_responder, load_suite, prepare, run_suite,
};
pub use reexec::file_digest;
pub use schedule::{missing_units, run};
pub use shared::final_records;

#[cfg(test)]
mod tests {

    use super::unit::*;
    use std::path::Path;

    use crate::unit::UnitKey;
    use crate::variant::Variant;

    #[test]
    fn every_unit_has_its_own_recording() {
        let root = Path::new("/c");
        let path = |variant: &str, repeat: u32| {
            let v = Variant::parse(variant).unwrap();
            let key = UnitKey {
                scenario: "obst_low_00_s0".to_owned(),
                variant: v.id(),
                repeat,
            };
            recording_path(&key, &v, root)
        };
        let paths = [
            path("nesycr", 0),
            path("nesycr", 1),
            path("nesycr", 2),
            path("nesycr+noise=op-drop=0.1", 0),
            path("nesycr+noise=op-drop=0.2", 0),
        ];
        for (i, a) in paths.iter().enumerate() {
            assert_eq!(a.extension().and_then(|e| e.to_str()), Some("json"), "{a:?}");
            for b in &paths[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }
}
