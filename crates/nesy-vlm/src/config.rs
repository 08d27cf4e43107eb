//! Configuration from flags, environment variables and an optional TOML file, in that order
//! of precedence. API keys come only from the environment (never a flag, so they stay out of
//! shell history and process lists); the file may name the variable that holds the key.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::time::Duration;

use serde::Deserialize;

use crate::accounting::PriceTable;
use crate::cassette::CassetteMode;
use crate::constraint::ConstrainMode;
use crate::profile::{BackendKind, BodyDefaults, Profile, ReasoningMode, ReplyCaps};
use crate::request::{ImageDetail, ReasoningEffort};
use crate::retry::RetryPolicy;

/// The output-token cap of every call to a hosted API unless configured otherwise.
pub const DEFAULT_CLOUD_OUTPUT_TOKENS: u32 = 4096;
use crate::secret::SecretString;

/// The Azure `api-version` used when none is configured: recent enough for reasoning models
/// and `max_completion_tokens`.
pub const DEFAULT_AZURE_API_VERSION: &str = "2025-04-01-preview";

/// The environment variable naming the file a replayed cassette's usage report (which
/// interactions were replayed, which were not) is written to, for configured cassettes and
/// `--vlm replay:` alike.
pub const CASSETTE_USAGE_ENV: &str = "NESY_CASSETTE_USAGE";

/// A configuration problem, naming where the bad value came from.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The TOML file could not be read.
    #[error("reading VLM config file {}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (shown in the message, so not also a `source`).
        error: std::io::Error,
    },
    /// The TOML file does not parse or has an unknown key (the message has line and column).
    #[error("VLM config file {}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A value is malformed.
    #[error("{origin}: {message}")]
    Invalid {
        /// Where the value came from: a flag, a variable or a file key.
        origin: String,
        /// What was expected.
        message: String,
    },
    /// A required value is missing.
    #[error("no {what} configured: {hint}")]
    Missing {
        /// What is missing.
        what: &'static str,
        /// How to provide it.
        hint: String,
    },
}

/// Where environment variables come from: the process, or a map in tests.
pub trait EnvSource {
    /// The value of a variable; empty values count as unset.
    fn var(&self, name: &str) -> Option<String>;
}

/// The process environment.
#[derive(Debug, Clone, Copy, Default)]
pub struct ProcessEnv;

impl EnvSource for ProcessEnv {
    fn var(&self, name: &str) -> Option<String> {
        std::env::var(name).ok().filter(|v| !v.is_empty())
    }
}

impl EnvSource for HashMap<String, String> {
    fn var(&self, name: &str) -> Option<String> {
        self.get(name).filter(|v| !v.is_empty()).cloned()
    }
}

/// Connect, read and total timeouts. reqwest has none by default, so a hung server would
/// hang a run forever.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Timeouts {
    /// Establishing a connection.
    pub connect: Option<Duration>,
    /// Between bytes of the response. A non-streaming completion sends nothing until it is
    /// done, so this is also the time to the first byte: reasoning models need minutes.
    pub read: Option<Duration>,
    /// One attempt from connecting to the end of the body.
    pub total: Option<Duration>,
    /// How long an idle keep-alive connection is kept for reuse. A connection silently
    /// dropped by a NAT would otherwise hang the next call until the read timeout.
    pub pool_idle: Option<Duration>,
}

impl Default for Timeouts {
    fn default() -> Self {
        Self {
            connect: Some(Duration::from_secs(10)),
            read: Some(Duration::from_secs(300)),
            total: Some(Duration::from_secs(600)),
            pool_idle: Some(Duration::from_secs(60)),
        }
    }
}

/// Where and how to use a cassette.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CassetteSettings {
    /// The cassette file (`.json`); blobs go to `blobs/` beside it.
    pub path: PathBuf,
    /// Record/replay mode.
    pub mode: CassetteMode,
    /// Fail at the end of a run if recorded interactions were not used.
    pub strict: bool,
    /// Where to write which interactions were used (input of `nesy cassette prune`).
    pub usage_report: Option<PathBuf>,
}

