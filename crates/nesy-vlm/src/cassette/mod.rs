//! Cassettes: record live calls to a file and replay them offline, as a [`Transport`] under
//! the client's retry layer.
//!
//! Modes follow vcrpy: `none` replays only and never touches the network; `once` records
//! everything if the file does not exist yet and otherwise behaves like `none`;
//! `new_episodes` replays what matches and records the rest; `all` records every call
//! afresh (the previous recording is discarded at the first write).
//!
//! A request matches by its key (see [`canonical`]); identical requests replay in the order
//! they were sent, which concurrent calls need: they complete in whatever order the server
//! finishes them. Recording appends each interaction as it completes, rewriting the file atomically
//! under a lock file, so a crash loses at most the call in flight and `new_episodes` resumes
//! where a broken recording stopped.

use std::collections::{HashMap, VecDeque};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::capabilities::ServerCapabilities;
use crate::constraint::ConstrainMode;
use crate::error::{TransportError, VlmError};
use crate::secret::SecretString;
use crate::transport::{BoxFuture, Origin, Transport, WireRequest, WireResponse};

mod canonical;
mod diff;
mod format;
pub mod tools;

pub(crate) use diff::json_diff;
pub use diff::{CassetteMiss, JsonDiff, MissReason, NearMatch};
pub use format::{
    CassetteFile, CassetteMeta, Interaction, SCHEMA_VERSION, StoredFailure, StoredRequest, StoredResponse,
    blobs_dir,
};

use canonical::{Canonical, canonicalize};
use format::{FileLock, write_atomically, write_blob};

/// Record/replay mode (vcrpy's names).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CassetteMode {
    /// Replay only; a miss is an error. Never touches the network.
    #[default]
    None,
    /// Record if the cassette does not exist, otherwise replay only.
    Once,
    /// Replay matches, record misses.
    NewEpisodes,
    /// Record every call; the old recording is replaced.
    All,
}

impl CassetteMode {
    /// The mode's name.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Once => "once",
            Self::NewEpisodes => "new_episodes",
            Self::All => "all",
        }
    }
}

impl fmt::Display for CassetteMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for CassetteMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().replace('-', "_").as_str() {
            "none" | "replay" => Ok(Self::None),
            "once" => Ok(Self::Once),
            "new_episodes" => Ok(Self::NewEpisodes),
            "all" => Ok(Self::All),
            other => Err(format!(
                "unknown cassette mode {other:?}; expected none, once, new_episodes or all"
            )),
        }
    }
}

/// A cassette failure.
#[derive(Debug, thiserror::Error)]
pub enum CassetteError {
    /// Reading or writing a file failed.
    #[error("cassette file {}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (shown in the message, so not also a `source`).
        error: std::io::Error,
    },
    /// The file is not valid JSON or does not have the cassette shape.
    #[error("cassette {}:{line}:{column}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// The file's schema is unsupported or inconsistent.
    #[error("cassette {}: {message}", path.display())]
    Schema {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Nothing recorded matches the request.
    #[error("{0}")]
    Miss(Box<CassetteMiss>),
    /// The mode needs to record but no live transport was given.
    #[error("cassette {} in mode {mode} needs to record, but no live transport is configured", path.display())]
    NoLiveTransport {
        /// The cassette.
        path: PathBuf,
        /// The mode.
        mode: CassetteMode,
    },
    /// Strict mode: recorded interactions were never replayed.
    #[error("cassette {}: {} recorded interaction(s) were not used (strict mode): {}", path.display(), unused.len(), unused.join("; "))]
    Unused {
        /// The cassette.
        path: PathBuf,
        /// One line per unused interaction.
        unused: Vec<String>,
    },
    /// Another recorder holds the cassette's lock file.
    #[error("cassette lock {} is held by another recorder (delete it if no recorder is running)", path.display())]
    Locked {
        /// The lock file.
        path: PathBuf,
    },
}

/// Identifies an interaction independently of its position: its key and which recording
/// of that key it is (0 for the first).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct InteractionRef {
    /// The request key.
    pub key: String,
    /// Occurrence among interactions with that key, in the order they were sent.
    pub occurrence: usize,
}

