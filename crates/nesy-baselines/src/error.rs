//! Why a baseline produced no plan.

use nesy_core::adapt::ReasonerErrorKind;
use nesy_vlm::VlmError;

use crate::prompts::PromptError;

/// Why a baseline produced no plan.
#[derive(Debug, thiserror::Error)]
pub enum BaselineError {
    /// A call failed before a reply arrived (transport, replay, a request the endpoint
    /// refuses, such as one over its image limit).
    #[error("{purpose}: the call failed: {error}")]
    Call {
        /// The stage's purpose label (`d2c.observe`, …).
        purpose: String,
        /// What the client said.
        error: VlmError,
    },
    /// No reply of the stage held its answer.
    #[error("{purpose}: no usable reply in {attempts} attempt(s); the last {problem}")]
    Unreadable {
        /// The stage's purpose label.
        purpose: String,
        /// The last reply, kept for the unit's record.
        reply: String,
        /// Why it could not be used.
        problem: String,
        /// Replies asked for.
        attempts: usize,
    },
    /// The flow ran to its end without a plan (LLM-DM in repaired mode: the planner never
    /// solved the model's domain).
    #[error("{message}")]
    NoPlan {
        /// What happened.
        message: String,
    },
    /// A prompt template failed (a defect of this crate's files).
    #[error(transparent)]
    Prompt(#[from] PromptError),
}

impl BaselineError {
    /// The kind of failure, as the harness scores it: a call's own kind, a reply that
    /// cannot be used, or a defect of the request.
    pub fn reasoner_kind(&self) -> ReasonerErrorKind {
        match self {
            BaselineError::Call { error, .. } => nesy_reasoner::failure_kind(error),
            BaselineError::Unreadable { .. } | BaselineError::NoPlan { .. } => ReasonerErrorKind::Reply,
            BaselineError::Prompt(_) => ReasonerErrorKind::Request,
        }
    }

    /// True when the flow ended without a plan rather than on an error.
    pub fn is_unresolved(&self) -> bool {
        matches!(self, BaselineError::NoPlan { .. })
    }

    /// The reply that could not be used, if that is the failure.
    pub fn reply(&self) -> Option<&str> {
        match self {
            BaselineError::Unreadable { reply, .. } => Some(reply),
            _ => None,
        }
    }
}
