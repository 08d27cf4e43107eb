//! Step 2: symbolic states for the demo's keyframes and the target's initial state.
//!
//! - `observed`: the ground-truth states the simulator recorded in the demo and observes in
//!   the target (the authors' setting, `docs/benchmark.md` §10.1).
//! - `vlm`: the paper's State Translation (Eq. 2) on the marked views, through
//!   [`VlmReasoner::translate_state`]. When ground truth exists anyway (simulated demos), the
//!   translation's precision, recall and F1 against it are reported, as the paper does.

use std::time::{Duration, Instant};

use nesy_core::Embodiment;
use nesy_core::Vocabulary;
use nesy_core::{Atom, State};
use nesy_reasoner::VlmReasoner;
use nesy_reasoner::translate::{StateTranslationRequest, TranslatedState};
use serde::{Deserialize, Serialize};

use crate::PipelineError;
use crate::inputs::{DemoInput, DemoKeyframes, TargetInput};
use crate::progress::Progress;
use crate::setting::Setting;

/// Where symbolic states come from (`--states`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum StatesMode {
    /// Ground truth when the demo has it for every keyframe, else the VLM.
    #[default]
    Auto,
    /// Ground truth from the demo and the target simulator.
    Observed,
    /// The VLM's State Translation prompt on the marked views.
    Vlm,
}

/// Which source was used, with the translation's quality when ground truth was at hand.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "source", rename_all = "snake_case")]
pub enum StateSource {
    /// Ground truth.
    Observed,
    /// State Translation.
    Vlm {
        /// States translated (keyframes + the target).
        translated: usize,
        /// Predicted atoms of real predicates outside the prompt's tier, left out.
        rejected_atoms: usize,
        /// Replies that could not be used (not a state list, names the task does not have,
        /// cut off, null content) and were re-asked.
        reasked_replies: usize,
        /// Micro-averaged precision/recall/F1 against ground truth, where it was known,
        /// over the demo keyframes and the target together. The reference is the truth
        /// restricted to the prompt's tier and its known atoms, which is what a reply can say.
        agreement: Option<Agreement>,
    },
}

/// Agreement of translated states with ground truth (micro-averaged over atoms). The
/// benchmark's unit records carry it as it is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Agreement {
    /// Translated atoms that are true.
    pub precision: f64,
    /// True atoms that were translated.
    pub recall: f64,
    /// Harmonic mean.
    pub f1: f64,
    /// The atom counts behind them: true positives, predicted, actual.
    pub counts: [u64; 3],
}

/// The states the adaptation runs on.
#[derive(Debug, Clone)]
pub struct SymbolicStates {
    /// s_1 … s_N.
    pub demo_states: Vec<State>,
    /// ŝ_1.
    pub target_state: State,
    /// Where they came from.
    pub source: StateSource,
    /// Time spent in model calls.
    pub vlm_time: Duration,
}

/// The embodiment atom the states carry when embodiments differ.
pub fn embodiment_atom(e: Embodiment) -> Atom {
    let text = match e {
        Embodiment::Finger => "(FingerGripper)",
        Embodiment::Vacuum => "(VacuumSuction)",
    };
    text.parse().expect("a built-in nullary atom parses")
}

/// `state` with `atom` added.
fn with_atom(state: &State, atom: Atom) -> State {
    let mut s = state.clone();
    s.insert(atom);
    s
}

