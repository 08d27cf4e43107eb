//! What a run will ask of the model, before any call: per method and cell, the model calls
//! and images, exact for the fixed stages and maxima for the loops, from each scenario's
//! recorded demonstration (its keyframe count). With a price table, an estimated cost.

use std::collections::BTreeMap;

use nesy_core::benchmark::{Complexity, FactorGroup};
use serde::Serialize;

use crate::demos::DemoCache;
use crate::harness::Prepared;
use crate::methods::nesycr::NeSyCr;
use crate::unit::Unit;

/// Images per induction call: the three labelled views before and after the action.
pub const IMAGES_PER_INDUCTION: u64 = 6;
/// Images per state translation: the three labelled views.
pub const IMAGES_PER_TRANSLATION: u64 = 3;

/// The most actions LLM-DM's model is assumed to recommend (one construction call each): the
/// method sets no bound, so the plan's maximum rests on this assumption.
pub const LLMDM_ACTIONS: u64 = 10;

/// Calls and images of one unit, or a range.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Load {
    /// Model calls, fewest.
    pub calls_min: u64,
    /// Model calls, most.
    pub calls_max: u64,
    /// Images, fewest.
    pub images_min: u64,
    /// Images, most.
    pub images_max: u64,
}

impl Load {
    fn add(&mut self, other: &Load) {
        self.calls_min += other.calls_min;
        self.calls_max += other.calls_max;
        self.images_min += other.images_min;
        self.images_max += other.images_max;
    }
}

/// A method's load on one scenario with `keyframes` keyframes and round budget `budget`.
pub fn unit_load(unit: &Unit, keyframes: u64, budget: u64) -> Load {
    let transitions = keyframes.saturating_sub(1);
    match unit.variant.method.as_str() {
        m @ ("nesycr" | "nesycr-released") => {
            let method = if m == "nesycr" {
                NeSyCr::full()
            } else {
                NeSyCr::released()
            };
            let Ok(s) = method.settings(&unit.variant) else {
                return Load::default();
            };
            let tries = s.adapt.induction_tries as u64;
            let budget = s.budget.map_or(budget, |b| b as u64);
            let codegen = u64::from(s.codegen == nesy_pipeline::synth::CodegenMode::Vlm);
            let (t_calls, t_images) = if s.states == nesy_pipeline::states::StatesMode::Vlm {
                (keyframes + 1, (keyframes + 1) * IMAGES_PER_TRANSLATION)
            } else {
                (0, 0)
            };
            Load {
                calls_min: transitions + codegen + t_calls,
                calls_max: transitions * tries + budget + codegen + t_calls,
                images_min: transitions * IMAGES_PER_INDUCTION + t_images,
                images_max: transitions * tries * IMAGES_PER_INDUCTION + t_images,
            }
        }
        "demo2code" | "gpt4v-robotics" | "critic-v" | "morevqa" | "statler" | "llm-dm" => {
            let shape = match unit.variant.method.as_str() {
                "demo2code" => nesy_baselines::demo2code::shape(keyframes),
                "gpt4v-robotics" => nesy_baselines::gpt4v::shape(keyframes),
                "critic-v" => nesy_baselines::critic::shape(keyframes, budget),
                "morevqa" => nesy_baselines::morevqa::shape(keyframes, budget),
                "llm-dm" => nesy_baselines::llmdm::shape(keyframes, budget, LLMDM_ACTIONS),
                _ => nesy_baselines::statler::shape(keyframes, budget),
            };
            // One code-generation call follows the flow's own calls.
            Load {
                calls_min: shape.calls_min + 1,
                calls_max: shape.calls_max + 1,
                images_min: shape.images_min,
                images_max: shape.images_max,
            }
        }
        "code-as-policies" => Load {
            calls_min: 1,
            calls_max: 1,
            images_min: 0,
            images_max: 0,
        },
        _ => Load::default(),
    }
}

/// One row of a plan: a variant in a cell.
#[derive(Debug, Clone, Serialize)]
pub struct BudgetRow {
    /// The variant.
    pub variant: String,
    /// The factor group.
    pub group: FactorGroup,
    /// The complexity.
    pub complexity: Complexity,
    /// Units.
    pub units: usize,
    /// Units whose demo is not recorded yet (their load is unknown and not counted).
    pub unrecorded: usize,
    /// The summed load.
    pub load: Load,
}

/// The plan of a run.
#[derive(Debug, Clone, Serialize)]
pub struct CallBudget {
    /// Rows, by variant then cell.
    pub rows: Vec<BudgetRow>,
    /// The whole run.
    pub total: Load,
    /// Units whose demo is not recorded.
    pub unrecorded: usize,
}

/// The plan of a prepared run, reading keyframe counts from the demo cache.
pub fn estimate(prepared: &Prepared, cache: &DemoCache) -> CallBudget {
    let mut keyframes: BTreeMap<String, Option<u64>> = BTreeMap::new();
    let mut rows: BTreeMap<(String, FactorGroup, Complexity), BudgetRow> = BTreeMap::new();
    let mut total = Load::default();
    let mut unrecorded = 0;
    for unit in &prepared.units {
        let n = *keyframes
            .entry(unit.scenario.id.clone())
            .or_insert_with(|| cache.lookup(&unit.scenario).map(|d| d.record.keyframes as u64));
        let key = (unit.key.variant.clone(), unit.factor().group(), unit.complexity());
        let row = rows.entry(key.clone()).or_insert_with(|| BudgetRow {
            variant: key.0.clone(),
            group: key.1,
            complexity: key.2,
            units: 0,
            unrecorded: 0,
            load: Load::default(),
        });
        row.units += 1;
        match n {
            Some(n) => {
                let budget = nesy_core::benchmark::iteration_budget(unit.factor(), unit.complexity()) as u64;
                let mut load = unit_load(unit, n, budget);
                if !prepared.manifest.settings.observation.is_images() {
                    // The scenes go as text: the calls stay, the pictures do not.
                    (load.images_min, load.images_max) = (0, 0);
                }
                row.load.add(&load);
                total.add(&load);
            }
            None => {
                row.unrecorded += 1;
                unrecorded += 1;
            }
        }
    }
    CallBudget {
        rows: rows.into_values().collect(),
        total,
        unrecorded,
    }
}
