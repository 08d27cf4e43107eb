//! MoReVQA as the paper runs it (no public code; the authors followed the paper's
//! supplementary material): the domain description (GPT4V-Robotics' first call); M1, event
//! parsing of the instruction into a question and an event queue (JSON); M2, rounds of
//! grounding the queue in the target (JSON), writing a `verify_action("…")` call, and
//! "executing" it on the target's views (JSON with `verified` and a reason) until verified;
//! M3, three visual sub-questions and their answers; then the plan from the end-effector
//! predicates, the target's full state, the answers and the queue. Code generation gets the
//! question form of the instruction, as in the authors' code.
//!
//! Deviations kept in both modes: the authors' M2 loop has no bound, and it is capped here at
//! the scenario's budget (10/15/20/30). In [`Fidelity::Authors`] a reply that is not exactly
//! a JSON object ends the unit (their `json.loads` raises), and a failed check's reason is
//! not shown to the next grounding call (their template has no slot for it, so a retry
//! resends the same prompt). [`Fidelity::Repaired`] reads the object out of prose or a fence
//! and shows the reason.

use nesy_core::Tier;
use nesy_vlm::{Part, ReplyLength, VlmClient};
use serde::Serialize;

use crate::gpt4v::describe_domain;
use crate::inputs::{BaselineInputs, Fidelity};
use crate::json;
use crate::parse::prepared;
use crate::prompts::{EpisodePrompts, bullets, numbered, state_lines};
use crate::stage::{NUMBERED_PLAN, Stage, StageRecord, numbered_plan};
use crate::{BaselineError, BaselinePlan, IMAGES_PER_SCENE, RequestShape};

/// M1: event parsing.
pub const PARSE: &str = "morevqa.parse";
/// M2: grounding the event queue.
pub const GROUND: &str = "morevqa.ground";
/// M2: writing the verification call.
pub const VERIFY_API: &str = "morevqa.verify_api";
/// M2: executing it.
pub const VERIFY: &str = "morevqa.verify";
/// M3: writing the visual sub-questions.
pub const VQA_API: &str = "morevqa.vqa_api";
/// M3: answering them.
pub const VQA: &str = "morevqa.vqa";
/// The plan.
pub const PLAN: &str = "morevqa.plan";

const JSON_ONLY: &str = "Answer with the JSON object only, as the format above shows.";

/// What M1 parsed.
struct Parsed {
    question: String,
    events: Vec<String>,
    objects: Vec<String>,
}

#[derive(Serialize)]
struct ParseVars<'a> {
    instruction: &'a str,
}

#[derive(Serialize)]
struct GroundVars<'a> {
    domain_description: &'a str,
    target_objects: String,
    event_queue: String,
    event_object: String,
}

#[derive(Serialize)]
struct QuestionVars<'a> {
    question: &'a str,
}

#[derive(Serialize)]
struct VerifyVars<'a> {
    verify_api: &'a str,
    question: &'a str,
    event_queue: String,
}

#[derive(Serialize)]
struct QueueVars {
    event_queue: String,
}

#[derive(Serialize)]
struct VqaVars<'a> {
    vqa: &'a str,
}

#[derive(Serialize)]
struct PlanVars<'a> {
    predicates: String,
    target_object_state: String,
    target_objects: String,
    vqa_answer: &'a str,
    event_queue: String,
}

/// Runs MoReVQA on `inputs`.
pub async fn run(client: &VlmClient, inputs: &BaselineInputs) -> Result<BaselinePlan, BaselineError> {
    let prompts = &EpisodePrompts::for_inputs(inputs)?;
    let tolerant = inputs.fidelity == Fidelity::Repaired;
    let (description, describe) = describe_domain(client, prompts, inputs).await?;
    let mut stages = vec![describe];
    let stage =
        |purpose: &'static str, (system, user): (String, String), images: bool, expected: &'static str| {
            let mut parts = vec![Part::text(user)];
            if images {
                parts.extend(inputs.target_observation.parts("scene"));
            }
            Stage {
                purpose,
                system,
                parts,
                expected,
                fidelity: inputs.fidelity,
                length: ReplyLength::Open,
                client,
            }
        };
    let mut keep = |record: StageRecord| stages.push(record);

    // M1: event parsing.
    let prompt = prompts.render(
        "morevqa.parse",
        &ParseVars {
            instruction: &inputs.instruction,
        },
    )?;
    let (parsed, record) = stage(PARSE, prompt, false, JSON_ONLY)
        .ask(|reply| {
            let map = json::object(reply, tolerant)?;
            Ok(Parsed {
                question: json::string(&map, "question")?,
                events: json::strings(&map, "parse_event")?,
                objects: json::strings(&map, "event_object")?,
            })
        })
        .await?;
    keep(record);

    // M2: ground and verify, up to the budget.
    let looped = ground_and_verify(&stage, &mut keep, prompts, inputs, &description, &parsed).await?;
    let (queue, rounds, verified) = (looped.queue, looped.rounds, looped.verified);

    // M3: three visual sub-questions and their answers.
    let prompt = prompts.render(
        "morevqa.vqa_api",
        &QueueVars {
            event_queue: numbered(&queue),
        },
    )?;
    let (questions, record) = stage(VQA_API, prompt, true, "Write three lines of the form vqa(\"…\").")
        .ask(non_empty)
        .await?;
    keep(record);
    let prompt = prompts.render("morevqa.vqa", &VqaVars { vqa: &questions })?;
    let (answers, record) = stage(VQA, prompt, true, "Answer every question, one line each.")
        .ask(non_empty)
        .await?;
    keep(record);

    // The plan.
    let prompt = prompts.render(
        "morevqa.plan",
        &PlanVars {
            predicates: inputs.vocabulary.render_definitions(Tier::EndEffector),
            target_object_state: state_lines(&inputs.target_state),
            target_objects: bullets(inputs.target_objects.iter().cloned()),
            vqa_answer: &answers,
            event_queue: numbered(&queue),
        },
    )?;
    let (steps, record) = stage(PLAN, prompt, true, NUMBERED_PLAN)
        .ask(numbered_plan)
        .await?;
    keep(record);

    let mut deviations = crate::Baseline::MoReVqa.deviations(inputs.fidelity);
    deviations.push(format!(
        "the verification loop ran {rounds} of its {} rounds{}",
        inputs.budget,
        if verified {
            " and verified"
        } else {
            " without verifying"
        }
    ));
    Ok(BaselinePlan {
        steps,
        stages,
        deviations,
        rounds: Some(rounds),
        instruction: Some(parsed.question),
    })
}

