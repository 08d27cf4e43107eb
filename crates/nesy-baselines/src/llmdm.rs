//! LLM-DM as the paper runs it: the model builds a PDDL domain one action at a time and
//! predicts the problem from the target scene, a classical planner solves it, and on failure
//! the model refines the whole domain from the planner's report, up to the budget; the plan is
//! then put into words for code generation.
//!
//! Stages: the domain description (GPT4V-Robotics' first call); `llmdm.actions` (text: the
//! numbered actions the domain needs); `llmdm.predicates` (text: `- ` predicates, joined with
//! every line of the planning tier, each cut at its first `:`); `llmdm.action` per action,
//! concurrently (the reply split once at "Preconditions" and once at "Effects"; the name is
//! the first `- ` line, the parameters the numbered lines, the formulas code blocks);
//! `llmdm.problem` (the target's state and six views; split once at "Initial state" and once
//! at "Goal state"; three code blocks that must open with `(:objects`, `(:init` and
//! `(:goal`); then rounds of planning and `llmdm.refine` (text: the predicates, the domain,
//! the problem and the planner's report; the refined domain in a code block); and
//! `llmdm.translate` (the numbered plan into numbered words).
//!
//! The planner is nesy-core's, not Fast Downward: A* with h_max (optimal plans, as
//! `seq-opt-lmcut`'s are, but not necessarily the same plan), relaxed-reachability grounding
//! with a cap on ground actions, and a 10 s limit over grounding and search
//! ([`PLANNER`]). Its reports are nesy-core's error messages, not Fast Downward's output.
//!
//! In both modes a domain or problem that does not parse goes back to the model as the
//! planner's report, with the parser's position (the authors build their environment
//! outside the `try`, so there it raises; catching it is a deviation). [`Fidelity::Authors`]
//! keeps the rest of their behaviour: after the budget's last refinement nothing is solved
//! again, and without a plan the specification is the single step "None", so code generation
//! runs from the instruction alone. [`Fidelity::Repaired`] solves once more after the last
//! refinement and ends without a plan as [`BaselineError::NoPlan`].

use std::time::Duration;

use nesy_core::pddl::{parse_domain, parse_problem};
use nesy_core::planner::{Grounding, Heuristic, PlannerConfig, Search, plan};
use nesy_vlm::{Part, ReplyLength, VlmClient};
use serde::Serialize;

use crate::gpt4v::describe_domain;
use crate::inputs::{BaselineInputs, Fidelity};
use crate::parse::{blocks, first_block, ordered_list, prepared, unordered_list};
use crate::prompts::{EpisodePrompts, bullets, numbered, state_lines};
use crate::stage::{NUMBERED_PLAN, Stage, StageRecord, numbered_plan};
use crate::{BaselineError, BaselinePlan, IMAGES_PER_SCENE, RequestShape};

/// The action-recommendation call.
pub const ACTIONS: &str = "llmdm.actions";
/// The predicate-proposal call.
pub const PREDICATES: &str = "llmdm.predicates";
/// The action-construction calls, one per action.
pub const ACTION: &str = "llmdm.action";
/// The problem-prediction call.
pub const PROBLEM: &str = "llmdm.problem";
/// The domain-refinement calls.
pub const REFINE: &str = "llmdm.refine";
/// The plan-translation call.
pub const TRANSLATE: &str = "llmdm.translate";

/// What the results are planned with, for every record and report that shows them.
pub const PLANNER: &str = "nesy planner (A* with h_max, relaxed-reachability grounding capped at 1 000 000 actions, 10 s over grounding and search), not Fast Downward";

/// The cap on ground actions.
pub const MAX_GROUND_ACTIONS: usize = 1_000_000;

/// The planner's settings.
pub fn planner_config() -> PlannerConfig {
    PlannerConfig {
        search: Search::AStar,
        heuristic: Heuristic::HMax,
        max_expansions: usize::MAX,
        time_limit: Some(Duration::from_secs(10)),
        preferred_operators: false,
        grounding: Grounding::Reachable,
        max_ground_actions: Some(MAX_GROUND_ACTIONS),
    }
}

/// One action the model wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
struct ActionModel {
    name: String,
    params: Vec<String>,
    precondition: String,
    effect: String,
}

#[derive(Serialize)]
struct RecommendVars<'a> {
    domain_description: &'a str,
    instruction: &'a str,
    objects: String,
}

#[derive(Serialize)]
struct PredicateVars<'a> {
    domain_description: &'a str,
    actions: String,
    predicates: String,
}

#[derive(Serialize)]
struct ActionVars<'a> {
    domain_description: &'a str,
    predicates: String,
    action: &'a str,
}

