//! Why a benchmark command could not do its work.

use std::path::PathBuf;

/// Everything the harness can fail with (a unit's own failure is a status in its record,
/// never one of these).
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// The command line or the run's settings are not acceptable.
    #[error("{0}")]
    Usage(String),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A file does not have the expected content.
    #[error("{}: {message}", path.display())]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the line or field.
        message: String,
    },
    /// The run directory holds another configuration than the one asked for.
    #[error("{}: {message}", path.display())]
    Mismatch {
        /// The manifest.
        path: PathBuf,
        /// What differs.
        message: String,
    },
    /// Merging shards found missing or duplicate units.
    #[error("{message}")]
    Incomplete {
        /// The summary, listing the units.
        message: String,
        /// Units without a final record.
        missing: Vec<String>,
        /// Units with more than one record.
        duplicates: Vec<String>,
    },
    /// The scenario suite could not be loaded or a scene not generated.
    #[error(transparent)]
    Scenario(Box<nesy_sim::tasks::scenario::ScenarioError>),
}

impl From<nesy_sim::tasks::scenario::ScenarioError> for BenchError {
    fn from(e: nesy_sim::tasks::scenario::ScenarioError) -> BenchError {
        BenchError::Scenario(Box::new(e))
    }
}

impl BenchError {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> BenchError {
        BenchError::Io {
            path: path.into(),
            source,
        }
    }
}
