//! The paper's baselines as methods of the harness: each runs its call flow from
//! nesy-baselines on the unit's demonstration and target, and hands its natural-language
//! plan to the shared code-generation tail.
//!
//! None of them can be measured offline: their calls are global ("describe the
//! demonstration", "write the plan for the target"), so a perfect answer would be the
//! planner's plan, not the method's. The harness refuses them with the offline responder.

use std::time::Instant;

use futures::FutureExt as _;
use futures::future::BoxFuture;
use nesy_baselines::{
    Baseline, BaselineError, BaselineInputs, BaselinePlan, Fidelity, Keyframe, SceneObservation, SceneViews,
};
use nesy_pipeline::synth::CodegenMode;
use nesy_reasoner::Views;
use nesy_vlm::{Image, VlmClient};

use super::{
    Classes, FailureKind, Method, MethodFailure, MethodInfo, OfflineMeaning, Role, Specification, Specified,
    UnitInputs, check_keys,
};
use crate::error::BenchError;
use crate::variant::Variant;

/// A baseline as a harness method.
#[derive(Debug, Clone, Copy)]
pub struct BaselineMethod {
    baseline: Baseline,
}

const SETTINGS: &[&str] = &["fidelity=authors|repaired (the authors' behaviour, or their quirks fixed)"];

impl BaselineMethod {
    /// The harness method of `baseline`.
    pub fn new(baseline: Baseline) -> BaselineMethod {
        BaselineMethod { baseline }
    }

    /// Which baseline this is.
    pub fn baseline(&self) -> Baseline {
        self.baseline
    }

    fn fidelity(variant: &Variant) -> Result<Fidelity, BenchError> {
        match variant.option("fidelity") {
            None | Some("authors") => Ok(Fidelity::Authors),
            Some("repaired") => Ok(Fidelity::Repaired),
            Some(other) => Err(BenchError::Usage(format!(
                "variant {variant}: fidelity={other:?}; expected authors or repaired"
            ))),
        }
    }
}

impl Method for BaselineMethod {
    fn info(&self) -> MethodInfo {
        let (name, title, classes, summary) = match self.baseline {
            Baseline::Demo2Code => (
                "demo2code",
                "Demo2Code",
                Classes {
                    natively_code: true,
                    ..Classes::default()
                },
                "one observation per keyframe, then one call that adapts them into the target's plan (no check)",
            ),
            Baseline::Gpt4vRobotics => (
                "gpt4v-robotics",
                "GPT4V-Robotics",
                Classes {
                    natively_code: true,
                    explicit_adapt: true,
                    replanning: true,
                    ..Classes::default()
                },
                "one domain description from every keyframe's views at once, then one planning call on the target (no check)",
            ),
            Baseline::CriticV => (
                "critic-v",
                "Critic-V",
                Classes {
                    explicit_adapt: true,
                    ..Classes::default()
                },
                "Demo2Code's unadapted plan, then rounds of model feedback on the target and text-line SEARCH/REPLACE corrections until \"no issue\" (no check)",
            ),
            Baseline::Statler => (
                "statler",
                "Statler",
                Classes {
                    explicit_adapt: true,
                    replanning: true,
                    world_model: true,
                    ..Classes::default()
                },
                "the domain description, a predicted state, then rounds that extend the plan and rewrite the state in text until \"goal reached\" (no check)",
            ),
            Baseline::MoReVqa => (
                "morevqa",
                "MoReVQA",
                Classes {
                    explicit_adapt: true,
                    ..Classes::default()
                },
                "the domain description, event parsing, grounding and model-executed verification rounds (capped at the budget), three visual sub-questions, then the plan (no check)",
            ),
            Baseline::LlmDm => (
                "llm-dm",
                "LLM-DM",
                Classes {
                    explicit_adapt: true,
                    replanning: true,
                    world_model: true,
                    symbolic_tool: true,
                    ..Classes::default()
                },
                "a PDDL domain written action by action and a predicted problem, solved by the nesy planner (A* with h_max; not Fast Downward), the domain refined from the planner's report up to the budget, the plan put into words",
            ),
        };
        MethodInfo {
            name,
            title,
            role: Role::Method,
            classes,
            summary,
            settings: SETTINGS,
            offline: OfflineMeaning::NotMeaningful,
        }
    }

    fn validate(&self, variant: &Variant) -> Result<(), BenchError> {
        check_keys(variant, SETTINGS)?;
        BaselineMethod::fidelity(variant).map(|_| ())
    }

    fn deviations(&self, variant: &Variant) -> Vec<String> {
        BaselineMethod::fidelity(variant)
            .map(|f| self.baseline.deviations(f))
            .unwrap_or_default()
    }

