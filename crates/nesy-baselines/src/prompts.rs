//! The baselines' prompt templates (`prompts/*.j2`, embedded), rendered with minijinja.
//! Every template sees `physical_constraints`, the same list NeSyCR's prompts state.

use std::sync::OnceLock;

use minijinja::Environment;
use serde::Serialize;

use crate::BaselineInputs;

/// `(name, text)` of every template.
const TEMPLATES: &[(&str, &str)] = &[
    (
        "demo2code.observe.system",
        include_str!("../prompts/demo2code.observe.system.j2"),
    ),
    (
        "demo2code.observe.user",
        include_str!("../prompts/demo2code.observe.user.j2"),
    ),
    (
        "demo2code.actions.system",
        include_str!("../prompts/demo2code.actions.system.j2"),
    ),
    (
        "demo2code.actions.user",
        include_str!("../prompts/demo2code.actions.user.j2"),
    ),
    (
        "gpt4v.describe.system",
        include_str!("../prompts/gpt4v.describe.system.j2"),
    ),
    (
        "gpt4v.describe.user",
        include_str!("../prompts/gpt4v.describe.user.j2"),
    ),
    (
        "gpt4v.plan.system",
        include_str!("../prompts/gpt4v.plan.system.j2"),
    ),
    ("gpt4v.plan.user", include_str!("../prompts/gpt4v.plan.user.j2")),
    (
        "demo2code.source_actions.system",
        include_str!("../prompts/demo2code.source_actions.system.j2"),
    ),
    (
        "demo2code.source_actions.user",
        include_str!("../prompts/demo2code.source_actions.user.j2"),
    ),
    (
        "critic.feedback.system",
        include_str!("../prompts/critic.feedback.system.j2"),
    ),
    (
        "critic.feedback.user",
        include_str!("../prompts/critic.feedback.user.j2"),
    ),
    (
        "critic.correction.system",
        include_str!("../prompts/critic.correction.system.j2"),
    ),
    (
        "critic.correction.user",
        include_str!("../prompts/critic.correction.user.j2"),
    ),
    (
        "statler.state.system",
        include_str!("../prompts/statler.state.system.j2"),
    ),
    (
        "statler.state.user",
        include_str!("../prompts/statler.state.user.j2"),
    ),
    (
        "statler.actions.system",
        include_str!("../prompts/statler.actions.system.j2"),
    ),
    (
        "statler.actions.user",
        include_str!("../prompts/statler.actions.user.j2"),
    ),
    (
        "morevqa.parse.system",
        include_str!("../prompts/morevqa.parse.system.j2"),
    ),
    (
        "morevqa.parse.user",
        include_str!("../prompts/morevqa.parse.user.j2"),
    ),
    (
        "morevqa.ground.system",
        include_str!("../prompts/morevqa.ground.system.j2"),
    ),
    (
        "morevqa.ground.user",
        include_str!("../prompts/morevqa.ground.user.j2"),
    ),
    (
        "morevqa.verify_api.system",
        include_str!("../prompts/morevqa.verify_api.system.j2"),
    ),
    (
        "morevqa.verify_api.user",
        include_str!("../prompts/morevqa.verify_api.user.j2"),
    ),
    (
        "morevqa.verify.system",
        include_str!("../prompts/morevqa.verify.system.j2"),
    ),
    (
        "morevqa.verify.user",
        include_str!("../prompts/morevqa.verify.user.j2"),
    ),
    (
        "morevqa.vqa_api.system",
        include_str!("../prompts/morevqa.vqa_api.system.j2"),
    ),
    (
        "morevqa.vqa_api.user",
        include_str!("../prompts/morevqa.vqa_api.user.j2"),
    ),
    (
        "morevqa.vqa.system",
        include_str!("../prompts/morevqa.vqa.system.j2"),
    ),
    ("morevqa.vqa.user", include_str!("../prompts/morevqa.vqa.user.j2")),
    (
        "morevqa.plan.system",
        include_str!("../prompts/morevqa.plan.system.j2"),
    ),
    (
        "morevqa.plan.user",
        include_str!("../prompts/morevqa.plan.user.j2"),
    ),
    (
        "llmdm.actions.system",
        include_str!("../prompts/llmdm.actions.system.j2"),
    ),
    (
        "llmdm.actions.user",
        include_str!("../prompts/llmdm.actions.user.j2"),
    ),
    (
        "llmdm.predicates.system",
        include_str!("../prompts/llmdm.predicates.system.j2"),
    ),
    (
        "llmdm.predicates.user",
        include_str!("../prompts/llmdm.predicates.user.j2"),
    ),
    (
        "llmdm.action.system",
        include_str!("../prompts/llmdm.action.system.j2"),
    ),
    (
        "llmdm.action.user",
        include_str!("../prompts/llmdm.action.user.j2"),
    ),
    (
        "llmdm.problem.system",
        include_str!("../prompts/llmdm.problem.system.j2"),
    ),
    (
        "llmdm.problem.user",
        include_str!("../prompts/llmdm.problem.user.j2"),
    ),
    (
        "llmdm.refine.system",
        include_str!("../prompts/llmdm.refine.system.j2"),
    ),
    (
        "llmdm.refine.user",
        include_str!("../prompts/llmdm.refine.user.j2"),
    ),
    (
        "llmdm.translate.system",
        include_str!("../prompts/llmdm.translate.system.j2"),
    ),
    (
        "llmdm.translate.user",
        include_str!("../prompts/llmdm.translate.user.j2"),
    ),
];

