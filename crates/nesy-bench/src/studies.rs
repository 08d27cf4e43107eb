//! Studies: named sets of NeSyCR variants run on the same units under one stated error
//! model, and reported as one table in the shape of the paper's.
//!
//! - [`Study::Ablation`] (Table 3's shape): the full loop and the loop without proposal
//!   verification (`verification`, Eq. 8), without counterfactual identification
//!   (`conflict`, Eq. 6), without both, and without the world-model check (`dynamics`,
//!   Eq. 4) in two readings: (A) induced operators are never checked against the
//!   demonstration; (B) the symbolic tool checks nothing at all and the revised procedure
//!   is compiled unverified. Every row runs under the same synthetic noise on the offline
//!   responder's answers.
//! - [`Study::Robustness`] (Table 8's shape): states translated by the offline responder
//!   with none, 10 % of the relations dropped or 10 % false relations injected along the
//!   demonstration, and a perception what-if whose precision and recall match the paper's
//!   reported real-scene state translation.
//! - [`Study::ComplexityGap`] (Figure 4(b)'s shape): NeSyCR given the target task's goal,
//!   NeSyCR with the goal derived from the demonstration, and the imitation and replanning
//!   controls, on the auxiliary complexity-gap suite (targets with 0–3 more subtasks than
//!   their demonstration; not part of the 440), with SR and PD against the added subtasks.
//!
//! With no model reachable, every number these studies produce is synthetic: it says what
//! the symbolic machinery does with a literal responder under the stated error model, not
//! what a model would do. The report's banner says so.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::error::BenchError;
use crate::variant::Variant;
use nesy_sim::tasks::scenario::Family;

/// The error model of the ablation study, in the responder's noise syntax: each induced
/// operator literal dropped or negated at 3 %, 30 % of patch replies corrupted, and, without
/// identification, the failing step missed half of the time.
pub const ABLATION_NOISE: &str = "op-drop=0.03;op-flip=0.03;bad-patch=0.3;localize-miss=0.5";

/// Relations dropped along the demonstration in the robustness study (Table 8's "10 % Drop").
pub const ROBUSTNESS_DROP: &str = "state-drop=0.1;state-scope=demo;relations=binary";

/// False relations injected along the demonstration (Table 8's "10 % Noise").
pub const ROBUSTNESS_INJECT: &str = "state-inject=0.1;state-scope=demo;relations=binary";

/// A perception what-if: every atom of every translated scene (demo and target) is missed
/// at 29 % and false atoms are added at 2.2 % of the scene's atoms, which gives recall
/// 0.71 and precision 0.71 / (0.71 + 0.022) ≈ 0.97, the paper's reported GPT-5 state
/// translation on real scenes (Table 7: P 0.97, R 0.71, F1 0.82).
pub const PERCEPTION_WHAT_IF: &str = "state-drop=0.29;state-inject=0.022;state-scope=both;relations=all";

/// A named study.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Study {
    /// Table 3's shape: the ablations of the three symbolic checks.
    Ablation,
    /// Table 8's shape: scene-graph perturbation along the demonstration.
    Robustness,
    /// Figure 4(b)'s shape: targets with more subtasks than their demonstration.
    #[serde(rename = "complexity-gap")]
    ComplexityGap,
    /// Table 2's task in simulation: the real-world drawers family.
    Drawers,
    /// Figures 1 and 5's task in simulation: the real-world hook-and-screws family.
    Hook,
}

/// One row of a study: its label in the table, the variant it runs, and what reading of
/// the paper it stands for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StudyRow {
    /// The row's label, as in the paper's table where it has one.
    pub label: &'static str,
    /// The variant.
    pub variant: Variant,
    /// What the row means, where the paper leaves room for more than one reading.
    pub reading: &'static str,
}

impl Study {
    /// Every study.
    pub const ALL: [Study; 5] = [
        Study::Ablation,
        Study::Robustness,
        Study::ComplexityGap,
        Study::Drawers,
        Study::Hook,
    ];

