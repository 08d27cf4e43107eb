//! Code generation: the adapted procedure, the instruction and the objects go into the
//! finger or extended code-generation prompt; the program comes out of the reply's code
//! block ([`extract_code`]).

mod check;
mod extract;

use nesy_core::Operator;
use serde::{Deserialize, Serialize};

pub use check::{CheckUnavailable, Finding, ProgramCheck};
pub use extract::{CodeBlock, ExtractError, ExtractedCode, StrippedImport, count_api_calls, extract_code};

use crate::context::{CodeGenerationContext, Embodiment, VlmTask};
use crate::prompts::{CodeGenerationPrompt, PromptError, Prompts, action_names, api_docs};
use nesy_vlm::CallSettings;
use nesy_vlm::VlmClient;
use nesy_vlm::VlmError;
use nesy_vlm::reply::{self, AskError, Rejected, ReplyProblem};
use nesy_vlm::{ChatRequest, Message};

/// What code generation needs.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CodeGenerationRequest {
    /// The instruction (of the target scene).
    pub instruction: String,
    /// The target scene's objects, in order.
    pub objects: Vec<String>,
    /// The adapted, verified procedure; its action names become the demonstration summary.
    pub procedure: Vec<Operator>,
    /// A natural-language plan (a baseline's specification); when it is not empty, its steps
    /// are the demonstration summary instead of the procedure's action names.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plan: Vec<String>,
    /// The target robot's end effector.
    pub embodiment: Embodiment,
    /// Use the extended prompt (both end effectors documented). The pipeline sets it when
    /// the demonstration's end effector differs from the target's, as the authors do; a
    /// vacuum target always gets it.
    pub extended: bool,
    /// Offer the tool-use functions (`gather_with_hook`): the target scene holds a magnetic
    /// hook. Off, the prompt is the one a scene without tools gets.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub tools: bool,
    /// The target robot's protective stop is on (`nesy_sim::scene::SceneSpec::protective_stop`):
    /// a template compilation of the procedure (the offline responder's answer) then keeps
    /// the hand's length off tall furniture when it turns the wrist for a fruit. The prompt
    /// does not change.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub protective_stop: bool,
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
    /// Import statements removed from it (see [`extract_code`]).
    pub stripped: Vec<StrippedImport>,
    /// Whether the extended prompt was used.
    pub extended: bool,
    /// Earlier replies of this call that could not be used, each re-asked with its problem.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rejected: Vec<RejectedProgram>,
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
    /// The checks before execution could not run (no check was configured, or the embedded
    /// interpreter that runs them failed to start).
    #[error("checking the generated program: {0}")]
    Check(#[from] CheckUnavailable),
    /// No reply within the budget held a usable program; every reply and why it was not used.
    #[error(
        "code generation gave no usable program in {} attempt(s); the last {}",
        attempts.len(),
        attempts.last().map_or_else(String::new, |a| a.problem.to_string())
    )]
    NoProgram {
        /// The replies, in order, each with its problem.
        attempts: Vec<RejectedProgram>,
    },
}

/// A code-generation reply that was not used, and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RejectedProgram {
    /// The reply (for a truncated one, the text before the cap).
    pub reply: String,
    /// Why it was not used.
    pub problem: ProgramProblem,
}

/// Why a code-generation reply cannot be run.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ProgramProblem {
    /// No program could be taken out of the reply.
    #[error("reply could not be read: {error}")]
    Unreadable {
        /// What was wrong.
        error: ExtractError,
    },
    /// The reply stopped at the token cap.
    #[error("{}", reply::truncation_text(*cutoff))]
    Truncated {
        /// Where the reply was cut.
        cutoff: nesy_vlm::Cutoff,
    },
    /// The reply's `content` was null and no `reasoning_content` held text.
    #[error("{}", reply::NULL_CONTENT_TEXT)]
    NullContent,
    /// The program's code block was never closed: the reply was cut off.
    #[error("program was cut off: its code block opened on line {line} of the reply is never closed")]
    Unterminated {
        /// 1-based line of the opening fence.
        line: usize,
    },
    /// The checks before execution refused the program.
    #[error("program was refused before running: {}", findings.join("; "))]
    Refused {
        /// `line:column: message`, one per finding.
        findings: Vec<String>,
    },
}

impl ReplyProblem for ProgramProblem {
    fn truncated(cutoff: nesy_vlm::Cutoff) -> Self {
        ProgramProblem::Truncated { cutoff }
    }

    fn null_content() -> Self {
        ProgramProblem::NullContent
    }

    fn feedback(&self) -> String {
        let ask = "Reply with the whole corrected program in one ```python code block.";
        match self {
            ProgramProblem::Truncated { .. } => format!(
                "Your {self}. Answer more briefly: the complete program in one ```python code block, without explanation."
            ),
            ProgramProblem::Unterminated { .. } => {
                format!("Your {self}. {ask} Close the block with ``` on its own line.")
            }
            ProgramProblem::Unreadable { .. } | ProgramProblem::NullContent => format!("Your {self}. {ask}"),
            ProgramProblem::Refused { findings } => format!(
                "Your program was refused before running, and the robot has not moved:\n{}\nUse only the robot API functions listed above for this end effector, Python's builtins, and names the program defines. {ask}",
                findings
                    .iter()
                    .map(|f| format!("- line {f}"))
                    .collect::<Vec<_>>()
                    .join("\n")
            ),
        }
    }
}

