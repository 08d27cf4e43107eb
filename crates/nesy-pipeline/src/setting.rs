//! The scenario settings a run derives from its demo and target: embodiments, the predicate
//! tier the prompts show, whether states carry embodiment atoms, the domain factor and
//! complexity, and the exploration budget.

use nesy_core::Embodiment;
use nesy_core::Tier;
use nesy_core::benchmark::{Complexity, Factor, iteration_budget, parse_scenario_id};
use nesy_vlm::ServerCapabilities;
use serde::Serialize;

use crate::AdaptOptions;
use crate::inputs::{DemoInput, TargetInput};

/// Whether model requests carry the keyframes' pictures (`--vlm-images`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum ImagesMode {
    /// Pictures unless the server announces that it takes none (llama.cpp's `/props`).
    #[default]
    Auto,
    /// Always pictures; a server that takes none refuses the request.
    Always,
    /// Never pictures: the calls see the states as text only, which needs ground-truth
    /// states (`--states observed`).
    Never,
}

impl ImagesMode {
    /// Whether requests carry pictures to a server that announced `caps`.
    ///
    /// ```
    /// use nesy_pipeline::ImagesMode;
    /// use nesy_vlm::ServerCapabilities;
    /// let text_only = ServerCapabilities { images: Some(false), ..ServerCapabilities::UNKNOWN };
    /// assert!(!ImagesMode::Auto.sends_images(&text_only));
    /// assert!(ImagesMode::Auto.sends_images(&ServerCapabilities::UNKNOWN));
    /// assert!(ImagesMode::Always.sends_images(&text_only));
    /// ```
    pub fn sends_images(self, caps: &ServerCapabilities) -> bool {
        match self {
            ImagesMode::Auto => !caps.refuses_images(),
            ImagesMode::Always => true,
            ImagesMode::Never => false,
        }
    }
}

/// The scenario settings the run derived (factor and complexity decide the budget).
#[derive(Debug, Clone, Serialize)]
pub struct Setting {
    /// The demo's end effector.
    pub source_embodiment: Embodiment,
    /// The target's end effector.
    pub target_embodiment: Embodiment,
    /// Predicate tier shown to the model (`extended` when a vacuum tool is involved).
    pub tier: Tier,
    /// Whether embodiment atoms (`(FingerGripper)`, `(VacuumSuction)`) are in the states.
    pub embodiment_in_state: bool,
    /// The domain factor (from the demo's scenario id, else inferred).
    pub factor: Factor,
    /// The complexity (from the scenario id, else the number of target subtasks).
    pub complexity: Complexity,
    /// The patch-proposal budget used.
    pub budget: usize,
    /// Where that budget came from: `flag` or `scenario`.
    pub budget_origin: &'static str,
    /// `--vlm-images` as given.
    pub images_mode: ImagesMode,
    /// Whether the model was shown the keyframes' pictures (the mode, resolved against
    /// what the server announced).
    pub images: bool,
}

/// Tier, embodiment atoms, factor, complexity and budget for a demo and a target.
pub fn derive_setting(demo: &DemoInput, target: &TargetInput, options: &AdaptOptions) -> Setting {
    let source = demo.demo.metadata.embodiment;
    let target_embodiment = target.embodiment;
    let changed = source != target_embodiment;
    let tier = if changed || source == Embodiment::Vacuum || target_embodiment == Embodiment::Vacuum {
        Tier::Extended
    } else {
        Tier::Full
    };
    let from_id = demo
        .demo
        .metadata
        .scenario_id
        .as_deref()
        .and_then(parse_scenario_id);
    let factor = from_id
        .map(|(f, _)| f)
        .unwrap_or(match (source, target_embodiment) {
            (Embodiment::Finger, Embodiment::Vacuum) => Factor::Grip,
            (Embodiment::Vacuum, Embodiment::Finger) => Factor::Vacu,
            _ => Factor::Obst,
        });
    let complexity = from_id.map(|(_, c)| c).unwrap_or(Complexity::of_subtask_count(
        // A camera target does not say how many subtasks it holds: one, and the low
        // complexity's budget, unless `--budget` says otherwise.
        target.subtasks.unwrap_or(1),
    ));
    let (budget, budget_origin) = match options.budget {
        Some(b) => (b, "flag"),
        None => (iteration_budget(factor, complexity), "scenario"),
    };
    Setting {
        source_embodiment: source,
        target_embodiment,
        tier,
        embodiment_in_state: changed,
        factor,
        complexity,
        budget,
        budget_origin,
        images_mode: options.images,
        images: options.images != ImagesMode::Never,
    }
}
