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

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

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

/// The file name under which [`PHYSICAL_CONSTRAINTS`] is exported and overridden.
pub const PHYSICAL_CONSTRAINTS_FILE: &str = "physical_constraints.txt";

/// One prompt file a run used: its name, the SHA-256 of its text, and the file it was read
/// from when it overrides the bundled one.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TemplateRecord {
    /// The file name, e.g. `induction.user.j2`.
    pub name: String,
    /// Hex SHA-256 of the text used.
    pub sha256: String,
    /// Where an override came from (absent for the bundled text).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overridden_by: Option<PathBuf>,
}

impl TemplateRecord {
    fn new(name: &str, text: &str, path: Option<&PathBuf>) -> TemplateRecord {
        use sha2::{Digest, Sha256};
        TemplateRecord {
            name: name.to_string(),
            sha256: Sha256::digest(text.as_bytes())
                .iter()
                .map(|b| format!("{b:02x}"))
                .collect(),
            overridden_by: path.cloned(),
        }
    }
}

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

/// SHA-256 (hex) over named prompt files in order, each name and text preceded by its
/// length: the fingerprint of a set of prompts ([`Prompts::fingerprint`]; the baselines'
/// templates have theirs).
///
/// ```
/// use nesy_reasoner::prompts::files_fingerprint;
/// let one = files_fingerprint([("a.j2", "hello")]);
/// assert_eq!(one.len(), 64);
/// assert_ne!(one, files_fingerprint([("a.j2", "hell"), ("o", "")]));
/// ```
pub fn files_fingerprint<'a>(files: impl IntoIterator<Item = (&'a str, &'a str)>) -> String {
    use sha2::{Digest, Sha256};
    let mut hash = Sha256::new();
    for (name, text) in files {
        for field in [name, text] {
            hash.update((field.len() as u64).to_le_bytes());
            hash.update(field.as_bytes());
        }
    }
    hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// What the induction templates are given.
const INDUCTION_VARIABLES: &[&str] = &[
    "predicates",
    "examples",
    "instruction",
    "objects",
    "previous",
    "current",
    "diff",
    "images",
];
/// What the feedback templates (after a rejected reply) are given.
const FEEDBACK_VARIABLES: &[&str] = &["attempt", "message", "unreadable"];
/// What the refinement templates are given.
const REFINEMENT_VARIABLES: &[&str] = &[
    "kind",
    "predicates",
    "instruction",
    "objects",
    "procedure",
    "executed",
    "erroneous",
    "remaining",
    "initial_state",
    "error_state",
    "unmet",
];
/// What the state-translation templates are given.
const STATE_TRANSLATION_VARIABLES: &[&str] = &[
    "predicates",
    "examples",
    "instruction",
    "objects",
    "known",
    "images",
];
/// What the code-generation templates are given.
const CODE_GENERATION_VARIABLES: &[&str] = &[
    "imports",
    "docstrings",
    "examples",
    "instruction",
    "objects",
    "end_effector",
    "summary",
];

/// A bundled template file: its name (as templates and overrides refer to it), its text,
/// and the variables its render call gives it (besides the global `physical_constraints`).
struct BundledTemplate {
    name: &'static str,
    text: &'static str,
    variables: &'static [&'static str],
}

