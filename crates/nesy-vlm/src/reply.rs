//! One reply-handling policy for every model call: ask, read the reply, and when it cannot be
//! used send it back as the assistant's turn with a message saying precisely why, up to a
//! per-call budget of replies.
//!
//! Two problems are the same for every call and are handled here: a reply cut off at the
//! token cap (`finish_reason: length`), which is re-asked with a request for a briefer
//! answer and reported with the cap, and a reply whose `content` was null with nothing in
//! `reasoning_content`, which is re-asked with a message naming the null content. What a
//! readable reply is, and what the re-ask says about one that is not, is the caller's: state
//! translation, code generation, and (through [`CallProblem`]) operator induction and patch
//! proposals, whose replies nesy-core reads and re-asks within its own attempt budget.

use crate::client::VlmClient;
use crate::error::{Cutoff, VlmError};
use crate::request::{ChatRequest, Message};

/// A reason a reply cannot be used, as one call defines it, with the two reasons every call
/// shares.
pub trait ReplyProblem: std::fmt::Display + Sized {
    /// The reply was cut short: at the request's token cap, or when the context filled.
    fn truncated(cutoff: Cutoff) -> Self;
    /// The reply's `content` was null and no `reasoning_content` held text.
    fn null_content() -> Self;
    /// The message that goes back to the model with the re-ask.
    fn feedback(&self) -> String;
}

/// The words for a reply cut short, shared by every call's problem type.
pub fn truncation_text(cutoff: Cutoff) -> String {
    format!("reply was {cutoff}")
}

/// The most characters of a rejected reply that a re-ask quotes back. A runaway reply of
/// thousands of tokens would otherwise ride along in every later turn and fill a small
/// server's context; the start of a reply is what the correction is about.
pub const QUOTE_LIMIT_CHARS: usize = 1500;

/// `reply` as a re-ask quotes it: whole when short, else its first [`QUOTE_LIMIT_CHARS`]
/// characters and a note of how much was left out.
///
/// ```
/// use nesy_vlm::reply::{QUOTE_LIMIT_CHARS, quote_for_reask};
/// assert_eq!(quote_for_reask("- (Open drawer)"), "- (Open drawer)");
/// let long = "x".repeat(QUOTE_LIMIT_CHARS + 10);
/// assert!(quote_for_reask(&long).ends_with("[10 more characters of this reply are not repeated here]"));
/// ```
pub fn quote_for_reask(reply: &str) -> String {
    match reply.char_indices().nth(QUOTE_LIMIT_CHARS) {
        None => reply.to_string(),
        Some((cut, _)) => {
            let rest = reply[cut..].chars().count();
            format!(
                "{}\n[{rest} more characters of this reply are not repeated here]",
                &reply[..cut]
            )
        }
    }
}

/// The words for a reply with null content, shared by every call's problem type.
pub const NULL_CONTENT_TEXT: &str =
    "reply had no text: its `content` was null and there was no `reasoning_content`";

/// A reply that was not used, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rejected<P> {
    /// The reply (for a truncated one, the text before the cap).
    pub reply: String,
    /// Why it was not used.
    pub problem: P,
}

/// A usable reply, what was read from it, and the replies before it that were not usable.
#[derive(Debug, Clone)]
pub struct Answer<T, P> {
    /// What the reader made of the reply.
    pub value: T,
    /// The reply as the model sent it.
    pub reply: String,
    /// Earlier replies of this call, in order, each re-asked with its problem.
    pub rejected: Vec<Rejected<P>>,
}

/// Why a call gave no usable reply.
#[derive(Debug)]
pub enum AskError<P, E> {
    /// The call itself failed (transport, replay, refusal): re-asking would not help.
    Vlm(VlmError),
    /// The reader could not run (a defect of the caller's side, never of the reply).
    Reader(E),
    /// Every reply within the budget had a problem; all of them, in order.
    Exhausted(Vec<Rejected<P>>),
}

/// Sends `chat` and reads each reply with `read` until one is usable, re-asking with the
/// problem's [`ReplyProblem::feedback`] after each one that is not, up to `attempts`
/// replies in all. `read` returns `Ok(Ok(value))` for a usable reply, `Ok(Err(problem))`
/// for one to re-ask, and `Err` only when it cannot run at all.
pub async fn ask_until_usable<T, P, E>(
    client: &VlmClient,
    mut chat: ChatRequest,
    attempts: usize,
    what: &str,
    mut read: impl FnMut(&str) -> Result<Result<T, P>, E>,
) -> Result<Answer<T, P>, AskError<P, E>>
where
    P: ReplyProblem,
{
    let mut rejected: Vec<Rejected<P>> = Vec::new();
    for _ in 0..attempts.max(1) {
        let (reply, outcome) = match client.chat(chat.clone()).await {
            Ok(response) if response.content_was_null => (response.text, Err(P::null_content())),
            Ok(response) => {
                let outcome = read(&response.text).map_err(AskError::Reader)?;
                (response.text, outcome)
            }
            Err(VlmError::Truncated {
                partial_text,
                usage,
                cap,
                context,
                ..
            }) => (
                partial_text,
                Err(P::truncated(Cutoff::of(cap, usage.as_ref(), context))),
            ),
            Err(other) => return Err(AskError::Vlm(other)),
        };
        match outcome {
            Ok(value) => {
                return Ok(Answer {
                    value,
                    reply,
                    rejected,
                });
            }
            Err(problem) => {
                tracing::info!(
                    call = what,
                    attempt = rejected.len() + 1,
                    "reply not used, re-asking: {problem}"
                );
                chat = chat
                    .message(Message::assistant(quote_for_reask(&reply)))
                    .message(Message::user_text(problem.feedback()));
                rejected.push(Rejected { reply, problem });
            }
        }
    }
    Err(AskError::Exhausted(rejected))
}

/// The problems of an operator-induction or patch reply that are the call's, not the
/// reply's wording: nesy-core reads the text and re-asks a reply it cannot parse within its
/// own attempt budget, but a cut-off or empty reply is re-asked here first.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CallProblem {
    /// See [`ReplyProblem::truncated`].
    #[error("{}", truncation_text(*cutoff))]
    Truncated {
        /// Where the reply was cut.
        cutoff: Cutoff,
    },
    /// See [`ReplyProblem::null_content`].
    #[error("{NULL_CONTENT_TEXT}")]
    NullContent,
}

impl ReplyProblem for CallProblem {
    fn truncated(cutoff: Cutoff) -> Self {
        CallProblem::Truncated { cutoff }
    }

    fn null_content() -> Self {
        CallProblem::NullContent
    }

    fn feedback(&self) -> String {
        match self {
            CallProblem::Truncated { .. } => format!(
                "Your {self}. Answer more briefly: keep the format asked for, with at most a sentence of rationale."
            ),
            CallProblem::NullContent => {
                format!("Your {self}. Answer again, in the format asked for.")
            }
        }
    }
}

/// How many replies an operator-induction or patch call asks for at most when a reply is
/// cut off or empty: the first and one re-ask. Replies that arrive whole but cannot be
/// parsed are re-asked by nesy-core's loop within its own budget.
pub const CALL_ATTEMPTS: usize = 2;