/// Everything needed to build a [`crate::VlmClient`].
#[derive(Debug, Clone, PartialEq)]
pub struct VlmConfig {
    /// The kind of server.
    pub backend: BackendKind,
    /// Base URL, e.g. `https://api.openai.com/v1`; the request path is appended.
    pub base_url: String,
    /// Model name (for Azure: the deployment name).
    pub model: String,
    /// The API key, if any.
    pub api_key: Option<SecretString>,
    /// Classic Azure deployment (defaults to `model`).
    pub azure_deployment: Option<String>,
    /// Classic Azure `api-version`.
    pub azure_api_version: String,
    /// Whether the model is a reasoning model.
    pub reasoning: ReasoningMode,
    /// Defaults for token cap, temperature, reasoning effort and image detail.
    pub defaults: BodyDefaults,
    /// HTTP timeouts.
    pub timeouts: Timeouts,
    /// Retry policy.
    pub retry: RetryPolicy,
    /// Calls in flight at once.
    pub max_concurrency: usize,
    /// The most images the endpoint accepts in one request (`None`: no limit is known).
    /// A request over it is refused before it is sent ([`crate::VlmError::TooManyImages`]),
    /// as vLLM's `--limit-mm-per-prompt` or a provider's cap would refuse it.
    pub max_images_per_request: Option<usize>,
    /// Cassette, if any.
    pub cassette: Option<CassetteSettings>,
    /// Prices for cost accounting.
    pub prices: PriceTable,
}

impl VlmConfig {
    /// A configuration with defaults for everything but the backend and model.
    pub fn new(backend: BackendKind, model: impl Into<String>) -> Self {
        Self {
            backend,
            base_url: backend.default_base_url().unwrap_or_default().to_string(),
            model: model.into(),
            api_key: None,
            azure_deployment: None,
            azure_api_version: DEFAULT_AZURE_API_VERSION.to_string(),
            reasoning: ReasoningMode::Auto,
            // A cloud model gets one generous cap; a local one a cap per kind of call, since
            // it generates slowly and a runaway reply would cost minutes.
            defaults: if backend.is_local() {
                BodyDefaults {
                    reply_caps: Some(ReplyCaps::LOCAL),
                    ..BodyDefaults::default()
                }
            } else {
                BodyDefaults {
                    max_output_tokens: Some(DEFAULT_CLOUD_OUTPUT_TOKENS),
                    ..BodyDefaults::default()
                }
            },
            timeouts: Timeouts::default(),
            retry: RetryPolicy::default(),
            max_concurrency: 8,
            max_images_per_request: None,
            cassette: None,
            prices: PriceTable::default(),
        }
    }

    /// The resolved backend profile.
    pub fn profile(&self) -> Profile {
        Profile::new(
            self.backend,
            &self.model,
            self.reasoning,
            self.azure_deployment.as_deref(),
            &self.azure_api_version,
            self.defaults.clone(),
        )
    }

    /// Reads the process environment and the config file it names (`NESY_VLM_CONFIG`).
    pub fn from_env() -> Result<Self, ConfigError> {
        Self::resolve(&ConfigOverrides::default(), &ProcessEnv)
    }

    /// Resolves a configuration: flags override environment variables, which override the
    /// TOML file (`--vlm-config` or `NESY_VLM_CONFIG`), which overrides defaults.
    pub fn resolve(flags: &ConfigOverrides, env: &dyn EnvSource) -> Result<Self, ConfigError> {
        let file_path = flags
            .config
            .clone()
            .or_else(|| env.var("NESY_VLM_CONFIG").map(PathBuf::from));
        let mut file = match &file_path {
            Some(path) => FileConfig::load(path)?,
            None => FileConfig::default(),
        };
        let sources = Sources {
            flags,
            env,
            file_path: file_path.as_deref(),
        };
        let backend = sources.backend(&file)?;
        let model = flags
            .model
            .clone()
            .or_else(|| env.var("NESY_VLM_MODEL"))
            .or(file.model.clone())
            .ok_or_else(|| ConfigError::Missing {
                what: "model",
                hint: "set NESY_VLM_MODEL, pass --vlm-model, or put `model` in the config file".into(),
            })?;
        let mut config = Self::new(backend, model);
        config.base_url = normalise_base_url(backend, &sources.base_url(backend, &file)?);
        config.api_key = sources.api_key(backend, &file);
        sources.azure(&mut config, file.azure.take().unwrap_or_default());
        sources.request_defaults(&mut config, &file)?;
        sources.retry(&mut config, file.retry.take().unwrap_or_default())?;
        sources.timeouts(&mut config, file.timeouts.take().unwrap_or_default())?;
        config.cassette = sources.cassette(file.cassette.take().unwrap_or_default())?;
        config.prices = file.prices.unwrap_or_default();
        Ok(config)
    }
}

