//! [`VlmReasoner`]: nesy-core's [`Reasoner`] over the VLM client. It renders the operator
//! induction and refinement prompts, attaches the keyframe images and the typed task
//! context, and returns the reply text for nesy-core to parse and verify.

use std::sync::Arc;

use nesy_core::adapt::{
    Feedback, InductionRequest, PatchRequest, Reasoner, ReasonerError, ReasonerErrorKind,
};

use crate::codegen::{
    self, CheckUnavailable, CodeGenerationRequest, CodegenError, PolicySource, ProgramCheck,
};
use crate::constraints::{self, Symbols};
use crate::context::{Embodiment, InductionContext, PatchContext, VlmTask};
use crate::keyframes::{KeyframeImages, NoKeyframes};
use crate::prompts::{PromptError, Prompts};
use crate::translate::{self, StateTranslationRequest, TranslateError, TranslatedState};
use nesy_vlm::PurposeSettings;
use nesy_vlm::VlmClient;
use nesy_vlm::VlmError;
use nesy_vlm::reply::{self, AskError, CALL_ATTEMPTS, CallProblem};
use nesy_vlm::{ChatRequest, Message, Part, ReplyForm};

/// The VLM side of the adaptation loop, plus state translation and code generation.
///
/// ```no_run
/// # async fn demo(client: nesy_vlm::VlmClient, keyframes: std::sync::Arc<dyn nesy_reasoner::KeyframeImages>)
/// # -> Result<(), Box<dyn std::error::Error>> {
/// use nesy_core::Embodiment;
/// use nesy_reasoner::VlmReasoner;
/// let mut reasoner = VlmReasoner::new(client)?
///     .with_keyframes(keyframes)
///     .with_embodiments(Embodiment::Finger, Embodiment::Vacuum);
/// // nesy_core::adapt::run(&mut reasoner, &demo, &target, &config).await?;
/// # Ok(()) }
/// ```
#[derive(Clone)]
pub struct VlmReasoner {
    client: VlmClient,
    prompts: Arc<Prompts>,
    keyframes: Arc<dyn KeyframeImages>,
    source: Embodiment,
    target: Embodiment,
    settings: PurposeSettings,
    checks: Option<Arc<dyn ProgramCheck>>,
}

impl std::fmt::Debug for VlmReasoner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VlmReasoner")
            .field("client", &self.client)
            .field("source", &self.source)
            .field("target", &self.target)
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

impl VlmReasoner {
    /// A reasoner over `client` with the built-in prompts, no keyframe images, a finger
    /// gripper on both sides and the default [`PurposeSettings`].
    pub fn new(client: VlmClient) -> Result<Self, PromptError> {
        Ok(VlmReasoner {
            client,
            prompts: Prompts::builtin()?,
            keyframes: Arc::new(NoKeyframes),
            source: Embodiment::Finger,
            target: Embodiment::Finger,
            settings: PurposeSettings::default(),
            checks: None,
        })
    }

    /// Where the demonstration's keyframe images come from.
    pub fn with_keyframes(mut self, keyframes: Arc<dyn KeyframeImages>) -> Self {
        self.keyframes = keyframes;
        self
    }

    /// The static checks every generated program must pass before [`generate_code`]
    /// accepts it (the sandbox's, which the pipeline supplies). Code generation without them
    /// fails with [`CodegenError::Check`] rather than accepting an unchecked program.
    ///
    /// [`generate_code`]: VlmReasoner::generate_code
    pub fn with_program_check(mut self, checks: Arc<dyn ProgramCheck>) -> Self {
        self.checks = Some(checks);
        self
    }

    /// The demonstration's and the target's end effectors (for the task contexts).
    pub fn with_embodiments(mut self, source: Embodiment, target: Embodiment) -> Self {
        self.source = source;
        self.target = target;
        self
    }

    /// Per-purpose token caps, reasoning effort and temperature.
    pub fn with_settings(mut self, settings: PurposeSettings) -> Self {
        self.settings = settings;
        self
    }

    /// The client (for usage accounting and `finish()`).
    pub fn client(&self) -> &VlmClient {
        &self.client
    }

    /// The prompts in use.
    pub fn prompts(&self) -> &Prompts {
        &self.prompts
    }

    /// Prompts other than the bundled ones (`Prompts::with_overrides`).
    pub fn with_prompts(mut self, prompts: Arc<Prompts>) -> Self {
        self.prompts = prompts;
        self
    }

    /// The operator-induction chat request for `request`, as [`Reasoner::induce_operator`]
    /// sends it: system prompt; user prompt with the previous and current keyframes' three
    /// views each (when available); then, for every rejected attempt, the rejected reply as
    /// an assistant message and the verifier's message as a user message.
    pub fn induction_request(&self, request: &InductionRequest) -> Result<ChatRequest, PromptError> {
        let before = self.keyframes.views(request.step);
        let after = self.keyframes.views(request.step + 1);
        let images = before.as_ref().zip(after.as_ref());
        let rendered = self.prompts.induction(request, images.is_some())?;
        let mut parts = vec![Part::text(rendered.user)];
        if let Some((before, after)) = images {
            parts.extend(before.parts("Before the action"));
            parts.extend(after.parts("After the action"));
        }
        let context = VlmTask::Induction(InductionContext {
            request: request.clone(),
            embodiment: self.source,
        });
        let chat = ChatRequest::new()
            .purpose(context.purpose())
            .task(context.to_task_context())
            .message(Message::system(rendered.system))
            .message(Message::user(parts));
        let mut chat = self.client.constrain(chat, || {
            constraints::induction_constraint(&Symbols::of_task(
                &request.task,
                [&request.previous, &request.next],
            ))
        });
        chat = self.follow_ups(chat, &request.feedback, |f| self.prompts.induction_feedback(f))?;
        Ok(self.settings.induce.apply(chat))
    }

