//! Which model answers (`--vlm`), and recording (`--record`).
//!
//! - no `--vlm`: the configuration from flags, environment and file (`NESY_VLM_*`), with its
//!   cassette if one is configured (nesy-vlm's `VlmClient::from_config`);
//! - `--vlm URL`: a live OpenAI-compatible server at URL (backend `vllm` unless configured);
//! - `--vlm replay:CASSETTE`: replay only; the backend and model come from the cassette's
//!   metadata, so the request bodies match the recording; a miss names the request;
//! - `--vlm oracle`: the offline reference responder (nesy-oracle's transport);
//! - in code, any [`Transport`] (tests' scripted responders).
//!
//! `--record CASSETTE` wraps whichever live transport in a cassette in `all` mode.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use nesy_vlm::CassetteFile;

use nesy_oracle::{OracleNoise, OracleTransport};
use nesy_sim::api::ApiCall;
use nesy_vlm::{
    BackendKind, CassetteMode, CassetteOptions, CassetteTransport, ConfigOverrides, ProcessEnv, Transport,
    VlmClient, VlmConfig,
};

use crate::{DemoInput, PipelineError};

/// The model name the offline responder's requests carry (recorded in its cassettes).
pub const ORACLE_MODEL: &str = "nesy-oracle";
/// The backend profile the offline responder's requests are built with.
pub const ORACLE_BACKEND: BackendKind = BackendKind::Vllm;

/// Where answers come from.
#[derive(Clone)]
pub enum VlmSource {
    /// The configured client (flags > environment > file).
    Configured(Box<ConfigOverrides>),
    /// A live OpenAI-compatible server at this base URL.
    Url(String, Box<ConfigOverrides>),
    /// Replay a cassette, never touching the network.
    Replay(PathBuf),
    /// The offline reference responder, with its noise settings (`op-drop=0.1,bad-patch=0.2`...).
    Oracle {
        /// Noise knobs as given on the command line (empty: none).
        noise: String,
        /// Seed of the noise draws (with the request body; the benchmark harness gives each
        /// unit its own).
        seed: u64,
    },
    /// Any transport, with the configuration whose profile builds the bodies.
    Transport {
        /// The configuration.
        config: Box<VlmConfig>,
        /// The transport.
        transport: Arc<dyn Transport>,
    },
}

impl std::fmt::Debug for VlmSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VlmSource::Configured(_) => f.write_str("Configured"),
            VlmSource::Url(url, _) => write!(f, "Url({url})"),
            VlmSource::Replay(p) => write!(f, "Replay({})", p.display()),
            VlmSource::Oracle { noise, seed } => write!(f, "Oracle({noise}, seed {seed})"),
            VlmSource::Transport { transport, .. } => write!(f, "Transport({})", transport.label()),
        }
    }
}

impl VlmSource {
    /// Parses `--vlm`: `oracle`, `replay:PATH`, or an `http(s)://` URL. The oracle's noise
    /// draws are seeded with 0 here; the benchmark harness seeds each unit.
    pub fn parse(text: &str, overrides: ConfigOverrides, noise: String) -> Result<VlmSource, PipelineError> {
        if text == "oracle" {
            return Ok(VlmSource::Oracle { noise, seed: 0 });
        }
        if let Some(path) = text.strip_prefix("replay:") {
            if path.is_empty() {
                return Err(setup_error(
                    "--vlm replay: needs a cassette path, e.g. --vlm replay:fixtures/cassettes/x.json",
                ));
            }
            return Ok(VlmSource::Replay(PathBuf::from(path)));
        }
        if text.starts_with("http://") || text.starts_with("https://") {
            return Ok(VlmSource::Url(text.to_owned(), Box::new(overrides)));
        }
        Err(setup_error(format!(
            "--vlm {text:?}: expected `oracle`, `replay:CASSETTE` or an http(s):// URL of an OpenAI-compatible server"
        )))
    }