/// Which interactions a run replayed: written at the end of a run when a usage report path
/// is configured, read by `nesy cassette prune`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct UsageReport {
    /// Format version (1).
    pub schema_version: u32,
    /// The cassette it describes.
    pub cassette: PathBuf,
    /// Interactions replayed.
    pub used: Vec<InteractionRef>,
    /// Interactions not replayed.
    pub unused: Vec<InteractionRef>,
}

/// Options for opening a cassette.
#[derive(Debug, Clone, Default)]
pub struct CassetteOptions {
    /// Fail in [`Transport::finish`] if interactions went unused.
    pub strict: bool,
    /// Write a [`UsageReport`] here in [`Transport::finish`].
    pub usage_report: Option<PathBuf>,
    /// The model, for metadata.
    pub model: Option<String>,
    /// The backend label, for metadata (defaults to the inner transport's label).
    pub backend: Option<String>,
    /// Secrets to blank out wherever they appear in what is written.
    pub redact: Vec<SecretString>,
    /// Once every recording of a request has been replayed, replay the last one again
    /// instead of missing (vcrpy's `allow_playback_repeats`; benchmarks use it).
    pub allow_playback_repeats: bool,
    /// Whether the recording client sends reply constraints, for metadata.
    pub constrain: ConstrainMode,
}

impl CassetteOptions {
    /// The options of a cassette recording what `config`'s client sends: its model, backend
    /// and constraint setting for the metadata, and its API key to blank out.
    pub fn recording(config: &crate::config::VlmConfig) -> CassetteOptions {
        CassetteOptions {
            model: Some(config.model.clone()),
            backend: Some(config.backend.as_str().to_owned()),
            redact: config.api_key.iter().cloned().collect(),
            constrain: config.defaults.constrain,
            ..CassetteOptions::default()
        }
    }
}

/// When a live call went out, and how long it took.
struct Sent {
    order: u64,
    latency_ms: f64,
}

struct Recorded {
    key: String,
    occurrence: usize,
    path: String,
    body: serde_json::Value,
    purpose: Option<String>,
    /// The response, or the failure a replay returns in its place.
    outcome: Result<WireResponse, StoredFailure>,
}

#[derive(Default)]
struct ReplayState {
    queues: HashMap<String, VecDeque<usize>>,
    used: Vec<bool>,
}

/// What the server announced: as the file recorded it, and as this run read it live.
#[derive(Default)]
struct Announced {
    recorded: Option<ServerCapabilities>,
    probed: Option<ServerCapabilities>,
}

/// A transport that replays from, and records to, a cassette file.
pub struct CassetteTransport {
    path: PathBuf,
    mode: CassetteMode,
    options: CassetteOptions,
    inner: Option<Arc<dyn Transport>>,
    existed: bool,
    replays: bool,
    records: bool,
    recorded: Vec<Recorded>,
    replay: Mutex<ReplayState>,
    announced: Mutex<Announced>,
    /// Whether the replayed recording sent constraints (its metadata's `constrain`).
    recorded_constrain: ConstrainMode,
    /// Serialises writes within the process (the lock file does so across processes) and
    /// remembers whether `all` mode has discarded the old recording yet.
    writer: Mutex<bool>,
    /// The send-order number of the next live call (see [`Interaction::send_order`]).
    next_send: AtomicU64,
}

impl fmt::Debug for CassetteTransport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CassetteTransport")
            .field("path", &self.path)
            .field("mode", &self.mode)
            .field("interactions", &self.recorded.len())
            .field("inner", &self.inner)
            .finish()
    }
}

impl CassetteTransport {
    /// Whether the recording it replays sent reply constraints (`auto` when it replays
    /// nothing).
    pub fn recorded_constrain(&self) -> ConstrainMode {
        self.recorded_constrain
    }

