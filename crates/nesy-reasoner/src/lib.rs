//! # nesy-reasoner
//!
//! NeSyCR's side of every model call: the prompts, the requests built from nesy-core's
//! adaptation loop, and the readers of the replies.
//!
//! - [`VlmReasoner`] implements nesy-core's [`Reasoner`](nesy_core::adapt::Reasoner): the
//!   operator-induction and refinement prompts with the demonstration's keyframe images from
//!   a [`KeyframeImages`] source. Its replies go to nesy-core, which parses and verifies them.
//! - [`translate`]: state translation, the keyframe views read into the task's predicates.
//! - [`codegen`]: code generation, the program taken out of the reply and checked (a closed
//!   code block, the sandbox's static checks through a [`codegen::ProgramCheck`], no call of
//!   the other end effector's functions) before it is accepted.
//! - [`prompts`]: the minijinja templates (`crates/nesy-reasoner/prompts/`) with their
//!   few-shot examples, and the template environment the baselines share.
//! - Every request carries a typed [`VlmTask`] context, which an offline responder reads
//!   instead of the prompt text.
//!
//! The model itself is reached through nesy-vlm's client; nothing here links the simulator
//! or the Python sandbox.
//!
//! ```
//! use std::sync::Arc;
//! use nesy_core::Embodiment;
//! use nesy_reasoner::{KeyframeList, VlmReasoner};
//! use nesy_vlm::{BackendKind, VlmClient, VlmConfig};
//!
//! let client = VlmClient::from_config(&VlmConfig::new(BackendKind::Vllm, "a-local-model")).unwrap();
//! let reasoner = VlmReasoner::new(client)
//!     .unwrap()
//!     .with_keyframes(Arc::new(KeyframeList::default()))
//!     .with_embodiments(Embodiment::Finger, Embodiment::Vacuum);
//! // nesy_core::adapt::run(&mut reasoner, &demo, &target, &config).await drives it.
//! # drop(reasoner);
//! ```

pub mod codegen;
pub mod constraints;
mod context;
mod failure;
mod keyframes;
pub mod prompts;
pub mod readability;
mod reasoner;
pub mod translate;

pub use context::{
    CodeGenerationContext, ContextError, InductionContext, PatchContext, StateTranslationContext, VlmTask,
};
pub use failure::failure_kind;
pub use keyframes::{KeyframeImages, KeyframeList, NoKeyframes, Views};
pub use reasoner::VlmReasoner;