    /// The scenarios a study runs on unless told otherwise: the paper's cell for both tables
    /// (Combination, medium), and every scenario of the complexity-gap suite.
    pub fn default_scenarios(self) -> &'static str {
        match self {
            Study::Ablation | Study::Robustness => "comb_medium",
            Study::ComplexityGap | Study::Drawers | Study::Hook => "all",
        }
    }

    /// Whether the study runs on the auxiliary complexity-gap suite
    /// ([`nesy_sim::tasks::scenario::generate_gap_suite`]) rather than the 440, when no
    /// suite folder is given.
    pub fn uses_gap_suite(self) -> bool {
        self == Study::ComplexityGap
    }

    /// The real-world task whose family the study runs on
    /// ([`nesy_sim::tasks::scenario::generate_family_file`]) when no suite folder is given.
    pub fn family(self) -> Option<Family> {
        match self {
            Study::Drawers => Some(Family::Drawers),
            Study::Hook => Some(Family::Hook),
            _ => None,
        }
    }

    /// The repeats (noise seeds) per scenario unless told otherwise: 3 for the noisy
    /// studies, 1 for the complexity gap, whose responder has no noise to reseed.
    pub fn default_repeats(self) -> u32 {
        match self {
            Study::Ablation | Study::Robustness => 3,
            Study::ComplexityGap | Study::Drawers | Study::Hook => 1,
        }
    }

    /// The study's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Study::Ablation => "ablation",
            Study::Robustness => "robustness",
            Study::ComplexityGap => "complexity-gap",
            Study::Drawers => "drawers",
            Study::Hook => "hook",
        }
    }

    /// Parses a study name.
    pub fn parse(text: &str) -> Result<Study, BenchError> {
        Study::ALL
            .into_iter()
            .find(|s| s.name() == text.trim())
            .ok_or_else(|| {
                BenchError::Usage(format!(
                    "--study {text:?}: expected one of {}",
                    Study::ALL.map(Study::name).join(", ")
                ))
            })
    }

    /// The table's title in the report.
    pub fn title(self) -> &'static str {
        match self {
            Study::Ablation => "Ablations (Table 3 shape)",
            Study::Robustness => "Robustness to scene-graph perturbation (Table 8 shape)",
            Study::ComplexityGap => "Complexity gap (Figure 4(b) shape)",
            Study::Drawers => "Drawers that block each other (Table 2's task, simulated)",
            Study::Hook => "A magnetic hook gathers scattered screws (Figures 1 and 5's task, simulated)",
        }
    }

    /// The error model, in words, for the report's SYNTHETIC banner.
    pub fn error_model(self) -> String {
        match self {
            Study::Ablation => format!(
                "every row answers with the offline responder under the same noise `{ABLATION_NOISE}`: each literal of an induced operator is left out (3 %, Bernoulli) or negated (3 %, Bernoulli); 30 % of patch replies are corrupted (a SEARCH naming no plan action, or the first inserted action lost); and when identification is off, the responder patches a step other than the failing one with probability 0.5 (an assumed localisation error, not a measured one). States are the simulator's ground truth."
            ),
            Study::Robustness => format!(
                "states are translated by the offline responder from ground truth (`states=vlm`) and perturbed along the demonstration only: `{ROBUSTNESS_DROP}` removes 10 % of each keyframe's binary relations (an exact count per scene graph, rounded stochastically); `{ROBUSTNESS_INJECT}` adds 10 % false binary relations of plausible types; the what-if row `{PERCEPTION_WHAT_IF}` misses 29 % of every scene's atoms and adds 2.2 % false ones, demo and target, to match the paper's reported precision 0.97 and recall 0.71. Operators are checked with the exact transition check (`TransitionCheck::Exact`) except in the two rows marked changed-atoms (`TransitionCheck::ChangedAtoms`). Operators, patches and code are otherwise the responder's literal answers."
            ),
            Study::ComplexityGap => "no noise; the offline responder answers every call from ground truth and nesy's true domain, and its patches are nesy-core's plans, so the subtasks the demonstration never shows are planned, not adapted from it. The NeSyCR rows are the responder's upper bound with the goal given by the target task or derived from the demonstration; the scenarios are the auxiliary complexity-gap suite (Obstruction, one demonstrated subtask, targets with 0 to 3 more), not part of the 440.".to_owned(),
            Study::Drawers => "no noise; the offline responder answers every call from ground truth and nesy's true domain (the upper bound), and the controls are model-free. The scenarios are the drawers family (two cabinets side by side in the demonstration, at right angles with the cubes stacked in the target; simulated, finger robot), not part of the 440 and not the paper's real-robot trials.".to_owned(),
            Study::Hook => "no noise; the offline responder answers every call from ground truth and nesy's true domain (the upper bound), and the controls are model-free. The scenarios are the hook family (the hook, the screws on its magnet and the cubes on the table in the demonstration; in the target the hook lies in the open drawer under a cube and the screws are scattered, so the hook must be uncovered, taken out and swept over them; simulated magnet, finger robot), not part of the 440 and not the paper's real-robot trials.".to_owned(),
        }
    }

    /// The rows, the full method first.
    pub fn rows(self) -> Vec<StudyRow> {
        match self {
            Study::Ablation => ablation_rows(),
            Study::Robustness => robustness_rows(),
            Study::ComplexityGap => complexity_gap_rows(),
            Study::Drawers | Study::Hook => family_rows(),
        }
    }

    /// The row a variant id belongs to, if it is one of this study's.
    pub fn row_of(self, variant_id: &str) -> Option<StudyRow> {
        self.rows().into_iter().find(|r| r.variant.id() == variant_id)
    }
}

