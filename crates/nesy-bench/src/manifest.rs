//! The run manifest, written before any unit runs: the unit list, every variant's settings
//! and configuration hash, the responder, and the provenance of the build and the machine.
//! A run directory holds one configuration; running it again resumes it, and a command with
//! other settings is refused rather than mixed in.

use std::path::{Path, PathBuf};

use nesy_vlm::ConstrainMode;
use serde::{Deserialize, Serialize};

use crate::error::BenchError;
use crate::unit::{Selection, UnitKey};
use crate::variant::{Variant, config_hash};

/// The manifest format version.
pub const MANIFEST_VERSION: u32 = 1;
/// The commit the harness was built from (`git describe --always --dirty`), empty outside a
/// git checkout.
pub const GIT_COMMIT: &str = env!("NESY_GIT_COMMIT");

/// Who answers the model calls.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Responder {
    /// The offline reference responder over the true domain: an upper bound for NeSyCR, no
    /// model's performance.
    Oracle,
    /// Per-unit cassettes of an earlier run, replayed offline.
    Replay {
        /// The folder holding `<scenario>/<variant>.json` cassettes.
        cassettes: PathBuf,
    },
    /// A live endpoint; every call is recorded to the unit's cassette.
    Live {
        /// The backend profile.
        backend: String,
        /// The model.
        model: String,
        /// The base URL (never a key).
        base_url: String,
        /// Whether replies were held to their grammars (`--vlm-constrain`); absent means
        /// `auto`, so earlier manifests keep their hashes.
        #[serde(default, skip_serializing_if = "ConstrainMode::is_auto")]
        constrain: ConstrainMode,
    },
}

impl Responder {
    /// True unless a live model answers.
    pub fn is_offline(&self) -> bool {
        !matches!(self, Responder::Live { .. })
    }

    /// The responder as it enters a run's configuration hash: a live server's address left
    /// out (the backend, the model and the constraint setting make the experiment, the port
    /// does not), so that a run resumes after its local server restarts elsewhere.
    ///
    /// ```
    /// use nesy_bench::manifest::Responder;
    /// use nesy_vlm::ConstrainMode;
    ///
    /// let at = |base_url: &str| Responder::Live {
    ///     backend: "llamacpp".into(),
    ///     model: "gemma3-270m-q4_k_m".into(),
    ///     base_url: base_url.into(),
    ///     constrain: ConstrainMode::Auto,
    /// };
    /// let (here, there) = (at("http://127.0.0.1:41505/v1"), at("http://127.0.0.1:57617/v1"));
    /// assert_eq!(here.identity(), there.identity());
    /// ```
    pub fn identity(&self) -> Responder {
        match self {
            Responder::Live {
                backend,
                model,
                constrain,
                ..
            } => Responder::Live {
                backend: backend.clone(),
                model: model.clone(),
                base_url: String::new(),
                constrain: *constrain,
            },
            offline => offline.clone(),
        }
    }

    /// One line for reports.
    pub fn describe(&self) -> String {
        match self {
            Responder::Oracle => "offline reference responder (oracle over nesy's true domain)".into(),
            Responder::Replay { cassettes } => format!("replayed cassettes from {}", cassettes.display()),
            Responder::Live {
                backend,
                model,
                base_url,
                constrain,
            } => format!("live model {model} ({backend} at {base_url}, constraints {constrain})"),
        }
    }
}

/// Settings that shape every unit's result besides its variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSettings {
    /// Run the methods on demos whose final state lacks part of their goal (the authors'
    /// behaviour) instead of recording those scenarios as `demo_unusable`.
    pub keep_gapped_demos: bool,
    /// Side of the rendered views, in pixels.
    pub image_size: u32,
    /// Wall-clock budget of one policy, in milliseconds.
    pub policy_wall_ms: u64,
    /// Cap on model calls per unit.
    pub max_calls_per_unit: Option<u64>,
    /// What the methods see of each scene. Left out of the manifest when it is the
    /// pictures, so runs made before the setting existed keep their configuration hashes.
    #[serde(default, skip_serializing_if = "Observation::is_images")]
    pub observation: Observation,
    /// Whether the robot's protective stop is on in every scene the run builds (its
    /// demonstrations and its executions; `nesy_sim::scene::SceneSpec::protective_stop`).
    /// Left out of the manifest when off, and off when absent, so runs made before the stop
    /// existed (which ran without it) keep their configuration hashes.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub protective_stop: bool,
}

