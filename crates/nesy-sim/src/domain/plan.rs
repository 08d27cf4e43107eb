//! Planning in the true domain: nesy-core's planner over the schemas of one end effector,
//! its actions named the way the offline responder writes them. The offline responder's
//! patches and the model-free `replan` control plan here.

use nesy_core::Formula;
use nesy_core::Operator;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::Universe;
use nesy_core::planner::{self, PlannerConfig};
use nesy_core::text::normalize_action_name;
use nesy_core::{Atom, apply};

use super::{WorldDomain, semantic};
use crate::api::Embodiment;

/// The planner settings for planning a whole task in the true domain (the `replan` control,
/// `nesy task new`): greedy best-first search on h_FF with a 10 s wall limit, the limit the
/// authors give Fast Downward.
pub fn control_planner_config() -> PlannerConfig {
    PlannerConfig {
        search: planner::Search::Gbfs,
        heuristic: planner::Heuristic::HFf,
        time_limit: Some(std::time::Duration::from_secs(10)),
        ..PlannerConfig::default()
    }
}

/// The true domain grounded for planning: the schemas of one end effector over a typed
/// universe of a scene's objects, with the planner's settings.
pub struct Planning<'a> {
    /// The scene's objects, typed.
    pub universe: Universe,
    /// The end effector's schemas whose constants are in the scene.
    pub schemas: Vec<Operator>,
    /// The end effector planned for.
    pub target: Embodiment,
    /// The planner's settings.
    pub config: &'a PlannerConfig,
}

impl<'a> Planning<'a> {
    /// The true domain's schemas for the `target` end effector over a typed universe of
    /// `names`.
    pub fn over<'n>(
        world: &WorldDomain,
        names: impl IntoIterator<Item = &'n str>,
        target: Embodiment,
        config: &'a PlannerConfig,
    ) -> Planning<'a> {
        let universe = world.universe(names);
        let schemas = world.schemas_for(target, &universe);
        Planning {
            universe,
            schemas,
            target,
            config,
        }
    }

    /// Plans from `state` to `goal`; returns the printable actions and the state after them.
    pub fn plan(&self, state: &State, goal: &Formula) -> Result<(Vec<Operator>, State), String> {
        let emb = Atom::new(self.target.state_predicate(), &[]);
        let mut init = state.clone();
        init.insert(emb);
        let plan = planner::plan(&self.schemas, &self.universe, &init, goal, self.config)
            .map_err(|e| format!("planning to {goal}: {e}"))?;
        let mut ops = Vec::new();
        let mut s = state.clone();
        for step in &plan.steps {
            let op = printable(step, state.contains(&emb));
            s = apply(&s, &op).map_err(|e| format!("planned action {} does not apply: {e:?}", op.name))?;
            ops.push(op);
        }
        Ok((ops, s))
    }
}

/// An instantiated schema as the reply writes it: named by its semantic, without the
/// end-effector atom when the scene's states do not state it.
pub fn printable(step: &Operator, state_names_embodiment: bool) -> Operator {
    let name = normalize_action_name(&semantic(&step.name, &step.args)).unwrap_or_else(|| step.name.clone());
    let pre: Vec<Formula> = step
        .pre
        .iter()
        .filter(|f| {
            state_names_embodiment
                || !matches!(f, Formula::Atom(p) if p.args.is_empty()
                    && (p.pred.as_str() == "FingerGripper" || p.pred.as_str() == "VacuumSuction"))
        })
        .cloned()
        .collect();
    Operator::new(name, pre, step.eff.clone())
}

/// A plan over the true domain's schemas of `embodiment` from `state` to `goal`, with the
/// objects `objects` (and those of the state and goal), its actions named as the reference
/// responder names them. The replanning control of the benchmark uses it: the planner stage
/// of a planning method given the true domain and problem.
pub fn plan_to_goal(
    world: &WorldDomain,
    state: &State,
    goal: &Formula,
    embodiment: Embodiment,
    objects: &[Symbol],
    config: &PlannerConfig,
) -> Result<Vec<Operator>, String> {
    let mut names: Vec<Symbol> = objects.to_vec();
    names.extend(state.objects());
    let planning = Planning::over(world, names.iter().map(|s| s.as_str()), embodiment, config);
    planning.plan(state, goal).map(|(ops, _)| ops)
}
