//! Which model answers (`--vlm`), and recording (`--record`).
//!
//! - no `--vlm`: the configuration from flags, environment and file (`NESY_VLM_*`), with its
//!   cassette if one is configured (nesy-vlm's `VlmClient::from_config`);
//! - `--vlm URL`: a live OpenAI-compatible server at URL (backend `vllm` unless configured);
//! - `--vlm replay:CASSETTE`: replay only; the backend and model come from the cassette's
//!   metadata, so the request bodies match the recording; a miss names the request;
//! - `--vlm oracle`: the offline reference responder (nesy-vlm's oracle transport);
//! - in code, any [`Transport`] (tests' scripted responders).
//!
//! `--record CASSETTE` wraps whichever live transport in a cassette in `all` mode.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::Context as _;
use nesy_vlm::cassette::CassetteFile;
use nesy_vlm::{
    BackendKind, CassetteMode, CassetteOptions, CassetteTransport, ConfigOverrides, OracleNoise,
    OracleTransport, ProcessEnv, Transport, VlmClient, VlmConfig,
};

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
    /// The offline reference responder, with its noise settings (`drop=0.1,flip=0.1`...).
    Oracle {
        /// Noise knobs as given on the command line (empty: none).
        noise: String,
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
            VlmSource::Oracle { noise } => write!(f, "Oracle({noise})"),
            VlmSource::Transport { transport, .. } => write!(f, "Transport({})", transport.label()),
        }
    }
}

impl VlmSource {
    /// Parses `--vlm`: `oracle`, `replay:PATH`, or an `http(s)://` URL.
    pub fn parse(text: &str, overrides: ConfigOverrides, noise: String) -> anyhow::Result<VlmSource> {
        if text == "oracle" {
            return Ok(VlmSource::Oracle { noise });
        }
        if let Some(path) = text.strip_prefix("replay:") {
            if path.is_empty() {
                anyhow::bail!(
                    "--vlm replay: needs a cassette path, e.g. --vlm replay:fixtures/cassettes/x.json"
                );
            }
            return Ok(VlmSource::Replay(PathBuf::from(path)));
        }
        if text.starts_with("http://") || text.starts_with("https://") {
            return Ok(VlmSource::Url(text.to_owned(), Box::new(overrides)));
        }
        anyhow::bail!(
            "--vlm {text:?}: expected `oracle`, `replay:CASSETTE` or an http(s):// URL of an OpenAI-compatible server"
        )
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
    config
}

/// The configuration that rebuilds the bodies a cassette recorded: its backend and model.
pub fn replay_config(path: &Path, file: &CassetteFile) -> anyhow::Result<VlmConfig> {
    let model = file.meta.model.clone().with_context(|| {
        format!(
            "{}: at meta.model: expected the recorded model name, found none",
            path.display()
        )
    })?;
    let backend_label = file.meta.backend.clone().unwrap_or_default();
    // Labels are `openai`, `http openai`, or the oracle's; the last word names the profile.
    let last = backend_label.split_whitespace().last().unwrap_or("");
    let backend = if model == ORACLE_MODEL {
        ORACLE_BACKEND
    } else {
        last.parse::<BackendKind>().map_err(|e| {
            anyhow::anyhow!(
                "{}: at meta.backend: {e}; replay this cassette with NESY_CASSETTE={} NESY_CASSETTE_MODE=none and the settings it was recorded with",
                path.display(),
                path.display()
            )
        })?
    };
    Ok(VlmConfig::new(backend, model))
}

/// Builds the client for `setup`.
pub fn build_client(setup: &VlmSetup) -> anyhow::Result<VlmClient> {
    let (config, live): (VlmConfig, Option<Arc<dyn Transport>>) = match &setup.source {
        VlmSource::Replay(path) => {
            if setup.record.is_some() {
                anyhow::bail!("--record cannot be combined with --vlm replay: (a replay makes no new calls)");
            }
            if !path.is_file() {
                anyhow::bail!("{}: cassette not found (from --vlm replay:)", path.display());
            }
            let file = CassetteFile::load(path)
                .with_context(|| format!("reading the cassette {}", path.display()))?;
            let config = replay_config(path, &file)?;
            let transport =
                CassetteTransport::open(path, CassetteMode::None, None, CassetteOptions::default())
                    .with_context(|| format!("opening the cassette {}", path.display()))?;
            return Ok(VlmClient::with_transport(&config, Arc::new(transport)));
        }
        VlmSource::Configured(overrides) => {
            let config =
                VlmConfig::resolve(overrides, &ProcessEnv).context("resolving the VLM configuration")?;
            if setup.record.is_none() {
                return Ok(VlmClient::from_config(&config)?);
            }
            if config.cassette.is_some() {
                anyhow::bail!(
                    "--record cannot be combined with a configured cassette (--cassette / NESY_CASSETTE)"
                );
            }
            let http = VlmClient::http_transport(&config)?;
            (config, Some(Arc::new(http)))
        }
        VlmSource::Url(url, overrides) => {
            let mut overrides = (**overrides).clone();
            overrides.base_url = Some(url.clone());
            if overrides.backend.is_none() && std::env::var_os("NESY_VLM_BACKEND").is_none() {
                overrides.backend = Some(BackendKind::Vllm);
            }
            let config =
                VlmConfig::resolve(&overrides, &ProcessEnv).context("resolving the VLM configuration")?;
            if setup.record.is_some() && config.cassette.is_some() {
                anyhow::bail!(
                    "--record cannot be combined with a configured cassette (--cassette / NESY_CASSETTE)"
                );
            }
            if config.cassette.is_some() {
                return Ok(VlmClient::from_config(&config)?);
            }
            let http = VlmClient::http_transport(&config)?;
            (config, Some(Arc::new(http)))
        }
        VlmSource::Oracle { noise } => {
            let transport = oracle_transport(noise)?;
            (oracle_config(), Some(transport))
        }
        VlmSource::Transport { config, transport } => ((**config).clone(), Some(transport.clone())),
    };
    let live = live.context("no transport")?;
    let transport: Arc<dyn Transport> = match &setup.record {
        Some(path) => {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
            }
            Arc::new(
                CassetteTransport::open(
                    path,
                    CassetteMode::All,
                    Some(live),
                    CassetteOptions {
                        model: Some(config.model.clone()),
                        backend: Some(config.backend.as_str().to_owned()),
                        redact: config.api_key.iter().cloned().collect(),
                        ..CassetteOptions::default()
                    },
                )
                .with_context(|| format!("opening {} for recording", path.display()))?,
            )
        }
        None => live,
    };
    Ok(VlmClient::with_transport(&config, transport))
}

/// The offline reference responder: nesy-vlm's oracle over the true domain, with the noise
/// knobs, answering code generation with the template compiler.
fn oracle_transport(noise: &str) -> anyhow::Result<Arc<dyn Transport>> {
    let noise: OracleNoise = if noise.trim().is_empty() {
        OracleNoise::NONE
    } else {
        noise
            .parse()
            .with_context(|| format!("--oracle-noise {noise:?}"))?
    };
    let oracle = OracleTransport::new()
        .context("loading the oracle's domain")?
        .with_noise(noise, 0)
        .with_compiler(Arc::new(super::synth::TemplateCompiler));
    Ok(Arc::new(oracle))
}
