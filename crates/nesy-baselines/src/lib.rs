//! The paper's baselines as call flows over the VLM client. Each flow takes the same episode
//! inputs NeSyCR gets ([`BaselineInputs`]: the ground-truth states as text, the plain and
//! labelled views of every keyframe and of the target, the objects and the predicate tiers)
//! and returns a natural-language plan ([`BaselinePlan`]) for the shared code-generation
//! tail, with a record of every stage's reply.
//!
//! The flows follow the authors' re-implementations stage by stage, with prompts in this
//! project's own words that keep the authors' slots and output markers:
//! - [`demo2code`]: one observation call per keyframe, then one action-planning call
//!   that adapts the observations to the target scene;
//! - [`gpt4v`] (GPT4V-Robotics): one domain-description call with every keyframe's six
//!   views, then one planning call on the target;
//! - [`critic`] (Critic-V, with the same model as critic): Demo2Code's unadapted plan, then
//!   rounds of feedback on the target and text-line SEARCH/REPLACE corrections until the
//!   feedback says "no issue" or the budget is spent;
//! - [`statler`]: the domain description, a predicted initial state, then rounds in which
//!   the model extends the plan and rewrites the world state until it says "goal reached";
//! - [`morevqa`] (MoReVQA): the domain description, event parsing, rounds of grounding and
//!   verification until verified (capped at the budget), three visual sub-questions and
//!   their answers, then the plan;
//! - [`llmdm`] (LLM-DM): a PDDL domain built action by action and a predicted problem,
//!   solved by nesy-core's planner (not Fast Downward), refined from the planner's report up
//!   to the budget, and the plan put into words.
//!
//! Only LLM-DM uses a symbolic tool (a planner over the model's own domain); the others plan
//! in text, and nothing checks their plans before code generation.
//!
//! Replies are untrusted. A cut-off reply or one with null content is re-asked once, as for
//! every call of the project ([`nesy_vlm::reply`]). A reply whose answer cannot be found
//! (no `- ` line, no numbered list, no code block) ends the flow as
//! [`BaselineError::Unreadable`] with the reply kept, which is the authors' behaviour (their
//! parsers raise and the episode fails); in [`Fidelity::Repaired`] it is re-asked with the
//! reason first, up to [`REPAIRED_ATTEMPTS`] replies.
//!
//! The readers are total: whatever a model writes, they return what they can find.
//!
//! ```
//! use nesy_baselines::parse::ordered_list;
//!
//! let reply = "Here is the plan:\n1. Open the bottom drawer.\n2. Put the red cylinder in it.\nDone.";
//! assert_eq!(ordered_list(reply), ["Open the bottom drawer.", "Put the red cylinder in it."]);
//! ```

pub mod critic;
pub mod demo2code;
mod error;
pub mod gpt4v;
mod inputs;
mod json;
pub mod llmdm;
pub mod morevqa;
pub mod parse;
mod prompts;
mod stage;
pub mod statler;

pub use error::BaselineError;
pub use inputs::{BaselineInputs, Fidelity, Keyframe, SceneObservation, SceneViews};
pub use prompts::{BaselinePrompts, PromptError};
pub use stage::{REPAIRED_ATTEMPTS, StageProblem, StageRecord};

use serde::Serialize;

/// What a baseline produced: the plan for code generation, and how it got there.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BaselinePlan {
    /// The plan's steps, in order (the demonstration summary of the code prompt).
    pub steps: Vec<String>,
    /// Every stage's call, in order.
    pub stages: Vec<StageRecord>,
    /// Where this run departs from the authors' implementation, in words (empty when it
    /// does not).
    pub deviations: Vec<String>,
    /// Rounds of the flow's loop that ran (`None` for flows without one); the budget is the
    /// scenario's.
    pub rounds: Option<usize>,
    /// The instruction code generation gets instead of the task's, when the flow rewrites
    /// it (MoReVQA's question form).
    pub instruction: Option<String>,
}

