//! Symbolic world-model construction (Eq. 3): induce, verify, re-predict.

use serde::{Deserialize, Serialize};

use super::reasoner::{Feedback, InductionRequest, Problem, Reasoner};
use super::symbols::{describe_unknown, known_objects, unknown_symbols};
use super::{
    AdaptConfig, AdaptError, Demonstration, Trace, TraceEvent, TransitionCheck, Verdict, derive_goal,
};
use crate::exec::{ExecError, apply_in, format_unmet, implicit_universe};
use crate::formula::Formula;
use crate::operator::Operator;
use crate::state::State;
use crate::symbol::Symbol;
use crate::text::{InductionReply, ParseError, normalize_reply, parse_induction_reply};

/// The verified symbolic world model W of a demonstration.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct WorldModel {
    /// The demonstrated procedure π = a_1 … a_{N−1}.
    pub procedure: Vec<Operator>,
    /// The demonstrated states s_1 … s_N.
    pub states: Vec<State>,
    /// The goal derived from s_N.
    pub goal: Formula,
    /// Transitions whose operator never verified; their last parsable attempt is used.
    pub unverified_steps: Vec<usize>,
}

impl WorldModel {
    /// True if every operator was verified against its transition.
    pub fn is_verified(&self) -> bool {
        self.unverified_steps.is_empty()
    }
}

/// Checks an induced operator against its transition: preconditions in `prev`, and the
/// successor against `next` under `check`. Quantifiers range over `objects` (the scene's
/// objects) plus every object the states and the operator mention, all typed `thing`.
/// Returns the problem if it fails.
pub fn check_transition(
    prev: &State,
    next: &State,
    op: &Operator,
    objects: &[Symbol],
    check: TransitionCheck,
) -> Result<(), Problem> {
    let mut universe = implicit_universe(prev, std::slice::from_ref(op), None);
    for o in next.objects().into_iter().chain(objects.iter().copied()) {
        universe.add_thing(o);
    }
    let produced = match apply_in(&universe, prev, op) {
        Ok(s) => s,
        Err(ExecError::Violation(v)) => return Err(Problem::PreconditionsUnmet { unmet: v.unmet }),
        Err(ExecError::Ground(error)) => return Err(Problem::Ungroundable { error }),
    };
    let (missing, unexpected) = match check {
        TransitionCheck::Exact => {
            let d = produced.diff(next);
            (d.added, d.removed)
        }
        TransitionCheck::ChangedAtoms => {
            let demo = prev.diff(next);
            let missing = demo
                .added
                .iter()
                .filter(|a| !produced.contains(a))
                .copied()
                .collect();
            let unexpected = demo
                .removed
                .iter()
                .filter(|a| produced.contains(a))
                .copied()
                .collect();
            (missing, unexpected)
        }
    };
    if missing.is_empty() && unexpected.is_empty() {
        Ok(())
    } else {
        Err(Problem::EffectMismatch { missing, unexpected })
    }
}

/// The prose the next induction prompt shows for a rejected attempt.
fn describe(problem: &Problem) -> String {
    let atoms = |v: &[crate::atom::Atom]| {
        let mut s: Vec<String> = v.iter().map(|a| format!("- {a}")).collect();
        s.sort();
        s.join("\n")
    };
    match problem {
        Problem::Unparsable { error } => format!("The reply could not be read: {error}."),
        Problem::UnknownSymbols { unknown } => describe_unknown(unknown),
        Problem::Ungroundable { error } => format!("The operator could not be grounded: {error}."),
        Problem::PreconditionsUnmet { unmet } => {
            format!(
                "These preconditions do not hold in the previous state:\n{}",
                format_unmet(unmet)
            )
        }
        Problem::EffectMismatch { missing, unexpected } => {
            let mut s =
                String::from("Applying the operator to the previous state does not give the current state.");
            if !missing.is_empty() {
                s.push_str(&format!(
                    "\nThe current state holds these atoms, which the effects do not produce:\n{}",
                    atoms(missing)
                ));
            }
            if !unexpected.is_empty() {
                s.push_str(&format!(
                    "\nThe effects produce these atoms, which the current state does not hold:\n{}",
                    atoms(unexpected)
                ));
            }
            s
        }
        other => format!("{other:?}"),
    }
}