/// A template failed to compile or render (a defect of this crate's files).
#[derive(Debug, thiserror::Error)]
#[error("baseline prompt template {name}: {error}")]
pub struct PromptError {
    /// The template.
    pub name: String,
    /// What minijinja said.
    #[source]
    pub error: minijinja::Error,
}

/// The compiled templates.
pub struct BaselinePrompts {
    env: Environment<'static>,
}

impl std::fmt::Debug for BaselinePrompts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BaselinePrompts")
            .field(
                "templates",
                &TEMPLATES.iter().map(|(n, _)| *n).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl BaselinePrompts {
    /// The process-wide instance, compiled on first use.
    pub fn builtin() -> Result<&'static BaselinePrompts, PromptError> {
        static PROMPTS: OnceLock<BaselinePrompts> = OnceLock::new();
        if let Some(prompts) = PROMPTS.get() {
            return Ok(prompts);
        }
        let loaded = BaselinePrompts::load()?;
        Ok(PROMPTS.get_or_init(|| loaded))
    }

    fn load() -> Result<BaselinePrompts, PromptError> {
        let error = |name: &str| {
            let name = name.to_string();
            move |error| PromptError { name, error }
        };
        let mut env =
            nesy_reasoner::prompts::template_environment().map_err(error("(syntax configuration)"))?;
        for (name, text) in TEMPLATES {
            env.add_template(name, text).map_err(error(name))?;
        }
        Ok(BaselinePrompts { env })
    }

    /// Renders `{stage}.system` and `{stage}.user` with `vars`, and `images` telling the
    /// templates whether the scenes are shown as pictures or as their ground-truth states in
    /// text, so that no request announces pictures it does not carry.
    pub fn render(
        &self,
        stage: &str,
        images: bool,
        vars: &impl Serialize,
    ) -> Result<(String, String), PromptError> {
        let context = WithSetting { images, vars };
        let one = |part: &str| {
            let name = format!("{stage}.{part}");
            self.env
                .get_template(&name)
                .and_then(|t| t.render(minijinja::value::Serde(&context)))
                .map_err(|error| PromptError { name, error })
        };
        Ok((one("system")?, one("user")?))
    }

    /// SHA-256 (hex) over every template's name and text
    /// ([`nesy_reasoner::prompts::files_fingerprint`]). A benchmark run records it beside
    /// NeSyCR's prompt fingerprint, so baseline results from different templates are never
    /// mixed.
    ///
    /// ```
    /// let fingerprint = nesy_baselines::BaselinePrompts::fingerprint();
    /// assert_eq!(fingerprint.len(), 64);
    /// ```
    pub fn fingerprint() -> String {
        nesy_reasoner::prompts::files_fingerprint(TEMPLATES.iter().copied())
    }

    /// The template names, for listings and tests.
    pub fn template_names() -> impl Iterator<Item = &'static str> {
        TEMPLATES.iter().map(|(n, _)| *n)
    }
}

