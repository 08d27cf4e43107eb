//! State translation (the paper's Eq. 2): three marked views of a scene, the objects and
//! the atoms already known go to the model; the reply's atom list, read with nesy-core's
//! state-list parser and checked against the vocabulary and the objects (a reply naming
//! something the task does not have is re-asked with the nearest names), is added to the
//! known atoms.

use nesy_core::Atom;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::adapt::{UnknownSymbol, known_objects, unknown_atom_symbols};
use nesy_core::text::{ParseError, normalize_reply, parse_state_list};
use nesy_core::{Tier, Vocabulary};
use serde::{Deserialize, Serialize};

use crate::constraints::{self, Symbols};
use crate::context::{StateTranslationContext, VlmTask};
use crate::keyframes::Views;
use crate::prompts::{PromptError, Prompts, StateTranslationPrompt};
use nesy_vlm::CallSettings;
use nesy_vlm::VlmClient;
use nesy_vlm::VlmError;
use nesy_vlm::reply::{self, AskError, Rejected, ReplyProblem};
use nesy_vlm::{ChatRequest, Message, Part, ReplyForm};

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

/// A predicted atom that was not accepted, and why: the predicate exists, but the prompt's
/// tier does not define it (the reply is still usable; the atom is listed and logged).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RejectedAtom {
    /// The atom as predicted.
    pub atom: Atom,
    /// The tier the prompt defined.
    pub tier: Tier,
}

/// The result of a translation.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TranslatedState {
    /// The known atoms plus every accepted predicted atom.
    pub state: State,
    /// The accepted predicted atoms.
    pub predicted: State,
    /// Predicted atoms outside the prompt's tier (never silently dropped: they are listed
    /// here and logged).
    pub rejected: Vec<RejectedAtom>,
    /// The reply.
    pub reply: String,
    /// Earlier replies of this call that could not be used, each re-asked with its problem.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reasked: Vec<RejectedTranslation>,
}

/// A state-translation reply that was not used, and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RejectedTranslation {
    /// The reply (for a truncated one, the text before the cap).
    pub reply: String,
    /// Why it was not used.
    pub problem: TranslationProblem,
}

/// Why a state-translation reply cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum TranslationProblem {
    /// The reply is not a state list.
    #[error("reply could not be read as a state list: {error}")]
    Unreadable {
        /// The parse error, with line and column in the (normalised) reply.
        error: ParseError,
    },
    /// The reply names predicates, arities or objects the task does not have.
    #[error("reply could not be read: {}", symbols.iter().map(|s| s.to_string()).collect::<Vec<_>>().join("; "))]
    UnknownSymbols {
        /// Each unknown name, with the nearest known one.
        symbols: Vec<UnknownSymbol>,
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
}

impl ReplyProblem for TranslationProblem {
    fn truncated(cutoff: nesy_vlm::Cutoff) -> Self {
        TranslationProblem::Truncated { cutoff }
    }

    fn null_content() -> Self {
        TranslationProblem::NullContent
    }

    fn feedback(&self) -> String {
        let format = "Answer with the true atoms only, one per line as `- (Predicate arg ...)`, or `None`, and nothing else.";
        match self {
            TranslationProblem::UnknownSymbols { symbols } => format!(
                "Your reply could not be read: it uses names this task does not have.\n{}\nUse only the predicates defined above, with their arguments, and the listed objects. {format}",
                symbols
                    .iter()
                    .map(|s| format!("- {s}"))
                    .collect::<Vec<_>>()
                    .join("\n")
            ),
            TranslationProblem::Truncated { .. } => {
                format!("Your {self}. Answer more briefly. {format}")
            }
            _ => format!("Your {self}. {format}"),
        }
    }
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
    /// No reply within the budget could be used.
    #[error(
        "state translation for {view_set}: no usable reply in {} attempt(s); the last {}",
        attempts.len(),
        attempts.last().map_or_else(String::new, |a| a.problem.to_string())
    )]
    NoState {
        /// Which views.
        view_set: String,
        /// The replies, in order, each with its problem.
        attempts: Vec<RejectedTranslation>,
    },
}

impl TranslateError {
    /// The reasoner failure this is: the call's own kind, a defect of the request, or a
    /// reply that cannot be read.
    pub fn reasoner_kind(&self) -> nesy_core::adapt::ReasonerErrorKind {
        use nesy_core::adapt::ReasonerErrorKind as Kind;
        match self {
            TranslateError::Vlm(e) => crate::failure_kind(e),
            TranslateError::Prompt(_) => Kind::Request,
            TranslateError::NoState { .. } => Kind::Reply,
        }
    }
}

