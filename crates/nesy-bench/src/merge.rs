//! Merging a sharded run: every shard's results file is read, the union must be exactly the
//! manifest's units (none missing, none twice, all of the manifest's configuration), and
//! then the report is written. A partial merge is only possible on request and is stamped.

use std::path::Path;

use serde::Serialize;

use crate::error::BenchError;
use crate::report::{self, ReportFiles, ReportOptions};

/// What a merge found and wrote.
#[derive(Debug, Clone, Serialize)]
pub struct Merged {
    /// Results files read.
    pub files: usize,
    /// Units with a final record.
    pub units: usize,
    /// Units of the manifest.
    pub expected: usize,
    /// The report.
    pub report: ReportFiles,
}

/// Checks the shards of `run` and writes its report.
pub fn merge(run: &Path, allow_partial: bool) -> Result<Merged, BenchError> {
    let manifest = crate::manifest::Manifest::read(run)?;
    let files = std::fs::read_dir(crate::store::results_dir(run))
        .map(|d| {
            d.flatten()
                .filter(|e| e.path().extension().is_some_and(|x| x == "jsonl"))
                .count()
        })
        .unwrap_or(0);
    if files == 0 {
        return Err(BenchError::Incomplete {
            message: format!(
                "{}: no results files under results/ (did the shards write to another run directory?)",
                run.display()
            ),
            missing: manifest.units.iter().map(|u| u.name()).collect(),
            duplicates: Vec::new(),
        });
    }
    let records = crate::harness::final_records(run)?;
    let report = report::write(run, &ReportOptions { allow_partial })?;
    Ok(Merged {
        files,
        units: records.len(),
        expected: manifest.units.len(),
        report,
    })
}