    /// Opens a cassette. `inner` is the live transport used to record; it may be `None` in
    /// `none` mode (and in `once` mode when the file exists).
    pub fn open(
        path: impl Into<PathBuf>,
        mode: CassetteMode,
        inner: Option<Arc<dyn Transport>>,
        options: CassetteOptions,
    ) -> Result<Self, CassetteError> {
        let path = path.into();
        let existed = path.exists();
        let (replays, records) = match mode {
            CassetteMode::None => (true, false),
            CassetteMode::Once => (existed, !existed),
            CassetteMode::NewEpisodes => (true, true),
            CassetteMode::All => (false, true),
        };
        if records && inner.is_none() {
            return Err(CassetteError::NoLiveTransport { path, mode });
        }
        let mut recorded = Vec::new();
        let mut state = ReplayState::default();
        let mut announced = Announced::default();
        let mut recorded_constrain = ConstrainMode::Auto;
        let mut next_send = 0;
        if existed && replays {
            let file = CassetteFile::load(&path)?;
            announced.recorded = file.meta.server.clone();
            recorded_constrain = file.meta.constrain;
            next_send = file.next_send_order();
            let sequence = file.send_sequence();
            let references = file.references(&sequence);
            for ((index, interaction), reference) in file.interactions.into_iter().enumerate().zip(references)
            {
                let schema = |message: String| CassetteError::Schema {
                    path: path.clone(),
                    message: format!("interaction #{index}: {message}"),
                };
                let outcome = match interaction.outcome().map_err(|problem| schema(problem.into()))? {
                    Ok(response) => Ok(response.to_wire(Origin::Replayed).map_err(schema)?),
                    Err(failure) => Err(failure.clone()),
                };
                recorded.push(Recorded {
                    key: reference.key,
                    occurrence: reference.occurrence,
                    path: interaction.request.path,
                    body: interaction.request.body,
                    purpose: interaction.purpose,
                    outcome,
                });
            }
            for index in sequence {
                let key = recorded[index].key.clone();
                state.queues.entry(key).or_default().push_back(index);
            }
            state.used = vec![false; recorded.len()];
        }
        Ok(Self {
            path,
            mode,
            options,
            inner,
            existed,
            replays,
            records,
            recorded,
            replay: Mutex::new(state),
            announced: Mutex::new(announced),
            recorded_constrain,
            writer: Mutex::new(false),
            next_send: AtomicU64::new(next_send),
        })
    }

    /// The cassette path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The mode it was opened in.
    pub fn mode(&self) -> CassetteMode {
        self.mode
    }

    /// Interactions loaded for replay that have not been replayed yet.
    pub fn unused(&self) -> Vec<InteractionRef> {
        let state = self
            .replay
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        self.recorded
            .iter()
            .zip(&state.used)
            .filter(|(_, used)| !**used)
            .map(|(r, _)| InteractionRef {
                key: r.key.clone(),
                occurrence: r.occurrence,
            })
            .collect()
    }

    /// What the cassette holds for this request: `Ok(None)` when it holds nothing, the
    /// number of recordings when every one was used.
    fn try_replay(
        &self,
        canonical: &Canonical,
    ) -> Result<Option<Result<WireResponse, TransportError>>, usize> {
        let mut state = self
            .replay
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        match state.queues.get_mut(&canonical.key) {
            Some(queue) => match queue.pop_front() {
                Some(index) => {
                    state.used[index] = true;
                    Ok(Some(self.replayed(index)))
                }
                None => {
                    let last = self.recorded.iter().rposition(|r| r.key == canonical.key);
                    match last.filter(|_| self.options.allow_playback_repeats) {
                        Some(index) => Ok(Some(self.replayed(index))),
                        None => Err(self.recorded.iter().filter(|r| r.key == canonical.key).count()),
                    }
                }
            },
            None => Ok(None),
        }
    }

    fn replayed(&self, index: usize) -> Result<WireResponse, TransportError> {
        self.recorded[index]
            .outcome
            .clone()
            .map_err(|failure| failure.to_transport())
    }