/// The six baselines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Baseline {
    /// Demo2Code, adapted to the target at its last stage.
    Demo2Code,
    /// GPT4V-Robotics, the target given at planning time.
    Gpt4vRobotics,
    /// Critic-V, with the same model as critic.
    CriticV,
    /// MoReVQA.
    MoReVqa,
    /// Statler, reader and writer in one call per round.
    Statler,
    /// LLM-DM, with nesy-core's planner.
    LlmDm,
}

impl Baseline {
    /// Every baseline, in the paper's table order.
    pub const ALL: [Baseline; 6] = [
        Baseline::Demo2Code,
        Baseline::Gpt4vRobotics,
        Baseline::CriticV,
        Baseline::MoReVqa,
        Baseline::Statler,
        Baseline::LlmDm,
    ];

    /// Runs the baseline's flow on `inputs`.
    pub async fn run(
        self,
        client: &nesy_vlm::VlmClient,
        inputs: &BaselineInputs,
    ) -> Result<BaselinePlan, BaselineError> {
        match self {
            Baseline::Demo2Code => demo2code::run(client, inputs).await,
            Baseline::Gpt4vRobotics => gpt4v::run(client, inputs).await,
            Baseline::CriticV => critic::run(client, inputs).await,
            Baseline::MoReVqa => morevqa::run(client, inputs).await,
            Baseline::Statler => statler::run(client, inputs).await,
            Baseline::LlmDm => llmdm::run(client, inputs).await,
        }
    }

    /// Where the flow departs from the authors' code in `fidelity`, in words: what a run's
    /// manifest lists, and what every plan carries.
    pub fn deviations(self, fidelity: Fidelity) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        match self {
            Baseline::MoReVqa => out.push(
                "the verification loop is capped at the scenario's budget (the authors' loop has no bound)"
                    .into(),
            ),
            Baseline::LlmDm => {
                out.push(format!("planned with the {}", llmdm::PLANNER));
                out.push("a domain or problem that does not parse goes back to the model as the planner's report, with the parser's position (the authors' code raises)".into());
            }
            _ => {}
        }
        if fidelity == Fidelity::Authors {
            return out;
        }
        out.push(
            "a reply without its answer is re-asked with the reason (the authors' parser raises)".into(),
        );
        let repaired: &[&str] = match self {
            Baseline::Demo2Code | Baseline::Gpt4vRobotics => &[],
            Baseline::CriticV => &[
                "SEARCH and REPLACE lines are read without list numbers, so numbered edits of the unnumbered plan apply",
            ],
            Baseline::MoReVqa => &[
                "JSON objects are read out of prose or a fence (the authors parse the whole reply)",
                "the grounding call is shown the last check's reason (the authors' template has no slot for it)",
            ],
            Baseline::Statler => &[
                "a reply that writes no world state keeps the previous one",
                "a \"goal reached\" step in any case, with or without a period, stops the loop and is removed",
            ],
            Baseline::LlmDm => &[
                "the domain is solved once more after the budget's last refinement",
                "without a plan the unit ends without a specification (the authors generate code from \"None\")",
            ],
        };
        out.extend(repaired.iter().map(|d| d.to_string()));
        out
    }
}

/// The model calls and images one scenario costs a flow, before code generation: exact for
/// fixed stages, the most for loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct RequestShape {
    /// Calls, fewest.
    pub calls_min: u64,
    /// Calls, most.
    pub calls_max: u64,
    /// Images over all calls, fewest.
    pub images_min: u64,
    /// Images over all calls, most.
    pub images_max: u64,
    /// Images in the largest single request (what an endpoint's per-request limit meets).
    pub largest_request_images: u64,
}

/// Images per scene in every baseline call that shows one: the top, front and back views,
/// plain and labelled.
pub const IMAGES_PER_SCENE: u64 = 6;