#[derive(Serialize)]
struct ProblemVars<'a> {
    domain_description: &'a str,
    predicates: String,
    instruction: &'a str,
    objects: String,
    object_state: String,
}

#[derive(Serialize)]
struct RefineVars<'a> {
    predicates: String,
    domain: &'a str,
    problem: &'a str,
    failure_context: &'a str,
}

#[derive(Serialize)]
struct TranslateVars {
    plan: String,
}

/// Why the planner gave no plan.
enum SolveError {
    /// The domain or the problem does not parse, with the parser's position.
    Parse(String),
    /// Parsed, but no plan was found.
    Plan(String),
}

/// Runs LLM-DM on `inputs`.
pub async fn run(client: &VlmClient, inputs: &BaselineInputs) -> Result<BaselinePlan, BaselineError> {
    let prompts = &EpisodePrompts::for_inputs(inputs)?;
    let (description, describe) = describe_domain(client, prompts, inputs).await?;
    let mut flow = Flow {
        client,
        inputs,
        prompts,
        description,
        stages: vec![describe],
    };
    let actions = flow.propose_actions().await?;
    let predicates = flow.propose_predicates(&actions).await?;
    let models = flow.construct_actions(&actions, &predicates).await?;
    let problem = flow.predict_problem(&predicates).await?;
    let (found, rounds) = flow
        .solve_and_refine(make_domain(&predicates, &models), &problem, &predicates)
        .await?;

    let deviations = crate::Baseline::LlmDm.deviations(inputs.fidelity);
    let steps = match found {
        Some(ground) => flow.translate_plan(&ground).await?,
        None if inputs.fidelity == Fidelity::Repaired => {
            return Err(BaselineError::NoPlan {
                message: format!("no plan for the model's domain after {rounds} refinement(s) ({PLANNER})"),
            });
        }
        None => vec!["None".to_string()],
    };
    Ok(BaselinePlan {
        steps,
        stages: flow.stages,
        deviations,
        rounds: Some(rounds),
        instruction: None,
    })
}

/// One LLM-DM episode in progress: its inputs, the domain description, and the records of
/// the stages asked so far.
struct Flow<'a> {
    client: &'a VlmClient,
    inputs: &'a BaselineInputs,
    prompts: &'a EpisodePrompts,
    description: String,
    stages: Vec<StageRecord>,
}

