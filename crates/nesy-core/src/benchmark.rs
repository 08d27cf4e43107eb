//! The benchmark's axes: the five domain factors, the three complexities, the factor groups
//! the paper's tables pool, the per-cell configuration counts, and the exploration budget
//! every iterative method gets (`docs/benchmark.md` §6–§7).
//!
//! These live here, below the simulator, the VLM layer and the harness, because all of them
//! name a scenario's factor and complexity and none may keep its own copy.
//!
//! ```
//! use nesy_core::benchmark::{Complexity, Factor, iteration_budget, parse_scenario_id};
//!
//! let (factor, complexity) = parse_scenario_id("comb_high_11_s1").unwrap();
//! assert_eq!((factor, complexity), (Factor::Comb, Complexity::High));
//! assert_eq!(iteration_budget(factor, complexity), 30);
//! assert_eq!(factor.group().title(), "Combination");
//! assert_eq!(Factor::Obst.configurations(Complexity::High), 10);
//! ```

use std::fmt;

use serde::{Deserialize, Serialize};

/// A domain factor: what differs between the demonstration (source) and the deployment
/// (target). Serialised by its configuration name (`obst`, `affo`, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(feature = "schemars", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
pub enum Factor {
    /// Source clean → target obstructed (the target needs extra steps).
    Obst,
    /// Source obstructed → target clean (the demo has redundant steps).
    Affo,
    /// Finger-gripper source → vacuum target.
    Grip,
    /// Vacuum source → finger-gripper target.
    Vacu,
    /// Obstruction changes both ways, with or without an embodiment change.
    Comb,
}

impl Factor {
    /// All five, in the order of the paper's table.
    pub const ALL: [Factor; 5] = [
        Factor::Obst,
        Factor::Affo,
        Factor::Grip,
        Factor::Vacu,
        Factor::Comb,
    ];

    /// `obst`, `affo`, `grip`, `vacu` or `comb`.
    pub fn as_str(self) -> &'static str {
        match self {
            Factor::Obst => "obst",
            Factor::Affo => "affo",
            Factor::Grip => "grip",
            Factor::Vacu => "vacu",
            Factor::Comb => "comb",
        }
    }

    /// The factor of a configuration name (exact, lower case).
    pub fn from_name(name: &str) -> Option<Factor> {
        Factor::ALL.into_iter().find(|f| f.as_str() == name)
    }

    /// The row block of the paper's tables this factor is pooled into.
    pub fn group(self) -> FactorGroup {
        match self {
            Factor::Obst | Factor::Affo => FactorGroup::ObstructionAffordance,
            Factor::Grip | Factor::Vacu => FactorGroup::KinematicGripper,
            Factor::Comb => FactorGroup::Combination,
        }
    }

    /// Source/target configurations at a complexity (the paper's Table 6): 15/15/10, and
    /// 20/20/20 for `comb`. Each is evaluated with two seeds.
    pub fn configurations(self, complexity: Complexity) -> usize {
        match (self, complexity) {
            (Factor::Comb, _) => 20,
            (_, Complexity::Low | Complexity::Medium) => 15,
            (_, Complexity::High) => 10,
        }
    }

    /// True for the factors whose states name the end effector (`(FingerGripper)`,
    /// `(VacuumSuction)`): the authors' `ee_set`, on for `grip`, `vacu` and `comb`.
    pub fn names_embodiment(self) -> bool {
        matches!(self, Factor::Grip | Factor::Vacu | Factor::Comb)
    }
}

impl fmt::Display for Factor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The row blocks of the paper's Table 1: factor files pooled pairwise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FactorGroup {
    /// `obst` + `affo`.
    ObstructionAffordance,
    /// `grip` + `vacu`.
    KinematicGripper,
    /// `comb`.
    Combination,
}

impl FactorGroup {
    /// All three, in table order.
    pub const ALL: [FactorGroup; 3] = [
        FactorGroup::ObstructionAffordance,
        FactorGroup::KinematicGripper,
        FactorGroup::Combination,
    ];

    /// The block's title as the paper prints it.
    pub fn title(self) -> &'static str {
        match self {
            FactorGroup::ObstructionAffordance => "Obstruction & Object Affordance",
            FactorGroup::KinematicGripper => "Kinematic Config & Gripper",
            FactorGroup::Combination => "Combination",
        }
    }

    /// The factors pooled into this block.
    pub fn factors(self) -> &'static [Factor] {
        match self {
            FactorGroup::ObstructionAffordance => &[Factor::Obst, Factor::Affo],
            FactorGroup::KinematicGripper => &[Factor::Grip, Factor::Vacu],
            FactorGroup::Combination => &[Factor::Comb],
        }
    }
}

/// Task complexity (the density level of the authors' configurations).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(feature = "schemars", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
pub enum Complexity {
    /// Two subtasks at multi level 0.
    Low,
    /// Three subtasks at multi level 1.
    Medium,
    /// All four subtasks at multi level 2.
    High,
}

impl Complexity {
    /// All three, in table order.
    pub const ALL: [Complexity; 3] = [Complexity::Low, Complexity::Medium, Complexity::High];