/// The three layers a setting can come from, highest first: flags, the environment, the
/// TOML file. Each step of [`VlmConfig::resolve`] reads one group of settings through it.
struct Sources<'a> {
    flags: &'a ConfigOverrides,
    env: &'a dyn EnvSource,
    file_path: Option<&'a std::path::Path>,
}

impl Sources<'_> {
    /// How a file key is named in errors: the file and the key.
    fn file_origin(&self, key: &str) -> String {
        match self.file_path {
            Some(path) => format!("{}: `{key}`", path.display()),
            None => key.to_string(),
        }
    }

    /// The flag's value, else the environment variable's (parsed), else the file's.
    fn setting<T: FromStr>(
        &self,
        flag: Option<T>,
        var: &'static str,
        file: Option<T>,
    ) -> Result<Option<T>, ConfigError>
    where
        T::Err: std::fmt::Display,
    {
        Ok(match (flag, self.env.var(var), file) {
            (Some(value), _, _) => Some(value),
            (None, Some(value), _) => Some(parse(&value, var)?),
            (None, None, Some(value)) => Some(value),
            (None, None, None) => None,
        })
    }

    /// As [`Sources::setting`], with the name of the source the value came from (the flag's
    /// name, given with its value; the variable; the file key), for errors about the value.
    fn setting_with_origin<T: FromStr>(
        &self,
        flag: Option<(T, &str)>,
        var: &'static str,
        file: Option<T>,
        key: &str,
    ) -> Result<Option<(T, String)>, ConfigError>
    where
        T::Err: std::fmt::Display,
    {
        Ok(match (flag, self.env.var(var), file) {
            (Some((value, name)), _, _) => Some((value, name.to_owned())),
            (None, Some(value), _) => Some((parse(&value, var)?, var.to_owned())),
            (None, None, Some(value)) => Some((value, self.file_origin(key))),
            (None, None, None) => None,
        })
    }

    /// A duration in seconds from the flag, the environment variable or the file key.
    fn seconds_setting(
        &self,
        flag: Option<(f64, &str)>,
        var: &'static str,
        file: Option<f64>,
        key: &str,
    ) -> Result<Option<Duration>, ConfigError> {
        self.setting_with_origin(flag, var, file, key)?
            .map(|(value, origin)| seconds(value, &origin))
            .transpose()
    }

    fn backend(&self, file: &FileConfig) -> Result<BackendKind, ConfigError> {
        Ok(
            match (
                self.flags.backend,
                self.env.var("NESY_VLM_BACKEND"),
                &file.backend,
            ) {
                (Some(backend), _, _) => backend,
                (None, Some(value), _) => parse(&value, "NESY_VLM_BACKEND")?,
                (None, None, Some(value)) => parse(value, &self.file_origin("backend"))?,
                (None, None, None) => BackendKind::OpenAi,
            },
        )
    }

    fn base_url(&self, backend: BackendKind, file: &FileConfig) -> Result<String, ConfigError> {
        self.flags
            .base_url
            .clone()
            .or_else(|| self.env.var("NESY_VLM_BASE_URL"))
            .or(file.base_url.clone())
            .or_else(|| {
                matches!(backend, BackendKind::Azure | BackendKind::AzureV1)
                    .then(|| self.env.var("AZURE_OPENAI_ENDPOINT"))
                    .flatten()
            })
            .or_else(|| backend.default_base_url().map(str::to_string))
            .ok_or_else(|| ConfigError::Missing {
                what: "base URL",
                hint: format!(
                    "the {backend} backend needs the resource endpoint (https://NAME.openai.azure.com): set \
                     NESY_VLM_BASE_URL or AZURE_OPENAI_ENDPOINT, or pass --vlm-base-url"
                ),
            })
    }

    /// The key: `NESY_VLM_API_KEY`, the variable the file names, or the backend's usual
    /// variable. Keys never come from flags or the file itself.
    fn api_key(&self, backend: BackendKind, file: &FileConfig) -> Option<SecretString> {
        let env = self.env;
        env.var("NESY_VLM_API_KEY")
            .or_else(|| file.api_key_env.as_deref().and_then(|name| env.var(name)))
            .or_else(|| match backend {
                BackendKind::OpenAi => env.var("OPENAI_API_KEY"),
                BackendKind::Azure | BackendKind::AzureV1 => env.var("AZURE_OPENAI_API_KEY"),
                // A cloud key is never sent to a local server by accident.
                BackendKind::Vllm | BackendKind::Ollama | BackendKind::LlamaCpp => None,
            })
            .map(SecretString::new)
    }

    fn azure(&self, config: &mut VlmConfig, azure: FileAzure) {
        config.azure_deployment = self
            .env
            .var("NESY_VLM_AZURE_DEPLOYMENT")
            .or(azure.deployment)
            .or(config.azure_deployment.take());
        if let Some(version) = self
            .env
            .var("NESY_VLM_AZURE_API_VERSION")
            .or_else(|| self.env.var("OPENAI_API_VERSION"))
            .or(azure.api_version)
        {
            config.azure_api_version = version;
        }
    }

    /// Reasoning mode and effort, token cap, temperature, image detail, concurrency.
    fn request_defaults(&self, config: &mut VlmConfig, file: &FileConfig) -> Result<(), ConfigError> {
        let flags = self.flags;
        if let Some(mode) = self.setting(flags.reasoning, "NESY_VLM_REASONING", file.reasoning)? {
            config.reasoning = mode;
        }
        if let Some(effort) = self.setting(
            flags.reasoning_effort,
            "NESY_VLM_REASONING_EFFORT",
            file.reasoning_effort,
        )? {
            config.defaults.reasoning_effort = Some(effort);
        }
        if let Some(tokens) = self.setting(
            flags.max_output_tokens,
            "NESY_VLM_MAX_TOKENS",
            file.max_output_tokens,
        )? {
            config.defaults.max_output_tokens = Some(tokens);
        }
        if let Some((temperature, origin)) = self.setting_with_origin(
            flags.temperature.map(|t| (t, "--vlm-temperature")),
            "NESY_VLM_TEMPERATURE",
            file.temperature,
            "temperature",
        )? {
            // NaN would go out as JSON `null`; providers accept 0 to 2.
            if !(0.0..=2.0).contains(&temperature) {
                return Err(invalid(
                    &origin,
                    &format!("expected a temperature from 0 to 2, got {temperature}"),
                ));
            }
            config.defaults.temperature = Some(temperature);
        }
        if let Some(mode) = self.setting(flags.constrain, "NESY_VLM_CONSTRAIN", file.constrain)? {
            config.defaults.constrain = mode;
        }
        if let Some(detail) = self.setting(flags.image_detail, "NESY_VLM_IMAGE_DETAIL", file.image_detail)? {
            config.defaults.image_detail = Some(detail);
        }
        if let Some(limit) = self.setting(
            flags.max_concurrency,
            "NESY_VLM_MAX_CONCURRENCY",
            file.max_concurrency,
        )? {
            if limit == 0 {
                return Err(invalid("max_concurrency", "must be at least 1"));
            }
            config.max_concurrency = limit;
        }
        if let Some(limit) = self.setting(
            flags.max_images,
            "NESY_VLM_MAX_IMAGES",
            file.max_images_per_request,
        )? {
            if limit == 0 {
                return Err(invalid("max_images_per_request", "must be at least 1"));
            }
            config.max_images_per_request = Some(limit);
        }
        Ok(())
    }

    fn retry(&self, config: &mut VlmConfig, retry: FileRetry) -> Result<(), ConfigError> {
        if let Some(attempts) = self.setting(
            self.flags.max_attempts,
            "NESY_VLM_MAX_ATTEMPTS",
            retry.max_attempts,
        )? {
            if attempts == 0 {
                return Err(invalid("max_attempts", "must be at least 1"));
            }
            config.retry.max_attempts = attempts;
        }
        if let Some(ms) = retry.base_delay_ms {
            config.retry.base_delay = Duration::from_millis(ms);
        }
        if let Some(ms) = retry.max_delay_ms {
            config.retry.max_delay = Duration::from_millis(ms);
        }
        if let Some(secs) = retry.max_retry_after_secs {
            config.retry.max_retry_after = seconds(secs, &self.file_origin("retry.max_retry_after_secs"))?;
        }
        Ok(())
    }

    fn timeouts(&self, config: &mut VlmConfig, timeouts: FileTimeouts) -> Result<(), ConfigError> {
        if let Some(t) = self.seconds_setting(
            None,
            "NESY_VLM_TIMEOUT_CONNECT_SECS",
            timeouts.connect_secs,
            "timeouts.connect_secs",
        )? {
            config.timeouts.connect = Some(t);
        }
        if let Some(t) = self.seconds_setting(
            None,
            "NESY_VLM_TIMEOUT_READ_SECS",
            timeouts.read_secs,
            "timeouts.read_secs",
        )? {
            config.timeouts.read = Some(t);
        }
        if let Some(t) = self.seconds_setting(
            self.flags.timeout_secs.map(|t| (t, "--vlm-timeout-secs")),
            "NESY_VLM_TIMEOUT_TOTAL_SECS",
            timeouts.total_secs,
            "timeouts.total_secs",
        )? {
            config.timeouts.total = Some(t);
        }
        Ok(())
    }

    fn cassette(&self, cassette: FileCassette) -> Result<Option<CassetteSettings>, ConfigError> {
        let flags = self.flags;
        let Some(path) = flags
            .cassette
            .clone()
            .or_else(|| self.env.var("NESY_CASSETTE").map(PathBuf::from))
            .or(cassette.path)
        else {
            return Ok(None);
        };
        let mode = self
            .setting(flags.cassette_mode, "NESY_CASSETTE_MODE", cassette.mode)?
            .unwrap_or(CassetteMode::None);
        let strict = flags.cassette_strict
            || match self.env.var("NESY_CASSETTE_STRICT") {
                Some(v) => parse_bool(&v, "NESY_CASSETTE_STRICT")?,
                None => cassette.strict.unwrap_or(false),
            };
        let usage_report = self
            .env
            .var(CASSETTE_USAGE_ENV)
            .map(PathBuf::from)
            .or(cassette.usage_report);
        Ok(Some(CassetteSettings {
            path,
            mode,
            strict,
            usage_report,
        }))
    }
}

