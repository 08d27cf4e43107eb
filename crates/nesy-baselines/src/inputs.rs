//! What every baseline sees of one episode.

use nesy_core::State;
use nesy_core::{Tier, Vocabulary};
use nesy_reasoner::Views;
use nesy_vlm::Part;
use serde::Serialize;

/// The images of one scene: each camera view as rendered and with the object names written
/// next to the objects (six images for the simulator's top, front and back cameras).
#[derive(Debug, Clone)]
pub struct SceneViews {
    /// The views as rendered.
    pub raw: Views,
    /// The same views with object labels.
    pub marked: Views,
}

impl SceneViews {
    /// The images as request parts, each after its own caption (`"{scene} top"`,
    /// `"{scene} top (with object labels)"`, …), as the authors attach them.
    pub fn parts(&self, scene: &str) -> Vec<Part> {
        let mut parts = Vec::with_capacity(4 * self.raw.len());
        for ((name, raw), (_, marked)) in self.raw.named().zip(self.marked.named()) {
            parts.push(Part::text(format!("{scene} {name}")));
            parts.push(Part::Image(raw.clone()));
            parts.push(Part::text(format!("{scene} {name} (with object labels)")));
            parts.push(Part::Image(marked.clone()));
        }
        parts
    }
}

/// What a flow is shown of one scene where the authors attach its pictures.
#[derive(Debug, Clone)]
pub enum SceneObservation {
    /// The scene's images, as the authors attach them.
    Images(SceneViews),
    /// The scene's ground-truth state written out in place of the images: the setting in
    /// which every method runs on a text-only model under the same perception.
    StateText(State),
}

impl SceneObservation {
    /// Whether the scene is shown as pictures (rather than as its state in text).
    pub fn is_images(&self) -> bool {
        matches!(self, SceneObservation::Images(_))
    }

    /// The request parts standing for the scene `scene`: its six captioned images, or one
    /// text part listing its ground-truth atoms.
    ///
    /// ```
    /// use nesy_baselines::SceneObservation;
    /// use nesy_core::{Atom, State};
    /// use nesy_vlm::Part;
    ///
    /// let state = State::from_atoms(["(OnTopOf red_cube floor)".parse::<Atom>().unwrap()]);
    /// let parts = SceneObservation::StateText(state).parts("scene");
    /// assert_eq!(parts.len(), 1);
    /// let Part::Text(text) = &parts[0] else { panic!("a text part") };
    /// assert!(text.starts_with("scene, as its ground-truth state"));
    /// assert!(text.contains("- (OnTopOf red_cube floor)"));
    /// ```
    pub fn parts(&self, scene: &str) -> Vec<Part> {
        match self {
            SceneObservation::Images(views) => views.parts(scene),
            SceneObservation::StateText(state) => vec![Part::text(format!(
                "{scene}, as its ground-truth state (no pictures in this setting):\n{}",
                crate::prompts::state_lines(state)
            ))],
        }
    }
}

/// One keyframe of the demonstration.
#[derive(Debug, Clone)]
pub struct Keyframe {
    /// The ground-truth state at the keyframe.
    pub state: State,
    /// What the flows see of it in place of pictures, or its images.
    pub observation: SceneObservation,
}

/// How closely a flow follows the authors' code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fidelity {
    /// The authors' behaviour, quirks included; a reply whose answer cannot be found ends
    /// the flow.
    #[default]
    Authors,
    /// The quirks fixed, and unreadable replies re-asked with the reason; every difference
    /// is listed in [`crate::BaselinePlan::deviations`].
    Repaired,
}

impl Fidelity {
    /// `authors` or `repaired`.
    pub fn as_str(self) -> &'static str {
        match self {
            Fidelity::Authors => "authors",
            Fidelity::Repaired => "repaired",
        }
    }
}

/// Everything a baseline sees of one episode: the same information NeSyCR gets.
#[derive(Debug, Clone)]
pub struct BaselineInputs {
    /// The task instruction.
    pub instruction: String,
    /// The demonstration scene's objects, in order.
    pub source_objects: Vec<String>,
    /// The demonstration's keyframes, in order.
    pub keyframes: Vec<Keyframe>,
    /// The target scene's objects, in order.
    pub target_objects: Vec<String>,
    /// The target's ground-truth initial state.
    pub target_state: State,
    /// The target scene as the flows see it: its images, or its state as text.
    pub target_observation: SceneObservation,
    /// The predicates, for the tier texts.
    pub vocabulary: Vocabulary,
    /// Whether the target's state carries end-effector atoms (the authors' `ee_set`: the
    /// end effector changes, or the factor is Combination); it selects the `extended` tier
    /// over `full` where a flow shows predicates.
    pub end_effector_in_state: bool,
    /// The refinement budget of the scenario (10/15/20/30), for flows with loops.
    pub budget: usize,
    /// How closely to follow the authors.
    pub fidelity: Fidelity,
}

impl BaselineInputs {
    /// The tier a flow shows as "the predicates": `extended` when the end effector is part
    /// of the state, else `full` (the authors' choice).
    pub fn planning_tier(&self) -> Tier {
        if self.end_effector_in_state {
            Tier::Extended
        } else {
            Tier::Full
        }
    }
}