    /// `low`, `medium` or `high`.
    pub fn as_str(self) -> &'static str {
        match self {
            Complexity::Low => "low",
            Complexity::Medium => "medium",
            Complexity::High => "high",
        }
    }

    /// The complexity of a name (exact, lower case).
    pub fn from_name(name: &str) -> Option<Complexity> {
        Complexity::ALL.into_iter().find(|c| c.as_str() == name)
    }

    /// Number of subtasks.
    pub fn subtasks(self) -> usize {
        match self {
            Complexity::Low => 2,
            Complexity::Medium => 3,
            Complexity::High => 4,
        }
    }

    /// The multi level (object-count level) of every subtask.
    pub fn multi_level(self) -> u8 {
        match self {
            Complexity::Low => 0,
            Complexity::Medium => 1,
            Complexity::High => 2,
        }
    }

    /// The complexity whose subtask count is `n` (1–2 low, 3 medium, 4 or more high), for
    /// scenes that do not come from the suite.
    pub fn of_subtask_count(n: usize) -> Complexity {
        match n {
            0..=2 => Complexity::Low,
            3 => Complexity::Medium,
            _ => Complexity::High,
        }
    }
}

impl fmt::Display for Complexity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The exploration budget of the benchmark's protocol and the paper's hyper-parameter
/// tables: 10 refinement rounds, or 15 for `comb`, doubled at high complexity (20 / 30).
/// Every iterative method, NeSyCR and the baselines alike, gets the same budget.
pub fn iteration_budget(factor: Factor, complexity: Complexity) -> usize {
    let base = if factor == Factor::Comb { 15 } else { 10 };
    if complexity == Complexity::High {
        base * 2
    } else {
        base
    }
}

/// The factor and complexity of a scenario id; `None` for any other name.
///
/// - A scenario of the 440 starts with `<factor>_<complexity>_`, e.g. `obst_low_03_s0`.
/// - A scenario of the auxiliary complexity-gap suite starts with `gap_<factor>_plus<k>_`,
///   e.g. `gap_obst_plus2_03_s1`. Its demonstration has one subtask and its target `1 + k`,
///   so its complexity is [`Complexity::of_subtask_count`] of `1 + k`: the budget follows
///   the task that has to be solved.
/// - A scenario of a real-world task's family starts with `family_<name>_`, e.g.
///   `family_drawers_03_s1`; the families are filed under Obstruction at low complexity.
///
/// ```
/// use nesy_core::benchmark::{parse_scenario_id, Complexity, Factor};
/// assert_eq!(parse_scenario_id("comb_high_07_s1"), Some((Factor::Comb, Complexity::High)));
/// assert_eq!(parse_scenario_id("gap_obst_plus3_00_s0"), Some((Factor::Obst, Complexity::High)));
/// assert_eq!(parse_scenario_id("family_drawers_03_s1"), Some((Factor::Obst, Complexity::Low)));
/// assert_eq!(parse_scenario_id("pick_place"), None);
/// ```
pub fn parse_scenario_id(id: &str) -> Option<(Factor, Complexity)> {
    let mut parts = id.split(['_', '-', '/']);
    let first = parts.next()?;
    // The real-world tasks' families are filed under Obstruction at low complexity
    // (`nesy_sim::tasks::scenario::generate_family_file`).
    if first == "family" {
        parts.next()?;
        return Some((Factor::Obst, Complexity::Low));
    }
    if first == "gap" {
        let factor = Factor::from_name(parts.next()?)?;
        let added: usize = parts.next()?.strip_prefix("plus")?.parse().ok()?;
        return Some((factor, Complexity::of_subtask_count(1 + added)));
    }
    let factor = Factor::from_name(first)?;
    let complexity = Complexity::from_name(parts.next()?)?;
    Some((factor, complexity))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_follow_the_protocol() {
        assert_eq!(iteration_budget(Factor::Obst, Complexity::Low), 10);
        assert_eq!(iteration_budget(Factor::Grip, Complexity::High), 20);
        assert_eq!(iteration_budget(Factor::Comb, Complexity::Medium), 15);
        assert_eq!(iteration_budget(Factor::Comb, Complexity::High), 30);
    }

    #[test]
    fn names_round_trip() {
        for f in Factor::ALL {
            assert_eq!(Factor::from_name(f.as_str()), Some(f));
            assert_eq!(serde_json::to_value(f).unwrap(), f.as_str());
        }
        for c in Complexity::ALL {
            assert_eq!(Complexity::from_name(c.as_str()), Some(c));
            assert_eq!(serde_json::to_value(c).unwrap(), c.as_str());
        }
        assert_eq!(parse_scenario_id("pick_place"), None);
        assert_eq!(parse_scenario_id("gap_obst"), None);
        assert_eq!(parse_scenario_id("gap_obst_minus1_00_s0"), None);
        assert_eq!(parse_scenario_id("gap_nope_plus1_00_s0"), None);
        let gap: Vec<_> = (0..4)
            .map(|k| parse_scenario_id(&format!("gap_obst_plus{k}_05_s1")))
            .collect();
        assert_eq!(
            gap,
            [
                Complexity::Low,
                Complexity::Low,
                Complexity::Medium,
                Complexity::High
            ]
            .map(|c| Some((Factor::Obst, c)))
        );
        assert_eq!(
            parse_scenario_id("obst_low_03_s0"),
            Some((Factor::Obst, Complexity::Low))
        );
    }

    #[test]
    fn the_suite_has_440_scenarios() {
        let configs: usize = Factor::ALL
            .iter()
            .flat_map(|&f| Complexity::ALL.map(|c| f.configurations(c)))
            .sum();
        assert_eq!(configs * 2, 440);
        let grouped: usize = FactorGroup::ALL.iter().map(|g| g.factors().len()).sum();
        assert_eq!(grouped, Factor::ALL.len());
    }
}