/// Produces the states for `mode`.
pub async fn symbolic_states(
    reasoner: &VlmReasoner,
    demo: &DemoInput,
    target: &TargetInput,
    setting: &Setting,
    mode: StatesMode,
    vocabulary: &Vocabulary,
    progress: &dyn Progress,
) -> Result<SymbolicStates, PipelineError> {
    let source_atom = setting
        .embodiment_in_state
        .then(|| embodiment_atom(setting.source_embodiment));
    let truth = ground_truth(demo, source_atom);
    let use_vlm = match mode {
        StatesMode::Observed => false,
        StatesMode::Vlm => true,
        StatesMode::Auto => truth.is_none() || target.observed.is_none(),
    };
    if !use_vlm {
        let demo_states = truth.ok_or_else(|| missing_ground_truth(demo))?;
        let target_state = target.observed.clone().ok_or_else(|| PipelineError::Target {
            path: target.path.clone(),
            message: "a camera target without a simulated scene has no ground-truth state; its state comes from the model (--states vlm)".into(),
        })?;
        progress.detail("ground-truth states");
        return Ok(SymbolicStates {
            demo_states,
            target_state,
            source: StateSource::Observed,
            vlm_time: Duration::ZERO,
        });
    }

    if !setting.images {
        return Err(PipelineError::States {
            message: format!(
                "state translation reads the keyframes' pictures, and this run sends none ({}); use ground-truth states (--states observed)",
                match setting.images_mode {
                    crate::ImagesMode::Never => "--vlm-images never",
                    _ => "the server announced that it takes no image input",
                }
            ),
            kind: Some(nesy_core::adapt::ReasonerErrorKind::Refused),
        });
    }
    let started = Instant::now();
    let requests = translation_requests(demo, target, setting, vocabulary, truth.as_deref(), source_atom)?;
    let total = requests.len();
    let results = translate_all(reasoner, requests, progress).await?;
    let rejected_atoms = results.iter().map(|(_, t)| t.rejected.len()).sum();
    let reasked_replies = results.iter().map(|(_, t)| t.reasked.len()).sum();
    let agreement = agreement(&results);
    let mut states: Vec<State> = results.into_iter().map(|(_, t)| t.state).collect();
    let target_state = states.pop().ok_or_else(|| PipelineError::States {
        message: "no translation of the target's state".into(),
        kind: None,
    })?;
    Ok(SymbolicStates {
        demo_states: states,
        target_state,
        source: StateSource::Vlm {
            translated: total,
            rejected_atoms,
            reasked_replies,
            agreement,
        },
        vlm_time: started.elapsed(),
    })
}

/// The demo's ground-truth states, if every keyframe has one, each with the source
/// embodiment's atom when the setting states it.
fn ground_truth(demo: &DemoInput, source_atom: Option<Atom>) -> Option<Vec<State>> {
    demo.demo.states().map(|states| match source_atom {
        // A demo recorded without the embodiment atom gets it on every state, as the authors
        // append `(FingerGripper)` to gripper demos adapted to suction.
        Some(atom) => states.iter().map(|s| with_atom(s, atom)).collect(),
        None => states,
    })
}

/// Why observed states cannot be had: the first keyframe without a ground-truth state.
fn missing_ground_truth(demo: &DemoInput) -> PipelineError {
    let missing = demo
        .demo
        .keyframes
        .iter()
        .find(|k| k.state.is_none())
        .map(|k| k.index)
        .unwrap_or_default();
    PipelineError::Demo {
        path: demo.path.clone(),
        message: format!(
            "keyframe {missing} has no ground-truth state; use --states vlm for demos without ground truth"
        ),
    }
}

/// One state-translation request per demo keyframe and a last one for the target, each with
/// the atoms already known (the embodiment's) and the ground truth when there is one.
fn translation_requests(
    demo: &DemoInput,
    target: &TargetInput,
    setting: &Setting,
    vocabulary: &Vocabulary,
    truth: Option<&[State]>,
    source_atom: Option<Atom>,
) -> Result<Vec<StateTranslationRequest>, PipelineError> {
    let keyframes = DemoKeyframes::from_demo(demo)?;
    let known = State::from_atoms(source_atom);
    let mut requests = Vec::new();
    for k in &demo.demo.keyframes {
        let views = keyframes
            .keyframe_views(k.index)
            .ok_or_else(|| PipelineError::Demo {
                path: demo.path.clone(),
                message: format!("keyframe {} has no views", k.index),
            })?;
        requests.push(StateTranslationRequest {
            view_set: format!("demo/keyframe/{}", k.index),
            instruction: demo.demo.metadata.instruction.clone(),
            objects: demo.objects(),
            tier: setting.tier,
            vocabulary: vocabulary.clone(),
            known: known.clone(),
            views: views.clone(),
            ground_truth: truth.and_then(|t| t.get(k.index).cloned()),
        });
    }
    let target_known = State::from_atoms(
        setting
            .embodiment_in_state
            .then(|| embodiment_atom(setting.target_embodiment)),
    );
    requests.push(StateTranslationRequest {
        view_set: "target/initial".into(),
        instruction: target.instruction(demo),
        objects: target.objects.clone(),
        tier: setting.tier,
        vocabulary: vocabulary.clone(),
        known: target_known,
        views: target.marked_views()?,
        ground_truth: target.observed.clone(),
    });
    Ok(requests)
}