const TEMPLATES: &[BundledTemplate] = &[
    BundledTemplate {
        name: "induction.system.j2",
        text: include_str!("../../prompts/induction.system.j2"),
        variables: INDUCTION_VARIABLES,
    },
    BundledTemplate {
        name: "induction.user.j2",
        text: include_str!("../../prompts/induction.user.j2"),
        variables: INDUCTION_VARIABLES,
    },
    BundledTemplate {
        name: "induction.feedback.j2",
        text: include_str!("../../prompts/induction.feedback.j2"),
        variables: FEEDBACK_VARIABLES,
    },
    BundledTemplate {
        name: "refinement.system.j2",
        text: include_str!("../../prompts/refinement.system.j2"),
        variables: REFINEMENT_VARIABLES,
    },
    BundledTemplate {
        name: "refinement.user.j2",
        text: include_str!("../../prompts/refinement.user.j2"),
        variables: REFINEMENT_VARIABLES,
    },
    BundledTemplate {
        name: "refinement.feedback.j2",
        text: include_str!("../../prompts/refinement.feedback.j2"),
        variables: FEEDBACK_VARIABLES,
    },
    BundledTemplate {
        name: "state_translation.system.j2",
        text: include_str!("../../prompts/state_translation.system.j2"),
        variables: STATE_TRANSLATION_VARIABLES,
    },
    BundledTemplate {
        name: "state_translation.user.j2",
        text: include_str!("../../prompts/state_translation.user.j2"),
        variables: STATE_TRANSLATION_VARIABLES,
    },
    BundledTemplate {
        name: "code_generation.system.j2",
        text: include_str!("../../prompts/code_generation.system.j2"),
        variables: CODE_GENERATION_VARIABLES,
    },
    BundledTemplate {
        name: "code_generation.user.j2",
        text: include_str!("../../prompts/code_generation.user.j2"),
        variables: CODE_GENERATION_VARIABLES,
    },
    BundledTemplate {
        name: "code_generation_extended.system.j2",
        text: include_str!("../../prompts/code_generation_extended.system.j2"),
        variables: CODE_GENERATION_VARIABLES,
    },
    BundledTemplate {
        name: "code_generation_extended.user.j2",
        text: include_str!("../../prompts/code_generation_extended.user.j2"),
        variables: CODE_GENERATION_VARIABLES,
    },
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
    /// A user's prompt file (`--prompts DIR`) cannot be used.
    #[error("{}: {message}", path.display())]
    Override {
        /// The file (or the folder).
        path: PathBuf,
        /// What is wrong: an unknown name, a syntax error with its line, an unknown variable.
        message: String,
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
    /// Document the tool-use functions (the scene holds a magnetic hook).
    pub tools: bool,
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
    templates: Vec<TemplateRecord>,
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
                &self.templates.iter().map(|t| t.name.as_str()).collect::<Vec<_>>(),
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
    /// Compiles the bundled templates and loads the examples.
    pub fn load() -> Result<Prompts, PromptError> {
        Prompts::assemble(&BTreeMap::new())
    }

    /// The bundled prompts with some files replaced by the ones in `dir`, by file name: any
    /// template ([`Prompts::template_names`]) and `physical_constraints.txt`. A file of
    /// another name, a template that does not compile, or one that uses a variable its
    /// render call does not give is refused, naming the file; files starting with `.` are
    /// skipped. `nesy prompts export` writes the bundled files as a starting point.
    pub fn with_overrides(dir: &Path) -> Result<Prompts, PromptError> {
        let refuse = |path: &Path, message: String| PromptError::Override {
            path: path.to_owned(),
            message,
        };
        let entries =
            std::fs::read_dir(dir).map_err(|e| refuse(dir, format!("reading the prompts folder: {e}")))?;
        let mut overrides = BTreeMap::new();
        for entry in entries {
            let entry = entry.map_err(|e| refuse(dir, format!("reading the prompts folder: {e}")))?;
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.starts_with('.') {
                continue;
            }
            let known = name == PHYSICAL_CONSTRAINTS_FILE || TEMPLATES.iter().any(|t| t.name == name);
            if !known {
                let mut names: Vec<&str> = Prompts::template_names().collect();
                names.push(PHYSICAL_CONSTRAINTS_FILE);
                return Err(refuse(
                    &path,
                    format!(
                        "not a prompt file nesy uses; expected one of {}",
                        names.join(", ")
                    ),
                ));
            }
            let text = nesy_input::read_text(&path, nesy_input::MAX_JSON_BYTES)
                .map_err(|e| refuse(&path, format!("reading the template: {e}")))?;
            overrides.insert(name, (path, text));
        }
        Prompts::assemble(&overrides)
    }

    /// Compiles the bundled templates with `overrides` (file name to path and text) in
    /// their place.
    fn assemble(overrides: &BTreeMap<String, (PathBuf, String)>) -> Result<Prompts, PromptError> {
        let mut env = template_environment().map_err(|error| PromptError::Template {
            name: "(syntax configuration)",
            error,
        })?;
        let mut templates = Vec::with_capacity(TEMPLATES.len() + 1);
        match overrides.get(PHYSICAL_CONSTRAINTS_FILE) {
            Some((path, text)) => {
                env.add_global("physical_constraints", text.trim_end().to_string());
                templates.push(TemplateRecord::new(PHYSICAL_CONSTRAINTS_FILE, text, Some(path)));
            }
            None => templates.push(TemplateRecord::new(
                PHYSICAL_CONSTRAINTS_FILE,
                PHYSICAL_CONSTRAINTS,
                None,
            )),
        }
        for bundled in TEMPLATES {
            match overrides.get(bundled.name) {
                Some((path, text)) => {
                    env.add_template_owned(bundled.name, text.clone())
                        .map_err(|error| PromptError::Override {
                            path: path.clone(),
                            message: format!("{error:#}"),
                        })?;
                    templates.push(TemplateRecord::new(bundled.name, text, Some(path)));
                }
                None => {
                    env.add_template(bundled.name, bundled.text)
                        .map_err(|error| PromptError::Template {
                            name: bundled.name,
                            error,
                        })?;
                    templates.push(TemplateRecord::new(bundled.name, bundled.text, None));
                }
            }
        }
        // An override may only use what its render call gives (an undefined variable would
        // otherwise stop the run at its first call); checked once every template is in, so
        // that `extends` resolves.
        for bundled in TEMPLATES {
            let Some((path, _)) = overrides.get(bundled.name) else {
                continue;
            };
            let template = env
                .get_template(bundled.name)
                .map_err(|error| PromptError::Override {
                    path: path.clone(),
                    message: format!("{error:#}"),
                })?;
            let mut unknown: Vec<String> = template
                .undeclared_variables(false)
                .into_iter()
                .filter(|v| v != "physical_constraints" && !bundled.variables.contains(&v.as_str()))
                .collect();
            unknown.sort();
            if !unknown.is_empty() {
                return Err(PromptError::Override {
                    path: path.clone(),
                    message: format!(
                        "uses {}, which {} is not given; it is given {} and physical_constraints",
                        unknown
                            .iter()
                            .map(|v| format!("`{v}`"))
                            .collect::<Vec<_>>()
                            .join(", "),
                        bundled.name,
                        bundled.variables.join(", ")
                    ),
                });
            }
        }
        Ok(Prompts {
            env,
            templates,
            induction_examples: examples::induction_examples()?,
            state_examples: examples::state_examples()?,
            finger_code: examples::code_examples(Embodiment::Finger)?,
            vacuum_code: examples::code_examples(Embodiment::Vacuum)?,
        })
    }

    /// The process-wide bundled instance, loaded on first use.
    pub fn builtin() -> Result<Arc<Prompts>, PromptError> {
        static PROMPTS: OnceLock<Arc<Prompts>> = OnceLock::new();
        if let Some(prompts) = PROMPTS.get() {
            return Ok(prompts.clone());
        }
        let loaded = Arc::new(Prompts::load()?);
        Ok(PROMPTS.get_or_init(|| loaded).clone())
    }

    /// Every template file in use with its SHA-256, and the file it was read from when it
    /// overrides the bundled one. A run records them.
    pub fn templates(&self) -> &[TemplateRecord] {
        &self.templates
    }

    /// Writes the bundled template files and `physical_constraints.txt` into `dir` (created
    /// if missing), refusing to overwrite a file that exists; returns the paths written.
    pub fn export_bundled(dir: &Path) -> Result<Vec<PathBuf>, PromptError> {
        let failed = |path: &Path, e: std::io::Error| PromptError::Override {
            path: path.to_owned(),
            message: format!("writing the template: {e}"),
        };
        std::fs::create_dir_all(dir).map_err(|e| failed(dir, e))?;
        let files = std::iter::once((PHYSICAL_CONSTRAINTS_FILE, PHYSICAL_CONSTRAINTS))
            .chain(TEMPLATES.iter().map(|t| (t.name, t.text)));
        let mut written = Vec::new();
        for (name, text) in files {
            let path = dir.join(name);
            let mut file = std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
                .map_err(|e| failed(&path, e))?;
            std::io::Write::write_all(&mut file, text.as_bytes()).map_err(|e| failed(&path, e))?;
            written.push(path);
        }
        Ok(written)
    }

    /// The variables the template `name` is given (besides `physical_constraints`).
    pub fn template_variables(name: &str) -> Option<&'static [&'static str]> {
        TEMPLATES.iter().find(|t| t.name == name).map(|t| t.variables)
    }

    /// SHA-256 (hex) over every embedded prompt file: templates, few-shot examples and API
    /// documentation, names and texts ([`files_fingerprint`]). A benchmark run records it, so
    /// results from different prompts are never mixed.
    pub fn fingerprint() -> String {
        let examples = [
            examples::INDUCTION_FILES,
            examples::STATE_FILES,
            examples::FINGER_CODE_FILES,
            examples::VACUUM_CODE_FILES,
            examples::SCENE_FILES,
        ];
        files_fingerprint(
            TEMPLATES
                .iter()
                .map(|template| (template.name, template.text))
                .chain([("physical_constraints.txt", PHYSICAL_CONSTRAINTS)])
                .chain(examples.into_iter().flatten().map(|f| (f.path, f.text)))
                .chain(api_docs::EMBEDDED),
        )
    }

    /// The names of all template files.
    pub fn template_names() -> impl Iterator<Item = &'static str> {
        TEMPLATES.iter().map(|t| t.name)
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
        let offer = api_docs::ApiOffer {
            vacuum: extended,
            tools: prompt.tools,
        };
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
                "imports": api_docs::imports(offer),
                "docstrings": api_docs::docstrings(offer),
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
