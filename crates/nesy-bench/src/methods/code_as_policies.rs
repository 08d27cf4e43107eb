//! Code-as-Policies: code from the instruction and the target's objects alone, with an
//! empty demonstration summary (the authors' implementation, not part of the paper's
//! tables). A no-demonstration control for live models.

use futures::FutureExt as _;
use futures::future::BoxFuture;
use nesy_pipeline::synth::CodegenMode;
use nesy_vlm::VlmClient;

use super::{
    Classes, Method, MethodFailure, MethodInfo, OfflineMeaning, Role, Specification, Specified, UnitInputs,
    check_keys,
};
use crate::error::BenchError;
use crate::variant::Variant;

/// Code-as-Policies.
#[derive(Debug, Clone, Copy)]
pub struct CodeAsPolicies;

impl Method for CodeAsPolicies {
    fn info(&self) -> MethodInfo {
        MethodInfo {
            name: "code-as-policies",
            title: "Code-as-Policies",
            role: Role::Control,
            classes: Classes {
                natively_code: true,
                ..Classes::default()
            },
            summary: "code generation from the instruction and the target's objects only, no demonstration",
            settings: &[],
            offline: OfflineMeaning::NotMeaningful,
        }
    }

    fn validate(&self, variant: &Variant) -> Result<(), BenchError> {
        check_keys(variant, &[])
    }

    fn specify<'a>(
        &'a self,
        _inputs: &'a UnitInputs,
        _client: &'a VlmClient,
    ) -> BoxFuture<'a, Result<Specified, MethodFailure>> {
        async move {
            Ok(Specified {
                spec: Specification::Plan {
                    steps: Vec::new(),
                    instruction: None,
                },
                codegen: CodegenMode::Vlm,
                adaptation: None,
                iterations: None,
                states: None,
                symbolic_s: (0.0, 0.0),
                vlm_s: 0.0,
                notes: Vec::new(),
            })
        }
        .boxed()
    }
}
