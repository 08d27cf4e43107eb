//! The prompt templates (minijinja files under `crates/nesy-reasoner/prompts/`, embedded with
//! `include_str!`) and their rendering.
//!
//! | task | templates | purpose label |
//! |---|---|---|
//! | operator induction | `induction.{system,user,feedback}.j2` | `induce` |
//! | refinement proposal | `refinement.{system,user,feedback}.j2` | `patch` |
//! | state translation | `state_translation.{system,user}.j2` | `translate` |
//! | code generation, finger gripper | `code_generation.{system,user}.j2` | `codegen` |
//! | code generation, extended (finger + vacuum) | `code_generation_extended.{system,user}.j2` (extend the above) | `codegen` |
//!
//! The wording is nesy's own; the structure and output formats follow the paper's appendix
//! prompts closely enough that nesy-core's parsers read the replies.

pub mod api_docs;
pub mod examples;

use std::sync::OnceLock;

use minijinja::{AutoEscape, Environment, UndefinedBehavior};
use nesy_core::State;
use nesy_core::adapt::{Feedback, InductionRequest, PatchRequest, ViolationKind};
use nesy_core::{Operator, format_procedure};
use nesy_core::{Tier, Vocabulary};
use serde::Serialize;

use crate::context::Embodiment;
use examples::{CodeExample, InductionExample, StateExample};

/// A template file: its name (as templates refer to each other) and its text.
/// The physical constraints every planning prompt states (one `- ` line each), shared by
/// NeSyCR's induction prompt and the baselines' prompts so that every method is told the
/// same. Templates see it as `{{ physical_constraints }}`.
pub const PHYSICAL_CONSTRAINTS: &str = include_str!("../../prompts/physical_constraints.txt");

/// The template environment every prompt of the project is rendered in: block tags trim
/// their newline, the trailing newline is dropped, an undefined variable is an error, nothing
/// is escaped, and `physical_constraints` is defined. Templates are added by the caller.
pub fn template_environment() -> Result<Environment<'static>, minijinja::Error> {
    let mut env = Environment::new();
    let syntax = minijinja::syntax::SyntaxConfig::builder()
        .trim_blocks(true)
        .lstrip_blocks(true)
        .keep_trailing_newline(false)
        .build()?;
    env.set_syntax(syntax);
    env.set_undefined_behavior(UndefinedBehavior::Strict);
    env.set_auto_escape_callback(|_| AutoEscape::None);
    env.add_global("physical_constraints", PHYSICAL_CONSTRAINTS.trim_end());
    Ok(env)
}

const TEMPLATES: &[(&str, &str)] = &[
    (
        "induction.system.j2",
        include_str!("../../prompts/induction.system.j2"),
    ),
    (
        "induction.user.j2",
        include_str!("../../prompts/induction.user.j2"),
    ),
    (
        "induction.feedback.j2",
        include_str!("../../prompts/induction.feedback.j2"),
    ),
    (
        "refinement.system.j2",
        include_str!("../../prompts/refinement.system.j2"),
    ),
    (
        "refinement.user.j2",
        include_str!("../../prompts/refinement.user.j2"),
    ),
    (
        "refinement.feedback.j2",
        include_str!("../../prompts/refinement.feedback.j2"),
    ),
    (
        "state_translation.system.j2",
        include_str!("../../prompts/state_translation.system.j2"),
    ),
    (
        "state_translation.user.j2",
        include_str!("../../prompts/state_translation.user.j2"),
    ),
    (
        "code_generation.system.j2",
        include_str!("../../prompts/code_generation.system.j2"),
    ),
    (
        "code_generation.user.j2",
        include_str!("../../prompts/code_generation.user.j2"),
    ),
    (
        "code_generation_extended.system.j2",
        include_str!("../../prompts/code_generation_extended.system.j2"),
    ),
    (
        "code_generation_extended.user.j2",
        include_str!("../../prompts/code_generation_extended.user.j2"),
    ),
];

