//! State translation (the paper's Eq. 2): three marked views of a scene, the objects and
//! the atoms already known go to the model; the reply's atom list, read with nesy-core's
//! state-list parser and checked against the vocabulary and the objects, is added to the
//! known atoms.

use nesy_core::atom::Atom;
use nesy_core::predicates::{Tier, Vocabulary};
use nesy_core::state::State;
use nesy_core::text::{ParseError, normalize_reply, parse_state_list};
use serde::{Deserialize, Serialize};

use crate::client::VlmClient;
use crate::context::{StateTranslationContext, VlmTask};
use crate::error::VlmError;
use crate::keyframes::Views;
use crate::prompts::{PromptError, Prompts, StateTranslationPrompt};
use crate::request::{ChatRequest, Message, Part};
use crate::settings::CallSettings;

/// What state translation needs.
#[derive(Debug, Clone)]
pub struct StateTranslationRequest {
    /// Which views these are, for the task context and logs (e.g. `demo/keyframe/3`).
    pub view_set: String,
    /// The instruction.
    pub instruction: String,
    /// The scene's objects, in order.
    pub objects: Vec<String>,
    /// Which predicates the prompt defines (the paper uses `partial`; the world model needs
    /// `full` or `extended`).
    pub tier: Tier,
    /// The vocabulary.
    pub vocabulary: Vocabulary,
    /// Atoms known without looking (for example the gripper's state); they are part of the
    /// result.
    pub known: State,
    /// The three marked views of the scene.
    pub views: Views,
    /// The true state when the caller has it (simulated scenes): only for offline
    /// responders, never shown to the model.
    pub ground_truth: Option<State>,
}

/// Why a predicted atom was not accepted.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum Rejection {
    /// The predicate is not in the vocabulary.
    UnknownPredicate,
    /// The predicate takes another number of arguments.
    WrongArity {
        /// Its arity.
        expected: usize,
    },
    /// The predicate exists but the prompt's tier does not define it.
    NotInTier,
    /// An argument is not an object of the scene.
    UnknownObject {
        /// The argument.
        object: String,
    },
}

/// A predicted atom that was not accepted, and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RejectedAtom {
    /// The atom as predicted.
    pub atom: Atom,
    /// Why it was rejected.
    pub rejection: Rejection,
}

/// The result of a translation.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TranslatedState {
    /// The known atoms plus every accepted predicted atom.
    pub state: State,
    /// The accepted predicted atoms.
    pub predicted: State,
    /// Predicted atoms that were not accepted (never silently dropped: they are listed here
    /// and logged).
    pub rejected: Vec<RejectedAtom>,
    /// The reply.
    pub reply: String,
}

/// Why translation failed.
#[derive(Debug, thiserror::Error)]
pub enum TranslateError {
    /// The call failed.
    #[error("state translation call failed: {0}")]
    Vlm(#[from] VlmError),
    /// A prompt template failed (a defect of nesy's own files).
    #[error(transparent)]
    Prompt(#[from] PromptError),
    /// No reply within the budget could be read as a state list.
    #[error(
        "state translation for {view_set}: no reply in {attempts} could be read as a state list; the last: {error}"
    )]
    Parse {
        /// Which views.
        view_set: String,
        /// The last parse error, with line and column in the (normalised) reply.
        error: ParseError,
        /// The last reply.
        reply: String,
        /// Replies asked for.
        attempts: usize,
    },
}

impl TranslateError {
    /// The reasoner failure this is: the call's own kind, a defect of the request, or a
    /// reply that cannot be read.
    pub fn reasoner_kind(&self) -> nesy_core::adapt::ReasonerErrorKind {
        use nesy_core::adapt::ReasonerErrorKind as Kind;
        match self {
            TranslateError::Vlm(e) => e.reasoner_kind(),
            TranslateError::Prompt(_) => Kind::Request,
            TranslateError::Parse { .. } => Kind::Reply,
        }
    }
}

