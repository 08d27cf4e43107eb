//! The results store: one append-only JSON-lines file per shard under `results/`, one line
//! per finished unit, flushed and synced before the unit counts as done. Reading tolerates a
//! torn last line (a process killed mid-write); any other malformed line is an error naming
//! the file and the line.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::BenchError;
use crate::unit_record::UnitRecord;

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
    /// Opens (creating it if needed) the file for appending. A torn last line (a process
    /// killed mid-write) is cut off first: its unit never counted as done and is redone, and
    /// the next record starts on a line of its own.
    pub fn open(path: &Path) -> Result<ResultsWriter, BenchError> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| BenchError::io(dir, e))?;
        }
        let complete = match std::fs::read(path) {
            Ok(bytes) if !bytes.is_empty() && !bytes.ends_with(b"\n") => {
                Some(bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1))
            }
            _ => None,
        };
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|e| BenchError::io(path, e))?;
        if let Some(len) = complete {
            file.set_len(len as u64)
                .and_then(|()| file.sync_data())
                .map_err(|e| BenchError::io(path, e))?;
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
    let text = nesy_input::read_text(path, MAX_RECORDS_BYTES).map_err(|e| BenchError::io(path, e))?;
    parse_records(path, &text)
}

/// Cap for one JSONL file of unit records (the 440 scenarios under three methods wrote
/// 1.5 MB).
pub const MAX_RECORDS_BYTES: u64 = 1 << 30;

/// The records of JSONL text (`path` names it in errors), with [`read_file`]'s rule for a
/// torn last line.
pub fn parse_records(path: &Path, text: &str) -> Result<Vec<UnitRecord>, BenchError> {
    let lines: Vec<&str> = text.lines().collect();
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

#[cfg(test)]
pub(crate) mod tests {
    use nesy_core::benchmark::{Complexity, Factor};

    use super::*;
    use crate::status::UnitStatus;
    use crate::unit::UnitKey;
    use crate::unit_record::{Effort, Scores};

    pub(crate) fn record(scenario: &str, variant: &str, status: UnitStatus, sr: f64) -> UnitRecord {
        UnitRecord {
            key: UnitKey {
                scenario: scenario.into(),
                variant: variant.into(),
                repeat: 0,
            },
            method: variant.into(),
            factor: Factor::Obst,
            complexity: Complexity::Low,
            added_subtasks: None,
            obstruction_change: None,
            seed: 1,
            config_hash: "h".into(),
            status,
            error: None,
            scores: Scores {
                sr,
                gc: sr,
                latched_sr: sr,
                latched_gc: sr,
                pd: 1.0 - sr,
                label: vec!["a".into()],
                achieved: Vec::new(),
                subtasks: Vec::new(),
            },
            spec: None,
            states: None,
            effort: Effort::default(),
            artifacts: String::new(),
            finished_at: String::new(),
        }
    }

    #[test]
    fn a_torn_last_line_is_skipped_and_the_next_record_starts_clean() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("results/shard-0-of-1.jsonl");
        let mut w = ResultsWriter::open(&path).unwrap();
        w.append(&record("s1", "m", UnitStatus::Succeeded, 1.0)).unwrap();
        drop(w);
        // A kill in the middle of the second write.
        let mut bytes = std::fs::read(&path).unwrap();
        bytes.extend_from_slice(b"{\"scenario\":\"s2\",\"vari");
        std::fs::write(&path, bytes).unwrap();
        assert_eq!(read_file(&path).unwrap().len(), 1);
        let mut w = ResultsWriter::open(&path).unwrap();
        w.append(&record("s3", "m", UnitStatus::Unresolved, 0.0)).unwrap();
        let records = read_file(&path).unwrap();
        assert_eq!(records.len(), 2, "the torn line is cut off, the new one is read");
        assert_eq!(records[1].key.scenario, "s3");
        // A malformed line that is not the last one is an error naming the line.
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, format!("not json\n{text}")).unwrap();
        let e = read_file(&path).unwrap_err().to_string();
        assert!(e.contains("line 1"), "{e}");
    }

    #[test]
    fn retryable_records_are_superseded_and_final_ones_kept() {
        let by = latest_by_unit(vec![
            record("s1", "m", UnitStatus::TransportError, 0.0),
            record("s1", "m", UnitStatus::Succeeded, 1.0),
            record("s2", "m", UnitStatus::Interrupted, 0.0),
            record("s3", "m", UnitStatus::Succeeded, 1.0),
            record("s3", "m", UnitStatus::Succeeded, 1.0),
        ]);
        assert_eq!(by["s1/m/r0"].len(), 1);
        assert_eq!(by["s1/m/r0"][0].status, UnitStatus::Succeeded);
        assert_eq!(by["s2/m/r0"][0].status, UnitStatus::Interrupted);
        assert_eq!(
            by["s3/m/r0"].len(),
            2,
            "a duplicate final record is kept for merge to report"
        );
        assert!(UnitStatus::TransportError.is_final().eq(&false) && !UnitStatus::Interrupted.is_final());
        assert!(UnitStatus::MethodError.is_scored() && !UnitStatus::DemoUnusable.is_scored());
    }
}