    /// True for the offline reference responder.
    pub fn is_oracle(&self) -> bool {
        matches!(self, VlmSource::Oracle { .. })
    }
}

/// The model and how to record it.
#[derive(Debug, Clone)]
pub struct VlmSetup {
    /// Where answers come from.
    pub source: VlmSource,
    /// Record every call to this cassette (mode `all`).
    pub record: Option<PathBuf>,
}

/// The configuration the offline responder's requests are built with.
pub fn oracle_config() -> VlmConfig {
    let mut config = VlmConfig::new(ORACLE_BACKEND, ORACLE_MODEL);
    config.base_url = "oracle:".into();
    // One cap for every call, as the responder's recordings were made with: it answers
    // instantly, so per-purpose caps for slow local servers do not apply.
    config.defaults.max_output_tokens = Some(nesy_vlm::DEFAULT_CLOUD_OUTPUT_TOKENS);
    config.defaults.reply_caps = None;
    // It answers from the task context, so a grammar would change nothing but its
    // recordings' request bodies.
    config.defaults.constrain = nesy_vlm::ConstrainMode::Off;
    config
}

/// The configuration that rebuilds the bodies a cassette recorded: its backend and model,
/// and whether its requests carried their reply constraints.
pub fn replay_config(path: &Path, file: &CassetteFile) -> Result<VlmConfig, PipelineError> {
    let model = file.meta.model.clone().ok_or_else(|| {
        setup_error(format!(
            "{}: at meta.model: expected the recorded model name, found none",
            path.display()
        ))
    })?;
    if model == ORACLE_MODEL {
        return Ok(oracle_config());
    }
    let backend_label = file.meta.backend.clone().unwrap_or_default();
    // Labels are `openai` or `http openai`; the last word names the profile.
    let last = backend_label.split_whitespace().last().unwrap_or("");
    let backend = last.parse::<BackendKind>().map_err(|e| {
        setup_error(format!(
            "{}: at meta.backend: {e}; replay this cassette with NESY_CASSETTE={} NESY_CASSETTE_MODE=none and the settings it was recorded with",
            path.display(),
            path.display()
        ))
    })?;
    let mut config = VlmConfig::new(backend, model);
    config.defaults.constrain = file.meta.constrain;
    Ok(config)
}

/// Builds the client for `setup`. The offline responder is given `demo`'s recorded robot
/// calls, which its induction answers start from.
pub fn build_client(setup: &VlmSetup, demo: &DemoInput) -> Result<VlmClient, PipelineError> {
    let (config, live): (VlmConfig, Option<Arc<dyn Transport>>) = match &setup.source {
        VlmSource::Replay(path) => {
            if setup.record.is_some() {
                return Err(setup_error(
                    "--record cannot be combined with --vlm replay: (a replay makes no new calls)",
                ));
            }
            if !path.is_file() {
                return Err(setup_error(format!(
                    "{}: cassette not found (from --vlm replay:)",
                    path.display()
                )));
            }
            let file = CassetteFile::load(path)
                .map_err(|e| setup_error(format!("reading the cassette {}: {e}", path.display())))?;
            let config = replay_config(path, &file)?;
            let options = CassetteOptions {
                usage_report: std::env::var_os(nesy_vlm::CASSETTE_USAGE_ENV).map(PathBuf::from),
                ..CassetteOptions::default()
            };
            let transport = CassetteTransport::open(path, CassetteMode::None, None, options)
                .map_err(|e| setup_error(format!("opening the cassette {}: {e}", path.display())))?;
            return Ok(VlmClient::with_transport(&config, Arc::new(transport)));
        }
        VlmSource::Configured(overrides) => {
            let config = resolve(overrides)?;
            if setup.record.is_none() {
                return VlmClient::from_config(&config).map_err(client_error);
            }
            if config.cassette.is_some() {
                return Err(setup_error(
                    "--record cannot be combined with a configured cassette (--cassette / NESY_CASSETTE)",
                ));
            }
            let http = VlmClient::http_transport(&config).map_err(client_error)?;
            (config, Some(Arc::new(http)))
        }
        VlmSource::Url(url, overrides) => {
            let mut overrides = (**overrides).clone();
            overrides.base_url = Some(url.clone());
            if overrides.backend.is_none() && std::env::var_os("NESY_VLM_BACKEND").is_none() {
                overrides.backend = Some(BackendKind::Vllm);
            }
            let config = resolve(&overrides)?;
            if setup.record.is_some() && config.cassette.is_some() {
                return Err(setup_error(
                    "--record cannot be combined with a configured cassette (--cassette / NESY_CASSETTE)",
                ));
            }
            if config.cassette.is_some() {
                return VlmClient::from_config(&config).map_err(client_error);
            }
            let http = VlmClient::http_transport(&config).map_err(client_error)?;
            (config, Some(Arc::new(http)))
        }
        VlmSource::Oracle { noise, seed } => {
            let transport = oracle_transport(noise, *seed, demo.recorded_calls())?;
            (oracle_config(), Some(transport))
        }
        VlmSource::Transport { config, transport } => ((**config).clone(), Some(transport.clone())),
    };
    let live = live.ok_or_else(|| setup_error("no transport"))?;
    let transport: Arc<dyn Transport> = match &setup.record {
        Some(path) => {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir).map_err(|e| PipelineError::write(dir, e))?;
            }
            Arc::new(
                CassetteTransport::open(
                    path,
                    CassetteMode::All,
                    Some(live),
                    CassetteOptions::recording(&config),
                )
                .map_err(|e| setup_error(format!("opening {} for recording: {e}", path.display())))?,
            )
        }
        None => live,
    };
    Ok(VlmClient::with_transport(&config, transport))
}