/// What the grounding and verification loop (M2) ends with: the event queue, the rounds it
/// ran, and whether the last check verified the queue.
struct Grounded {
    queue: Vec<String>,
    rounds: usize,
    verified: bool,
}

/// M2: the event queue grounded in the target's objects and checked, until a check verifies
/// it or the budget is spent; in repaired mode each round is told why the last check failed.
async fn ground_and_verify<'a>(
    stage: &impl Fn(&'static str, (String, String), bool, &'static str) -> Stage<'a>,
    keep: &mut impl FnMut(StageRecord),
    prompts: &EpisodePrompts,
    inputs: &BaselineInputs,
    description: &str,
    parsed: &Parsed,
) -> Result<Grounded, BaselineError> {
    let tolerant = inputs.fidelity == Fidelity::Repaired;
    let mut queue = parsed.events.clone();
    let mut reason: Option<String> = None;
    let mut rounds = 0;
    let mut verified = false;
    while rounds < inputs.budget {
        rounds += 1;
        let (system, mut user) = prompts.render(
            "morevqa.ground",
            &GroundVars {
                domain_description: description,
                target_objects: bullets(inputs.target_objects.iter().cloned()),
                event_queue: numbered(&queue),
                event_object: bullets(parsed.objects.iter().cloned()),
            },
        )?;
        if let (true, Some(reason)) = (tolerant, &reason) {
            user.push_str(&format!("\n\nThe last check of the queue failed: {reason}"));
        }
        let (grounded, record) = stage(GROUND, (system, user), true, JSON_ONLY)
            .ask(|reply| json::strings(&json::object(reply, tolerant)?, "event_queue"))
            .await?;
        keep(record);
        queue = grounded;
        let prompt = prompts.render(
            "morevqa.verify_api",
            &QuestionVars {
                question: &parsed.question,
            },
        )?;
        let (api, record) = stage(
            VERIFY_API,
            prompt,
            false,
            "Answer with one line of the form verify_action(\"the query\").",
        )
        .ask(|reply| {
            prepared(reply)
                .lines()
                .map(str::trim)
                .find(|l| l.contains("verify_action("))
                .map(str::to_string)
                .ok_or_else(|| "it has no verify_action(...) call".to_string())
        })
        .await?;
        keep(record);
        let prompt = prompts.render(
            "morevqa.verify",
            &VerifyVars {
                verify_api: &api,
                question: &parsed.question,
                event_queue: numbered(&queue),
            },
        )?;
        let ((checked, ok, why), record) = stage(VERIFY, prompt, true, JSON_ONLY)
            .ask(|reply| {
                let map = json::object(reply, tolerant)?;
                Ok((
                    json::strings(&map, "event_queue")?,
                    json::boolean(&map, "verified")?,
                    json::string(&map, "reason").unwrap_or_default(),
                ))
            })
            .await?;
        keep(record);
        if !checked.is_empty() {
            queue = checked;
        }
        if ok {
            verified = true;
            break;
        }
        reason = Some(why);
    }
    Ok(Grounded {
        queue,
        rounds,
        verified,
    })
}

fn non_empty(reply: &str) -> Result<String, String> {
    let text = prepared(reply).trim().to_string();
    if text.is_empty() {
        Err("it is empty".into())
    } else {
        Ok(text)
    }
}

/// The calls and images of one scenario with `keyframes` keyframes and round budget
/// `budget`, before code generation: the description, M1, one to `budget` rounds of three
/// calls, M3's two calls and the plan.
pub fn shape(keyframes: u64, budget: u64) -> RequestShape {
    let images_per_round = 2 * IMAGES_PER_SCENE;
    let fixed_images = keyframes * IMAGES_PER_SCENE + 3 * IMAGES_PER_SCENE;
    RequestShape {
        calls_min: 2 + 3 + 3,
        calls_max: 2 + 3 * budget + 3,
        images_min: fixed_images + images_per_round,
        images_max: fixed_images + budget * images_per_round,
        largest_request_images: keyframes * IMAGES_PER_SCENE,
    }
}