/// Runs the translations concurrently (the client caps how many calls are in flight) and
/// returns them in request order. Every translation runs to its end before the first
/// failure in request order is reported: stopping at the first one to fail would leave the
/// calls made to timing, and a replay of the run would not make the same ones.
async fn translate_all(
    reasoner: &VlmReasoner,
    requests: Vec<StateTranslationRequest>,
    progress: &dyn Progress,
) -> Result<Vec<(StateTranslationRequest, TranslatedState)>, PipelineError> {
    let total = requests.len();
    let mut set = tokio::task::JoinSet::new();
    for (i, request) in requests.into_iter().enumerate() {
        let reasoner = reasoner.clone();
        set.spawn(async move {
            let result = reasoner.translate_state(&request).await;
            (i, request, result)
        });
    }
    let mut results: Vec<Option<Result<(StateTranslationRequest, TranslatedState), PipelineError>>> =
        (0..total).map(|_| None).collect();
    let mut done = 0;
    while let Some(joined) = set.join_next().await {
        let (i, request, result) = joined.map_err(|e| PipelineError::States {
            message: format!("a state-translation task ended abnormally: {e}"),
            kind: None,
        })?;
        done += 1;
        progress.detail(&format!("state translation {done}/{total}"));
        results[i] = Some(match result {
            Ok(translated) => Ok((request, translated)),
            Err(e) => Err(PipelineError::States {
                message: format!("translating the states of {}: {e}", request.view_set),
                kind: Some(e.reasoner_kind()),
            }),
        });
    }
    results.into_iter().flatten().collect()
}

/// Precision, recall and F1 of the translations against ground truth, micro-averaged over
/// every request that has one; `None` when none has.
fn agreement(results: &[(StateTranslationRequest, TranslatedState)]) -> Option<Agreement> {
    let (mut tp, mut predicted, mut actual) = (0usize, 0usize, 0usize);
    for (request, translated) in results {
        let Some(truth) = &request.ground_truth else {
            continue;
        };
        // The reference is the part of the truth the prompt could express: its tier's
        // predicates and the atoms given as known. Atoms of predicates outside the tier are
        // never accepted from any reply, so counting them would lower recall for a perfect
        // translator.
        let in_tier: Vec<_> = request
            .vocabulary
            .tier(request.tier)
            .iter()
            .map(|p| p.name)
            .collect();
        let expressible = |a: &&Atom| in_tier.contains(&a.pred()) || request.known.contains(a);
        predicted += translated.state.len();
        actual += truth.iter().filter(expressible).count();
        tp += translated.state.iter().filter(|a| truth.contains(a)).count();
    }
    (actual > 0).then(|| {
        let precision = if predicted == 0 {
            0.0
        } else {
            tp as f64 / predicted as f64
        };
        let recall = tp as f64 / actual as f64;
        let f1 = if precision + recall == 0.0 {
            0.0
        } else {
            2.0 * precision * recall / (precision + recall)
        };
        Agreement {
            precision,
            recall,
            f1,
            counts: [tp, predicted, actual].map(|n| n as u64),
        }
    })
}
