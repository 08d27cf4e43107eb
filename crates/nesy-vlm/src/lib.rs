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
pub mod request;
pub mod response;
pub mod retry;
pub mod secret;
pub mod settings;
mod timefmt;
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
pub use oracle::{OracleNoise, OracleTransport, PolicyCompiler};
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