/// Azure v1 lives under `/openai/v1` of the resource endpoint; accept either form.
fn normalise_base_url(backend: BackendKind, base_url: &str) -> String {
    let trimmed = base_url.trim().trim_end_matches('/');
    if backend == BackendKind::AzureV1 && !trimmed.ends_with("/openai/v1") {
        format!("{}/openai/v1", trimmed.trim_end_matches("/openai"))
    } else {
        trimmed.to_string()
    }
}

fn parse<T: FromStr>(value: &str, origin: &str) -> Result<T, ConfigError>
where
    T::Err: std::fmt::Display,
{
    value
        .trim()
        .parse()
        .map_err(|err: T::Err| invalid(origin, &err.to_string()))
}

fn parse_bool(value: &str, origin: &str) -> Result<bool, ConfigError> {
    match value.trim().to_ascii_lowercase().as_str() {
        "1" | "true" | "yes" | "on" => Ok(true),
        "0" | "false" | "no" | "off" => Ok(false),
        _ => Err(invalid(origin, &format!("expected true or false, got {value:?}"))),
    }
}

fn seconds(value: f64, origin: &str) -> Result<Duration, ConfigError> {
    // A zero timeout would fail every call before it is sent.
    Duration::try_from_secs_f64(value)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| {
            invalid(
                origin,
                &format!("expected a positive number of seconds, got {value}"),
            )
        })
}

