//! The demo cache: every scenario's source demonstration is recorded once by the scripted
//! expert and shared by every method and variant.
//!
//! A scenario's folder holds `demo.mcap`, `target.json` and `record.json`. The record names
//! the cache key: the SHA-256 of the scenario's source and target task configurations, the
//! simulator's fingerprint and the image size. A key that differs (a changed simulator, an
//! edited suite) means the demo is recorded again; a stale demo is never reused.

use std::path::{Path, PathBuf};
use std::time::Instant;

use nesy_sim::demo::{RecordOptions, record_scene, write_mcap_file};
use nesy_sim::tasks::scenario::{Scenario, Side};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::error::BenchError;
use crate::variant::hex;

/// What the cache knows about a recorded demonstration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DemoRecord {
    /// The cache key it was recorded under.
    pub key: String,
    /// The scenario.
    pub scenario: String,
    /// The expert finished and every subtask reached `full_success`.
    pub full_success: bool,
    /// Latched objects out of place at the end (the final state lacks them).
    pub displaced: Vec<String>,
    /// Why the expert stopped early, if it did.
    pub expert_error: Option<String>,
    /// The goal checks' summary.
    pub summary: String,
    /// Keyframes recorded.
    pub keyframes: usize,
    /// Simulated seconds.
    pub sim_seconds: f64,
    /// Wall seconds simulating and rendering.
    pub wall_s: f64,
    /// When it was recorded.
    pub recorded_at: String,
}

impl DemoRecord {
    /// True when the demo shows its goal and can be adapted from.
    pub fn usable(&self) -> bool {
        self.full_success && self.displaced.is_empty() && self.expert_error.is_none()
    }

    /// Why the demo cannot be used, when it cannot.
    pub fn unusable_reason(&self) -> Option<String> {
        if let Some(e) = &self.expert_error {
            return Some(format!("the expert stopped: {e}"));
        }
        if !self.full_success {
            return Some(format!("the expert did not succeed: {}", self.summary));
        }
        if !self.displaced.is_empty() {
            return Some(format!(
                "placed objects ended out of place, so the demo's final state lacks them: {}",
                self.displaced.join(", ")
            ));
        }
        None
    }
}

/// A demonstration in the cache, ready to load.
#[derive(Debug, Clone)]
pub struct CachedDemo {
    /// `demo.mcap`.
    pub demo: PathBuf,
    /// `target.json`.
    pub target: PathBuf,
    /// Its record.
    pub record: DemoRecord,
    /// True when this call recorded it (false: it was in the cache).
    pub recorded_now: bool,
}

/// The cache folder.
#[derive(Debug, Clone)]
pub struct DemoCache {
    dir: PathBuf,
    image_size: u32,
    protective_stop: bool,
}

impl DemoCache {
    /// A cache in `dir`, recording views of `image_size` pixels with the robot's protective
    /// stop off.
    pub fn new(dir: impl Into<PathBuf>, image_size: u32) -> DemoCache {
        DemoCache {
            dir: dir.into(),
            image_size,
            protective_stop: false,
        }
    }

    /// The same cache with the robot's protective stop set as given, in the demonstrations
    /// it records and the target scenes it writes (part of the cache key).
    pub fn with_protective_stop(mut self, on: bool) -> DemoCache {
        self.protective_stop = on;
        self
    }

    /// The cache folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The cache key of a scenario's demonstration.
    pub fn key(&self, scenario: &Scenario) -> String {
        let mut h = Sha256::new();
        for side in [Side::Source, Side::Target] {
            let task = serde_json::to_string(&scenario.task(side)).unwrap_or_default();
            h.update((task.len() as u64).to_le_bytes());
            h.update(task.as_bytes());
        }
        h.update(nesy_sim::FINGERPRINT.as_bytes());
        h.update(self.image_size.to_le_bytes());
        if self.protective_stop {
            h.update(b"protective stop");
        }
        hex(&h.finalize())
    }

    /// The cached demonstration if it is current, else `None`.
    pub fn lookup(&self, scenario: &Scenario) -> Option<CachedDemo> {
        let folder = self.dir.join(&scenario.id);
        let record: DemoRecord = std::fs::read_to_string(folder.join("record.json"))
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())?;
        let demo = folder.join("demo.mcap");
        let target = folder.join("target.json");
        (record.key == self.key(scenario) && demo.is_file() && target.is_file()).then_some(CachedDemo {
            demo,
            target,
            record,
            recorded_now: false,
        })
    }

    /// The scenario's demonstration: from the cache when current, else recorded now with
    /// `render_threads` renderer threads. Files are written under temporary names and
    /// renamed, so a concurrent or killed recorder never leaves a half-written demo.
    pub fn ensure(&self, scenario: &Scenario, render_threads: usize) -> Result<CachedDemo, BenchError> {
        if let Some(hit) = self.lookup(scenario) {
            return Ok(hit);
        }
        let started = Instant::now();
        let mut source = scenario.generate(Side::Source)?.scene;
        let mut target = scenario.generate(Side::Target)?.scene;
        source.protective_stop = self.protective_stop;
        target.protective_stop = self.protective_stop;
        let options = RecordOptions {
            image_size: self.image_size,
            render_threads: render_threads.max(1),
            scenario_id: Some(scenario.id.clone()),
            side: Some(Side::Source.as_str().to_owned()),
            target_scene: Some(target.clone()),
        };
        let recording = record_scene(&source, &options).map_err(|e| BenchError::Format {
            path: self.dir.join(&scenario.id),
            message: format!("recording the demonstration: {e}"),
        })?;
        let folder = self.dir.join(&scenario.id);
        std::fs::create_dir_all(&folder).map_err(|e| BenchError::io(&folder, e))?;
        let tag = format!("{}.tmp", std::process::id());
        let demo = folder.join("demo.mcap");
        let demo_tmp = folder.join(format!("demo.mcap.{tag}"));
        write_mcap_file(&recording.demo, &demo_tmp).map_err(|e| BenchError::Format {
            path: demo_tmp.clone(),
            message: e.to_string(),
        })?;
        let target_path = folder.join("target.json");
        let record = DemoRecord {
            key: self.key(scenario),
            scenario: scenario.id.clone(),
            full_success: recording.full_success(),
            displaced: recording.outcome.displaced.clone(),
            expert_error: recording.expert_error.as_ref().map(|e| e.to_string()),
            summary: recording.outcome.summary(),
            keyframes: recording.demo.keyframes.len(),
            sim_seconds: recording.sim_seconds,
            wall_s: started.elapsed().as_secs_f64(),
            recorded_at: nesy_vlm::now_rfc3339(),
        };
        // The demo and the target first, the record (which makes them current) last: a
        // reader that finds a stale record records again, and a current record always has
        // its files.
        std::fs::rename(&demo_tmp, &demo).map_err(|e| BenchError::io(&demo, e))?;
        let writes = [
            (target_path.clone(), target.to_json_pretty() + "\n"),
            (
                folder.join("record.json"),
                serde_json::to_string_pretty(&record).unwrap_or_default() + "\n",
            ),
        ];
        for (path, text) in &writes {
            let tmp = path.with_extension(format!("json.{tag}"));
            std::fs::write(&tmp, text).map_err(|e| BenchError::io(&tmp, e))?;
            std::fs::rename(&tmp, path).map_err(|e| BenchError::io(path, e))?;
        }
        Ok(CachedDemo {
            demo,
            target: target_path,
            record,
            recorded_now: true,
        })
    }
}
