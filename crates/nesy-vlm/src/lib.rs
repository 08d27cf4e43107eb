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
//! On top of the client, the NeSyCR prompts (minijinja templates under `prompts/`, see
//! [`prompts`]):
//! - [`VlmReasoner`] implements nesy-core's `Reasoner` (operator induction with keyframe
//!   images from a [`KeyframeImages`] source, refinement proposals) and offers
//!   [`VlmReasoner::translate_state`] and [`VlmReasoner::generate_code`];
//! - every request carries a typed [`VlmTask`] context for offline responders.
//!
//! ```no_run
//! # async fn demo() -> Result<(), nesy_vlm::VlmError> {
//! use nesy_vlm::{ChatRequest, Image, Message, Part, VlmClient, VlmConfig};
//! let client = VlmClient::from_config(&VlmConfig::from_env()?)?;
//! let png: Vec<u8> = std::fs::read("keyframe.png").unwrap();
//! let reply = client
//!     .chat(ChatRequest::new().purpose("describe").message(Message::user(vec![
//!         Part::text("What is on the table?"),
//!         Image::png(png)?.into(),
//!     ])))
//!     .await?;
//! println!("{} ({} attempts)", reply.text, reply.attempts);
//! client.finish()?;
//! # Ok(()) }
//! ```
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
//! The offline reference responder plugs in where HTTP would; a compiler turns verified
//! procedures into code for its code-generation answers:
//!
//! ```
//! use std::sync::Arc;
//! use nesy_vlm::{BackendKind, OracleNoise, OracleTransport, VlmClient, VlmConfig};
//!
//! let noise: OracleNoise = "op-drop=0.1,bad-patch=0.2".parse().unwrap();
//! let oracle = Arc::new(OracleTransport::new().unwrap().with_noise(noise, 7));
//! let config = VlmConfig::new(BackendKind::OpenAi, "oracle");
//! let client = VlmClient::with_transport(&config, oracle.clone());
//! assert_eq!(oracle.stats().inductions, 0);
//! # drop(client);
//! ```

pub mod accounting;
pub mod cassette;
pub mod client;
pub mod codegen;
pub mod config;
pub mod context;
pub mod error;
pub mod keyframes;
pub mod oracle;
pub mod profile;
pub mod prompts;
pub mod reasoner;
pub mod reply;
pub mod request;
pub mod response;
pub mod retry;
pub mod secret;
pub mod settings;
pub mod timefmt;
pub mod translate;
pub mod transport;

pub use accounting::{CallRecord, ModelPrice, PriceTable, RunUsage, UsageTotals};
pub use cassette::{CassetteError, CassetteMode, CassetteOptions, CassetteTransport};
pub use client::VlmClient;
pub use codegen::{CodeGenerationRequest, CodegenError, PolicySource, generate_code};
pub use config::{
    CassetteSettings, ConfigError, ConfigOverrides, EnvSource, ProcessEnv, Timeouts, VlmConfig,
};
pub use context::{
    CodeGenerationContext, ContextError, Embodiment, InductionContext, PatchContext, StateTranslationContext,
    VlmTask,
};
pub use error::{ProviderError, TimeoutPhase, TransportError, VlmError};
pub use keyframes::{KeyframeImages, KeyframeList, NoKeyframes, Views};
pub use oracle::{OracleNoise, OracleTransport, PolicyCompileError, PolicyCompiler};
pub use profile::{BackendKind, BodyDefaults, Profile, ReasoningMode, TokenCapField};
pub use prompts::{PromptError, Prompts};
pub use reasoner::VlmReasoner;
pub use request::{ChatRequest, Image, ImageDetail, Message, Part, ReasoningEffort, Role, TaskContext};
pub use response::{ChatResponse, FinishReason, Usage};
pub use retry::RetryPolicy;
pub use secret::SecretString;
pub use settings::{CallSettings, PurposeSettings};
pub use translate::{StateTranslationRequest, TranslateError, TranslatedState, translate_state};
pub use transport::http::Auth;
pub use transport::{BoxFuture, HttpTransport, Origin, Transport, WireRequest, WireResponse};
