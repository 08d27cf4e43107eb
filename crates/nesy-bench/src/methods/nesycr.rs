//! NeSyCR: the verified world model and counterfactual adaptation of the paper (Algorithm 1),
//! through nesy-pipeline's stages, with the ablation switches as settings; and the authors'
//! released loop as a preset of the same switches.

use std::sync::Arc;

use futures::FutureExt as _;
use futures::future::BoxFuture;
use nesy_core::adapt::{Ablation, AdaptConfig, Outcome, TransitionCheck};
use nesy_pipeline::states::StatesMode;
use nesy_pipeline::synth::CodegenMode;
use nesy_pipeline::{NoProgress, PipelineError, adapt_episode, adaptation_inputs, states};
use nesy_reasoner::VlmReasoner;
use nesy_vlm::VlmClient;

use super::{
    Classes, FailureKind, Method, MethodFailure, MethodInfo, OfflineMeaning, Role, Specification, Specified,
    UnitInputs, check_keys, switch,
};
use crate::error::BenchError;
use crate::variant::Variant;

/// What an unresolved adaptation turns into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum OnUnresolved {
    /// No specification: the unit ends `unresolved` (the project's NeSyCR never compiles an
    /// unverified plan).
    Fail,
    /// Compile the last accepted procedure anyway, unverified (the authors' released code).
    CompileLast,
    /// Compile the procedure that got furthest, unverified.
    CompileBest,
}

/// NeSyCR, or the authors' released loop.
#[derive(Debug, Clone, Copy)]
pub struct NeSyCr {
    released: bool,
}

const SETTINGS: &[&str] = &[
    "world-model=on|off (Eq. 4, `dynamics`: verify induced operators against the demo)",
    "identification=on|off (Eq. 6, `conflict`: tell the model where and why the procedure fails)",
    "verification=on|off (Eq. 8, `verification`: check each proposal before accepting it)",
    "goal-check=on|off (require the derived goal at the end)",
    "goal=demo|target (the goal derived from the demonstration, or the target task's own, as a complexity-gap target states it)",
    "drop-unconditioned=on|off (drop induced operators without preconditions)",
    "on-unresolved=fail|compile-last|compile-best",
    "induction-tries=N",
    "transition-check=exact|changed-atoms",
    "budget=N (refinement rounds; default 10/15/20/30 by factor and complexity)",
    "states=observed|vlm",
    "codegen=vlm|template",
    "noise=KNOBS (the offline responder's noise, knobs separated by `;`)",
];

/// The loop's settings a variant gives.
#[derive(Debug, Clone)]
pub(crate) struct Settings {
    pub adapt: AdaptConfig,
    pub on_unresolved: OnUnresolved,
    pub budget: Option<usize>,
    pub states: StatesMode,
    pub codegen: CodegenMode,
    /// Take the goal from the target task instead of the demonstration.
    pub target_goal: bool,
}

impl NeSyCr {
    /// The project's NeSyCR: every check on, an unresolved adaptation is never compiled.
    pub fn full() -> NeSyCr {
        NeSyCr { released: false }
    }

    /// The authors' released loop: the first parsable operator per transition, operators
    /// without preconditions dropped, no proposal check, stop when every precondition holds
    /// (no goal check), and the last plan compiled even when unresolved.
    pub fn released() -> NeSyCr {
        NeSyCr { released: true }
    }

    fn name(&self) -> &'static str {
        if self.released {
            "nesycr-released"
        } else {
            "nesycr"
        }
    }

    pub(crate) fn settings(&self, variant: &Variant) -> Result<Settings, BenchError> {
        check_keys(variant, SETTINGS)?;
        let r = self.released;
        let ablation = Ablation {
            world_model: switch(variant, "world-model", !r)?,
            identification: switch(variant, "identification", true)?,
            verification: switch(variant, "verification", !r)?,
        };
        let number = |key: &str| -> Result<Option<usize>, BenchError> {
            variant
                .option(key)
                .map(|v| {
                    v.parse::<usize>().ok().filter(|n| *n > 0).ok_or_else(|| {
                        BenchError::Usage(format!(
                            "variant {variant}: {key}={v:?}; expected a positive number"
                        ))
                    })
                })
                .transpose()
        };
        let on_unresolved = match variant.option("on-unresolved") {
            None if r => OnUnresolved::CompileLast,
            None | Some("fail") => OnUnresolved::Fail,
            Some("compile-last") => OnUnresolved::CompileLast,
            Some("compile-best") => OnUnresolved::CompileBest,
            Some(other) => {
                return Err(BenchError::Usage(format!(
                    "variant {variant}: on-unresolved={other:?}; expected fail, compile-last or compile-best"
                )));
            }
        };
        let transition_check = match variant.option("transition-check") {
            None | Some("exact") => TransitionCheck::Exact,
            Some("changed-atoms") => TransitionCheck::ChangedAtoms,
            Some(other) => {
                return Err(BenchError::Usage(format!(
                    "variant {variant}: transition-check={other:?}; expected exact or changed-atoms"
                )));
            }
        };
        let states = match variant.option("states") {
            None | Some("observed") => StatesMode::Observed,
            Some("vlm") => StatesMode::Vlm,
            Some(other) => {
                return Err(BenchError::Usage(format!(
                    "variant {variant}: states={other:?}; expected observed or vlm"
                )));
            }
        };
        let target_goal = match variant.option("goal") {
            None | Some("demo") => false,
            Some("target") => true,
            Some(other) => {
                return Err(BenchError::Usage(format!(
                    "variant {variant}: goal={other:?}; expected demo or target"
                )));
            }
        };
        let codegen = match variant.option("codegen") {
            None | Some("vlm") => CodegenMode::Vlm,
            Some("template") => CodegenMode::Template,
            Some(other) => {
                return Err(BenchError::Usage(format!(
                    "variant {variant}: codegen={other:?}; expected vlm or template"
                )));
            }
        };
        Ok(Settings {
            adapt: AdaptConfig {
                induction_tries: number("induction-tries")?.unwrap_or(if r { 1 } else { 5 }),
                budget: 10,
                transition_check,
                ablation,
                goal_check: switch(variant, "goal-check", !r)?,
                drop_unconditioned: switch(variant, "drop-unconditioned", r)?,
            },
            on_unresolved,
            budget: number("budget")?,
            states,
            codegen,
            target_goal,
        })
    }
}