/// A stage's variables with the observation setting beside them.
#[derive(Serialize)]
struct WithSetting<'a, V> {
    images: bool,
    #[serde(flatten)]
    vars: &'a V,
}

/// The templates as the flows of one episode render them: in that episode's observation
/// setting (pictures, or ground-truth states as text).
#[derive(Debug, Clone, Copy)]
pub(crate) struct EpisodePrompts {
    templates: &'static BaselinePrompts,
    images: bool,
}

impl EpisodePrompts {
    /// The built-in templates in the setting of `inputs`.
    pub(crate) fn for_inputs(inputs: &BaselineInputs) -> Result<EpisodePrompts, PromptError> {
        Ok(EpisodePrompts {
            templates: BaselinePrompts::builtin()?,
            images: inputs.target_observation.is_images(),
        })
    }

    /// Renders `{stage}.system` and `{stage}.user` with `vars` in the episode's setting.
    pub(crate) fn render(&self, stage: &str, vars: &impl Serialize) -> Result<(String, String), PromptError> {
        self.templates.render(stage, self.images, vars)
    }
}

/// `- item` lines, or `None` for an empty list.
pub(crate) fn bullets<I: IntoIterator<Item = String>>(items: I) -> String {
    let lines: Vec<String> = items.into_iter().map(|l| format!("- {l}")).collect();
    if lines.is_empty() {
        "None".to_string()
    } else {
        lines.join("\n")
    }
}

/// `1. item` lines, or `None` for an empty list.
pub(crate) fn numbered<'a, I: IntoIterator<Item = &'a String>>(items: I) -> String {
    let lines: Vec<String> = items
        .into_iter()
        .enumerate()
        .map(|(i, l)| format!("{}. {l}", i + 1))
        .collect();
    if lines.is_empty() {
        "None".to_string()
    } else {
        lines.join("\n")
    }
}

/// A state as `- atom` lines, sorted.
pub(crate) fn state_lines(state: &nesy_core::State) -> String {
    bullets(state.sorted_by_text().into_iter().map(|a| a.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every template rendered with only the setting defined (any other variable renders
    /// empty), so the wording chosen by the setting is all that differs.
    fn render_all(images: bool) -> Vec<(&'static str, String)> {
        let mut env = nesy_reasoner::prompts::template_environment().unwrap();
        env.set_undefined_behavior(minijinja::UndefinedBehavior::Chainable);
        TEMPLATES
            .iter()
            .map(|(name, text)| {
                let rendered = env
                    .render_str(text, minijinja::context! { images })
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                (*name, rendered)
            })
            .collect()
    }

    #[test]
    fn no_template_announces_pictures_in_the_state_text_setting() {
        for (name, text) in render_all(false) {
            let lower = text.to_lowercase();
            for word in ["image", "visual", " views"] {
                assert!(
                    !lower.contains(word),
                    "{name} says {word:?} without pictures:\n{text}"
                );
            }
        }
    }

    #[test]
    fn the_pictures_setting_keeps_the_authors_wording() {
        let with = render_all(true);
        let announcing = with.iter().filter(|(_, t)| t.contains("images")).count();
        assert_eq!(announcing, 26, "the templates that attach the scene's images");
        let (_, describe) = with.iter().find(|(n, _)| *n == "gpt4v.describe.system").unwrap();
        assert!(describe.contains(
            "and for every keyframe six images (the top, front and back views, each plain and with object labels), each captioned with its keyframe's number."
        ));
    }
}