/// How many replies code generation asks for at most: the first and two re-asks, each with
/// the reason the previous reply could not be used.
pub const CODEGEN_ATTEMPTS: usize = 3;

impl CodegenError {
    /// The reasoner failure this is: the call's own kind, a defect of the request, or a
    /// reply without a program.
    pub fn reasoner_kind(&self) -> nesy_core::adapt::ReasonerErrorKind {
        use nesy_core::adapt::ReasonerErrorKind as Kind;
        match self {
            CodegenError::Vlm(e) => crate::failure_kind(e),
            CodegenError::Prompt(_) => Kind::Request,
            CodegenError::Check(_) => Kind::Request,
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
    let names = if request.plan.is_empty() {
        action_names(&request.procedure)
    } else {
        request.plan.clone()
    };
    let prompt = CodeGenerationPrompt {
        instruction: &request.instruction,
        objects: &request.objects,
        action_names: &names,
        embodiment: request.embodiment,
        extended: request.extended,
        tools: request.tools,
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
        protective_stop: request.protective_stop,
    });
    let chat = ChatRequest::new()
        .purpose(context.purpose())
        .task(context.to_task_context())
        .message(Message::system(rendered.system))
        .message(Message::user_text(rendered.user));
    Ok((settings.apply(chat), extended))
}

/// Asks the model for a program, takes it out of the reply and checks it before anything
/// runs: the code block must be closed, the sandbox's static checks (which refuse names
/// nothing defines and robot API calls whose arguments do not bind) must pass, and no
/// function of the other end effector may be called. A reply that fails goes back to the
/// model with the reason, up to [`CODEGEN_ATTEMPTS`] replies in all, through the shared
/// [`reply`] policy (a reply cut off at the token cap asks for a briefer
/// answer; one with null content says so). `checks` are the sandbox's static checks.
pub(crate) async fn generate_code(
    client: &VlmClient,
    prompts: &Prompts,
    request: &CodeGenerationRequest,
    settings: &CallSettings,
    checks: &dyn ProgramCheck,
) -> Result<PolicySource, CodegenError> {
    let (chat, extended) = build_request(prompts, request, settings)?;
    let answer = reply::ask_until_usable(client, chat, CODEGEN_ATTEMPTS, "code generation", |text| {
        usable_program(text, request.embodiment, checks)
    })
    .await
    .map_err(|error| match error {
        AskError::Vlm(e) => CodegenError::Vlm(e),
        AskError::Reader(e) => CodegenError::Check(e),
        AskError::Exhausted(attempts) => CodegenError::NoProgram {
            attempts: attempts.into_iter().map(RejectedProgram::from).collect(),
        },
    })?;
    let extracted = answer.value;
    for s in &extracted.stripped {
        tracing::info!(line = s.line, statement = %s.text, "removed an import from the generated program: {}", s.reason);
    }
    Ok(PolicySource {
        code: extracted.code,
        reply: answer.reply,
        block: extracted.block,
        stripped: extracted.stripped,
        extended,
        rejected: answer.rejected.into_iter().map(RejectedProgram::from).collect(),
    })
}

impl From<Rejected<ProgramProblem>> for RejectedProgram {
    fn from(rejected: Rejected<ProgramProblem>) -> Self {
        RejectedProgram {
            reply: rejected.reply,
            problem: rejected.problem,
        }
    }
}

/// The program of `reply` if it may run on `embodiment` and passes `checks`; otherwise why
/// not. `Err` of the outer result only when the checks themselves cannot run.
pub fn usable_program(
    reply: &str,
    embodiment: Embodiment,
    checks: &dyn ProgramCheck,
) -> Result<Result<ExtractedCode, ProgramProblem>, CheckUnavailable> {
    let extracted = match extract_code(reply) {
        Ok(extracted) => extracted,
        Err(error) => return Ok(Err(ProgramProblem::Unreadable { error })),
    };
    if !extracted.block.terminated {
        return Ok(Err(ProgramProblem::Unterminated {
            line: extracted.block.line,
        }));
    }
    let mut findings: Vec<(u32, u32, String)> = checks
        .check(&extracted.code)?
        .into_iter()
        .map(|f| (f.line, f.column, f.message))
        .collect();
    findings.extend(other_end_effector_calls(&extracted.code, embodiment));
    findings.sort();
    if findings.is_empty() {
        Ok(Ok(extracted))
    } else {
        Ok(Err(ProgramProblem::Refused {
            findings: findings
                .into_iter()
                .map(|(line, column, message)| format!("{line}:{column}: {message}"))
                .collect(),
        }))
    }
}

/// Calls of functions the target's end effector does not have (the simulator would refuse
/// them after the robot had already moved), as `(line, column, message)`.
fn other_end_effector_calls(code: &str, embodiment: Embodiment) -> Vec<(u32, u32, String)> {
    let (foreign, own): (&[&str], &str) = match embodiment {
        Embodiment::Finger => (&api_docs::VACUUM_FUNCTIONS, "a finger gripper"),
        Embodiment::Vacuum => (&api_docs::FINGER_ONLY_FUNCTIONS, "a vacuum suction tool"),
    };
    let mut found = Vec::new();
    for (index, line) in code.lines().enumerate() {
        for name in foreign {
            if let Some(at) = extract::call_offsets(line, name).next() {
                found.push((
                    index as u32 + 1,
                    line[..at].chars().count() as u32 + 1,
                    format!("{name}() is not available: this robot has {own}"),
                ));
            }
        }
    }
    found
}