impl<'a> Flow<'a> {
    /// A text-only stage with the rendered `(system, user)` prompt.
    fn text_stage(
        &self,
        purpose: &'static str,
        (system, user): (String, String),
        expected: &'static str,
    ) -> Stage<'a> {
        Stage {
            purpose,
            system,
            parts: vec![Part::text(user)],
            expected,
            fidelity: self.inputs.fidelity,
            length: ReplyLength::Open,
            client: self.client,
        }
    }

    /// The actions the task needs, from the demonstration's objects.
    async fn propose_actions(&mut self) -> Result<Vec<String>, BaselineError> {
        let prompt = self.prompts.render(
            "llmdm.actions",
            &RecommendVars {
                domain_description: &self.description,
                instruction: &self.inputs.instruction,
                objects: bullets(self.inputs.source_objects.iter().cloned()),
            },
        )?;
        let (actions, record) = self
            .text_stage(ACTIONS, prompt, NUMBERED_PLAN)
            .ask(numbered_plan)
            .await?;
        self.stages.push(record);
        Ok(actions)
    }

    /// The predicates: the model's new ones, then the tier's, each kept once.
    async fn propose_predicates(&mut self, actions: &[String]) -> Result<Vec<String>, BaselineError> {
        let tier = self
            .inputs
            .vocabulary
            .render_definitions(self.inputs.planning_tier());
        let prompt = self.prompts.render(
            "llmdm.predicates",
            &PredicateVars {
                domain_description: &self.description,
                actions: numbered(actions),
                predicates: tier.clone(),
            },
        )?;
        let (proposed, record) = self
            .text_stage(
                PREDICATES,
                prompt,
                "List the new predicates, one per line starting with \"- \".",
            )
            .ask(|reply| Ok(unordered_list(reply)))
            .await?;
        self.stages.push(record);
        let mut predicates: Vec<String> = Vec::new();
        for line in proposed.iter().map(String::as_str).chain(tier.lines()) {
            // The authors keep the part before the first `:`.
            let cleaned = line.split(':').next().unwrap_or("").trim().to_string();
            if !cleaned.is_empty() && !predicates.contains(&cleaned) {
                predicates.push(cleaned);
            }
        }
        Ok(predicates)
    }

    /// Each action's PDDL model, asked for concurrently.
    async fn construct_actions(
        &mut self,
        actions: &[String],
        predicates: &[String],
    ) -> Result<Vec<ActionModel>, BaselineError> {
        let this = &*self;
        let constructions = actions.iter().map(|action| {
            let prompt = this.prompts.render(
                "llmdm.action",
                &ActionVars {
                    domain_description: &this.description,
                    predicates: predicates.join("\n"),
                    action,
                },
            );
            async move {
                this.text_stage(
                    ACTION,
                    prompt?,
                    "Write \"Action name:\", the \"- \" name, \"Parameters:\", the numbered parameters, then \"Preconditions\" and \"Effects\" once each, each followed by one code block.",
                )
                .ask(read_action)
                .await
            }
        });
        let (models, records): (Vec<ActionModel>, Vec<StageRecord>) =
            crate::stage::all_in_order(constructions)
                .await?
                .into_iter()
                .unzip();
        self.stages.extend(records);
        Ok(models)
    }

    /// The problem predicted from the target's objects, state and views, as PDDL.
    async fn predict_problem(&mut self, predicates: &[String]) -> Result<String, BaselineError> {
        let inputs = self.inputs;
        let (system, user) = self.prompts.render(
            "llmdm.problem",
            &ProblemVars {
                domain_description: &self.description,
                predicates: format!("{predicates:?}"),
                instruction: &inputs.instruction,
                objects: bullets(inputs.target_objects.iter().cloned()),
                object_state: state_lines(&inputs.target_state),
            },
        )?;
        let mut parts = vec![Part::text(user)];
        parts.extend(inputs.target_observation.parts("scene"));
        let ((objects, init, goal), record) = Stage {
            purpose: PROBLEM,
            system,
            parts,
            expected: "Write \"Initial state\" with the (:objects ...) and (:init ...) code blocks, then \"Goal state\" with the (:goal ...) code block.",
            fidelity: inputs.fidelity,
            length: ReplyLength::Open,
            client: self.client,
        }
        .ask(read_problem)
        .await?;
        self.stages.push(record);
        Ok(format!(
            "(define (problem llmdm-problem) (:domain llmdm)\n  {objects}\n  {init}\n  {goal})"
        ))
    }

    /// Solves, and while there is no plan and budget left, asks the model to repair the
    /// domain from the planner's report. Returns the plan, if one was found, and the rounds
    /// of refinement made.
    async fn solve_and_refine(
        &mut self,
        mut domain: String,
        problem: &str,
        predicates: &[String],
    ) -> Result<(Option<Vec<String>>, usize), BaselineError> {
        let inputs = self.inputs;
        let repaired = inputs.fidelity == Fidelity::Repaired;
        let mut rounds = 0;
        let mut solve_again = true;
        while solve_again {
            let context = match solve(&domain, problem) {
                Ok(steps) => return Ok((Some(steps), rounds)),
                // A domain or problem that does not parse is reported like a failed plan; the
                // authors' code raises there instead (a deviation in both modes).
                Err(SolveError::Plan(context) | SolveError::Parse(context)) => context,
            };
            if rounds == inputs.budget {
                break;
            }
            rounds += 1;
            let prompt = self.prompts.render(
                "llmdm.refine",
                &RefineVars {
                    predicates: predicates.join("\n"),
                    domain: &domain,
                    problem,
                    failure_context: &context,
                },
            )?;
            let (refined, record) = self
                .text_stage(
                    REFINE,
                    prompt,
                    "Write the whole repaired domain in one code block.",
                )
                .ask(|reply| first_block(reply).map_err(|e| e.to_string()))
                .await?;
            self.stages.push(record);
            domain = refined;
            // The authors do not solve again after the budget's last refinement.
            solve_again = repaired || rounds < inputs.budget;
        }
        Ok((None, rounds))
    }

    /// The grounded plan put into words.
    async fn translate_plan(&mut self, ground: &[String]) -> Result<Vec<String>, BaselineError> {
        let prompt = self.prompts.render(
            "llmdm.translate",
            &TranslateVars {
                plan: numbered(ground),
            },
        )?;
        let (steps, record) = self
            .text_stage(TRANSLATE, prompt, NUMBERED_PLAN)
            .ask(numbered_plan)
            .await?;
        self.stages.push(record);
        Ok(steps)
    }
}

