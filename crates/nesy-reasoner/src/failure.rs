//! Which kind of reasoner failure a failed model call is.

use nesy_core::adapt::ReasonerErrorKind;
use nesy_vlm::{TransportError, VlmError};

/// The reasoner failure that `error` is, for callers that must branch on it: the benchmark
/// harness retries transport failures later and scores the rest, and the adaptation loop
/// ends without asking again when an offline responder declined.
///
/// ```
/// use nesy_core::adapt::ReasonerErrorKind;
/// use nesy_vlm::VlmError;
///
/// let error = VlmError::InvalidRequest("no messages".into());
/// assert_eq!(nesy_reasoner::failure_kind(&error), ReasonerErrorKind::Request);
/// ```
pub fn failure_kind(error: &VlmError) -> ReasonerErrorKind {
    use ReasonerErrorKind as Kind;
    match error {
        VlmError::Config(_) | VlmError::InvalidRequest(_) => Kind::Request,
        VlmError::TooManyImages { .. } | VlmError::Unsupported { .. } | VlmError::ContextExceeded { .. } => {
            Kind::Refused
        }
        // A server that says it cannot take the request's content (pictures to a text-only
        // model) refuses it however often it is sent, whatever the status code.
        VlmError::Http { provider, .. } if provider.missing_capability().is_some() => Kind::Refused,
        VlmError::Transport {
            error: TransportError::Declined(_),
            ..
        } => Kind::Exhausted,
        VlmError::Transport { .. } => Kind::Transport,
        // Timeouts, rate limits and server errors are the endpoint's state; a quota that ran
        // out or a key that is refused will not fix itself, but they say nothing about the
        // method either, so they count as transport failures too.
        VlmError::Http { status, .. } if matches!(status, 401 | 403 | 408 | 409 | 429) || *status >= 500 => {
            Kind::Transport
        }
        VlmError::Http { .. } => Kind::Refused,
        VlmError::InvalidResponse { .. } | VlmError::Truncated { .. } | VlmError::Refusal { .. } => {
            Kind::Reply
        }
        VlmError::Cassette(_) => Kind::Replay,
    }
}