    fn miss(&self, request: &WireRequest, canonical: &Canonical, exhausted: Option<usize>) -> CassetteError {
        let reason = match exhausted {
            Some(recorded) => MissReason::Exhausted { recorded },
            None if !self.existed => MissReason::NoCassette,
            None => MissReason::NotRecorded,
        };
        let mut seen = std::collections::HashSet::new();
        let mut nearest: Vec<NearMatch> = self
            .recorded
            .iter()
            .enumerate()
            .filter(|(_, r)| seen.insert(r.key.clone()))
            .map(|(index, r)| NearMatch {
                index,
                purpose: r.purpose.clone(),
                path: r.path.clone(),
                diffs: json_diff(&r.body, &canonical.body),
            })
            .collect();
        let distance =
            |near: &NearMatch| diff::json_distance(&self.recorded[near.index].body, &canonical.body);
        nearest.sort_by_cached_key(|near| (near.path != request.path, distance(near), near.index));
        nearest.truncate(3);
        CassetteError::Miss(Box::new(CassetteMiss {
            cassette: self.path.clone(),
            mode: self.mode,
            reason,
            path: request.path.clone(),
            key: canonical.key.clone(),
            summary: diff::summarize_request(&canonical.body, request.purpose.as_deref()),
            nearest,
            rerecord_command: diff::rerecord_command(),
        }))
    }

    async fn handle(&self, request: &WireRequest) -> Result<WireResponse, TransportError> {
        let canonical = canonicalize(&request.path, &request.body, self.records);
        let mut exhausted = None;
        if self.replays {
            match self.try_replay(&canonical) {
                Ok(Some(outcome)) => return outcome,
                Ok(None) => {}
                Err(recorded) => exhausted = Some(recorded),
            }
        }
        let Some(inner) = self.inner.as_ref().filter(|_| self.records) else {
            return Err(self.miss(request, &canonical, exhausted).into());
        };
        // Numbered before the first await, so concurrent calls are numbered in the order
        // they were issued, which is the order a replay issues them in.
        let send_order = self.next_send.fetch_add(1, Ordering::Relaxed);
        let started = Instant::now();
        let result = inner.send(request).await;
        let sent = Sent {
            order: send_order,
            latency_ms: started.elapsed().as_secs_f64() * 1e3,
        };
        match &result {
            Ok(response) => self.append(request, canonical, Ok(response), sent)?,
            Err(error) => {
                // A sent attempt that got no response is kept too, so that a replay fails it
                // the same way; an error that never reached the network is not.
                if let Some(failure) = StoredFailure::from_transport(error) {
                    self.append(request, canonical, Err(failure), sent)?;
                }
            }
        }
        result
    }

    fn append(
        &self,
        request: &WireRequest,
        canonical: Canonical,
        outcome: Result<&WireResponse, StoredFailure>,
        sent: Sent,
    ) -> Result<(), CassetteError> {
        let blobs = blobs_dir(&self.path);
        for image in &canonical.images {
            if let Some(bytes) = &image.bytes {
                write_blob(&blobs, &image.file_name(), bytes)?;
            }
        }
        let interaction = Interaction {
            key: canonical.key,
            purpose: request.purpose.clone(),
            recorded_at: crate::timefmt::now_rfc3339(),
            latency_ms: (sent.latency_ms * 1000.0).round() / 1000.0,
            send_order: Some(sent.order),
            request: StoredRequest {
                method: "POST".into(),
                path: request.path.clone(),
                body: canonical.body,
            },
            response: outcome
                .as_ref()
                .ok()
                .map(|response| StoredResponse::from_wire(response)),
            failure: outcome.err(),
        };
        self.write_with(Some(interaction))
    }

    /// Loads (or starts) the cassette file, brings its metadata up to date (recorder, model,
    /// backend, what the server announced, the constraint setting), appends `interaction` if
    /// there is one, and writes the file atomically under its lock.
    fn write_with(&self, interaction: Option<Interaction>) -> Result<(), CassetteError> {
        let mut cleared = self
            .writer
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        let _lock = FileLock::acquire(&self.path)?;
        let backend = self
            .options
            .backend
            .clone()
            .or_else(|| self.inner.as_ref().map(|inner| inner.label()));
        let model = interaction
            .as_ref()
            .and_then(|i| i.request.body.get("model"))
            .and_then(|m| m.as_str())
            .map(str::to_string);
        let mut file = if (*cleared || self.mode != CassetteMode::All) && self.path.exists() {
            CassetteFile::load(&self.path)?
        } else {
            CassetteFile::new(None, None)
        };
        *cleared = true;
        file.meta.recorder = format::recorder();
        file.meta.updated_at = interaction
            .as_ref()
            .map_or_else(crate::timefmt::now_rfc3339, |i| i.recorded_at.clone());
        file.meta.model = model.or_else(|| self.options.model.clone()).or(file.meta.model);
        file.meta.backend = backend.or(file.meta.backend);
        let probed = self
            .announced
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .probed
            .clone();
        file.meta.server = probed.or(file.meta.server);
        file.meta.constrain = self.options.constrain;
        file.interactions.extend(interaction);
        write_atomically(&self.path, file.to_pretty_json(&self.options.redact).as_bytes())
    }

