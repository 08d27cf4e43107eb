//! The replanning control: nesy-core's planner over nesy's true domain, from the target's
//! observed initial state to the target's goal (every object in its container, lids and
//! drawers closed, the end effector released), compiled by the template compiler. It is the
//! planner stage of a planning method given a perfect domain and problem: an idealized
//! control, and a measure of the planner's own capacity.

use futures::FutureExt as _;
use futures::future::BoxFuture;
use nesy_core::Formula;
use nesy_core::Symbol;
use nesy_pipeline::synth::CodegenMode;
use nesy_sim::domain::{WorldDomain, control_planner_config, plan_to_goal};
use nesy_vlm::VlmClient;

use super::{
    Classes, FailureKind, Method, MethodFailure, MethodInfo, OfflineMeaning, Role, Specification, Specified,
    UnitInputs, check_keys,
};
use crate::error::BenchError;
use crate::variant::Variant;

/// The replanning control.
#[derive(Debug, Clone, Copy)]
pub struct Replan;

/// The target's goal as the planner takes it: every scene goal's atoms, and the end effector
/// open with nothing held ([`nesy_sim::scene::SceneSpec::symbolic_goal`]).
pub(super) fn target_goal(inputs: &UnitInputs) -> Result<Formula, MethodFailure> {
    let scene = inputs
        .target
        .sim_scene()
        .map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?;
    Ok(Formula::And(
        scene.symbolic_goal().into_iter().map(Formula::atom).collect(),
    ))
}

impl Method for Replan {
    fn info(&self) -> MethodInfo {
        MethodInfo {
            name: "replan",
            title: "Replanning (control, idealized)",
            role: Role::Control,
            classes: Classes {
                natively_code: false,
                explicit_adapt: true,
                replanning: true,
                world_model: true,
                symbolic_tool: true,
            },
            summary: "nesy-core's planner over the true domain from the target's state to its goal, compiled: the planner stage of a planning method with a perfect domain and problem",
            settings: &[],
            offline: OfflineMeaning::ModelFree,
        }
    }

    fn validate(&self, variant: &Variant) -> Result<(), BenchError> {
        check_keys(variant, &[])
    }

    fn specify<'a>(
        &'a self,
        inputs: &'a UnitInputs,
        _client: &'a VlmClient,
    ) -> BoxFuture<'a, Result<Specified, MethodFailure>> {
        async move {
            let world =
                WorldDomain::builtin().map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?;
            let goal = target_goal(inputs)?;
            let fail =
                |e: nesy_pipeline::PipelineError| MethodFailure::new(FailureKind::Method, e.to_string());
            let observed = inputs.target.observed_state().map_err(fail)?;
            let embodiment = inputs.target.sim_scene().map_err(fail)?.embodiment;
            let objects: Vec<Symbol> = inputs.target.objects.iter().map(|o| Symbol::new(o)).collect();
            let started = std::time::Instant::now();
            let procedure = plan_to_goal(
                world,
                observed,
                &goal,
                embodiment,
                &objects,
                &control_planner_config(),
            )
            .map_err(|e| MethodFailure::new(FailureKind::Unresolved, format!("no plan: {e}")))?;
            let symbolic = started.elapsed().as_secs_f64();
            Ok(Specified {
                spec: Specification::Procedure {
                    procedure,
                    verified: true,
                },
                codegen: CodegenMode::Template,
                adaptation: None,
                iterations: None,
                states: None,
                symbolic_s: (symbolic, 0.0),
                vlm_s: 0.0,
                notes: Vec::new(),
            })
        }
        .boxed()
    }
}
