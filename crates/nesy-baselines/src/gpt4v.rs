//! GPT4V-Robotics, with the target scene given at planning time as the paper runs it: one
//! domain-description call that sees every keyframe's ground-truth state and six images at
//! once and answers in a fenced block, then one planning call that gets the description, the
//! end-effector predicates and atoms of the target and its six images, and answers with a
//! numbered plan.
//!
//! The description call is large: every keyframe's six views in one request, about 546
//! images for a high-complexity demonstration. A client configured with the endpoint's
//! image limit refuses it before sending ([`nesy_vlm::VlmError::TooManyImages`]).

use nesy_core::State;
use nesy_core::Tier;
use nesy_vlm::{ReplyLength, VlmClient};
use serde::Serialize;

use crate::inputs::BaselineInputs;
use crate::parse::first_block;
use crate::prompts::{EpisodePrompts, bullets, state_lines};
use crate::stage::{Stage, StageRecord, target_plan};
use crate::{BaselineError, BaselinePlan, IMAGES_PER_SCENE, RequestShape};

/// The purpose label of the domain-description call.
pub const DESCRIBE: &str = "gpt4v.describe";
/// The purpose label of the planning call.
pub const PLAN: &str = "gpt4v.plan";

#[derive(Serialize)]
struct DescribeVars<'a> {
    instruction: &'a str,
    objects: String,
    states: String,
}

#[derive(Serialize)]
struct PlanVars<'a> {
    predicates: String,
    domain_description: &'a str,
    instruction: &'a str,
    objects: String,
    end_effector_state: String,
}

/// Runs GPT4V-Robotics on `inputs`.
pub async fn run(client: &VlmClient, inputs: &BaselineInputs) -> Result<BaselinePlan, BaselineError> {
    let prompts = &EpisodePrompts::for_inputs(inputs)?;
    let (description, describe) = describe_domain(client, prompts, inputs).await?;
    let prompt = prompts.render(
        "gpt4v.plan",
        &PlanVars {
            predicates: inputs.vocabulary.render_definitions(Tier::EndEffector),
            domain_description: &description,
            instruction: &inputs.instruction,
            objects: bullets(inputs.target_objects.iter().cloned()),
            end_effector_state: state_lines(&end_effector_atoms(inputs, &inputs.target_state)),
        },
    )?;
    target_plan(
        crate::Baseline::Gpt4vRobotics,
        client,
        inputs,
        PLAN,
        prompt,
        vec![describe],
    )
    .await
}

/// The domain description (the first fenced block of the reply) from every keyframe's
/// state and images in one request; Statler, LLM-DM and MoReVQA open with the same call.
pub(crate) async fn describe_domain(
    client: &VlmClient,
    prompts: &EpisodePrompts,
    inputs: &BaselineInputs,
) -> Result<(String, StageRecord), BaselineError> {
    let states: Vec<String> = inputs
        .keyframes
        .iter()
        .enumerate()
        .map(|(i, k)| {
            let atoms: Vec<String> = k.state.sorted_by_text().iter().map(|a| a.to_string()).collect();
            format!("{}. {}", i + 1, atoms.join(", "))
        })
        .collect();
    let (system, user) = prompts.render(
        "gpt4v.describe",
        &DescribeVars {
            instruction: &inputs.instruction,
            objects: bullets(inputs.source_objects.iter().cloned()),
            states: states.join("\n"),
        },
    )?;
    let mut parts = vec![nesy_vlm::Part::text(user)];
    for (i, keyframe) in inputs.keyframes.iter().enumerate() {
        parts.extend(keyframe.observation.parts(&format!("demo keyframe {}", i + 1)));
    }
    Stage {
        purpose: DESCRIBE,
        system,
        parts,
        expected: "Write the whole description inside one fenced block, with ``` on its own line before and after it.",
        fidelity: inputs.fidelity,
        length: ReplyLength::Open,
        client,
    }
    .ask(|reply| first_block(reply).map_err(|e| e.to_string()))
    .await
}

/// The atoms of `state` whose predicate is one of the end-effector tier's (the authors
/// filter the target state this way for the planning call).
fn end_effector_atoms(inputs: &BaselineInputs, state: &State) -> State {
    let tier: Vec<_> = inputs
        .vocabulary
        .tier(Tier::EndEffector)
        .iter()
        .map(|p| p.name)
        .collect();
    State::from_atoms(state.iter().filter(|a| tier.contains(&a.pred())).copied())
}

/// The calls and images of one scenario with `keyframes` keyframes, before code generation.
pub fn shape(keyframes: u64) -> RequestShape {
    RequestShape {
        calls_min: 2,
        calls_max: 2,
        images_min: (keyframes + 1) * IMAGES_PER_SCENE,
        images_max: (keyframes + 1) * IMAGES_PER_SCENE,
        largest_request_images: keyframes * IMAGES_PER_SCENE,
    }
}