    /// A recording that sent no request still keeps what the server announced: a run
    /// refused before its first call (a prompt larger than the context window, pictures for
    /// a text-only server) then replays to the same refusal.
    fn keep_announcement(&self) -> Result<(), CassetteError> {
        let announced = self
            .announced
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .probed
            .is_some();
        let written = *self
            .writer
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if self.records && announced && !written && !self.path.exists() {
            self.write_with(None)?;
        }
        Ok(())
    }

    fn write_usage_report(&self, path: &Path) -> Result<(), CassetteError> {
        let state = self
            .replay
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        let (mut used, mut unused) = (Vec::new(), Vec::new());
        for (recorded, was_used) in self.recorded.iter().zip(&state.used) {
            let reference = InteractionRef {
                key: recorded.key.clone(),
                occurrence: recorded.occurrence,
            };
            if *was_used {
                used.push(reference)
            } else {
                unused.push(reference)
            }
        }
        let report = UsageReport {
            schema_version: 1,
            cassette: self.path.clone(),
            used,
            unused,
        };
        let text = serde_json::to_string_pretty(&report).unwrap_or_default();
        write_atomically(path, text.as_bytes())
    }
}

impl Transport for CassetteTransport {
    fn send<'a>(&'a self, request: &'a WireRequest) -> BoxFuture<'a, Result<WireResponse, TransportError>> {
        Box::pin(self.handle(request))
    }

    fn label(&self) -> String {
        match &self.inner {
            Some(inner) => format!(
                "cassette {} ({}) over {}",
                self.path.display(),
                self.mode,
                inner.label()
            ),
            None => format!("cassette {} ({})", self.path.display(), self.mode),
        }
    }

    fn capabilities(&self) -> BoxFuture<'_, ServerCapabilities> {
        Box::pin(async move {
            let recorded = self
                .announced
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .recorded
                .clone();
            if let Some(recorded) = recorded.filter(|_| self.replays) {
                return recorded;
            }
            let Some(inner) = self.inner.as_ref().filter(|_| self.records) else {
                return ServerCapabilities::UNKNOWN;
            };
            let live = inner.capabilities().await;
            if live != ServerCapabilities::UNKNOWN {
                self.announced
                    .lock()
                    .unwrap_or_else(|poisoned| poisoned.into_inner())
                    .probed = Some(live.clone());
            }
            live
        })
    }

    fn finish(&self) -> Result<(), VlmError> {
        self.keep_announcement()?;
        if let Some(report) = &self.options.usage_report {
            self.write_usage_report(report)?;
        }
        if let Some(inner) = &self.inner {
            inner.finish()?;
        }
        let unused = self.unused();
        if self.options.strict && self.replays && !unused.is_empty() {
            let lines = unused
                .iter()
                .map(|reference| {
                    let recorded = self
                        .recorded
                        .iter()
                        .position(|r| r.key == reference.key && r.occurrence == reference.occurrence);
                    let purpose = recorded
                        .and_then(|i| self.recorded[i].purpose.clone())
                        .unwrap_or_else(|| "-".into());
                    format!(
                        "#{} (purpose {purpose}, key {})",
                        recorded.unwrap_or(0),
                        &reference.key[..12]
                    )
                })
                .collect();
            return Err(CassetteError::Unused {
                path: self.path.clone(),
                unused: lines,
            }
            .into());
        }
        Ok(())
    }
}
