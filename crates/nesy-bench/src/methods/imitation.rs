//! The imitation control: the demonstration's own procedure, unadapted, compiled by the
//! template compiler and executed in the target. Its operators come from the reference
//! responder's induction over nesy's true domain, so the control uses no model; it measures
//! the domain gap itself (how often, and how far from the goal, the demonstrated procedure
//! fails in the target).

use futures::FutureExt as _;
use futures::future::BoxFuture;
use nesy_core::adapt::{AdaptConfig, Trace, construct_world_model, identify};
use nesy_core::verify_procedure;
use nesy_pipeline::states::StatesMode;
use nesy_pipeline::synth::CodegenMode;
use nesy_pipeline::{DemoInput, NoProgress, adaptation_inputs, states, vlm};
use nesy_reasoner::VlmReasoner;
use nesy_vlm::VlmClient;

use super::{
    Classes, FailureKind, Method, MethodFailure, MethodInfo, OfflineMeaning, Role, Specification, Specified,
    UnitInputs, check_keys,
};
use crate::error::BenchError;
use crate::variant::Variant;

/// The imitation control.
#[derive(Debug, Clone, Copy)]
pub struct Imitation;

/// An offline client over the reference responder without noise: the true domain's
/// induction from `demo`'s recorded calls, used by the controls.
pub(crate) fn ground_truth_client(demo: &DemoInput) -> Result<VlmClient, MethodFailure> {
    let transport = vlm::oracle_transport("", 0, demo.recorded_calls())
        .map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?;
    Ok(VlmClient::with_transport(&vlm::oracle_config(), transport))
}

impl Method for Imitation {
    fn info(&self) -> MethodInfo {
        MethodInfo {
            name: "imitation",
            title: "Imitation (control)",
            role: Role::Control,
            classes: Classes {
                natively_code: false,
                explicit_adapt: false,
                replanning: false,
                world_model: false,
                symbolic_tool: false,
            },
            summary: "the demonstration's procedure (operators induced over the true domain), unadapted, compiled and executed in the target: the domain gap itself",
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
            let client = ground_truth_client(&inputs.demo)?;
            let setting = &inputs.setting;
            let mut reasoner = VlmReasoner::new(client)
                .map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?
                .with_keyframes(inputs.keyframes.clone())
                .with_embodiments(setting.source_embodiment, setting.target_embodiment);
            let vocabulary = &inputs.vocabulary;
            let states = states::symbolic_states(
                &reasoner,
                &inputs.demo,
                &inputs.target,
                setting,
                StatesMode::Observed,
                vocabulary,
                &NoProgress,
            )
            .await
            .map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?;
            let (demonstration, target) =
                adaptation_inputs(&inputs.demo, &inputs.target, setting, &states, vocabulary);
            let started = std::time::Instant::now();
            let mut trace = Trace::default();
            let world =
                construct_world_model(&mut reasoner, &demonstration, &AdaptConfig::default(), &mut trace)
                    .await
                    .map_err(|e| MethodFailure::new(FailureKind::Method, e.to_string()))?;
            // Whether the demonstrated procedure happens to hold in the target, as a note.
            let report = verify_procedure(&target.init, &world.procedure, Some(&world.goal));
            let holds = identify(&report, &world.procedure).is_none();
            let symbolic = started.elapsed().as_secs_f64();
            Ok(Specified {
                spec: Specification::Procedure {
                    procedure: world.procedure,
                    verified: holds,
                },
                codegen: CodegenMode::Template,
                adaptation: None,
                iterations: None,
                states: None,
                symbolic_s: (symbolic, symbolic),
                vlm_s: 0.0,
                notes: vec![if holds {
                    "the demonstrated procedure holds in the target as it is".to_owned()
                } else {
                    "the demonstrated procedure does not hold in the target (run unadapted)".to_owned()
                }],
            })
        }
        .boxed()
    }
}
