//! Code generation: the adapted procedure, the instruction and the objects go into the
//! finger or extended code-generation prompt; the program comes out of the reply's code
//! block ([`extract`]).

pub mod extract;

use nesy_core::operator::Operator;
use serde::{Deserialize, Serialize};

pub use extract::{CodeBlock, ExtractError, ExtractedCode, StrippedImport, count_api_calls, extract_code};

use crate::client::VlmClient;
use crate::context::{CodeGenerationContext, Embodiment, VlmTask};
use crate::error::VlmError;
use crate::prompts::{CodeGenerationPrompt, PromptError, Prompts, action_names};
use crate::request::{ChatRequest, Message};
use crate::settings::CallSettings;

/// What code generation needs.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CodeGenerationRequest {
    /// The instruction (of the target scene).
    pub instruction: String,
    /// The target scene's objects, in order.
    pub objects: Vec<String>,
    /// The adapted, verified procedure; its action names become the demonstration summary.
    pub procedure: Vec<Operator>,
    /// The target robot's end effector.
    pub embodiment: Embodiment,
    /// Use the extended prompt (both end effectors documented). The pipeline sets it when
    /// the demonstration's end effector differs from the target's, as the authors do; a
    /// vacuum target always gets it.
    pub extended: bool,
}

/// A generated program, ready for the sandbox, with how it was obtained.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct PolicySource {
    /// The program.
    pub code: String,
    /// The full reply it was taken from.
    pub reply: String,
    /// Which fenced block it came from.
    pub block: CodeBlock,
    /// Import statements removed from it (see [`extract`]).
    pub stripped: Vec<StrippedImport>,
    /// Whether the extended prompt was used.
    pub extended: bool,
}

/// Why code generation failed.
#[derive(Debug, thiserror::Error)]
pub enum CodegenError {
    /// The call failed.
    #[error("code generation call failed: {0}")]
    Vlm(#[from] VlmError),
    /// A prompt template failed (a defect of nesy's own files).
    #[error(transparent)]
    Prompt(#[from] PromptError),
    /// The reply holds no usable program.
    #[error("code generation reply holds no program: {error}")]
    NoProgram {
        /// What was wrong.
        error: ExtractError,
        /// The reply.
        reply: String,
    },
}

impl CodegenError {
    /// The reasoner failure this is: the call's own kind, a defect of the request, or a
    /// reply without a program.
    pub fn reasoner_kind(&self) -> nesy_core::adapt::ReasonerErrorKind {
        use nesy_core::adapt::ReasonerErrorKind as Kind;
        match self {
            CodegenError::Vlm(e) => e.reasoner_kind(),
            CodegenError::Prompt(_) => Kind::Request,
            CodegenError::NoProgram { .. } => Kind::Reply,
        }
    }
}

/// Builds the code-generation chat request (prompt and task context) without sending it.
pub fn build_request(
    prompts: &Prompts,
    request: &CodeGenerationRequest,
    settings: &CallSettings,
) -> Result<(ChatRequest, bool), PromptError> {
    let names = action_names(&request.procedure);
    let prompt = CodeGenerationPrompt {
        instruction: &request.instruction,
        objects: &request.objects,
        action_names: &names,
        embodiment: request.embodiment,
        extended: request.extended,
    };
    let extended = prompt.uses_extended();
    let rendered = prompts.code_generation(&prompt)?;
    let context = VlmTask::CodeGeneration(CodeGenerationContext {
        instruction: request.instruction.clone(),
        objects: request.objects.clone(),
        procedure: request.procedure.clone(),
        action_names: names
            .iter()
            .enumerate()
            .map(|(i, n)| format!("{}. {n}", i + 1))
            .collect(),
        embodiment: request.embodiment,
        extended,
    });
    let chat = ChatRequest::new()
        .purpose(context.purpose())
        .task(context.to_task_context())
        .message(Message::system(rendered.system))
        .message(Message::user_text(rendered.user));
    Ok((settings.apply(chat), extended))
}

/// Asks the model for a program and extracts it from the reply.
pub async fn generate_code(
    client: &VlmClient,
    prompts: &Prompts,
    request: &CodeGenerationRequest,
    settings: &CallSettings,
) -> Result<PolicySource, CodegenError> {
    let (chat, extended) = build_request(prompts, request, settings)?;
    let reply = client.chat(chat).await?.text;
    match extract_code(&reply) {
        Ok(extracted) => {
            for s in &extracted.stripped {
                tracing::info!(line = s.line, statement = %s.text, "removed an import from the generated program: {}", s.reason);
            }
            Ok(PolicySource {
                code: extracted.code,
                reply,
                block: extracted.block,
                stripped: extracted.stripped,
                extended,
            })
        }
        Err(error) => Err(CodegenError::NoProgram { error, reply }),
    }
}
