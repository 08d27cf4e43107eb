//! # nesy-bench
//!
//! The benchmark of the paper: NeSyCR and the other methods over the 440 scenarios, with
//! SR, GC and PD per domain factor × complexity, shaped like the paper's Table 1.
//!
//! - [`methods`]: the [`methods::Method`] interface (episode inputs → a task specification)
//!   and the methods: `nesycr` (with its ablation switches as settings), `nesycr-released`,
//!   `code-as-policies`, and the model-free controls `imitation` and `replan`.
//! - [`harness`]: a run — the manifest first, then every pending unit of a shard, phase A
//!   (specification and code) and phase B (execution), one JSON line per finished unit;
//!   running it again resumes.
//! - [`demos`]: each scenario's demonstration recorded once, keyed by the scenario and the
//!   simulator's fingerprint.
//! - [`Shard`], [`merge`]: job arrays and their merge; [`slurm`] writes the `sbatch` file.
//! - [`call_budget`]: model calls and images per method and cell, before any call.
//! - [`report`]: `report.md`, `tables/*.csv` and PNG plots.
//! - [`studies`]: the ablation and robustness studies, each a set of variants under one
//!   stated error model, reported in the shape of the paper's Table 3 and Table 8.
//!
//! Offline, no number is a method's performance: the reference responder bounds NeSyCR
//! from above, the controls measure the benchmark, and every report says which it is.
//!
//! A method with its settings is a [`Variant`], written as on the command line:
//!
//! ```
//! use nesy_bench::Variant;
//! use nesy_bench::methods::parse_variants;
//!
//! let variants = parse_variants("nesycr,nesycr+verification=off,replan").unwrap();
//! assert_eq!(variants[1].method, "nesycr");
//! assert_eq!(variants[1].option("verification"), Some("off"));
//! assert!(Variant::parse("nesycr+verification").is_err());
//! ```

pub mod call_budget;
pub mod compare;
pub mod demos;
mod error;
pub mod harness;
pub mod manifest;
pub mod merge;
pub mod meter;
pub mod methods;
pub mod pool;
pub mod report;
mod shard;
pub mod slurm;
pub mod stats;
mod status;
pub mod store;
pub mod studies;
mod unit;
mod unit_record;
mod variant;

pub use error::BenchError;
pub use shard::Shard;
pub use status::UnitStatus;
pub use unit::Selection;
pub use unit_record::UnitRecord;
pub use variant::Variant;