/// Builds the world model: one verified operator per transition, re-predicting with the
/// verifier's feedback up to `config.induction_tries` times.
pub async fn construct_world_model<R: Reasoner>(
    reasoner: &mut R,
    demo: &Demonstration,
    config: &AdaptConfig,
    trace: &mut Trace,
) -> Result<WorldModel, AdaptError> {
    if demo.states.len() < 2 {
        return Err(AdaptError::TooShort(demo.states.len()));
    }
    let tries = config.induction_tries.max(1);
    let mut procedure = Vec::with_capacity(demo.states.len() - 1);
    let mut unverified_steps = Vec::new();
    let induction = Induction {
        demo,
        config,
        demo_objects: known_objects(&demo.task.objects, &demo.states, []),
        tries,
    };
    for (step, pair) in demo.states.windows(2).enumerate() {
        let transition = Transition {
            step,
            prev: &pair[0],
            next: &pair[1],
        };
        let (accepted, last_parsed) = induction.induce(reasoner, &transition, trace).await?;
        match (accepted, last_parsed) {
            (Some(op), _) => procedure.push(op),
            (None, Some(op)) => {
                unverified_steps.push(step);
                procedure.push(op);
            }
            (None, None) => {
                return Err(AdaptError::NoOperator {
                    step,
                    attempts: tries,
                });
            }
        }
    }
    if config.drop_unconditioned {
        procedure.retain(|op| !op.pre.is_empty());
    }
    let goal = if config.goal_check {
        derive_goal(&demo.states, &demo.task.vocabulary)
    } else {
        Formula::And(Vec::new())
    };
    let wm = WorldModel {
        procedure,
        states: demo.states.clone(),
        goal,
        unverified_steps,
    };
    trace.events.push(TraceEvent::WorldModel {
        procedure: wm.procedure.clone(),
        goal: wm.goal.clone(),
        unverified_steps: wm.unverified_steps.clone(),
    });
    Ok(wm)
}

/// One demonstrated transition: step `step` leads from `prev` to `next`.
struct Transition<'a> {
    step: usize,
    prev: &'a State,
    next: &'a State,
}

/// What inducing every transition's operator shares: the demonstration, the settings, the
/// objects an operator may name and the number of attempts per transition.
struct Induction<'a> {
    demo: &'a Demonstration,
    config: &'a AdaptConfig,
    demo_objects: Vec<Symbol>,
    tries: usize,
}

impl Induction<'_> {
    /// Asks for the operator of `transition` until one passes or the tries run out. Returns
    /// the accepted operator, if any, and the last one that parsed (the fallback for an
    /// unverified step).
    async fn induce<R: Reasoner>(
        &self,
        reasoner: &mut R,
        transition: &Transition<'_>,
        trace: &mut Trace,
    ) -> Result<(Option<Operator>, Option<Operator>), AdaptError> {
        let Transition { step, prev, next } = *transition;
        let mut feedback: Vec<Feedback> = Vec::new();
        let mut last_parsed: Option<Operator> = None;
        let mut accepted = None;
        for attempt in 0..self.tries {
            let request = InductionRequest {
                step,
                attempt,
                previous: prev.clone(),
                next: next.clone(),
                diff: prev.diff(next),
                task: self.demo.task.clone(),
                feedback: feedback.clone(),
            };
            let reply = reasoner.induce_operator(&request).await?;
            let parsed = parse_induction_reply(&normalize_reply(&reply));
            let problem = self.problem(parsed.as_ref(), transition);
            let verdict = match &problem {
                None => Verdict::Accepted {
                    checked: self.config.ablation.world_model,
                },
                Some(p) => {
                    let fb = Feedback {
                        attempt,
                        reply: reply.clone(),
                        problem: p.clone(),
                        message: describe(p),
                    };
                    feedback.push(fb.clone());
                    Verdict::Rejected { feedback: fb }
                }
            };
            let parsed_ok = parsed.ok();
            if let Some(r) = &parsed_ok {
                last_parsed = Some(r.operator.clone());
            }
            let done = problem.is_none();
            trace.events.push(TraceEvent::Induction {
                step,
                attempt,
                reply,
                parsed: parsed_ok.clone(),
                verdict,
            });
            if done {
                accepted = parsed_ok.map(|r| r.operator);
                break;
            }
        }
        Ok((accepted, last_parsed))
    }

    /// Why a reply's operator is rejected for `transition`, or `None` if it passes.
    fn problem(
        &self,
        parsed: Result<&InductionReply, &ParseError>,
        transition: &Transition<'_>,
    ) -> Option<Problem> {
        let demo = self.demo;
        match parsed {
            Err(error) => Some(Problem::Unparsable { error: error.clone() }),
            Ok(r) => {
                // Names are read before anything is verified, with or without the check.
                let unknown = unknown_symbols(
                    &[&r.operator],
                    &demo.task.vocabulary,
                    Some(self.demo_objects.as_slice()),
                );
                if !unknown.is_empty() {
                    Some(Problem::UnknownSymbols { unknown })
                } else if !self.config.ablation.world_model {
                    None
                } else {
                    check_transition(
                        transition.prev,
                        transition.next,
                        &r.operator,
                        &demo.task.objects,
                        self.config.transition_check,
                    )
                    .err()
                }
            }
        }
    }
}
