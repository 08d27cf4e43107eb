//! The methods the harness compares, behind one interface: episode inputs in, a task
//! specification out (a symbolic procedure, verified or not, or a natural-language plan).
//! The harness then turns the specification into code (the shared code-generation tail) and
//! executes it.
//!
//! Each method names its class in the paper's baseline table (natively code, explicit
//! adaptation, replanning, world model, symbolic tool), whether it is a method or a
//! model-free control, and what an offline run of it means.

mod baselines;
mod code_as_policies;
mod imitation;
pub(crate) mod nesycr;
mod replan;

use std::sync::Arc;

use futures::future::BoxFuture;
use nesy_core::Operator;
use nesy_core::Vocabulary;
use nesy_core::adapt::Adaptation;
use nesy_pipeline::states::StateSource;
use nesy_pipeline::synth::CodegenMode;
use nesy_pipeline::{DemoInput, DemoKeyframes, Setting, TargetInput};
use nesy_vlm::VlmClient;
use serde::Serialize;

use crate::error::BenchError;
use crate::variant::Variant;

pub use baselines::BaselineMethod;
pub use code_as_policies::CodeAsPolicies;
pub use imitation::Imitation;
pub use nesycr::NeSyCr;
pub use replan::Replan;

/// Whether a method is one the paper compares or a control the harness adds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// A method of the paper's comparison.
    Method,
    /// A control: it measures the benchmark, not a method.
    Control,
}

/// The columns of the paper's baseline-comparison table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Classes {
    /// Produces code natively.
    pub natively_code: bool,
    /// Adapts the demonstration explicitly.
    pub explicit_adapt: bool,
    /// Replans in the target.
    pub replanning: bool,
    /// Keeps a world model.
    pub world_model: bool,
    /// Uses a symbolic tool.
    pub symbolic_tool: bool,
}

/// What an offline run (the reference responder, or no model) of a method measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OfflineMeaning {
    /// The oracle's answers bound the method from above (NeSyCR: local calls with ground
    /// truth answers, every answer still checked by the symbolic executor).
    UpperBound,
    /// The method uses no model; the number is the control's own.
    ModelFree,
    /// The method's calls are global ("write the target plan"): a perfect answer is the
    /// planner's plan, so an offline number would not be the method's. Offline runs are
    /// refused.
    NotMeaningful,
}

/// A method's description.
#[derive(Debug, Clone, Serialize)]
pub struct MethodInfo {
    /// Its name in variant ids (`nesycr`).
    pub name: &'static str,
    /// Its name in tables (`NeSyCR`).
    pub title: &'static str,
    /// Method or control.
    pub role: Role,
    /// Its classes in the paper's comparison table.
    pub classes: Classes,
    /// One sentence on what it does.
    pub summary: &'static str,
    /// The settings it takes (`key=values`), for `nesy bench methods`.
    pub settings: &'static [&'static str],
    /// What an offline run of it measures.
    pub offline: OfflineMeaning,
}

/// Everything a method sees of one unit.
pub struct UnitInputs {
    /// The predicates the task is stated in (the built-ins, or a real-world task family's).
    pub vocabulary: Arc<Vocabulary>,
    /// The source demonstration.
    pub demo: Arc<DemoInput>,
    /// The demonstration's decoded views and recorded calls, for the reasoner.
    pub keyframes: Arc<DemoKeyframes>,
    /// The target scene, built, observed and rendered.
    pub target: Arc<TargetInput>,
    /// The scenario's settings (embodiments, tier, factor, complexity, budget).
    pub setting: Setting,
    /// The variant, with its settings.
    pub variant: Variant,
    /// The unit's seed.
    pub seed: u64,
}

/// A specification the shared tail turns into code.
#[derive(Debug, Clone)]
pub enum Specification {
    /// Symbolic actions.
    Procedure {
        /// The actions, in order.
        procedure: Vec<Operator>,
        /// True if the symbolic executor verified it from the target's initial state
        /// (every precondition and the goal).
        verified: bool,
    },
    /// Natural-language steps.
    Plan {
        /// The steps, in order.
        steps: Vec<String>,
        /// The instruction code generation gets instead of the target's, when the method
        /// rewrites it (MoReVQA passes its question form).
        instruction: Option<String>,
    },
}

