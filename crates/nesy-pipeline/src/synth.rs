//! Step 5: the adapted, verified procedure becomes a Python code policy.
//!
//! - `vlm`: the paper's Code Generation prompt (finger, or extended with the vacuum
//!   functions when the embodiment changed or the target is a vacuum tool), the numbered
//!   action names as the demonstration summary; the program is extracted from the reply.
//! - `template`: every verified symbolic action compiled deterministically to API calls by
//!   nesy-sim's template compiler (beyond the paper).

use nesy_core::Embodiment;
use nesy_core::Operator;
use nesy_core::adapt::ReasonerErrorKind;
use nesy_reasoner::VlmReasoner;
use nesy_reasoner::codegen::{
    CheckUnavailable, CodeGenerationRequest, CodegenError, Finding, ProgramCheck, RejectedProgram,
};
use nesy_sim::codegen::compile_policy;
use serde::Serialize;

/// How code is synthesized (`--codegen`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum CodegenMode {
    /// The VLM's Code Generation prompt.
    #[default]
    Vlm,
    /// The deterministic template compiler.
    Template,
}

/// What synthesis needs.
#[derive(Debug, Clone)]
pub struct SynthesisRequest {
    /// The target's instruction.
    pub instruction: String,
    /// The target's objects.
    pub objects: Vec<String>,
    /// The adapted procedure.
    pub procedure: Vec<Operator>,
    /// The demo's end effector.
    pub source: Embodiment,
    /// The target's end effector.
    pub target: Embodiment,
    /// The target scene holds a tool: offer the tool-use calls.
    pub tools: bool,
    /// The target robot's protective stop is on: the template compiler keeps the hand off
    /// tall furniture where it chooses a wrist turn.
    pub protective_stop: bool,
}

/// A synthesized program and how it was obtained.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SynthesizedPolicy {
    /// The program.
    pub code: String,
    /// Which synthesizer made it.
    pub mode: CodegenMode,
    /// The model's full reply (`vlm` only).
    pub reply: Option<String>,
    /// Whether the extended (both end effectors) prompt was used (`vlm` only).
    pub extended: bool,
    /// Import lines removed from the model's program, with why.
    pub stripped: Vec<String>,
    /// Earlier replies that could not be used and were re-asked (`vlm` only).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub rejected: Vec<RejectedProgram>,
}

/// Why synthesis produced no program.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SynthError {
    /// The generator answered, but without a usable program (a negative verdict).
    NoProgram {
        /// What was wrong.
        message: String,
        /// Every reply the budget allowed, with why it could not be used (`vlm` only).
        #[serde(skip_serializing_if = "Vec::is_empty")]
        replies: Vec<RejectedProgram>,
    },
    /// The generator could not be asked (transport, cassette miss, prompt defect): the run
    /// fails with an error after writing its outputs.
    Call {
        /// What went wrong.
        message: String,
        /// The kind of reasoner failure.
        failure: ReasonerErrorKind,
    },
}

impl std::fmt::Display for SynthError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SynthError::NoProgram { message, .. } => write!(f, "no program: {message}"),
            SynthError::Call { message, .. } => write!(f, "code generation failed: {message}"),
        }
    }
}

/// Synthesizes the policy.
pub async fn synthesize(
    reasoner: &VlmReasoner,
    mode: CodegenMode,
    request: &SynthesisRequest,
) -> Result<SynthesizedPolicy, SynthError> {
    match mode {
        CodegenMode::Vlm => {
            let result = reasoner
                .generate_code(&CodeGenerationRequest {
                    instruction: request.instruction.clone(),
                    objects: request.objects.clone(),
                    procedure: request.procedure.clone(),
                    plan: Vec::new(),
                    embodiment: request.target,
                    extended: request.source != request.target,
                    tools: request.tools,
                    protective_stop: request.protective_stop,
                })
                .await;
            let source = match result {
                Ok(source) => source,
                Err(error) => {
                    let message = error.to_string();
                    return Err(match error {
                        CodegenError::NoProgram { attempts } => SynthError::NoProgram {
                            message,
                            replies: attempts,
                        },
                        other => SynthError::Call {
                            message,
                            failure: other.reasoner_kind(),
                        },
                    });
                }
            };
            Ok(SynthesizedPolicy {
                code: source.code,
                mode,
                reply: Some(source.reply),
                extended: source.extended,
                stripped: source
                    .stripped
                    .iter()
                    .map(|s| format!("line {}: {} ({})", s.line, s.text, s.reason))
                    .collect(),
                rejected: source.rejected,
            })
        }
        CodegenMode::Template => template(request),
    }
}

fn template(request: &SynthesisRequest) -> Result<SynthesizedPolicy, SynthError> {
    let compiled = compile_policy(
        &request.procedure,
        &request.objects,
        request.target,
        request.protective_stop,
    )
    .map_err(|e| SynthError::NoProgram {
        message: e.to_string(),
        replies: Vec::new(),
    })?;
    Ok(SynthesizedPolicy {
        code: compiled.code,
        mode: CodegenMode::Template,
        reply: None,
        extended: false,
        stripped: Vec::new(),
        rejected: Vec::new(),
    })
}

/// The sandbox's static checks (nesy-policy's, in its embedded CPython), which every
/// generated program passes before code generation accepts it.
#[derive(Debug, Clone, Copy, Default)]
pub struct SandboxChecks;

impl ProgramCheck for SandboxChecks {
    fn check(&self, program: &str) -> Result<Vec<Finding>, CheckUnavailable> {
        let violations = nesy_policy::check_source(program).map_err(|e| CheckUnavailable(e.to_string()))?;
        Ok(violations
            .into_iter()
            .map(|v| Finding {
                line: v.line,
                column: v.column,
                message: v.message,
            })
            .collect())
    }
}