/// Why a prompt could not be built. These are defects of nesy's own template or example
/// files (the tests render every template), never of user input.
#[derive(Debug, thiserror::Error)]
pub enum PromptError {
    /// A template failed to compile or render.
    #[error("prompt template {name}: {error:#}")]
    Template {
        /// The template file.
        name: &'static str,
        /// minijinja's error (with the line).
        error: minijinja::Error,
    },
    /// An example file is malformed.
    #[error("prompt example {file}: {message}")]
    Example {
        /// The example file under `prompts/`.
        file: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// A rendered prompt: the system message and the user message's text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RenderedPrompt {
    /// The system message.
    pub system: String,
    /// The user message's text (images, where a task has them, follow it as separate parts).
    pub user: String,
}

/// What the state-translation prompt shows (besides the images).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StateTranslationPrompt<'a> {
    /// The instruction.
    pub instruction: &'a str,
    /// The objects, in order.
    pub objects: &'a [String],
    /// Which predicates to define.
    pub tier: Tier,
    /// The vocabulary (built-ins plus extras).
    pub vocabulary: &'a Vocabulary,
    /// Atoms given as already known (may be empty).
    pub known: &'a State,
    /// Whether images follow the text (always, for requests built by
    /// [`crate::translate::build_request`]).
    pub images: bool,
}

/// What the code-generation prompt shows.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CodeGenerationPrompt<'a> {
    /// The instruction.
    pub instruction: &'a str,
    /// The objects, in order.
    pub objects: &'a [String],
    /// The demonstration summary's action names, in order (numbered by the template).
    pub action_names: &'a [String],
    /// The target robot's end effector.
    pub embodiment: Embodiment,
    /// Use the extended prompt (both end effectors' functions and examples).
    pub extended: bool,
}

impl CodeGenerationPrompt<'_> {
    /// Whether the extended template is used: when asked for, and always for a vacuum
    /// robot (the finger-only prompt documents no vacuum function).
    pub fn uses_extended(&self) -> bool {
        self.extended || self.embodiment == Embodiment::Vacuum
    }
}

/// The loaded templates and examples. Build once ([`Prompts::builtin`]) and share.
pub struct Prompts {
    env: Environment<'static>,
    induction_examples: Vec<InductionExample>,
    state_examples: Vec<StateExample>,
    finger_code: Vec<CodeExample>,
    vacuum_code: Vec<CodeExample>,
}

impl std::fmt::Debug for Prompts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Prompts")
            .field(
                "templates",
                &TEMPLATES.iter().map(|(n, _)| *n).collect::<Vec<_>>(),
            )
            .field("induction_examples", &self.induction_examples.len())
            .field("state_examples", &self.state_examples.len())
            .field("finger_code_examples", &self.finger_code.len())
            .field("vacuum_code_examples", &self.vacuum_code.len())
            .finish()
    }
}

fn lines_or_none<I: IntoIterator<Item = String>>(items: I) -> String {
    let lines: Vec<String> = items.into_iter().map(|l| format!("- {l}")).collect();
    if lines.is_empty() {
        "None".to_string()
    } else {
        lines.join("\n")
    }
}

fn numbered(names: &[String]) -> String {
    if names.is_empty() {
        return "None".to_string();
    }
    names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{}. {n}", i + 1))
        .collect::<Vec<_>>()
        .join("\n")
}

#[derive(Serialize)]
struct InductionExampleVars {
    title: String,
    instruction: String,
    objects: String,
    previous: String,
    current: String,
    diff: String,
    rationale: String,
    semantic: String,
    preconditions: String,
    effects: String,
}

#[derive(Serialize)]
struct StateExampleVars {
    title: String,
    instruction: String,
    objects: String,
    known: String,
    answer: String,
}

#[derive(Serialize)]
struct CodeExampleVars<'a> {
    title: &'a str,
    instruction: &'a str,
    objects: String,
    summary: String,
    code: &'a str,
}

impl Prompts {
    /// Compiles the templates and loads the examples.
    pub fn load() -> Result<Prompts, PromptError> {
        let mut env = template_environment().map_err(|error| PromptError::Template {
            name: "(syntax configuration)",
            error,
        })?;
        for (name, text) in TEMPLATES {
            env.add_template(name, text)
                .map_err(|error| PromptError::Template { name, error })?;
        }
        Ok(Prompts {
            env,
            induction_examples: examples::induction_examples()?,
            state_examples: examples::state_examples()?,
            finger_code: examples::code_examples(Embodiment::Finger)?,
            vacuum_code: examples::code_examples(Embodiment::Vacuum)?,
        })
    }