impl RunSettings {
    /// Which settings differ, each as `name here vs there`.
    ///
    /// ```
    /// use nesy_bench::manifest::{Observation, RunSettings};
    ///
    /// let old = RunSettings {
    ///     keep_gapped_demos: false,
    ///     image_size: 256,
    ///     policy_wall_ms: 300_000,
    ///     max_calls_per_unit: None,
    ///     observation: Observation::Images,
    ///     protective_stop: false,
    /// };
    /// let new = RunSettings { protective_stop: true, ..old.clone() };
    /// assert_eq!(old.difference(&new), "protective stop off vs on");
    /// ```
    pub fn difference(&self, other: &RunSettings) -> String {
        let on_off = |on: bool| if on { "on" } else { "off" };
        let calls = |cap: Option<u64>| cap.map_or("no cap".to_owned(), |n| n.to_string());
        let pairs = [
            (
                "keep gapped demos",
                on_off(self.keep_gapped_demos).to_owned(),
                on_off(other.keep_gapped_demos).to_owned(),
            ),
            (
                "image size",
                self.image_size.to_string(),
                other.image_size.to_string(),
            ),
            (
                "policy wall ms",
                self.policy_wall_ms.to_string(),
                other.policy_wall_ms.to_string(),
            ),
            (
                "max calls per unit",
                calls(self.max_calls_per_unit),
                calls(other.max_calls_per_unit),
            ),
            (
                "observation",
                self.observation.as_str().to_owned(),
                other.observation.as_str().to_owned(),
            ),
            (
                "protective stop",
                on_off(self.protective_stop).to_owned(),
                on_off(other.protective_stop).to_owned(),
            ),
        ];
        pairs
            .into_iter()
            .filter(|(_, here, there)| here != there)
            .map(|(name, here, there)| format!("{name} {here} vs {there}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// What every method is shown of the demonstration's keyframes and the target scene.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Observation {
    /// The rendered views, as the authors attach them.
    #[default]
    Images,
    /// Each scene's ground-truth symbolic state as text in place of its pictures, for every
    /// method alike: the setting in which all of them run on a text-only model under the same
    /// perception. NeSyCR reads the ground-truth states (`states=vlm` is refused).
    StateText,
}

impl Observation {
    /// True for the rendered views.
    pub fn is_images(&self) -> bool {
        *self == Observation::Images
    }

    /// `images` or `state-text`, as the option spells it.
    pub fn as_str(self) -> &'static str {
        match self {
            Observation::Images => "images",
            Observation::StateText => "state-text",
        }
    }
}

/// One variant of the run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VariantEntry {
    /// The variant.
    pub variant: Variant,
    /// Its id.
    pub id: String,
    /// Hash of everything that shapes its units' results: the variant, the responder, the
    /// run settings, the simulator and the prompts.
    pub config_hash: String,
    /// Where the variant departs from the authors' implementation (the baselines' fidelity
    /// modes, LLM-DM's planner, MoReVQA's cap).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub deviations: Vec<String>,
}

/// SHA-256 (hex) over NeSyCR's prompt fingerprint and the baselines' template fingerprint:
/// every prompt text a benchmark run can send.
pub fn prompts_fingerprint() -> String {
    use sha2::{Digest, Sha256};
    let mut hash = Sha256::new();
    hash.update(nesy_reasoner::prompts::Prompts::fingerprint());
    hash.update(nesy_baselines::BaselinePrompts::fingerprint());
    crate::variant::hex(&hash.finalize())
}

/// The build and the machine a run came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The nesy version.
    pub nesy_version: String,
    /// The commit (`git describe --always --dirty`), if known.
    pub git_commit: String,
    /// The simulator's fingerprint.
    pub sim_fingerprint: String,
    /// The prompts' fingerprint: NeSyCR's prompt files and the baselines' templates
    /// ([`prompts_fingerprint`]).
    pub prompts_fingerprint: String,
    /// Host name.
    pub host: String,
    /// Cores and memory.
    pub machine: String,
}

impl Provenance {
    /// This build on this machine.
    pub fn current() -> Provenance {
        Provenance {
            nesy_version: env!("CARGO_PKG_VERSION").to_owned(),
            git_commit: GIT_COMMIT.to_owned(),
            sim_fingerprint: nesy_sim::FINGERPRINT.to_owned(),
            prompts_fingerprint: prompts_fingerprint(),
            host: host_name(),
            machine: machine(),
        }
    }
}

/// The manifest of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Format version (1).
    pub schema_version: u32,
    /// When the run was created.
    pub created_at: String,
    /// Where it came from.
    pub provenance: Provenance,
    /// Hash of the scenario suite's configuration files.
    pub suite_hash: String,
    /// Who answers.
    pub responder: Responder,
    /// The run seed units derive theirs from.
    pub run_seed: u64,
    /// Repeats per (variant, scenario).
    pub repeats: u32,
    /// The scenarios.
    pub selection: Selection,
    /// Run-wide settings.
    pub settings: RunSettings,
    /// The variants.
    pub variants: Vec<VariantEntry>,
    /// The study the variants make up, if the run is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub study: Option<crate::studies::Study>,
    /// Every unit, in stable order.
    pub units: Vec<UnitKey>,
    /// The run whose specifications this run re-executes (phase B only), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reexecutes: Option<PathBuf>,
    /// Hash of everything above except the creation time and the provenance's host and
    /// machine: two runs with the same hash are the same experiment.
    pub config_hash: String,
}

/// The manifest file of a run.
pub fn manifest_path(run: &Path) -> PathBuf {
    run.join("manifest.json")
}

