//! The results store: one append-only JSON-lines file per shard under `results/`, one line
//! per finished unit, flushed and synced before the unit counts as done. Reading tolerates a
//! torn last line (a process killed mid-write); any other malformed line is an error naming
//! the file and the line.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

use crate::error::BenchError;
use crate::record::UnitRecord;

/// The results folder of a run.
pub fn results_dir(run: &Path) -> PathBuf {
    run.join("results")
}

/// The results file of shard `i` of `n`.
pub fn shard_file(run: &Path, shard: crate::shard::Shard) -> PathBuf {
    results_dir(run).join(format!("shard-{}-of-{}.jsonl", shard.index, shard.count))
}

/// Appends records to a shard's file.
pub struct ResultsWriter {
    path: PathBuf,
    file: File,
}

impl ResultsWriter {
    /// Opens (creating it if needed) the file for appending. A file whose last line was torn
    /// gets a newline first, so the next record starts on a line of its own.
    pub fn open(path: &Path) -> Result<ResultsWriter, BenchError> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| BenchError::io(dir, e))?;
        }
        let torn = match std::fs::read(path) {
            Ok(bytes) => !bytes.is_empty() && !bytes.ends_with(b"\n"),
            Err(_) => false,
        };
        let mut file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|e| BenchError::io(path, e))?;
        if torn {
            file.write_all(b"\n").map_err(|e| BenchError::io(path, e))?;
        }
        Ok(ResultsWriter {
            path: path.to_owned(),
            file,
        })
    }

    /// Appends one record as one line, then flushes and syncs the file.
    pub fn append(&mut self, record: &UnitRecord) -> Result<(), BenchError> {
        let mut line = serde_json::to_string(record)
            .map_err(|e| BenchError::io(&self.path, std::io::Error::other(e)))?;
        line.push('\n');
        self.file
            .write_all(line.as_bytes())
            .and_then(|()| self.file.flush())
            .and_then(|()| self.file.sync_data())
            .map_err(|e| BenchError::io(&self.path, e))
    }
}

/// The records of one file, in order. The last line may be torn (skipped); a malformed line
/// before it is an error.
pub fn read_file(path: &Path) -> Result<Vec<UnitRecord>, BenchError> {
    let file = File::open(path).map_err(|e| BenchError::io(path, e))?;
    let lines: Vec<String> = BufReader::new(file)
        .lines()
        .collect::<Result<_, _>>()
        .map_err(|e| BenchError::io(path, e))?;
    let mut records = Vec::with_capacity(lines.len());
    let last = lines.len().saturating_sub(1);
    for (i, line) in lines.iter().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<UnitRecord>(line) {
            Ok(r) => records.push(r),
            // A kill during the write leaves a partial last line: that unit is redone.
            Err(_) if i == last => {}
            Err(e) => {
                return Err(BenchError::Format {
                    path: path.to_owned(),
                    message: format!("line {}: not a unit record: {e}", i + 1),
                });
            }
        }
    }
    Ok(records)
}

/// Every record under the run's `results/`, from all shards, files in name order.
pub fn read_all(run: &Path) -> Result<Vec<UnitRecord>, BenchError> {
    let dir = results_dir(run);
    let mut files: Vec<PathBuf> = match std::fs::read_dir(&dir) {
        Ok(entries) => entries
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "jsonl"))
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(BenchError::io(&dir, e)),
    };
    files.sort();
    let mut all = Vec::new();
    for f in files {
        all.extend(read_file(&f)?);
    }
    Ok(all)
}

/// The latest record of each unit: a unit retried after a transport error has several
/// lines; a later final one supersedes an earlier retryable one. Two final records of one
/// unit are kept both, so a merge can report the duplicate.
pub fn latest_by_unit(records: Vec<UnitRecord>) -> BTreeMap<String, Vec<UnitRecord>> {
    let mut by: BTreeMap<String, Vec<UnitRecord>> = BTreeMap::new();
    for r in records {
        let slot = by.entry(r.key.name()).or_default();
        // Retryable records are superseded by whatever comes after them.
        slot.retain(|old| old.status.is_final());
        if r.status.is_final() || slot.is_empty() {
            slot.push(r);
        }
    }
    by
}