    /// The refinement chat request for `request`, as [`Reasoner::propose_patch`] sends it:
    /// text only (as the authors do), with the rejected proposals and their feedback as
    /// follow-up turns.
    pub fn patch_request(&self, request: &PatchRequest) -> Result<ChatRequest, PromptError> {
        let rendered = self.prompts.refinement(request)?;
        let context = VlmTask::Patch(PatchContext {
            request: request.clone(),
            target_embodiment: self.target,
        });
        let chat = ChatRequest::new()
            .purpose(context.purpose())
            .task(context.to_task_context())
            .message(Message::system(rendered.system))
            .message(Message::user_text(rendered.user));
        let mut chat = self.client.constrain(chat, || {
            let symbols = Symbols::of_task(&request.task, [&request.initial_state, &request.error_state]);
            constraints::patch_constraint(&symbols, &request.procedure)
        });
        chat = self.follow_ups(chat, &request.feedback, |f| self.prompts.refinement_feedback(f))?;
        Ok(self.settings.patch.apply(chat))
    }

    fn follow_ups(
        &self,
        mut chat: ChatRequest,
        feedback: &[Feedback],
        render: impl Fn(&Feedback) -> Result<String, PromptError>,
    ) -> Result<ChatRequest, PromptError> {
        for f in feedback {
            chat = chat
                .message(Message::assistant(reply::quote_for_reask(&f.reply)))
                .message(Message::user_text(render(f)?));
        }
        Ok(chat)
    }

    /// State translation with this reasoner's client, prompts and `translate` settings.
    pub async fn translate_state(
        &self,
        request: &StateTranslationRequest,
    ) -> Result<TranslatedState, TranslateError> {
        translate::translate_state(&self.client, &self.prompts, request, &self.settings.translate).await
    }

    /// Code generation with this reasoner's client, prompts and `codegen` settings.
    pub async fn generate_code(&self, request: &CodeGenerationRequest) -> Result<PolicySource, CodegenError> {
        let checks = self.checks.as_deref().ok_or_else(|| {
            CheckUnavailable("no static checks were configured for generated programs".to_owned())
        })?;
        codegen::generate_code(
            &self.client,
            &self.prompts,
            request,
            &self.settings.codegen,
            checks,
        )
        .await
    }

    /// Sends an induction or patch request through the shared [`reply`](nesy_vlm::reply)
    /// policy: a reply cut short or with null content is re-asked here (up to
    /// [`CALL_ATTEMPTS`] replies), and the text that arrives (whole, or the last cut-short
    /// one) goes to nesy-core, which parses it and re-asks within its own budget. A reply
    /// held to the call's JSON schema is first written out in the prompt's layout by
    /// `layout` (a JSON reply that is not the schema's object goes on as it is).
    async fn send(
        &self,
        what: &str,
        chat: Result<ChatRequest, PromptError>,
        layout: impl Fn(&str) -> Option<String>,
    ) -> Result<String, ReasonerError> {
        let chat =
            chat.map_err(|e| ReasonerError::new(ReasonerErrorKind::Request, format!("{what}: {e}")))?;
        let json = self.client.reply_form(&chat) == ReplyForm::Json;
        let answer = reply::ask_until_usable(&self.client, chat, CALL_ATTEMPTS, what, |text| {
            let written_out = if json { layout(text) } else { None };
            Ok::<_, std::convert::Infallible>(Ok::<_, CallProblem>(
                written_out.unwrap_or_else(|| text.to_string()),
            ))
        })
        .await;
        match answer {
            Ok(answer) => Ok(answer.value),
            Err(AskError::Vlm(error)) => Err(reasoner_error(what, &error)),
            Err(AskError::Reader(never)) => match never {},
            // Every reply was cut short or empty. What the model did say goes to nesy-core
            // like any other reply: it re-asks one it cannot read within the loop's own
            // budget, so a few runaway replies cost attempts, not the whole run.
            Err(AskError::Exhausted(attempts)) => {
                tracing::warn!(
                    call = what,
                    "no whole reply in {} attempt(s) ({}); passing the last one on as it is",
                    attempts.len(),
                    attempts
                        .iter()
                        .map(|a| a.problem.to_string())
                        .collect::<Vec<_>>()
                        .join("; then ")
                );
                Ok(attempts.into_iter().last().map(|a| a.reply).unwrap_or_default())
            }
        }
    }
}

fn reasoner_error(what: &str, error: &VlmError) -> ReasonerError {
    // VlmError's message already carries its cause (transport, cassette, provider body).
    ReasonerError::new(crate::failure_kind(error), format!("{what}: {error}"))
}

impl Reasoner for VlmReasoner {
    async fn induce_operator(&mut self, request: &InductionRequest) -> Result<String, ReasonerError> {
        let what = format!(
            "operator induction for transition {} (attempt {})",
            request.step + 1,
            request.attempt + 1
        );
        let chat = self.induction_request(request);
        self.send(&what, chat, constraints::induction_layout).await
    }

    async fn propose_patch(&mut self, request: &PatchRequest) -> Result<String, ReasonerError> {
        let what = format!("patch proposal {}", request.iteration + 1);
        let chat = self.patch_request(request);
        self.send(&what, chat, |reply| {
            constraints::patch_layout(reply, &request.procedure)
        })
        .await
    }
}