impl fmt::Display for Study {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// NeSyCR.
fn nesycr() -> Variant {
    Variant::plain("nesycr")
}

/// The ablation's rows (Table 3's shape), all under the ablation's error model.
fn ablation_rows() -> Vec<StudyRow> {
    let noisy = || nesycr().with("noise", ABLATION_NOISE);
    vec![
        StudyRow {
            label: "NeSyCR",
            variant: noisy(),
            reading: "every check on",
        },
        StudyRow {
            label: "w/o verification (Eq. 8)",
            variant: noisy().with("verification", "off"),
            reading: "a proposal whose SEARCH matches is accepted without checking that it resolves the violation; identification still runs on the patched procedure",
        },
        StudyRow {
            label: "w/o conflict (Eq. 6)",
            variant: noisy().with("identification", "off"),
            reading: "requests carry only the procedure and the target state; the responder localises the failure itself, missing it at the stated rate",
        },
        StudyRow {
            label: "w/o both",
            variant: noisy().with("identification", "off").with("verification", "off"),
            reading: "one revision with no signal, retried only when it cannot be read or does not match",
        },
        StudyRow {
            label: "w/o dynamics (Eq. 4), reading A",
            variant: noisy().with("world-model", "off"),
            reading: "reading A: induced operators exist but are never checked against the demonstration (the first parsable reply per transition is kept); identification and verification still run on them",
        },
        StudyRow {
            label: "w/o dynamics (Eq. 4), reading B",
            variant: noisy()
                .with("world-model", "off")
                .with("identification", "off")
                .with("verification", "off")
                .with("on-unresolved", "compile-last"),
            reading: "reading B, as the loop can express it: the symbolic tool checks nothing. Induced operators stay the model's own unchecked account of the demonstration; nothing identifies or verifies, so the loop makes one revision with no signal; the revised procedure is compiled and executed whatever the executor would say of it. Offline, the responder localises the failure with its own unchecked operators, missing at the stated rate",
        },
    ]
}

/// The robustness rows (Table 8's shape): translated states, perturbed as each row says.
fn robustness_rows() -> Vec<StudyRow> {
    let vlm = || nesycr().with("states", "vlm");
    vec![
        StudyRow {
            label: "None",
            variant: vlm(),
            reading: "translated states equal the ground truth; exact transition check, as in every row not marked otherwise",
        },
        StudyRow {
            label: "10 % Drop",
            variant: vlm().with("noise", ROBUSTNESS_DROP),
            reading: "10 % of each demo keyframe's binary relations removed",
        },
        StudyRow {
            label: "10 % Noise (injected)",
            variant: vlm().with("noise", ROBUSTNESS_INJECT),
            reading: "10 % false binary relations added to each demo keyframe; none removed",
        },
        StudyRow {
            label: "10 % Drop, changed-atoms check",
            variant: vlm()
                .with("noise", ROBUSTNESS_DROP)
                .with("transition-check", "changed-atoms"),
            reading: "as 10 % Drop, with operators checked only on the atoms the transition changes (`TransitionCheck::ChangedAtoms`), closer to Eq. 4's entailment than the exact check",
        },
        StudyRow {
            label: "10 % Noise, changed-atoms check",
            variant: vlm()
                .with("noise", ROBUSTNESS_INJECT)
                .with("transition-check", "changed-atoms"),
            reading: "as 10 % Noise, with the changed-atoms transition check",
        },
        StudyRow {
            label: "Perception what-if (P 0.97, R 0.71)",
            variant: vlm().with("noise", PERCEPTION_WHAT_IF),
            reading: "every scene, demo and target, perceived at the paper's reported real-scene precision and recall; a what-if, not a measurement",
        },
    ]
}

/// A real-world task family's rows: NeSyCR and the two model-free controls.
fn family_rows() -> Vec<StudyRow> {
    let mut rows = vec![StudyRow {
        label: "NeSyCR",
        variant: nesycr(),
        reading: "the full loop on the family's demonstration and target",
    }];
    rows.extend(control_rows());
    rows
}

/// The two model-free controls every study of a suite beside the 440 compares with.
fn control_rows() -> [StudyRow; 2] {
    [
        StudyRow {
            label: "Imitation (control)",
            variant: Variant::plain("imitation"),
            reading: "the demonstrated procedure, unadapted, compiled and executed in the target",
        },
        StudyRow {
            label: "Replan (control)",
            variant: Variant::plain("replan"),
            reading: "nesy-core's planner from the target's state to its goal over the true domain, no demonstration",
        },
    ]
}

/// The complexity-gap rows: NeSyCR with either goal and the two model-free controls.
fn complexity_gap_rows() -> Vec<StudyRow> {
    let mut rows = vec![
        StudyRow {
            label: "NeSyCR, target's goal",
            variant: nesycr().with("goal", "target"),
            reading: "the goal is the target task's, as its instruction states it (the scene's goal atoms, every object let go); the loop patches the demonstrated procedure until it reaches that goal",
        },
        StudyRow {
            label: "NeSyCR, demonstrated goal",
            variant: nesycr(),
            reading: "the goal derived from the demonstration, which never shows the added subtasks: the loop cannot know they are wanted",
        },
    ];
    rows.extend(control_rows());
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_row_is_a_valid_distinct_variant_with_the_full_method_first() {
        for study in Study::ALL {
            let rows = study.rows();
            assert_eq!(Study::parse(study.name()).unwrap(), study);
            let mut ids: Vec<String> = rows.iter().map(|r| r.variant.id()).collect();
            for row in &rows {
                let method = crate::methods::find(&row.variant.method).unwrap();
                method.validate(&row.variant).unwrap();
                assert_eq!(study.row_of(&row.variant.id()).unwrap(), *row);
            }
            ids.sort();
            ids.dedup();
            assert_eq!(ids.len(), rows.len(), "{study}");
        }
        // The ablation rows share one error model; only the switches differ.
        for row in Study::Ablation.rows() {
            assert_eq!(row.variant.option("noise"), Some(ABLATION_NOISE));
        }
        assert!(Study::parse("ablations").is_err());
    }

    #[test]
    fn reading_b_leaves_the_symbolic_tool_no_check_and_compiles_unverified() {
        use crate::methods::nesycr::{NeSyCr, OnUnresolved};
        let settings_of = |reading: &str| {
            let row = Study::Ablation
                .rows()
                .into_iter()
                .find(|r| r.label.contains(reading))
                .unwrap();
            NeSyCr::full().settings(&row.variant).unwrap()
        };
        let b = settings_of("reading B");
        let a = b.adapt.ablation;
        assert!(!a.world_model && !a.identification && !a.verification);
        assert_eq!(b.on_unresolved, OnUnresolved::CompileLast);
        // Reading A keeps identification and verification, and never compiles an
        // unresolved procedure.
        let reading_a = settings_of("reading A");
        let a = reading_a.adapt.ablation;
        assert!(!a.world_model && a.identification && a.verification);
        assert_eq!(reading_a.on_unresolved, OnUnresolved::Fail);
    }

    #[test]
    fn the_perception_what_if_matches_the_reported_precision_and_recall() {
        let noise = crate::variant::noise_of(PERCEPTION_WHAT_IF).unwrap();
        let recall = 1.0 - noise.state_drop;
        let precision = recall / (recall + noise.state_inject);
        assert!((recall - 0.71).abs() < 1e-9);
        assert!((precision - 0.97).abs() < 0.005, "{precision}");
    }
}