/// The offline reference responder: nesy-oracle's transport over the true domain, with the
/// noise knobs seeded by `seed` and the demonstration's recorded robot calls `demo_calls`
/// (one per transition).
pub fn oracle_transport(
    noise: &str,
    seed: u64,
    demo_calls: Vec<Option<ApiCall>>,
) -> Result<Arc<dyn Transport>, PipelineError> {
    let noise: OracleNoise = if noise.trim().is_empty() {
        OracleNoise::NONE
    } else {
        noise
            .parse()
            .map_err(|e| setup_error(format!("--oracle-noise {noise:?}: {e}")))?
    };
    let oracle = OracleTransport::new()
        .map_err(|e| setup_error(format!("loading the oracle's domain: {e}")))?
        .with_noise(noise, seed)
        .with_demo_calls(demo_calls);
    Ok(Arc::new(oracle))
}

fn setup_error(message: impl Into<String>) -> PipelineError {
    PipelineError::VlmSetup {
        message: message.into(),
    }
}

fn client_error(e: nesy_vlm::VlmError) -> PipelineError {
    setup_error(e.to_string())
}

fn resolve(overrides: &ConfigOverrides) -> Result<VlmConfig, PipelineError> {
    VlmConfig::resolve(overrides, &ProcessEnv)
        .map_err(|e| setup_error(format!("resolving the VLM configuration: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_replay_sends_constraints_as_the_recording_did() {
        let mut file = CassetteFile::new(Some("gemma3-270m-q4_k_m".into()), Some("http llamacpp".into()));
        let path = Path::new("c.json");
        let config = replay_config(path, &file).unwrap();
        assert_eq!(config.backend, BackendKind::LlamaCpp);
        assert_eq!(config.defaults.constrain, nesy_vlm::ConstrainMode::Auto);
        file.meta.constrain = nesy_vlm::ConstrainMode::Off;
        let config = replay_config(path, &file).unwrap();
        assert_eq!(config.defaults.constrain, nesy_vlm::ConstrainMode::Off);
        // The offline responder's recordings keep its own settings.
        file.meta.model = Some(ORACLE_MODEL.into());
        assert_eq!(replay_config(path, &file).unwrap(), oracle_config());
    }
}