fn invalid(origin: &str, message: &str) -> ConfigError {
    ConfigError::Invalid {
        origin: origin.to_string(),
        message: message.to_string(),
    }
}

/// Flags that override the environment and the file; the CLI flattens these into its
/// commands (with the `clap` feature). There is deliberately no API-key flag.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct ConfigOverrides {
    /// TOML file with VLM settings [env: NESY_VLM_CONFIG].
    #[cfg_attr(feature = "clap", arg(long = "vlm-config", value_name = "FILE"))]
    pub config: Option<PathBuf>,
    /// Backend: openai, azure, azure-v1, vllm, ollama, llamacpp [env: NESY_VLM_BACKEND].
    #[cfg_attr(feature = "clap", arg(long = "vlm-backend", value_name = "KIND"))]
    pub backend: Option<BackendKind>,
    /// Base URL of the server [env: NESY_VLM_BASE_URL].
    #[cfg_attr(feature = "clap", arg(long = "vlm-base-url", value_name = "URL"))]
    pub base_url: Option<String>,
    /// Model (Azure: deployment) name [env: NESY_VLM_MODEL].
    #[cfg_attr(feature = "clap", arg(long = "vlm-model", value_name = "NAME"))]
    pub model: Option<String>,
    /// Treat the model as a reasoning model: auto, on, off [env: NESY_VLM_REASONING].
    #[cfg_attr(feature = "clap", arg(long = "vlm-reasoning", value_name = "MODE"))]
    pub reasoning: Option<ReasoningMode>,
    /// Reasoning effort for reasoning models [env: NESY_VLM_REASONING_EFFORT].
    #[cfg_attr(feature = "clap", arg(long = "vlm-reasoning-effort", value_name = "EFFORT"))]
    pub reasoning_effort: Option<ReasoningEffort>,
    /// Output-token cap per call [env: NESY_VLM_MAX_TOKENS].
    #[cfg_attr(feature = "clap", arg(long = "vlm-max-tokens", value_name = "N"))]
    pub max_output_tokens: Option<u32>,
    /// Sampling temperature for non-reasoning models [env: NESY_VLM_TEMPERATURE].
    #[cfg_attr(feature = "clap", arg(long = "vlm-temperature", value_name = "T"))]
    pub temperature: Option<f32>,
    /// Hold replies to each call's grammar where the backend can: auto, off
    /// [env: NESY_VLM_CONSTRAIN].
    #[cfg_attr(feature = "clap", arg(long = "vlm-constrain", value_name = "MODE"))]
    pub constrain: Option<ConstrainMode>,
    /// Image detail: auto, low, high [env: NESY_VLM_IMAGE_DETAIL].
    #[cfg_attr(feature = "clap", arg(long = "vlm-image-detail", value_name = "DETAIL"))]
    pub image_detail: Option<ImageDetail>,
    /// Calls in flight at once [env: NESY_VLM_MAX_CONCURRENCY].
    #[cfg_attr(feature = "clap", arg(long = "vlm-max-concurrency", value_name = "N"))]
    pub max_concurrency: Option<usize>,
    /// The most images the endpoint accepts in one request [env: NESY_VLM_MAX_IMAGES].
    #[cfg_attr(feature = "clap", arg(long = "vlm-max-images", value_name = "N"))]
    pub max_images: Option<usize>,
    /// Attempts per call, the first included [env: NESY_VLM_MAX_ATTEMPTS].
    #[cfg_attr(feature = "clap", arg(long = "vlm-max-attempts", value_name = "N"))]
    pub max_attempts: Option<u32>,
    /// Total timeout of one attempt in seconds [env: NESY_VLM_TIMEOUT_TOTAL_SECS].
    #[cfg_attr(feature = "clap", arg(long = "vlm-timeout-secs", value_name = "SECS"))]
    pub timeout_secs: Option<f64>,
    /// Cassette file for record/replay [env: NESY_CASSETTE].
    #[cfg_attr(feature = "clap", arg(long = "cassette", value_name = "FILE"))]
    pub cassette: Option<PathBuf>,
    /// Cassette mode: none, once, new_episodes, all [env: NESY_CASSETTE_MODE].
    #[cfg_attr(feature = "clap", arg(long = "cassette-mode", value_name = "MODE"))]
    pub cassette_mode: Option<CassetteMode>,
    /// Fail if recorded interactions go unused [env: NESY_CASSETTE_STRICT].
    #[cfg_attr(feature = "clap", arg(long = "cassette-strict"))]
    pub cassette_strict: bool,
}