/// Builds the state-translation chat request without sending it, and without the reply
/// constraint that [`translate_state`] attaches when its client sends one.
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

/// Reads a translation reply: a state list (after [`nesy_core::text::normalize_reply`])
/// whose predicates, arities and objects the task knows. The objects a reply may name are
/// the scene's and those of the known atoms. Atoms of real predicates the prompt's tier
/// does not define are kept apart as [`RejectedAtom`]s.
pub fn read_translation(
    reply: &str,
    request: &StateTranslationRequest,
) -> Result<(State, Vec<RejectedAtom>), TranslationProblem> {
    let parsed = parse_state_list(&normalize_reply(reply))
        .map_err(|error| TranslationProblem::Unreadable { error })?;
    let scene: Vec<Symbol> = request.objects.iter().map(|o| Symbol::new(o)).collect();
    let objects = known_objects(&scene, [&request.known], []);
    let unknown = unknown_atom_symbols(parsed.sorted_by_text(), &request.vocabulary, &objects);
    if !unknown.is_empty() {
        return Err(TranslationProblem::UnknownSymbols { symbols: unknown });
    }
    let in_tier: Vec<Symbol> = request
        .vocabulary
        .tier(request.tier)
        .iter()
        .map(|p| p.name)
        .collect();
    let (accepted, outside): (Vec<Atom>, Vec<Atom>) = parsed
        .sorted_by_text()
        .into_iter()
        .copied()
        .partition(|a| in_tier.contains(&a.pred()));
    let rejected = outside
        .into_iter()
        .map(|atom| RejectedAtom {
            atom,
            tier: request.tier,
        })
        .collect();
    Ok((State::from_atoms(accepted), rejected))
}

/// How many replies one state translation asks for at most: the first and two re-asks, each
/// with the reason the previous reply could not be used.
pub const TRANSLATION_ATTEMPTS: usize = 3;

/// Asks the model for the atoms of one view set and reads the reply with
/// [`read_translation`]. A reply that cannot be used (not a state list, unknown names, cut
/// off, null content) goes back to the model with the reason through the shared
/// [`reply`] policy, up to [`TRANSLATION_ATTEMPTS`] replies; only then is it
/// [`TranslateError::NoState`].
pub async fn translate_state(
    client: &VlmClient,
    prompts: &Prompts,
    request: &StateTranslationRequest,
    settings: &CallSettings,
) -> Result<TranslatedState, TranslateError> {
    let chat = client.constrain(build_request(prompts, request, settings)?, || {
        let objects = request.objects.iter().map(String::as_str);
        let symbols = Symbols::new(&request.vocabulary, request.tier, objects, [&request.known]);
        constraints::translation_constraint(&symbols)
    });
    let what = format!("state translation for {}", request.view_set);
    // A reply held to the JSON schema is written out as the prompt's list first.
    let json = client.reply_form(&chat) == ReplyForm::Json;
    let answer = reply::ask_until_usable(client, chat, TRANSLATION_ATTEMPTS, &what, |text| {
        let written_out = if json {
            constraints::translation_layout(text)
        } else {
            None
        };
        Ok::<_, std::convert::Infallible>(read_translation(written_out.as_deref().unwrap_or(text), request))
    })
    .await
    .map_err(|error| match error {
        AskError::Vlm(e) => TranslateError::Vlm(e),
        AskError::Reader(never) => match never {},
        AskError::Exhausted(attempts) => TranslateError::NoState {
            view_set: request.view_set.clone(),
            attempts: attempts.into_iter().map(RejectedTranslation::from).collect(),
        },
    })?;
    let (predicted, rejected) = answer.value;
    for r in &rejected {
        tracing::warn!(view_set = %request.view_set, atom = %r.atom, tier = ?r.tier, "a predicted atom's predicate is not in the prompt's tier; not used");
    }
    let state = State::from_atoms(request.known.iter().chain(predicted.iter()).copied());
    Ok(TranslatedState {
        state,
        predicted,
        rejected,
        reply: answer.reply,
        reasked: answer
            .rejected
            .into_iter()
            .map(RejectedTranslation::from)
            .collect(),
    })
}

impl From<Rejected<TranslationProblem>> for RejectedTranslation {
    fn from(rejected: Rejected<TranslationProblem>) -> Self {
        RejectedTranslation {
            reply: rejected.reply,
            problem: rejected.problem,
        }
    }
}