/// Builds the state-translation chat request without sending it.
pub fn build_request(
    prompts: &Prompts,
    request: &StateTranslationRequest,
    settings: &CallSettings,
) -> Result<ChatRequest, PromptError> {
    let rendered = prompts.state_translation(&StateTranslationPrompt {
        instruction: &request.instruction,
        objects: &request.objects,
        tier: request.tier,
        vocabulary: &request.vocabulary,
        known: &request.known,
        images: true,
    })?;
    let context = VlmTask::StateTranslation(StateTranslationContext {
        view_set: request.view_set.clone(),
        instruction: request.instruction.clone(),
        objects: request.objects.clone(),
        tier: request.tier,
        known: request.known.clone(),
        ground_truth: request.ground_truth.clone(),
    });
    let mut parts = vec![Part::text(rendered.user)];
    parts.extend(request.views.parts("The scene"));
    let chat = ChatRequest::new()
        .purpose(context.purpose())
        .task(context.to_task_context())
        .message(Message::system(rendered.system))
        .message(Message::user(parts));
    Ok(settings.apply(chat))
}

/// Checks predicted atoms against the vocabulary, the tier and the objects.
pub fn check_atoms(
    predicted: &State,
    vocabulary: &Vocabulary,
    tier: Tier,
    objects: &[String],
) -> (State, Vec<RejectedAtom>) {
    let in_tier: Vec<_> = vocabulary.tier(tier).iter().map(|p| p.name).collect();
    let mut accepted = Vec::new();
    let mut rejected = Vec::new();
    for atom in predicted.sorted_by_text() {
        let rejection = match vocabulary.get(atom.pred()) {
            None => Some(Rejection::UnknownPredicate),
            Some(p) if p.arity != atom.args().len() => Some(Rejection::WrongArity { expected: p.arity }),
            Some(_) if !in_tier.contains(&atom.pred()) => Some(Rejection::NotInTier),
            Some(_) => atom
                .args()
                .iter()
                .find(|a| !objects.iter().any(|o| o == a.as_str()))
                .map(|a| Rejection::UnknownObject {
                    object: a.to_string(),
                }),
        };
        match rejection {
            None => accepted.push(*atom),
            Some(rejection) => rejected.push(RejectedAtom {
                atom: *atom,
                rejection,
            }),
        }
    }
    (State::from_atoms(accepted), rejected)
}

/// How many replies one state translation asks for at most: the first and two re-asks, each
/// with the reason the previous reply could not be read.
pub const TRANSLATION_ATTEMPTS: usize = 3;

/// Asks the model for the atoms of one view set, reads the reply (after
/// [`nesy_core::text::normalize_reply`]) as a state list, and keeps the atoms the vocabulary,
/// the tier and the objects allow. A reply that is not a state list goes back to the model
/// with the parse error, up to [`TRANSLATION_ATTEMPTS`] replies; only then is it
/// [`TranslateError::Parse`].
pub async fn translate_state(
    client: &VlmClient,
    prompts: &Prompts,
    request: &StateTranslationRequest,
    settings: &CallSettings,
) -> Result<TranslatedState, TranslateError> {
    let mut chat = build_request(prompts, request, settings)?;
    let mut attempt = 0;
    let (reply, parsed) = loop {
        attempt += 1;
        let reply = client.chat(chat.clone()).await?.text;
        match parse_state_list(&normalize_reply(&reply)) {
            Ok(parsed) => break (reply, parsed),
            Err(error) if attempt < TRANSLATION_ATTEMPTS => {
                tracing::info!(view_set = %request.view_set, attempt, "state translation reply could not be read: {error}");
                let feedback = format!(
                    "Your reply could not be read as a state list: {error}. Answer with the true atoms only, one per line as `- (Predicate arg ...)`, or `None`, and nothing else."
                );
                chat = chat
                    .message(Message::assistant(reply))
                    .message(Message::user_text(feedback));
            }
            Err(error) => {
                return Err(TranslateError::Parse {
                    view_set: request.view_set.clone(),
                    error,
                    reply,
                    attempts: attempt,
                });
            }
        }
    };
    let (predicted, rejected) = check_atoms(&parsed, &request.vocabulary, request.tier, &request.objects);
    for r in &rejected {
        tracing::warn!(view_set = %request.view_set, atom = %r.atom, rejection = ?r.rejection, "rejected a predicted atom");
    }
    let state = State::from_atoms(request.known.iter().chain(predicted.iter()).copied());
    Ok(TranslatedState {
        state,
        predicted,
        rejected,
        reply,
    })
}