fn pipeline_failure(e: PipelineError) -> MethodFailure {
    match e.reasoner_kind() {
        Some(kind) => MethodFailure::from_reasoner(kind, e.to_string()),
        None => MethodFailure::new(FailureKind::Method, e.to_string()),
    }
}

impl Method for NeSyCr {
    fn info(&self) -> MethodInfo {
        MethodInfo {
            name: self.name(),
            title: if self.released {
                "NeSyCR (released loop)"
            } else {
                "NeSyCR"
            },
            role: Role::Method,
            classes: Classes {
                natively_code: false,
                explicit_adapt: true,
                replanning: true,
                world_model: true,
                symbolic_tool: true,
            },
            summary: if self.released {
                "the authors' released loop: first parsable operator, operators without preconditions dropped, no proposal check, stops when every precondition holds, compiles the last plan even unresolved"
            } else {
                "verified world model from the demo, counterfactual identification of the first violated precondition, verified SEARCH/REPLACE patches until the procedure holds and reaches the goal"
            },
            settings: SETTINGS,
            offline: OfflineMeaning::UpperBound,
        }
    }

    fn validate(&self, variant: &Variant) -> Result<(), BenchError> {
        self.settings(variant).map(|_| ())
    }

    fn specify<'a>(
        &'a self,
        inputs: &'a UnitInputs,
        client: &'a VlmClient,
    ) -> BoxFuture<'a, Result<Specified, MethodFailure>> {
        async move {
            let settings = self
                .settings(&inputs.variant)
                .map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?;
            let setting = &inputs.setting;
            let reasoner = VlmReasoner::new(client.clone())
                .map_err(|e| MethodFailure::new(FailureKind::Method, format!("loading nesy's prompts: {e}")))?
                .with_embodiments(setting.source_embodiment, setting.target_embodiment);
            // Without pictures the induction prompts carry the keyframes' states alone, as
            // text, which they always include.
            let reasoner = if setting.images {
                reasoner.with_keyframes(inputs.keyframes.clone())
            } else {
                reasoner
            };
            let vocabulary = &inputs.vocabulary;
            let states = states::symbolic_states(
                &reasoner,
                &inputs.demo,
                &inputs.target,
                setting,
                settings.states,
                vocabulary,
                &NoProgress,
            )
            .await
            .map_err(pipeline_failure)?;
            let (demonstration, mut target) =
                adaptation_inputs(&inputs.demo, &inputs.target, setting, &states, vocabulary);
            if settings.target_goal {
                // The target task's goal as its scene states it: what the target instruction
                // asks for, including subtasks the demonstration never shows.
                target.goal = Some(super::replan::target_goal(inputs)?);
            }
            let budget = settings.budget.unwrap_or(setting.budget);
            let config = AdaptConfig {
                budget,
                ..settings.adapt
            };
            let adapted = adapt_episode(reasoner, &demonstration, &target, &config, Arc::new(NoProgress))
                .await
                .map_err(pipeline_failure)?;
            let symbolic_s = (
                adapted.symbolic.as_secs_f64(),
                adapted.symbolic_world_model.as_secs_f64(),
            );
            let vlm_s = states.vlm_time.as_secs_f64() + adapted.vlm.as_secs_f64();
            let adaptation = adapted.adaptation;
            let mut notes = Vec::new();
            let (procedure, verified, iterations) = match &adaptation.outcome {
                Outcome::Adapted {
                    procedure,
                    iterations,
                    ..
                } => (procedure.clone(), config.goal_check, *iterations),
                Outcome::Unresolved {
                    best,
                    last,
                    iterations,
                    ..
                } => match settings.on_unresolved {
                    OnUnresolved::Fail => {
                        return Err(MethodFailure {
                            kind: FailureKind::Unresolved,
                            message: format!(
                                "no verified procedure within the budget of {budget} refinement round(s)"
                            ),
                            adaptation: Some(Box::new(adaptation.clone())),
                            iterations: Some((*iterations, budget)),
                            symbolic_s: Some(symbolic_s),
                        });
                    }
                    OnUnresolved::CompileLast => {
                        notes.push("unresolved: compiled the last accepted procedure, unverified".to_owned());
                        (last.clone(), false, *iterations)
                    }
                    OnUnresolved::CompileBest => {
                        notes.push(
                            "unresolved: compiled the procedure that got furthest, unverified".to_owned(),
                        );
                        (best.clone(), false, *iterations)
                    }
                },
            };
            Ok(Specified {
                spec: Specification::Procedure { procedure, verified },
                codegen: settings.codegen,
                iterations: Some((iterations, budget)),
                adaptation: Some(adaptation),
                states: Some(states.source),
                symbolic_s,
                vlm_s,
                notes,
            })
        }
        .boxed()
    }
}
