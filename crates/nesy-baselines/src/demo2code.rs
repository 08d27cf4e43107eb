//! Demo2Code, adapted to a target scene as the paper runs it: one observation call per
//! keyframe (the keyframe's ground-truth state and six images in, one `- ` observation
//! out), then one action-planning call that gets the observations, the target's state and
//! images and the predicates, and answers with the numbered plan for the target.

use nesy_vlm::{ReplyLength, VlmClient};
use serde::Serialize;

use crate::inputs::{BaselineInputs, Keyframe};
use crate::parse::unordered_list;
use crate::prompts::{EpisodePrompts, bullets, numbered, state_lines};
use crate::stage::{Stage, StageRecord, target_plan};
use crate::{BaselineError, BaselinePlan, IMAGES_PER_SCENE, RequestShape};

/// The purpose label of the observation calls.
pub const OBSERVE: &str = "d2c.observe";
/// The purpose label of the action-planning call.
pub const ACTIONS: &str = "d2c.actions";

#[derive(Serialize)]
struct ObserveVars<'a> {
    instruction: &'a str,
    objects: String,
    object_state: String,
}

#[derive(Serialize)]
struct ActionsVars<'a> {
    predicates: String,
    instruction: &'a str,
    objects: String,
    object_state: String,
    observations: String,
}

/// Runs Demo2Code on `inputs`: the observations (concurrently, as the client's concurrency
/// allows), then the plan.
pub async fn run(client: &VlmClient, inputs: &BaselineInputs) -> Result<BaselinePlan, BaselineError> {
    let prompts = &EpisodePrompts::for_inputs(inputs)?;
    let (observations, stages) = observe_all(client, prompts, inputs).await?;
    let prompt = prompts.render(
        "demo2code.actions",
        &ActionsVars {
            predicates: inputs.vocabulary.render_definitions(inputs.planning_tier()),
            instruction: &inputs.instruction,
            objects: bullets(inputs.target_objects.iter().cloned()),
            object_state: state_lines(&inputs.target_state),
            observations: numbered(&observations),
        },
    )?;
    target_plan(
        crate::Baseline::Demo2Code,
        client,
        inputs,
        ACTIONS,
        prompt,
        stages,
    )
    .await
}

/// One observation per keyframe, in keyframe order, with their stage records.
pub(crate) async fn observe_all(
    client: &VlmClient,
    prompts: &EpisodePrompts,
    inputs: &BaselineInputs,
) -> Result<(Vec<String>, Vec<StageRecord>), BaselineError> {
    let calls = inputs
        .keyframes
        .iter()
        .map(|keyframe| observe(client, prompts, inputs, keyframe));
    Ok(crate::stage::all_in_order(calls).await?.into_iter().unzip())
}

async fn observe(
    client: &VlmClient,
    prompts: &EpisodePrompts,
    inputs: &BaselineInputs,
    keyframe: &Keyframe,
) -> Result<(String, StageRecord), BaselineError> {
    let (system, user) = prompts.render(
        "demo2code.observe",
        &ObserveVars {
            instruction: &inputs.instruction,
            objects: bullets(inputs.source_objects.iter().cloned()),
            object_state: state_lines(&keyframe.state),
        },
    )?;
    let mut parts = vec![nesy_vlm::Part::text(user)];
    parts.extend(keyframe.observation.parts("scene"));
    Stage {
        purpose: OBSERVE,
        system,
        parts,
        expected: "Give the observation as one line that starts with \"- \".",
        fidelity: inputs.fidelity,
        // One observation line: on a local server a runaway reply stops at the brief cap.
        length: ReplyLength::Brief,
        client,
    }
    .ask(|reply| {
        // The authors take the first `- ` line.
        unordered_list(reply)
            .into_iter()
            .next()
            .ok_or_else(|| "it has no line starting with \"- \"".to_string())
    })
    .await
}

/// The calls and images of one scenario with `keyframes` keyframes, before code generation.
pub fn shape(keyframes: u64) -> RequestShape {
    RequestShape {
        calls_min: keyframes + 1,
        calls_max: keyframes + 1,
        images_min: (keyframes + 1) * IMAGES_PER_SCENE,
        images_max: (keyframes + 1) * IMAGES_PER_SCENE,
        largest_request_images: IMAGES_PER_SCENE,
    }
}
