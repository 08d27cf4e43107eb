//! One stage's call: a system prompt, a user message of text and captioned images, the
//! stage's reader, and the reply policy of [`crate::Fidelity`].

use nesy_vlm::reply::{self, AskError, CALL_ATTEMPTS, NULL_CONTENT_TEXT, ReplyProblem, truncation_text};
use nesy_vlm::{ChatRequest, Message, Part, ReasoningEffort, ReplyLength, VlmClient};
use serde::Serialize;

use crate::error::BaselineError;
use crate::inputs::Fidelity;

/// How many replies a stage asks for at most in [`Fidelity::Repaired`]: the first and two
/// re-asks, each with the reason the previous reply could not be used.
pub const REPAIRED_ATTEMPTS: usize = 3;

/// One stage's call as it went.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct StageRecord {
    /// The purpose label (`d2c.observe`, `gpt4v.plan`, …), as in the usage accounting.
    pub purpose: String,
    /// Images in the request.
    pub images: usize,
    /// The reply that was used.
    pub reply: String,
    /// The problems of earlier replies of this call that were re-asked, in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub reasked: Vec<String>,
}

/// Why a stage's reply was not used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StageProblem {
    /// The reply stopped at the token cap.
    #[error("{}", truncation_text(*cutoff))]
    Truncated {
        /// Where the reply was cut.
        cutoff: nesy_vlm::Cutoff,
    },
    /// The reply's `content` was null.
    #[error("{NULL_CONTENT_TEXT}")]
    NullContent,
    /// The stage's answer is not in the reply.
    #[error("reply could not be read: {what}")]
    Unreadable {
        /// What is missing.
        what: String,
        /// What the stage asks for, said again in the re-ask.
        expected: &'static str,
    },
}

impl ReplyProblem for StageProblem {
    fn truncated(cutoff: nesy_vlm::Cutoff) -> Self {
        StageProblem::Truncated { cutoff }
    }

    fn null_content() -> Self {
        StageProblem::NullContent
    }

    fn feedback(&self) -> String {
        match self {
            StageProblem::Truncated { .. } => {
                format!("Your {self}. Answer more briefly, in the format asked for.")
            }
            StageProblem::NullContent => format!("Your {self}. Answer again, in the format asked for."),
            StageProblem::Unreadable { expected, .. } => format!("Your {self}. {expected}"),
        }
    }
}

/// A stage to run.
pub(crate) struct Stage<'a> {
    /// The purpose label.
    pub purpose: &'static str,
    /// The system prompt.
    pub system: String,
    /// The user message: the rendered text, then the captioned images.
    pub parts: Vec<Part>,
    /// What the answer must look like (for the re-ask in repaired mode).
    pub expected: &'static str,
    /// How closely to follow the authors.
    pub fidelity: Fidelity,
    /// How long the answer is expected to be (its output cap on a local server).
    pub length: ReplyLength,
    /// The client.
    pub client: &'a VlmClient,
}

impl Stage<'_> {
    /// Sends the stage's request (reasoning effort `low`, as the authors set for every
    /// stage but code generation) and reads the reply with `read`, which says what is
    /// missing when the answer is not there.
    pub(crate) async fn ask<T>(
        self,
        read: impl Fn(&str) -> Result<T, String>,
    ) -> Result<(T, StageRecord), BaselineError> {
        let chat = ChatRequest::new()
            .purpose(self.purpose)
            .reply_length(self.length)
            .reasoning_effort(ReasoningEffort::Low)
            .message(Message::system(self.system))
            .message(Message::user(self.parts));
        let images = chat.image_count();
        let purpose = self.purpose.to_string();
        let expected = self.expected;
        let unreadable = |what: String| StageProblem::Unreadable { what, expected };
        let answer = match self.fidelity {
            // The authors' parsers raise on a reply without the answer: it is used as it is
            // and fails below, with no re-ask.
            Fidelity::Authors => {
                reply::ask_until_usable(self.client, chat, CALL_ATTEMPTS, self.purpose, |text| {
                    Ok::<_, std::convert::Infallible>(Ok::<_, StageProblem>(read(text)))
                })
                .await
            }
            Fidelity::Repaired => {
                reply::ask_until_usable(self.client, chat, REPAIRED_ATTEMPTS, self.purpose, |text| {
                    Ok::<_, std::convert::Infallible>(read(text).map(Ok).map_err(unreadable))
                })
                .await
            }
        };
        let answer = answer.map_err(|error| match error {
            AskError::Vlm(error) => BaselineError::Call {
                purpose: purpose.clone(),
                error,
            },
            AskError::Reader(never) => match never {},
            AskError::Exhausted(attempts) => BaselineError::Unreadable {
                purpose: purpose.clone(),
                attempts: attempts.len(),
                reply: attempts.last().map(|a| a.reply.clone()).unwrap_or_default(),
                problem: attempts.last().map(|a| a.problem.to_string()).unwrap_or_default(),
            },
        })?;
        let reasked: Vec<String> = answer.rejected.iter().map(|r| r.problem.to_string()).collect();
        match answer.value {
            Ok(value) => Ok((
                value,
                StageRecord {
                    purpose,
                    images,
                    reply: answer.reply,
                    reasked,
                },
            )),
            Err(what) => Err(BaselineError::Unreadable {
                purpose,
                attempts: reasked.len() + 1,
                reply: answer.reply,
                problem: unreadable(what).to_string(),
            }),
        }
    }
}

/// The last stage of a flow: the rendered prompt with the target's six images, read as a
/// numbered plan; returns the plan with every stage's record (`earlier` and this one).
pub(crate) async fn target_plan(
    baseline: crate::Baseline,
    client: &VlmClient,
    inputs: &crate::BaselineInputs,
    purpose: &'static str,
    (system, user): (String, String),
    mut earlier: Vec<StageRecord>,
) -> Result<crate::BaselinePlan, BaselineError> {
    let mut parts = vec![Part::text(user)];
    parts.extend(inputs.target_observation.parts("scene"));
    let (steps, record) = Stage {
        purpose,
        system,
        parts,
        expected: NUMBERED_PLAN,
        fidelity: inputs.fidelity,
        length: ReplyLength::Open,
        client,
    }
    .ask(numbered_plan)
    .await?;
    earlier.push(record);
    Ok(crate::BaselinePlan {
        steps,
        stages: earlier,
        deviations: baseline.deviations(inputs.fidelity),
        rounds: None,
        instruction: None,
    })
}

/// What a planning stage asks for, said again in a re-ask.
pub(crate) const NUMBERED_PLAN: &str = "Write the plan as a numbered list, one action per line: \"1. ...\".";

/// A planning stage's reader: the numbered list of the reply, which must not be empty.
pub(crate) fn numbered_plan(reply: &str) -> Result<Vec<String>, String> {
    let steps = crate::parse::ordered_list(reply);
    if steps.is_empty() {
        Err("it has no numbered list (lines \"1. ...\")".to_string())
    } else {
        Ok(steps)
    }
}

/// Runs every call to its end and returns their results in order, or the first error in
/// that order. Stopping at the first failure would leave how many of the other calls were
/// made to timing, and a replay of the run would not make the same calls.
pub(crate) async fn all_in_order<T, E>(
    calls: impl IntoIterator<Item = impl std::future::Future<Output = Result<T, E>>>,
) -> Result<Vec<T>, E> {
    futures::future::join_all(calls).await.into_iter().collect()
}
