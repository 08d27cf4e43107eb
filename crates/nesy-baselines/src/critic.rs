//! Critic-V as the paper runs it, with the same prompted model as critic (not a trained
//! one): Demo2Code's unadapted plan (the observations, then a text-only call that turns them
//! into the demonstrated plan with the source objects and no target information), then up to
//! the budget's rounds of a feedback call on the target (its state, objects and six views,
//! the plan numbered; the first `- ` line is the feedback, "no issue" stops the loop) and a
//! text-only correction call (the plan one action per line, unnumbered, and the feedback;
//! the reply's SEARCH/REPLACE blocks edit the plan's lines).
//!
//! The authors' quirk is kept in [`Fidelity::Authors`]: their correction prompt's example
//! numbers the SEARCH lines while the plan it is shown is unnumbered, so numbered SEARCH
//! lines never match and the edit is silently not applied; a numbered REPLACE line keeps its
//! number in the action's text. [`Fidelity::Repaired`] reads both without list numbers.

use nesy_vlm::{Part, ReplyLength, VlmClient};
use serde::Serialize;

use crate::demo2code::observe_all;
use crate::inputs::{BaselineInputs, Fidelity};
use crate::parse::{LinePatch, apply_line_patches, line_patches, prepared, unordered_list, without_number};
use crate::prompts::{EpisodePrompts, bullets, numbered, state_lines};
use crate::stage::{NUMBERED_PLAN, Stage, numbered_plan};
use crate::{BaselineError, BaselinePlan, IMAGES_PER_SCENE, RequestShape};

/// The purpose label of the unadapted plan's call.
pub const SOURCE_ACTIONS: &str = "d2c.source_actions";
/// The purpose label of the feedback calls.
pub const FEEDBACK: &str = "critic.feedback";
/// The purpose label of the correction calls.
pub const CORRECTION: &str = "critic.correction";

#[derive(Serialize)]
struct SourceVars<'a> {
    instruction: &'a str,
    objects: String,
    observations: String,
}

#[derive(Serialize)]
struct FeedbackVars<'a> {
    instruction: &'a str,
    objects: String,
    object_state: String,
    plan: String,
}

#[derive(Serialize)]
struct CorrectionVars<'a> {
    instruction: &'a str,
    objects: String,
    plan: String,
    feedback: &'a str,
}

/// Runs Critic-V on `inputs`.
pub async fn run(client: &VlmClient, inputs: &BaselineInputs) -> Result<BaselinePlan, BaselineError> {
    let prompts = &EpisodePrompts::for_inputs(inputs)?;
    let (observations, mut stages) = observe_all(client, prompts, inputs).await?;
    let (system, user) = prompts.render(
        "demo2code.source_actions",
        &SourceVars {
            instruction: &inputs.instruction,
            objects: bullets(inputs.source_objects.iter().cloned()),
            observations: numbered(&observations),
        },
    )?;
    let (mut plan, record) = Stage {
        purpose: SOURCE_ACTIONS,
        system,
        parts: vec![Part::text(user)],
        expected: NUMBERED_PLAN,
        fidelity: inputs.fidelity,
        length: ReplyLength::Open,
        client,
    }
    .ask(numbered_plan)
    .await?;
    stages.push(record);

    let repaired = inputs.fidelity == Fidelity::Repaired;
    let mut rounds = 0;
    while rounds < inputs.budget {
        rounds += 1;
        let (system, user) = prompts.render(
            "critic.feedback",
            &FeedbackVars {
                instruction: &inputs.instruction,
                objects: bullets(inputs.target_objects.iter().cloned()),
                object_state: state_lines(&inputs.target_state),
                plan: numbered(&plan),
            },
        )?;
        let mut parts = vec![Part::text(user)];
        parts.extend(inputs.target_observation.parts("scene"));
        let (feedback, record) = Stage {
            purpose: FEEDBACK,
            system,
            parts,
            expected: "Give your feedback as one line that starts with \"- \"; write \"No issue\" there if the plan works.",
            fidelity: inputs.fidelity,
            length: ReplyLength::Open,
            client,
        }
        .ask(|reply| {
            unordered_list(reply)
                .into_iter()
                .next()
                .ok_or_else(|| "it has no line starting with \"- \"".to_string())
        })
        .await?;
        stages.push(record);
        if feedback.to_lowercase().contains("no issue") {
            break;
        }
        let (system, user) = prompts.render(
            "critic.correction",
            &CorrectionVars {
                instruction: &inputs.instruction,
                objects: bullets(inputs.target_objects.iter().cloned()),
                plan: plan.join("\n"),
                feedback: &feedback,
            },
        )?;
        let (patches, record) = Stage {
            purpose: CORRECTION,
            system,
            parts: vec![Part::text(user)],
            expected: "Give your diagnosis, then an empty line, then the edits as SEARCH/REPLACE blocks.",
            fidelity: inputs.fidelity,
            length: ReplyLength::Open,
            client,
        }
        .ask(read_correction)
        .await?;
        stages.push(record);
        let patches = if repaired {
            patches.iter().map(unnumbered).collect()
        } else {
            patches
        };
        let applied = apply_line_patches(&mut plan, &patches);
        tracing::debug!(
            round = rounds,
            edits = patches.len(),
            applied,
            "critic correction"
        );
    }
    let deviations = crate::Baseline::CriticV.deviations(inputs.fidelity);
    Ok(BaselinePlan {
        steps: plan,
        stages,
        deviations,
        rounds: Some(rounds),
        instruction: None,
    })
}

/// The correction's edits. The authors split the reply at its first empty line into the
/// diagnosis and the edits, and a reply without one raises; blocks that do not parse are
/// no edit.
fn read_correction(reply: &str) -> Result<Vec<LinePatch>, String> {
    let text = prepared(reply);
    match text.split_once("\n\n") {
        Some((_, edits)) => Ok(line_patches(edits)),
        None => Err("it has no empty line between the diagnosis and the edits".into()),
    }
}

fn unnumbered(patch: &LinePatch) -> LinePatch {
    let strip = |lines: &[String]| lines.iter().map(|l| without_number(l).to_string()).collect();
    LinePatch {
        search: strip(&patch.search),
        replace: strip(&patch.replace),
    }
}

/// The calls and images of one scenario with `keyframes` keyframes and round budget
/// `budget`, before code generation: the observations and the unadapted plan, then one
/// feedback call at least and a feedback and a correction per round at most.
pub fn shape(keyframes: u64, budget: u64) -> RequestShape {
    let fixed = keyframes + 1;
    RequestShape {
        calls_min: fixed + 1,
        calls_max: fixed + 2 * budget,
        images_min: (keyframes + 1) * IMAGES_PER_SCENE,
        images_max: (keyframes + budget) * IMAGES_PER_SCENE,
        largest_request_images: IMAGES_PER_SCENE,
    }
}