impl Specification {
    /// `procedure` or `plan`.
    pub fn kind(&self) -> &'static str {
        match self {
            Specification::Procedure { .. } => "procedure",
            Specification::Plan { .. } => "plan",
        }
    }

    /// Number of steps.
    pub fn len(&self) -> usize {
        match self {
            Specification::Procedure { procedure, .. } => procedure.len(),
            Specification::Plan { steps, .. } => steps.len(),
        }
    }

    /// True without steps.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// What a method produced for a unit.
#[derive(Debug, Clone)]
pub struct Specified {
    /// The specification.
    pub spec: Specification,
    /// How its code is made.
    pub codegen: CodegenMode,
    /// The adaptation trace, for NeSyCR.
    pub adaptation: Option<Adaptation>,
    /// Refinement rounds used and the budget.
    pub iterations: Option<(usize, usize)>,
    /// Where the states came from (translation quality for `--states vlm`).
    pub states: Option<StateSource>,
    /// Seconds of symbolic work, and the part of it building the world model.
    pub symbolic_s: (f64, f64),
    /// Seconds in model calls made by the method itself (not code generation).
    pub vlm_s: f64,
    /// Notes for the unit's record (e.g. "compiled the last unverified plan").
    pub notes: Vec<String>,
}

/// What kind of failure kept a method from a specification. The harness turns it into the
/// unit's status; the methods know nothing of how units are recorded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FailureKind {
    /// The adaptation (or the plan search) ran out without a verified specification.
    Unresolved,
    /// The method could not produce one: a reply it cannot read, a parse or planner failure
    /// that ends it, a defect of its own request.
    Method,
    /// The endpoint refused a request as built.
    Refused,
    /// A model call did not complete (network, rate limit, server error, a missing
    /// recording).
    Transport,
}

impl FailureKind {
    /// The kind of a reasoner failure of `kind`.
    pub fn of_reasoner(kind: nesy_core::adapt::ReasonerErrorKind) -> FailureKind {
        use nesy_core::adapt::ReasonerErrorKind as K;
        match kind {
            K::Transport | K::Replay => FailureKind::Transport,
            K::Refused => FailureKind::Refused,
            K::Reply | K::Request | K::Exhausted => FailureKind::Method,
        }
    }
}

/// Why a method produced no specification.
#[derive(Debug, Clone)]
pub struct MethodFailure {
    /// What kind of failure it is.
    pub kind: FailureKind,
    /// What happened.
    pub message: String,
    /// The adaptation trace, when there is one (an unresolved NeSyCR run).
    pub adaptation: Option<Box<Adaptation>>,
    /// Refinement rounds used and the budget.
    pub iterations: Option<(usize, usize)>,
    /// Symbolic seconds spent before the failure, in all and on the world model, when the
    /// method got as far as its symbolic stages (an unresolved NeSyCR run).
    pub symbolic_s: Option<(f64, f64)>,
}

impl MethodFailure {
    /// A failure of a kind, with a message.
    pub fn new(kind: FailureKind, message: impl Into<String>) -> MethodFailure {
        MethodFailure {
            kind,
            message: message.into(),
            adaptation: None,
            iterations: None,
            symbolic_s: None,
        }
    }

    /// The failure a reasoner failure of `kind` is.
    pub fn from_reasoner(kind: nesy_core::adapt::ReasonerErrorKind, message: String) -> MethodFailure {
        MethodFailure::new(FailureKind::of_reasoner(kind), message)
    }
}

/// A method of the benchmark.
pub trait Method: Send + Sync {
    /// Its description.
    fn info(&self) -> MethodInfo;

    /// Checks a variant's settings (called before a run starts, so a typo fails at once).
    fn validate(&self, variant: &Variant) -> Result<(), BenchError>;

    /// Where the variant departs from the authors' implementation, in words, for the run
    /// manifest (none by default).
    fn deviations(&self, _variant: &Variant) -> Vec<String> {
        Vec::new()
    }