    fn specify<'a>(
        &'a self,
        inputs: &'a UnitInputs,
        client: &'a VlmClient,
    ) -> BoxFuture<'a, Result<Specified, MethodFailure>> {
        async move {
            let fidelity = BaselineMethod::fidelity(&inputs.variant)
                .map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?;
            let baseline_inputs = baseline_inputs(inputs, fidelity)?;
            let started = Instant::now();
            let plan = self
                .baseline
                .run(client, &baseline_inputs)
                .await
                .map_err(baseline_failure)?;
            Ok(specified(
                plan,
                baseline_inputs.budget,
                started.elapsed().as_secs_f64(),
            ))
        }
        .boxed()
    }
}

fn specified(plan: BaselinePlan, budget: usize, vlm_s: f64) -> Specified {
    let mut notes: Vec<String> = plan
        .deviations
        .iter()
        .map(|d| format!("deviation: {d}"))
        .collect();
    for stage in &plan.stages {
        for problem in &stage.reasked {
            notes.push(format!("{}: re-asked: {problem}", stage.purpose));
        }
    }
    Specified {
        spec: Specification::Plan {
            steps: plan.steps,
            instruction: plan.instruction,
        },
        codegen: CodegenMode::Vlm,
        adaptation: None,
        iterations: plan.rounds.map(|rounds| (rounds, budget)),
        states: None,
        symbolic_s: (0.0, 0.0),
        vlm_s,
        notes,
    }
}

/// The unit's failure for a baseline error; an unreadable reply is kept in the message.
fn baseline_failure(error: BaselineError) -> MethodFailure {
    if error.is_unresolved() {
        return MethodFailure::new(FailureKind::Unresolved, error.to_string());
    }
    let mut message = error.to_string();
    if let Some(reply) = error.reply() {
        let excerpt: String = reply.chars().take(2000).collect();
        message.push_str(&format!("\nthe reply:\n{excerpt}"));
    }
    MethodFailure::from_reasoner(error.reasoner_kind(), message)
}

/// What the baselines see of a unit: the demonstration's ground-truth states, and per
/// keyframe and for the target either the six views or, when the run sends no pictures, the
/// scene's ground-truth state as text.
fn baseline_inputs(inputs: &UnitInputs, fidelity: Fidelity) -> Result<BaselineInputs, MethodFailure> {
    let fail = |message: String| MethodFailure::new(FailureKind::Method, message);
    let pictures = inputs.setting.images;
    let demo = &inputs.demo.demo;
    let mut keyframes = Vec::with_capacity(demo.keyframes.len());
    for k in &demo.keyframes {
        let state = k.state.clone().ok_or_else(|| {
            fail(format!(
                "keyframe {} has no ground-truth state; the baselines read the states as text",
                k.index
            ))
        })?;
        let view = |marked: bool| -> Result<Views, MethodFailure> {
            let mut named = Vec::with_capacity(k.views.len());
            for view in k.views.iter() {
                let bytes = if marked {
                    view.images.marked_or_raw()
                } else {
                    &view.images.raw
                };
                let image = Image::from_encoded(bytes.to_vec())
                    .map_err(|e| fail(format!("keyframe {}: {} view: {e}", k.index, view.name)))?;
                named.push((view.name.clone(), image));
            }
            Ok(Views::new(named))
        };
        let observation = if pictures {
            SceneObservation::Images(SceneViews {
                raw: view(false)?,
                marked: view(true)?,
            })
        } else {
            SceneObservation::StateText(state.clone())
        };
        keyframes.push(Keyframe { state, observation });
    }
    let target = &inputs.target;
    let target_state = target.observed_state().map_err(|e| fail(e.to_string()))?.clone();
    let target_observation = if pictures {
        SceneObservation::Images(SceneViews {
            raw: target.raw_views().map_err(|e| fail(e.to_string()))?,
            marked: target.marked_views().map_err(|e| fail(e.to_string()))?,
        })
    } else {
        SceneObservation::StateText(target_state.clone())
    };
    Ok(BaselineInputs {
        instruction: target.instruction(&inputs.demo),
        source_objects: demo.metadata.objects.clone(),
        keyframes,
        target_objects: target.objects.clone(),
        target_state,
        target_observation,
        vocabulary: (*inputs.vocabulary).clone(),
        end_effector_in_state: inputs.setting.embodiment_in_state
            || inputs.setting.factor == nesy_core::benchmark::Factor::Comb,
        budget: inputs.setting.budget,
        fidelity,
    })
}
