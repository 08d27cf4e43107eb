//! # nesy-vlm
//!
//! The client through which every NeSyCR step that thinks talks to a vision-language
//! model: an OpenAI-compatible chat-completions client with backend profiles, retries,
//! accounting and cassette record/replay.
//!
//! Layers, top to bottom:
//! - [`VlmClient`]: typed [`ChatRequest`] in, typed [`ChatResponse`] out; the backend
//!   [`Profile`] builds the body; retries, the concurrency cap and accounting live here.
//! - [`Transport`]: a wire request (path + JSON body + task context that is never sent)
//!   in, a wire response out. [`HttpTransport`] talks to a server; [`CassetteTransport`]
//!   replays or records around an optional inner transport; an offline responder can be
//!   added as another implementation without touching the client.
//!
//! nesy-vlm knows nothing of NeSyCR: the prompts, the reasoner and the offline responder
//! are the crates above it (nesy-reasoner, nesy-oracle). A request may carry an opaque
//! [`TaskContext`] (a kind and JSON data) for transports that answer offline; it is never sent
//! to a server and never part of a cassette key.
//!
//! Settings resolve from flags over the environment over a TOML file over defaults; keys come
//! from the environment only:
//!
//! ```
//! use std::collections::HashMap;
//! use nesy_vlm::{BackendKind, ConfigOverrides, VlmConfig};
//!
//! let env: HashMap<String, String> = [
//!     ("NESY_VLM_BACKEND", "vllm"),
//!     ("NESY_VLM_BASE_URL", "http://gpu-host:8000/v1/"),
//!     ("NESY_VLM_MODEL", "Qwen/Qwen2.5-VL-7B-Instruct"),
//!     ("NESY_VLM_MAX_TOKENS", "2048"),
//! ]
//! .into_iter()
//! .map(|(k, v)| (k.to_owned(), v.to_owned()))
//! .collect();
//! let flags = ConfigOverrides { max_output_tokens: Some(4096), ..ConfigOverrides::default() };
//! let config = VlmConfig::resolve(&flags, &env).unwrap();
//! assert_eq!(config.backend, BackendKind::Vllm);
//! assert_eq!(config.base_url, "http://gpu-host:8000/v1");
//! assert_eq!(config.defaults.max_output_tokens, Some(4096)); // the flag wins
//! assert!(config.api_key.is_none()); // a cloud key is never sent to a local server
//! ```
//!
mod accounting;
mod capabilities;
mod cassette;
mod client;
mod config;
mod constraint;
mod error;
mod profile;
pub mod reply;
mod request;
mod response;
mod retry;
mod secret;
mod settings;
mod timefmt;
mod transport;

pub use accounting::{CallRecord, ModelPrice, PriceTable, RunUsage, UsageTotals};
pub use capabilities::ServerCapabilities;
pub use cassette::tools as cassette_tools;
pub use cassette::{
    CassetteError, CassetteFile, CassetteMeta, CassetteMiss, CassetteMode, CassetteOptions,
    CassetteTransport, Interaction, InteractionRef, JsonDiff, MissReason, NearMatch,
    SCHEMA_VERSION as CASSETTE_SCHEMA_VERSION, StoredFailure, StoredRequest, StoredResponse, UsageReport,
    blobs_dir,
};
pub use client::VlmClient;
pub use config::{
    CASSETTE_USAGE_ENV, CassetteSettings, ConfigError, ConfigOverrides, DEFAULT_AZURE_API_VERSION,
    DEFAULT_CLOUD_OUTPUT_TOKENS, EnvSource, ProcessEnv, Timeouts, VlmConfig,
};
pub use constraint::{CONSTRAINT_FIELDS, ConstrainMode, ReplyConstraint, ReplyForm, gbnf_literal};
pub use error::{Cutoff, ProviderError, TimeoutPhase, TransportError, VlmError};
pub use profile::{BackendKind, BodyDefaults, Profile, ReasoningMode, ReplyCaps, TokenCapField};
pub use request::{
    ChatRequest, Image, ImageDetail, Message, Part, ReasoningEffort, ReplyLength, Role, TaskContext,
};
pub use response::{ChatResponse, FinishReason, Usage};
pub use retry::RetryPolicy;
pub use secret::SecretString;
pub use settings::{CallSettings, PurposeSettings};
pub use timefmt::{now_rfc3339, rfc3339};
pub use transport::{Auth, BoxFuture, HttpTransport, Origin, Transport, WireRequest, WireResponse};