    /// Produces the unit's specification, asking `client` for any model calls (clones of a
    /// client share its transport and accounting).
    fn specify<'a>(
        &'a self,
        inputs: &'a UnitInputs,
        client: &'a VlmClient,
    ) -> BoxFuture<'a, Result<Specified, MethodFailure>>;
}

/// Every method the harness knows, in table order.
pub fn registry() -> Vec<Arc<dyn Method>> {
    let mut methods: Vec<Arc<dyn Method>> = vec![Arc::new(NeSyCr::full()), Arc::new(NeSyCr::released())];
    methods.extend(
        nesy_baselines::Baseline::ALL
            .into_iter()
            .map(|b| Arc::new(BaselineMethod::new(b)) as Arc<dyn Method>),
    );
    methods.push(Arc::new(CodeAsPolicies));
    methods.push(Arc::new(Imitation));
    methods.push(Arc::new(Replan));
    methods
}

/// What `all` in a method list stands for: NeSyCR and every baseline of the paper's Table 1
/// that is implemented, in table order (not the authors' released loop, not the controls).
pub fn table_methods() -> Vec<&'static str> {
    registry()
        .iter()
        .map(|m| m.info())
        .filter(|i| i.role == Role::Method && i.name != "nesycr-released")
        .map(|i| i.name)
        .collect()
}

/// Parses a comma-separated list of variants. Commas inside a setting's value are not
/// supported; noise settings use `,` and therefore `;` between knobs (see
/// [`Variant::option`]). The item `all` stands for [`table_methods`].
pub fn parse_variants(text: &str) -> Result<Vec<Variant>, BenchError> {
    let mut variants: Vec<Variant> = Vec::new();
    for item in text.split(',').filter(|s| !s.trim().is_empty()) {
        if item.trim() == "all" {
            for name in table_methods() {
                variants.push(Variant::parse(name)?);
            }
        } else {
            variants.push(Variant::parse(item)?);
        }
    }
    if variants.is_empty() {
        return Err(BenchError::Usage(
            "no variant given (e.g. --methods nesycr,imitation)".into(),
        ));
    }
    Ok(variants)
}

/// The method of a name.
pub fn find(name: &str) -> Result<Arc<dyn Method>, BenchError> {
    registry()
        .into_iter()
        .find(|m| m.info().name == name)
        .ok_or_else(|| {
            let known: Vec<&str> = registry().iter().map(|m| m.info().name).collect();
            BenchError::Usage(format!(
                "unknown method {name:?}; known: {} (`nesy bench methods` describes them)",
                known.join(", ")
            ))
        })
}

/// Checks that every setting of `variant` is one of `known` (keys of the form
/// `key=v1|v2|…` or `key=N`).
pub(crate) fn check_keys(variant: &Variant, known: &[&str]) -> Result<(), BenchError> {
    for key in variant.options.keys() {
        if !known.iter().any(|k| k.split('=').next() == Some(key.as_str())) {
            return Err(BenchError::Usage(format!(
                "variant {}: {} takes no setting {key:?}; its settings: {}",
                variant,
                variant.method,
                if known.is_empty() {
                    "none".to_owned()
                } else {
                    known.join(", ")
                }
            )));
        }
    }
    Ok(())
}

/// `on` or `off` of a setting (with a default), or a usage error naming it.
pub(crate) fn switch(variant: &Variant, key: &str, default: bool) -> Result<bool, BenchError> {
    match variant.option(key) {
        None => Ok(default),
        Some("on") => Ok(true),
        Some("off") => Ok(false),
        Some(other) => Err(BenchError::Usage(format!(
            "variant {variant}: {key}={other:?}; expected on or off"
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_stands_for_the_table_methods_in_order() {
        let all: Vec<String> = parse_variants("all,imitation")
            .unwrap()
            .iter()
            .map(|v| v.id())
            .collect();
        assert_eq!(
            all,
            [
                "nesycr",
                "demo2code",
                "gpt4v-robotics",
                "critic-v",
                "morevqa",
                "statler",
                "llm-dm",
                "imitation"
            ]
        );
        assert_eq!(parse_variants("nesycr, imitation").unwrap().len(), 2);
        assert!(parse_variants(" , ").is_err());
    }
}