/// The TOML file's shape. Unknown keys are errors, so a typo is reported, not ignored.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileConfig {
    backend: Option<String>,
    base_url: Option<String>,
    model: Option<String>,
    /// The name of the environment variable holding the key (the key itself never goes in
    /// a file).
    api_key_env: Option<String>,
    reasoning: Option<ReasoningMode>,
    reasoning_effort: Option<ReasoningEffort>,
    max_output_tokens: Option<u32>,
    temperature: Option<f32>,
    image_detail: Option<ImageDetail>,
    constrain: Option<ConstrainMode>,
    max_concurrency: Option<usize>,
    max_images_per_request: Option<usize>,
    azure: Option<FileAzure>,
    timeouts: Option<FileTimeouts>,
    retry: Option<FileRetry>,
    cassette: Option<FileCassette>,
    prices: Option<PriceTable>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileAzure {
    deployment: Option<String>,
    api_version: Option<String>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileTimeouts {
    connect_secs: Option<f64>,
    read_secs: Option<f64>,
    total_secs: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileRetry {
    max_attempts: Option<u32>,
    base_delay_ms: Option<u64>,
    max_delay_ms: Option<u64>,
    max_retry_after_secs: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileCassette {
    path: Option<PathBuf>,
    mode: Option<CassetteMode>,
    strict: Option<bool>,
    usage_report: Option<PathBuf>,
}

impl FileConfig {
    fn load(path: &Path) -> Result<Self, ConfigError> {
        let text =
            nesy_input::read_text(path, nesy_input::MAX_JSON_BYTES).map_err(|source| ConfigError::Io {
                path: path.to_path_buf(),
                error: source,
            })?;
        // The parser quotes the offending line, which may hold a key.
        toml::from_str(&text).map_err(|err| ConfigError::File {
            path: path.to_path_buf(),
            message: crate::secret::redact_credentials(&err.to_string()),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(pairs: &[(&str, &str)]) -> HashMap<String, String> {
        pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    }

    #[test]
    fn env_configures_openai_and_flags_win() {
        let vars = env(&[
            ("NESY_VLM_MODEL", "gpt-5"),
            ("OPENAI_API_KEY", "sk-env-secret-123"),
            ("NESY_VLM_REASONING_EFFORT", "low"),
            ("NESY_CASSETTE", "c.json"),
            ("NESY_CASSETTE_MODE", "new_episodes"),
        ]);
        let flags = ConfigOverrides {
            model: Some("gpt-5-mini".into()),
            ..Default::default()
        };
        let config = VlmConfig::resolve(&flags, &vars).unwrap();
        assert_eq!(config.backend, BackendKind::OpenAi);
        assert_eq!(config.base_url, "https://api.openai.com/v1");
        assert_eq!(config.model, "gpt-5-mini");
        assert_eq!(
            config.api_key.as_ref().map(SecretString::expose),
            Some("sk-env-secret-123")
        );
        assert_eq!(config.defaults.reasoning_effort, Some(ReasoningEffort::Low));
        assert_eq!(config.cassette.as_ref().unwrap().mode, CassetteMode::NewEpisodes);
        assert!(config.profile().reasoning);
        // The key never shows in Debug output.
        assert!(!format!("{config:?}").contains("sk-env-secret"));
    }

    #[test]
    fn file_settings_apply_below_env() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("vlm.toml");
        std::fs::write(
            &path,
            r#"
backend = "azure"
base_url = "https://res.openai.azure.com/"
model = "gpt-4o-deploy"
api_key_env = "MY_AZURE_KEY"
temperature = 0.2
[azure]
api_version = "2024-10-21"
[timeouts]
connect_secs = 3
[prices."gpt-4o"]
input_per_mtok = 2.5
output_per_mtok = 10.0
"#,
        )
        .unwrap();
        let vars = env(&[
            ("NESY_VLM_CONFIG", path.to_str().unwrap()),
            ("MY_AZURE_KEY", "azure-secret"),
            ("NESY_VLM_TEMPERATURE", "0.5"),
        ]);
        let config = VlmConfig::resolve(&ConfigOverrides::default(), &vars).unwrap();
        assert_eq!(config.backend, BackendKind::Azure);
        assert_eq!(config.base_url, "https://res.openai.azure.com");
        assert_eq!(
            config.api_key.as_ref().map(SecretString::expose),
            Some("azure-secret")
        );
        assert_eq!(config.defaults.temperature, Some(0.5));
        assert_eq!(config.timeouts.connect, Some(Duration::from_secs(3)));
        assert_eq!(
            config.profile().path,
            "/openai/deployments/gpt-4o-deploy/chat/completions?api-version=2024-10-21"
        );
        assert!(config.prices.lookup("gpt-4o").is_some());
    }

    #[test]
    fn errors_name_their_origin() {
        let err = VlmConfig::resolve(&ConfigOverrides::default(), &env(&[]))
            .unwrap_err()
            .to_string();
        assert!(err.contains("NESY_VLM_MODEL"), "{err}");
        let vars = env(&[("NESY_VLM_MODEL", "m"), ("NESY_VLM_MAX_TOKENS", "lots")]);
        let err = VlmConfig::resolve(&ConfigOverrides::default(), &vars)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("NESY_VLM_MAX_TOKENS:"), "{err}");
        let vars = env(&[("NESY_VLM_MODEL", "m"), ("NESY_VLM_BACKEND", "azure")]);
        let err = VlmConfig::resolve(&ConfigOverrides::default(), &vars)
            .unwrap_err()
            .to_string();
        assert!(err.contains("AZURE_OPENAI_ENDPOINT"), "{err}");

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, "model = \"m\"\nmax_tokens = 5\n").unwrap();
        let vars = env(&[("NESY_VLM_CONFIG", path.to_str().unwrap())]);
        let err = VlmConfig::resolve(&ConfigOverrides::default(), &vars)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("bad.toml") && err.contains("max_tokens") && err.contains("line 2"),
            "{err}"
        );
    }

    #[test]
    fn out_of_range_flags_are_refused_by_name() {
        let vars = env(&[("NESY_VLM_MODEL", "m")]);
        for temperature in [f32::NAN, -0.5, 2.5] {
            let flags = ConfigOverrides {
                temperature: Some(temperature),
                ..ConfigOverrides::default()
            };
            let err = VlmConfig::resolve(&flags, &vars).unwrap_err().to_string();
            assert!(err.starts_with("--vlm-temperature:"), "{err}");
        }
        for seconds in [0.0, -1.0, f64::NAN, 1e300] {
            let flags = ConfigOverrides {
                timeout_secs: Some(seconds),
                ..ConfigOverrides::default()
            };
            let err = VlmConfig::resolve(&flags, &vars).unwrap_err().to_string();
            assert!(err.starts_with("--vlm-timeout-secs:"), "{err}");
            assert!(err.contains("positive number of seconds"), "{err}");
        }
        let vars = env(&[("NESY_VLM_MODEL", "m"), ("NESY_VLM_TEMPERATURE", "NaN")]);
        let err = VlmConfig::resolve(&ConfigOverrides::default(), &vars)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("NESY_VLM_TEMPERATURE:"), "{err}");
    }

    #[test]
    fn a_key_in_a_bad_config_file_is_not_echoed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("vlm.toml");
        std::fs::write(&path, "model = \"m\"\napi_key = \"sk-proj-from-a-file-0042\"\n").unwrap();
        let vars = env(&[("NESY_VLM_CONFIG", path.to_str().unwrap())]);
        let err = VlmConfig::resolve(&ConfigOverrides::default(), &vars)
            .unwrap_err()
            .to_string();
        assert!(err.contains("vlm.toml") && err.contains("api_key"), "{err}");
        assert!(!err.contains("from-a-file"), "{err}");
    }

    #[cfg(feature = "clap")]
    #[test]
    fn flags_parse_through_clap() {
        use clap::Parser as _;
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            vlm: ConfigOverrides,
        }
        let cli = Cli::try_parse_from([
            "nesy",
            "--vlm-backend",
            "llama.cpp",
            "--vlm-model",
            "local",
            "--vlm-reasoning-effort",
            "high",
            "--cassette-mode",
            "new_episodes",
            "--cassette-strict",
        ])
        .unwrap();
        assert_eq!(cli.vlm.backend, Some(BackendKind::LlamaCpp));
        assert_eq!(cli.vlm.reasoning_effort, Some(ReasoningEffort::High));
        assert_eq!(cli.vlm.cassette_mode, Some(CassetteMode::NewEpisodes));
        assert!(cli.vlm.cassette_strict);
        let err = Cli::try_parse_from(["nesy", "--vlm-backend", "bedrock"])
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("expected openai"), "{err}");
    }

    #[test]
    fn local_backends_never_pick_up_cloud_keys_and_azure_v1_path_is_normalised() {
        let vars = env(&[
            ("NESY_VLM_MODEL", "qwen"),
            ("NESY_VLM_BACKEND", "vllm"),
            ("OPENAI_API_KEY", "sk-x"),
        ]);
        let config = VlmConfig::resolve(&ConfigOverrides::default(), &vars).unwrap();
        assert_eq!(config.api_key, None);
        assert_eq!(config.base_url, "http://localhost:8000/v1");
        let vars = env(&[
            ("NESY_VLM_MODEL", "gpt-5"),
            ("NESY_VLM_BACKEND", "azure-v1"),
            ("AZURE_OPENAI_ENDPOINT", "https://res.openai.azure.com/"),
        ]);
        let config = VlmConfig::resolve(&ConfigOverrides::default(), &vars).unwrap();
        assert_eq!(config.base_url, "https://res.openai.azure.com/openai/v1");
    }
}