impl Manifest {
    /// The hash of the experiment: what determines the results.
    pub fn compute_hash(&self) -> String {
        #[derive(Serialize)]
        struct Experiment<'a> {
            sim: &'a str,
            prompts: &'a str,
            suite: &'a str,
            responder: &'a Responder,
            run_seed: u64,
            repeats: u32,
            settings: &'a RunSettings,
            variants: &'a [VariantEntry],
            #[serde(skip_serializing_if = "Option::is_none")]
            study: Option<crate::studies::Study>,
            units: &'a [UnitKey],
            reexecutes: &'a Option<PathBuf>,
        }
        config_hash(&Experiment {
            sim: &self.provenance.sim_fingerprint,
            prompts: &self.provenance.prompts_fingerprint,
            suite: &self.suite_hash,
            responder: &self.responder.identity(),
            run_seed: self.run_seed,
            repeats: self.repeats,
            settings: &self.settings,
            variants: &self.variants,
            study: self.study,
            units: &self.units,
            reexecutes: &self.reexecutes,
        })
    }

    /// Reads a run's manifest.
    pub fn read(run: &Path) -> Result<Manifest, BenchError> {
        let path = manifest_path(run);
        let text =
            nesy_input::read_text(&path, nesy_input::MAX_JSON_BYTES).map_err(|e| BenchError::io(&path, e))?;
        Manifest::parse(&path, &text)
    }

    /// Parses manifest text (`path` names it in errors).
    pub fn parse(path: &Path, text: &str) -> Result<Manifest, BenchError> {
        serde_json::from_str(text).map_err(|e| BenchError::Format {
            path: path.to_owned(),
            message: format!("not a run manifest: {e}"),
        })
    }

    /// Writes the manifest if the run has none; otherwise checks that the existing one is the
    /// same experiment. Written to a temporary file and renamed, so concurrent shards that
    /// start together never see a half-written manifest.
    pub fn write_or_check(&self, run: &Path) -> Result<(), BenchError> {
        let path = manifest_path(run);
        if path.exists() {
            let existing = Manifest::read(run)?;
            if existing.config_hash != self.config_hash {
                return Err(BenchError::Mismatch {
                    path,
                    message: format!(
                        "this run directory holds another configuration (hash {} there, {} asked for): {}; use a new run directory",
                        short(&existing.config_hash),
                        short(&self.config_hash),
                        existing.difference(self)
                    ),
                });
            }
            return Ok(());
        }
        std::fs::create_dir_all(run).map_err(|e| BenchError::io(run, e))?;
        let tmp = run.join(format!(".manifest.{}.tmp", std::process::id()));
        let text = serde_json::to_string_pretty(self).unwrap_or_default() + "\n";
        std::fs::write(&tmp, text).map_err(|e| BenchError::io(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| BenchError::io(&path, e))
    }

    /// What differs between two manifests, in words.
    pub fn difference(&self, other: &Manifest) -> String {
        let mut parts = Vec::new();
        if self.provenance.sim_fingerprint != other.provenance.sim_fingerprint {
            parts.push("the simulator changed".to_owned());
        }
        if self.provenance.prompts_fingerprint != other.provenance.prompts_fingerprint {
            parts.push("the prompts changed".to_owned());
        }
        if self.responder.identity() != other.responder.identity() {
            parts.push(format!(
                "the responder ({} vs {})",
                self.responder.describe(),
                other.responder.describe()
            ));
        }
        if self.variants != other.variants {
            parts.push("the variants or their settings".to_owned());
        }
        if self.units != other.units {
            parts.push(format!(
                "the units ({} vs {})",
                self.units.len(),
                other.units.len()
            ));
        }
        if self.settings != other.settings {
            parts.push(format!(
                "the run settings ({})",
                self.settings.difference(&other.settings)
            ));
        }
        if self.run_seed != other.run_seed || self.repeats != other.repeats {
            parts.push("the seed or the repeats".to_owned());
        }
        if parts.is_empty() {
            parts.push("the suite or the re-executed run".to_owned());
        }
        parts.join(", ")
    }

    /// The entry of a variant id.
    pub fn variant(&self, id: &str) -> Option<&VariantEntry> {
        self.variants.iter().find(|v| v.id == id)
    }
}

fn short(hash: &str) -> &str {
    &hash[..hash.len().min(12)]
}

fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .map(|s| s.trim().to_owned())
        .unwrap_or_else(|_| "unknown".into())
}

/// `N cores, M GiB, <cpu model>` from /proc.
pub fn machine() -> String {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mem_gib = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("MemTotal:"))
                .and_then(|l| l.split_whitespace().nth(1).and_then(|kb| kb.parse::<f64>().ok()))
        })
        .map(|kb| kb / 1024.0 / 1024.0);
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':').map(|(_, m)| m.trim().to_owned()))
        })
        .unwrap_or_else(|| "unknown CPU".into());
    match mem_gib {
        Some(m) => format!("{cores} cores, {m:.0} GiB, {model}"),
        None => format!("{cores} cores, {model}"),
    }
}