/// Splits `text` once at `marker`: exactly one occurrence, as the authors' `split` needs.
fn split_once_exactly<'a>(text: &'a str, marker: &str) -> Result<(&'a str, &'a str), String> {
    match text.matches(marker).count() {
        1 => text
            .split_once(marker)
            .ok_or_else(|| format!("it has no \"{marker}\"")),
        0 => Err(format!("it has no \"{marker}\"")),
        n => Err(format!("it has \"{marker}\" {n} times; it must appear once")),
    }
}

fn read_action(reply: &str) -> Result<ActionModel, String> {
    let text = prepared(reply);
    let (head, rest) = split_once_exactly(&text, "Preconditions")?;
    let (pre, eff) = split_once_exactly(rest, "Effects")?;
    let name = unordered_list(head)
        .into_iter()
        .next()
        .ok_or_else(|| "it has no \"- \" line naming the action".to_string())?;
    let params = ordered_list(head)
        .into_iter()
        .filter_map(|p| {
            p.split([':', ' ', ','])
                .find(|t| t.starts_with('?'))
                .map(str::to_string)
        })
        .collect();
    let block = |part: &str, what: &str| first_block(part).map_err(|e| format!("its {what} section: {e}"));
    Ok(ActionModel {
        name: name.split_whitespace().next().unwrap_or_default().to_string(),
        params,
        precondition: block(pre, "Preconditions")?,
        effect: block(eff, "Effects")?,
    })
}

fn read_problem(reply: &str) -> Result<(String, String, String), String> {
    let text = prepared(reply);
    let (_, rest) = split_once_exactly(&text, "Initial state")?;
    let (initial, goal) = split_once_exactly(rest, "Goal state")?;
    let mut initial_blocks = blocks(initial).into_iter();
    let objects = initial_blocks
        .next()
        .ok_or_else(|| "its initial state has no code block for the objects".to_string())?;
    let init = initial_blocks
        .next()
        .ok_or_else(|| "its initial state has no second code block for the atoms".to_string())?;
    let goal = first_block(goal).map_err(|e| format!("its goal: {e}"))?;
    for (block, prefix) in [(&objects, "(:objects"), (&init, "(:init"), (&goal, "(:goal")] {
        if !block.starts_with(prefix) {
            return Err(format!(
                "a block that must open with {prefix} opens with {:?}",
                block.chars().take(20).collect::<String>()
            ));
        }
    }
    Ok((objects, init, goal))
}

/// The domain file: `:strips` and `:negative-preconditions`, untyped parameters.
fn make_domain(predicates: &[String], actions: &[ActionModel]) -> String {
    let mut out = String::from(
        "(define (domain llmdm)\n  (:requirements :strips :negative-preconditions)\n  (:predicates\n",
    );
    for p in predicates {
        out.push_str(&format!("    {p}\n"));
    }
    out.push_str("  )\n");
    for a in actions {
        out.push_str(&format!(
            "  (:action {}\n    :parameters ({})\n    :precondition {}\n    :effect {})\n",
            a.name,
            a.params.join(" "),
            a.precondition,
            a.effect
        ));
    }
    out.push(')');
    out
}

fn solve(domain: &str, problem: &str) -> Result<Vec<String>, SolveError> {
    let d = parse_domain(domain).map_err(|e| SolveError::Parse(format!("the domain does not parse: {e}")))?;
    let p = parse_problem(problem, &d)
        .map_err(|e| SolveError::Parse(format!("the problem does not parse: {e}")))?;
    let universe = d
        .universe(&p)
        .map_err(|e| SolveError::Parse(format!("the problem's objects do not fit the domain: {e}")))?;
    let found = plan(&d.actions, &universe, &p.init, &p.goal, &planner_config())
        .map_err(|e| SolveError::Plan(format!("Plan not found by the nesy planner: {e}")))?;
    Ok(found
        .steps
        .iter()
        .map(|op| {
            let args: Vec<&str> = op.args.iter().map(|a| a.as_str()).collect();
            format!("({} {})", op.name, args.join(" ")).replace(" )", ")")
        })
        .collect())
}

/// The calls and images of one scenario with `keyframes` keyframes and round budget `budget`,
/// before code generation, for a model that recommends from 1 to `actions` actions: the
/// description, the recommendation, the predicates, one construction per action, the
/// problem, up to `budget` refinements and the translation.
pub fn shape(keyframes: u64, budget: u64, actions: u64) -> RequestShape {
    RequestShape {
        calls_min: 5 + 1,
        calls_max: 5 + actions + budget,
        images_min: (keyframes + 1) * IMAGES_PER_SCENE,
        images_max: (keyframes + 1) * IMAGES_PER_SCENE,
        largest_request_images: keyframes * IMAGES_PER_SCENE,
    }
}
