//! Statler as the paper runs it, reader and writer merged into one call per round: the
//! domain description (GPT4V-Robotics' first call), a predicted initial state (the `partial`
//! tier, the target's objects without the robot, its ground-truth state as "partial ground
//! truth" and six views; the prediction joined with the ground truth), then up to the
//! budget's rounds in which the model gets the actions so far, the current world state and
//! the same six initial views, and answers with further numbered actions and the world state
//! after them, until it says "goal reached".
//!
//! In [`Fidelity::Authors`] the model-written state replaces the state whatever it holds
//! (nothing checks it); "goal reached" in the reply appends the step `goal reached`, the loop
//! stops once any step reads `goal reached` in lower case, and that last step is removed (a
//! numbered "Goal reached." with a period stays in the plan and the loop goes on).
//! [`Fidelity::Repaired`] keeps the previous state when a reply writes none, and stops at any
//! "goal reached" step, which it removes.

use std::collections::BTreeSet;

use nesy_core::Tier;
use nesy_vlm::{Part, ReplyLength, VlmClient};
use serde::Serialize;

use crate::gpt4v::describe_domain;
use crate::inputs::{BaselineInputs, Fidelity};
use crate::parse::{ordered_list, unordered_list};
use crate::prompts::{EpisodePrompts, bullets, numbered, state_lines};
use crate::stage::Stage;
use crate::{BaselineError, BaselinePlan, IMAGES_PER_SCENE, RequestShape};

/// The purpose label of the initial-state call.
pub const STATE: &str = "statler.state";
/// The purpose label of the planning rounds.
pub const ACTIONS: &str = "statler.actions";

/// The stop word.
const GOAL_REACHED: &str = "goal reached";

#[derive(Serialize)]
struct StateVars<'a> {
    predicates: String,
    instruction: &'a str,
    objects: String,
    object_state: String,
}

#[derive(Serialize)]
struct ActionsVars<'a> {
    predicates: String,
    domain_description: &'a str,
    instruction: &'a str,
    objects: String,
    actions: String,
    state: String,
}

/// Runs Statler on `inputs`.
pub async fn run(client: &VlmClient, inputs: &BaselineInputs) -> Result<BaselinePlan, BaselineError> {
    let prompts = &EpisodePrompts::for_inputs(inputs)?;
    let (description, describe) = describe_domain(client, prompts, inputs).await?;
    let mut stages = vec![describe];
    let objects: Vec<String> = inputs
        .target_objects
        .iter()
        .filter(|o| o.as_str() != "gripper")
        .cloned()
        .collect();
    let (system, user) = prompts.render(
        "statler.state",
        &StateVars {
            predicates: inputs.vocabulary.render_definitions(Tier::Partial),
            instruction: &inputs.instruction,
            objects: bullets(objects.iter().cloned()),
            object_state: state_lines(&inputs.target_state),
        },
    )?;
    let mut parts = vec![Part::text(user)];
    parts.extend(inputs.target_observation.parts("scene"));
    let (predicted, record) = Stage {
        purpose: STATE,
        system,
        parts,
        expected: "List the atoms, one per line starting with \"- \".",
        fidelity: inputs.fidelity,
        length: ReplyLength::Open,
        client,
    }
    .ask(|reply| Ok(unordered_list(reply)))
    .await?;
    stages.push(record);
    let mut state: BTreeSet<String> = predicted.into_iter().collect();
    state.extend(inputs.target_state.iter().map(|a| a.to_string()));
    let mut state: Vec<String> = state.into_iter().collect();

    let repaired = inputs.fidelity == Fidelity::Repaired;
    let mut actions: Vec<String> = Vec::new();
    let mut rounds = 0;
    while rounds < inputs.budget {
        rounds += 1;
        let (system, user) = prompts.render(
            "statler.actions",
            &ActionsVars {
                predicates: inputs.vocabulary.render_definitions(inputs.planning_tier()),
                domain_description: &description,
                instruction: &inputs.instruction,
                objects: bullets(inputs.target_objects.iter().cloned()),
                actions: numbered(&actions),
                state: bullets(state.iter().cloned()),
            },
        )?;
        let mut parts = vec![Part::text(user)];
        parts.extend(inputs.target_observation.parts("scene"));
        let ((steps, written, reached), record) = Stage {
            purpose: ACTIONS,
            system,
            parts,
            expected: "Give the next actions as a numbered list and the world state as \"- \" lines.",
            fidelity: inputs.fidelity,
            length: ReplyLength::Open,
            client,
        }
        .ask(|reply| {
            Ok((
                ordered_list(reply),
                unordered_list(reply),
                reply.contains(GOAL_REACHED),
            ))
        })
        .await?;
        stages.push(record);
        actions.extend(steps);
        if !(repaired && written.is_empty()) {
            state = written;
        }
        if reached {
            actions.push(GOAL_REACHED.to_string());
        }
        if repaired && actions.iter().any(|a| is_stop(a)) {
            actions.retain(|a| !is_stop(a));
            break;
        }
        if actions.iter().any(|a| a.to_lowercase() == GOAL_REACHED) {
            actions.pop();
            break;
        }
    }
    let deviations = crate::Baseline::Statler.deviations(inputs.fidelity);
    Ok(BaselinePlan {
        steps: actions,
        stages,
        deviations,
        rounds: Some(rounds),
        instruction: None,
    })
}

/// A step that says the goal is reached, in any case and with or without a final period.
fn is_stop(step: &str) -> bool {
    step.trim().trim_end_matches('.').to_lowercase() == GOAL_REACHED
}

/// The calls and images of one scenario with `keyframes` keyframes and round budget
/// `budget`, before code generation.
pub fn shape(keyframes: u64, budget: u64) -> RequestShape {
    RequestShape {
        calls_min: 3,
        calls_max: 2 + budget,
        images_min: (keyframes + 2) * IMAGES_PER_SCENE,
        images_max: (keyframes + 1 + budget) * IMAGES_PER_SCENE,
        largest_request_images: keyframes * IMAGES_PER_SCENE,
    }
}
