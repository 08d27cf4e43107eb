//! Why a pipeline stage could not produce its result. Callers branch on the kind: bad input
//! is the user's to fix, a transport failure is worth retrying later, and the rest are the
//! episode's own failures.

use std::path::PathBuf;

use nesy_core::adapt::{AdaptError, ReasonerErrorKind};

/// Everything a stage of the pipeline can fail with.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The demonstration cannot be read or used.
    #[error("{}: {message}", path.display())]
    Demo {
        /// The demo file or folder.
        path: PathBuf,
        /// What is wrong, naming the field or keyframe.
        message: String,
    },
    /// The target scene cannot be read, built or checked.
    #[error("{}: {message}", path.display())]
    Target {
        /// The scene file (or `<demo>#target_scene`).
        path: PathBuf,
        /// What is wrong, naming the JSON field.
        message: String,
    },
    /// A task input beside the demo and the scene cannot be used: the vocabulary file, the
    /// prompt templates.
    #[error("{}: {message}", path.display())]
    TaskFile {
        /// The file or folder.
        path: PathBuf,
        /// What is wrong, naming the line and field.
        message: String,
    },
    /// The model client cannot be set up (configuration, cassette, offline responder).
    #[error("setting up the VLM: {message}")]
    VlmSetup {
        /// What is wrong.
        message: String,
    },
    /// Symbolic states could not be produced.
    #[error("symbolic states: {message}")]
    States {
        /// What went wrong, naming the view set.
        message: String,
        /// The reasoner failure behind it, when a model call failed.
        kind: Option<ReasonerErrorKind>,
    },
    /// The adaptation loop could not produce an outcome (the reasoner failed, or no reply
    /// for a transition parsed).
    #[error("adaptation: {0}")]
    Adapt(#[from] AdaptError),
    /// The policy could not be run at all (not: it ran and failed).
    #[error("running the policy on {}: {message}", scene.display())]
    Execute {
        /// The scene the worker was to run.
        scene: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// An output file could not be written.
    #[error("writing {}: {source}", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Closing the client failed (a strict cassette with unused interactions, a usage report
    /// that could not be written).
    #[error("closing the VLM client (cassette): {message}")]
    Finish {
        /// What went wrong.
        message: String,
    },
}

/// Why a run stopped before it had an outcome of its own (succeeded, unresolved,
/// codegen_failed, execution_failed), as `failure.json` and the summary name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The demo, the scene or the settings are at fault.
    BadInput,
    /// The model gave no reply the method could use within its budgets (every reply cut
    /// short, unreadable, or no operator for a transition parsed).
    NoUsableReply,
    /// The server refused the request as built (pictures to a text-only model, a prompt
    /// longer than its context); sending it again cannot help.
    RequestRefused,
    /// The server could not be reached or kept failing (network, timeouts, server errors).
    ModelUnreachable,
    /// A replayed cassette holds no answer for a request of this run.
    ReplayMismatch,
    /// Anything else: a file that could not be written, a policy that could not be run.
    Internal,
}

impl StopReason {
    /// `bad_input`, `no_usable_reply`, ...
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::BadInput => "bad_input",
            StopReason::NoUsableReply => "no_usable_reply",
            StopReason::RequestRefused => "request_refused",
            StopReason::ModelUnreachable => "model_unreachable",
            StopReason::ReplayMismatch => "replay_mismatch",
            StopReason::Internal => "internal",
        }
    }

    /// True when the model's side ended the run (its replies, its refusal, its absence):
    /// an outcome of the episode, not a fault of the input.
    pub fn is_model_side(self) -> bool {
        matches!(
            self,
            StopReason::NoUsableReply | StopReason::RequestRefused | StopReason::ModelUnreachable
        )
    }
}

impl PipelineError {
    /// Why the run stopped, for the summary, `failure.json` and the exit code.
    pub fn stop_reason(&self) -> StopReason {
        if self.is_bad_input() {
            return StopReason::BadInput;
        }
        match self {
            PipelineError::Adapt(AdaptError::NoOperator { .. }) => StopReason::NoUsableReply,
            PipelineError::Adapt(AdaptError::TooShort(_)) => StopReason::BadInput,
            _ => match self.reasoner_kind() {
                Some(ReasonerErrorKind::Reply | ReasonerErrorKind::Exhausted) => StopReason::NoUsableReply,
                Some(ReasonerErrorKind::Refused) => StopReason::RequestRefused,
                Some(ReasonerErrorKind::Transport) => StopReason::ModelUnreachable,
                Some(ReasonerErrorKind::Replay) => StopReason::ReplayMismatch,
                Some(ReasonerErrorKind::Request) => StopReason::BadInput,
                None => StopReason::Internal,
            },
        }
    }

    /// True when the user's input is at fault (a demo, a scene, settings), so a command line
    /// exits with its bad-input code.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            PipelineError::Demo { .. }
                | PipelineError::Target { .. }
                | PipelineError::TaskFile { .. }
                | PipelineError::VlmSetup { .. }
        )
    }

    /// The reasoner failure behind the error, if a model call is what failed.
    pub fn reasoner_kind(&self) -> Option<ReasonerErrorKind> {
        match self {
            PipelineError::States { kind, .. } => *kind,
            PipelineError::Adapt(AdaptError::Reasoner(e)) => Some(e.kind),
            _ => None,
        }
    }

    pub(crate) fn write(path: impl Into<PathBuf>, source: std::io::Error) -> PipelineError {
        PipelineError::Write {
            path: path.into(),
            source,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nesy_core::adapt::ReasonerError;

    fn reasoner(kind: ReasonerErrorKind) -> PipelineError {
        PipelineError::Adapt(AdaptError::Reasoner(ReasonerError::new(kind, "x")))
    }

    #[test]
    fn stops_on_the_model_side_are_outcomes_and_the_rest_errors() {
        use StopReason as S;
        let cases = [
            (reasoner(ReasonerErrorKind::Reply), S::NoUsableReply),
            (reasoner(ReasonerErrorKind::Exhausted), S::NoUsableReply),
            (reasoner(ReasonerErrorKind::Refused), S::RequestRefused),
            (reasoner(ReasonerErrorKind::Transport), S::ModelUnreachable),
            (reasoner(ReasonerErrorKind::Replay), S::ReplayMismatch),
            (reasoner(ReasonerErrorKind::Request), S::BadInput),
            (
                PipelineError::Adapt(AdaptError::NoOperator { step: 1, attempts: 5 }),
                S::NoUsableReply,
            ),
            (
                PipelineError::States {
                    message: "no pictures".into(),
                    kind: Some(ReasonerErrorKind::Refused),
                },
                S::RequestRefused,
            ),
            (PipelineError::VlmSetup { message: "x".into() }, S::BadInput),
            (PipelineError::Finish { message: "x".into() }, S::Internal),
        ];
        for (error, expected) in cases {
            assert_eq!(error.stop_reason(), expected, "{error}");
            assert_eq!(
                expected.is_model_side(),
                matches!(
                    expected,
                    S::NoUsableReply | S::RequestRefused | S::ModelUnreachable
                )
            );
        }
    }
}