    /// The process-wide instance, loaded on first use.
    pub fn builtin() -> Result<&'static Prompts, PromptError> {
        static PROMPTS: OnceLock<Prompts> = OnceLock::new();
        if let Some(prompts) = PROMPTS.get() {
            return Ok(prompts);
        }
        let loaded = Prompts::load()?;
        Ok(PROMPTS.get_or_init(|| loaded))
    }

    /// SHA-256 (hex) over every embedded prompt file: templates, few-shot examples and API
    /// documentation, names and texts. A benchmark run records it, so results from different
    /// prompts are never mixed.
    pub fn fingerprint() -> String {
        use sha2::{Digest, Sha256};
        let mut h = Sha256::new();
        let mut add = |name: &str, text: &str| {
            h.update((name.len() as u64).to_le_bytes());
            h.update(name.as_bytes());
            h.update((text.len() as u64).to_le_bytes());
            h.update(text.as_bytes());
        };
        for (name, text) in TEMPLATES {
            add(name, text);
        }
        add("physical_constraints.txt", PHYSICAL_CONSTRAINTS);
        for files in [
            examples::INDUCTION_FILES,
            examples::STATE_FILES,
            examples::FINGER_CODE_FILES,
            examples::VACUUM_CODE_FILES,
            examples::SCENE_FILES,
        ] {
            for f in files {
                add(f.path, f.text);
            }
        }
        for (name, text) in api_docs::EMBEDDED {
            add(name, text);
        }
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// The names of all template files.
    pub fn template_names() -> impl Iterator<Item = &'static str> {
        TEMPLATES.iter().map(|(n, _)| *n)
    }

    /// The induction examples.
    pub fn induction_examples(&self) -> &[InductionExample] {
        &self.induction_examples
    }

    /// The state-translation examples.
    pub fn state_examples(&self) -> &[StateExample] {
        &self.state_examples
    }

    /// The code examples of one end effector.
    pub fn code_examples(&self, embodiment: Embodiment) -> &[CodeExample] {
        match embodiment {
            Embodiment::Finger => &self.finger_code,
            Embodiment::Vacuum => &self.vacuum_code,
        }
    }

    fn render<S: Serialize>(&self, name: &'static str, vars: S) -> Result<String, PromptError> {
        self.env
            .get_template(name)
            .and_then(|t| t.render(minijinja::value::Serde(vars)))
            .map_err(|error| PromptError::Template { name, error })
    }

    fn pair<S: Serialize>(
        &self,
        system: &'static str,
        user: &'static str,
        vars: S,
    ) -> Result<RenderedPrompt, PromptError> {
        Ok(RenderedPrompt {
            system: self.render(system, &vars)?,
            user: self.render(user, &vars)?,
        })
    }

    /// The examples an induction prompt of this tier shows, projected onto the tier's
    /// predicates (vacuum examples only in the extended tier).
    fn induction_example_vars(&self, vocabulary: &Vocabulary, tier: Tier) -> Vec<InductionExampleVars> {
        self.induction_examples
            .iter()
            .filter(|e| !e.extended_only || tier == Tier::Extended)
            .map(|e| {
                let previous = examples::project_state(&e.previous, vocabulary, tier);
                let current = examples::project_state(&e.current, vocabulary, tier);
                let op = examples::project_operator(&e.operator, vocabulary, tier);
                InductionExampleVars {
                    title: e.title.clone(),
                    instruction: e.instruction.clone(),
                    objects: e.objects.join(", "),
                    diff: previous.diff(&current).to_string(),
                    previous: previous.to_string(),
                    current: current.to_string(),
                    rationale: e.rationale.clone(),
                    semantic: e.semantic.clone(),
                    preconditions: lines_or_none(op.pre.iter().map(|f| f.to_string())),
                    effects: lines_or_none(op.eff.iter().map(|f| f.to_string())),
                }
            })
            .collect()
    }

    /// The operator-induction prompt for one transition (`images`: whether the six keyframe
    /// views follow the text).
    pub fn induction(&self, request: &InductionRequest, images: bool) -> Result<RenderedPrompt, PromptError> {
        let task = &request.task;
        self.pair(
            "induction.system.j2",
            "induction.user.j2",
            serde_json::json!({
                "predicates": task.predicate_definitions(),
                "examples": self.induction_example_vars(&task.vocabulary, task.tier),
                "instruction": task.instruction.trim(),
                "objects": task.object_list(),
                "previous": request.previous.to_string(),
                "current": request.next.to_string(),
                "diff": request.diff.to_string(),
                "images": images,
            }),
        )
    }

    /// The follow-up message after a rejected induction reply.
    pub fn induction_feedback(&self, feedback: &Feedback) -> Result<String, PromptError> {
        self.render(
            "induction.feedback.j2",
            serde_json::json!({
                "attempt": feedback.attempt + 1,
                "message": feedback.message.trim(),
                "unreadable": feedback.problem.is_unreadable(),
            }),
        )
    }

    /// The refinement-proposal prompt (text only, as the authors do).
    pub fn refinement(&self, request: &PatchRequest) -> Result<RenderedPrompt, PromptError> {
        let task = &request.task;
        let kind = match request.kind {
            ViolationKind::Precondition => "precondition",
            ViolationKind::Goal => "goal",
            ViolationKind::Unidentified => "unidentified",
        };
        self.pair(
            "refinement.system.j2",
            "refinement.user.j2",
            serde_json::json!({
                "kind": kind,
                "predicates": task.predicate_definitions(),
                "instruction": task.instruction.trim(),
                "objects": task.object_list(),
                "procedure": format_procedure(&request.procedure),
                "executed": request.executed_text(),
                "erroneous": request.erroneous_text(),
                "remaining": request.remaining_text(),
                "initial_state": request.initial_state.to_string(),
                "error_state": request.error_state.to_string(),
                "unmet": request.unfulfilled_preconditions(),
            }),
        )
    }

    /// The follow-up message after a rejected patch.
    pub fn refinement_feedback(&self, feedback: &Feedback) -> Result<String, PromptError> {
        self.render(
            "refinement.feedback.j2",
            serde_json::json!({
                "attempt": feedback.attempt + 1,
                "message": feedback.message.trim(),
                "unreadable": feedback.problem.is_unreadable(),
            }),
        )
    }

    /// The state-translation prompt.
    pub fn state_translation(
        &self,
        prompt: &StateTranslationPrompt<'_>,
    ) -> Result<RenderedPrompt, PromptError> {
        let examples: Vec<StateExampleVars> = self
            .state_examples
            .iter()
            .map(|e| StateExampleVars {
                title: e.title.clone(),
                instruction: e.instruction.clone(),
                objects: e.objects.join(", "),
                known: examples::project_state(&e.known, prompt.vocabulary, prompt.tier).to_string(),
                answer: examples::project_state(&e.answer, prompt.vocabulary, prompt.tier).to_string(),
            })
            .collect();
        self.pair(
            "state_translation.system.j2",
            "state_translation.user.j2",
            serde_json::json!({
                "predicates": prompt.vocabulary.render_definitions(prompt.tier),
                "examples": examples,
                "instruction": prompt.instruction.trim(),
                "objects": prompt.objects.join(", "),
                "known": prompt.known.to_string(),
                "images": prompt.images,
            }),
        )
    }

    /// The code-generation prompt: the finger-gripper template, or the extended one (see
    /// [`CodeGenerationPrompt::uses_extended`]).
    pub fn code_generation(&self, prompt: &CodeGenerationPrompt<'_>) -> Result<RenderedPrompt, PromptError> {
        let extended = prompt.uses_extended();
        let mut shown: Vec<&CodeExample> = self.finger_code.iter().collect();
        if extended {
            shown.extend(self.vacuum_code.iter());
        }
        let examples: Vec<CodeExampleVars<'_>> = shown
            .into_iter()
            .map(|e| CodeExampleVars {
                title: &e.title,
                instruction: &e.instruction,
                objects: e.objects.join(", "),
                summary: numbered(&e.summary),
                code: &e.code,
            })
            .collect();
        let (system, user) = if extended {
            (
                "code_generation_extended.system.j2",
                "code_generation_extended.user.j2",
            )
        } else {
            ("code_generation.system.j2", "code_generation.user.j2")
        };
        self.pair(
            system,
            user,
            serde_json::json!({
                "imports": api_docs::imports(extended),
                "docstrings": api_docs::docstrings(extended),
                "examples": examples,
                "instruction": prompt.instruction.trim(),
                "objects": prompt.objects.join(", "),
                "end_effector": prompt.embodiment.description(),
                "summary": numbered(prompt.action_names),
            }),
        )
    }
}

/// The demonstration summary's action names of a procedure (display names, in order).
pub fn action_names(procedure: &[Operator]) -> Vec<String> {
    procedure.iter().map(|o| o.display_name()).collect()
}
