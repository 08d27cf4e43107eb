//! The true domain against the simulator: for expert runs on both end effectors, every
//! observed transition (state before and after each successful action call) is matched by
//! a schema of `assets/pddl/nesy-world.pddl` for that call, and the oracle's induced
//! operator verifies against the transition (nesy-core's Eq. 3 check, exact). How many
//! transitions the grounded schema reproduces by itself is counted and printed; the rest
//! are the observer effects the README documents.

use nesy_core::Embodiment;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::adapt::{InductionRequest, TaskContext, TransitionCheck, check_transition};
use nesy_core::{Tier, Vocabulary};
use nesy_oracle::induce;
use nesy_reasoner::InductionContext;
use nesy_sim::api::ApiCall;
use nesy_sim::domain::WorldDomain;
use nesy_sim::perception::observer::observe;
use nesy_sim::scene::SubtaskKind;
use nesy_sim::tasks::{SubtaskConfig, TaskConfig};
use nesy_sim::world::Sim;

use crate::common::Keyframes;

struct Transitions {
    objects: Vec<Symbol>,
    states: Vec<State>,
    calls: Vec<ApiCall>,
}

fn expert_run(kind: SubtaskKind, obst: u8, multi: u8, embodiment: Embodiment, variant: u64) -> Transitions {
    let cfg = TaskConfig {
        subtasks: vec![SubtaskConfig {
            kind,
            variant,
            obst_level: obst,
            multi_level: multi,
        }],
        episode: variant,
        embodiment,
        embodiment_in_state: true,
    };
    let task = cfg.generate().unwrap();
    let mut sim = Sim::new(&task.scene).unwrap();
    let objects = nesy_sim::perception::observer::snapshot(&sim)
        .objects
        .iter()
        .map(|o| Symbol::new(&o.name))
        .collect();
    let init = observe(&sim);
    sim.add_hook(Box::new(Keyframes::default()));
    nesy_sim::tasks::experts::run(&mut sim, &task.scene).unwrap();
    let k = sim.hook::<Keyframes>().unwrap();
    let mut states = vec![init];
    states.extend(k.calls.iter().map(|(_, s)| s.clone()));
    Transitions {
        objects,
        states,
        calls: k.calls.iter().map(|(c, _)| c.clone()).collect(),
    }
}

#[test]
fn every_expert_transition_matches_a_schema_and_verifies() {
    let world = WorldDomain::builtin().unwrap();
    let mut total = 0;
    let mut exact = 0;
    let mut report = Vec::new();
    for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
        for kind in SubtaskKind::ALL {
            for obst in [0, 2] {
                let run = expert_run(kind, obst, 0, embodiment, 1);
                let task = TaskContext {
                    instruction: kind.instruction().into(),
                    objects: run.objects.clone(),
                    tier: Tier::Extended,
                    vocabulary: Vocabulary::default(),
                };
                for (t, call) in run.calls.iter().enumerate() {
                    let (prev, next) = (&run.states[t], &run.states[t + 1]);
                    let ctx = InductionContext {
                        request: InductionRequest {
                            step: t,
                            attempt: 0,
                            previous: prev.clone(),
                            next: next.clone(),
                            diff: prev.diff(next),
                            task: task.clone(),
                            feedback: Vec::new(),
                        },
                        embodiment,
                    };
                    let action = induce(world, &ctx, Some(call))
                        .unwrap_or_else(|e| panic!("{embodiment} {kind} obst {obst} step {t} {call:?}: {e}"));
                    check_transition(prev, next, &action.operator, &run.objects, TransitionCheck::Exact)
                        .unwrap_or_else(|p| {
                            panic!(
                                "{embodiment} {kind} obst {obst} step {t}: {p:?}\n{}",
                                action.operator
                            )
                        });
                    total += 1;
                    if action.exact && action.dropped_preconditions.is_empty() {
                        exact += 1;
                    } else {
                        report.push(format!(
                            "{embodiment} {kind} obst {obst} step {t} {} ({}): missing {:?} unexpected {:?} unmet pre {:?}",
                            action.schema,
                            call.name(),
                            action.missing.iter().map(|a| a.to_string()).collect::<Vec<_>>(),
                            action.unexpected.iter().map(|a| a.to_string()).collect::<Vec<_>>(),
                            action.dropped_preconditions
                        ));
                    }
                }
            }
        }
    }
    for line in &report {
        println!("{line}");
    }
    println!(
        "{exact}/{total} transitions reproduced exactly by their grounded schema with every precondition holding"
    );
    // The schemas must model the great majority of what the observer reports.
    assert!(exact * 10 >= total * 8, "{exact}/{total}");
}
