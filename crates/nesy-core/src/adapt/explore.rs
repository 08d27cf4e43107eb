//! Counterfactual identification (Eq. 6) and exploration with verified patches (Eq. 7–8).

use super::reasoner::{Feedback, PatchRequest, Problem, Reasoner, ReasonerErrorKind, ViolationKind};
use super::symbols::{describe_unknown, known_objects, unknown_symbols};
use super::{
    Ablation, AdaptConfig, AdaptError, Outcome, Target, Trace, TraceEvent, Verdict, ViolationInfo, WorldModel,
};
use crate::exec::{
    CompiledProcedure, GroundingCache, Report, UnmetPrecondition, format_unmet, implicit_universe,
};
use crate::formula::Formula;
use crate::operator::Operator;
use crate::patch::{AppliedPatch, apply_patch};
use crate::state::State;
use crate::text::{ParseError, RefinementReply, normalize_reply, parse_refinement_reply};
use crate::types::Universe;

/// The universe the loop verifies over: every object of the target's initial state, the
/// demonstrated procedure, the goal and the target's object list, then any object a later
/// procedure version names. It only grows. A patch that drops the last action naming some
/// object (a drawer handle the target no longer needs) therefore keeps the universe, and with
/// it every grounded action in the cache. No action names the object any more, so no atom
/// about it can become true: a `forall` over negated atoms or an `exists` over atoms (the
/// quantified forms actions are written with) has the same truth with it in range or not.
fn loop_universe(
    init: &State,
    demonstrated: &[Operator],
    goal: &Formula,
    target_objects: &[crate::symbol::Symbol],
) -> Universe {
    let mut universe = implicit_universe(init, demonstrated, Some(goal));
    for o in target_objects {
        universe.add_thing(*o);
    }
    universe
}

/// Verifies `procedure` from `init` towards `goal`, first adding to `universe` the objects
/// the procedure names that it lacks.
fn verify(
    init: &State,
    universe: &mut Universe,
    procedure: &[Operator],
    goal: &Formula,
    cache: &mut GroundingCache,
) -> Report {
    for op in procedure {
        for c in op.constants().into_iter().chain(op.args.iter().copied()) {
            universe.add_thing(c);
        }
    }
    CompiledProcedure::new_cached(universe, procedure, Some(goal), cache).verify(init)
}

/// Eq. 6: the first inconsistency of a verified procedure — the first failing step's unmet
/// preconditions, or the unmet goal literals if every step applied. `None` if the report
/// is valid.
pub fn identify(report: &Report, procedure: &[Operator]) -> Option<ViolationInfo> {
    if let Some(i) = report.first_failure {
        let unmet = match &report.steps[i].status {
            crate::exec::StepStatus::Failed { violation } => violation.unmet.clone(),
            _ => Vec::new(),
        };
        return Some(ViolationInfo {
            kind: ViolationKind::Precondition,
            failing_step: Some(i),
            action: Some(procedure[i].display_name()),
            unmet,
            state: report.failing_state.clone().unwrap_or_default(),
        });
    }
    if let Some(g) = report.goal.as_ref().filter(|g| !g.satisfied) {
        return Some(ViolationInfo {
            kind: ViolationKind::Goal,
            failing_step: None,
            action: None,
            unmet: g.unmet.clone(),
            state: report.final_state.clone(),
        });
    }
    None
}

/// How far a procedure gets: valid first, then every step applying, then fewer actions
/// left from the failing one to the end (so inserting actions before a failure that stays
/// put is no progress), then fewer unmet literals.
type Progress = (bool, bool, std::cmp::Reverse<usize>, std::cmp::Reverse<usize>);

fn progress(report: &Report) -> Progress {
    let unmet = identify_unmet(report).map_or(0, |u| u.len());
    let left = report.first_failure.map_or(0, |f| report.steps.len() - f);
    (
        report.is_valid(),
        report.first_failure.is_none(),
        std::cmp::Reverse(left),
        std::cmp::Reverse(unmet),
    )
}

fn identify_unmet(report: &Report) -> Option<Vec<UnmetPrecondition>> {
    if let Some(v) = report.first_violation() {
        return Some(v.unmet.clone());
    }
    report.goal.as_ref().map(|g| g.unmet.clone())
}

fn literal_set(unmet: &[UnmetPrecondition]) -> Vec<String> {
    let mut v: Vec<String> = unmet.iter().map(|u| u.literal.to_string()).collect();
    v.sort();
    v.dedup();
    v
}

fn strict_subset(new: &[UnmetPrecondition], old: &[UnmetPrecondition]) -> bool {
    let (new, old) = (literal_set(new), literal_set(old));
    new.len() < old.len() && new.iter().all(|x| old.contains(x))
}

/// Eq. 8: does the patched procedure resolve `violation`? The kept prefix and the inserted
/// actions must all apply, and then either the erroneous action now applies (or was
/// replaced), or it fails on a strict subset of its former unmet literals; for a goal
/// violation, every step must apply and the unmet goal literals must shrink strictly (or
/// vanish). Returns the remaining problem otherwise.
pub fn resolves(violation: &ViolationInfo, applied: &AppliedPatch, report: &Report) -> Result<(), Problem> {
    let region_end = applied.at + applied.inserted;
    let not_resolved = || Problem::NotResolved {
        failing_step: report.first_failure,
        unmet: identify_unmet(report).unwrap_or_default(),
    };
    if report.first_failure.is_some_and(|f| f < region_end) {
        return Err(not_resolved());
    }
    match violation.kind {
        ViolationKind::Precondition => {
            let p = violation.failing_step.unwrap_or(0);
            if (applied.at..applied.at + applied.removed).contains(&p) {
                return Ok(()); // the erroneous action itself was replaced or removed
            }
            let shifted = if p >= applied.at + applied.removed {
                p - applied.removed + applied.inserted
            } else {
                p
            };
            match report.first_failure {
                None => Ok(()),
                Some(f) if f > shifted => Ok(()),
                Some(f) if f == shifted => {
                    let now = report
                        .first_violation()
                        .map(|v| v.unmet.clone())
                        .unwrap_or_default();
                    if strict_subset(&now, &violation.unmet) {
                        Ok(())
                    } else {
                        Err(not_resolved())
                    }
                }
                Some(_) => Err(not_resolved()),
            }
        }
        ViolationKind::Goal => {
            if report.first_failure.is_some() {
                return Err(not_resolved());
            }
            match &report.goal {
                Some(g) if g.satisfied || strict_subset(&g.unmet, &violation.unmet) => Ok(()),
                _ => Err(not_resolved()),
            }
        }
        ViolationKind::Unidentified => Ok(()),
    }
}

fn describe(problem: &Problem, procedure: &[Operator]) -> String {
    match problem {
        Problem::Unparsable { error } => format!("The reply could not be read: {error}."),
        Problem::UnknownSymbols { unknown } => describe_unknown(unknown),
        Problem::MultiplePatches { count } => format!(
            "The reply held {count} SEARCH/REPLACE blocks; exactly one is required. Nothing was applied."
        ),
        Problem::PatchDidNotApply { error } => format!("The patch was not applied: {error}."),
        Problem::NotResolved {
            failing_step: Some(i),
            unmet,
        } => format!(
            "After the patch the procedure still fails at step {} ({}) with these unfulfilled preconditions:\n{}",
            i + 1,
            procedure.get(*i).map_or_else(String::new, |o| o.display_name()),
            format_unmet(unmet)
        ),
        Problem::NotResolved {
            failing_step: None,
            unmet,
        } => format!(
            "After the patch every action applies but these goal conditions still do not hold:\n{}",
            format_unmet(unmet)
        ),
        Problem::Ungroundable { error } => format!("The patched procedure could not be grounded: {error}."),
        other => format!("{other:?}"),
    }
}

/// The result of exploration.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExplorationResult {
    /// How it ended.
    pub outcome: Outcome,
}

/// Identification and exploration from the target's initial state (Algorithm 1, lines
/// 9–20), within `config.budget` patch proposals.
pub async fn explore<R: Reasoner>(
    reasoner: &mut R,
    world_model: &WorldModel,
    target: &Target,
    config: &AdaptConfig,
    trace: &mut Trace,
) -> Result<ExplorationResult, AdaptError> {
    let ablation = config.ablation;
    let mut state = ExplorationLoop::new(world_model, target, ablation);
    // With identification and verification both ablated nothing tells the loop whether a
    // revision helped, so it makes one revision (retrying only replies that fail to parse
    // or match) and stops.
    let single_shot = !ablation.identification && !ablation.verification;
    loop {
        state.record_identification(trace);
        let violation = identify(&state.report, &state.procedure);
        let finished = if single_shot {
            state.revised
        } else {
            violation.is_none()
        };
        if finished || state.iteration >= config.budget {
            return Ok(state.finish());
        }
        let violation = violation.unwrap_or_else(|| unidentified(target));
        let (request, visible) = state.next_request(violation);
        let reply = match reasoner.propose_patch(&request).await {
            Ok(reply) => reply,
            // The reasoner has no proposal at all (an offline responder's planner found none):
            // asking again would get the same answer, so the loop stops, unresolved.
            Err(e) if e.kind == ReasonerErrorKind::Exhausted => {
                trace.events.push(TraceEvent::GaveUp {
                    iteration: state.iteration,
                    message: e.message,
                });
                // The loop only asks while there is a violation, so the report is not valid
                // here and `finish` returns the unresolved outcome.
                return Ok(state.finish());
            }
            Err(e) => return Err(e.into()),
        };
        state.cached_request = Some((state.procedure_version, request));
        let this_iteration = state.iteration;
        state.iteration += 1;
        state.handle_reply(this_iteration, reply, &visible, trace);
    }
}

/// What the exploration loop carries from one proposal to the next.
struct ExplorationLoop<'a> {
    target: &'a Target,
    goal: &'a Formula,
    ablation: Ablation,
    procedure: Vec<Operator>,
    /// Every verification of this loop runs over the same initial state and goal, and
    /// successive procedures share most actions: each distinct action is grounded once.
    cache: GroundingCache,
    universe: Universe,
    report: Report,
    /// The procedure that got furthest so far, returned if the loop ends unresolved.
    best: (Progress, Vec<Operator>),
    feedback: Vec<Feedback>,
    last_violation: Option<ViolationInfo>,
    iteration: usize,
    /// Whether a patch was accepted: a single-shot loop stops after one.
    revised: bool,
    /// Identification is recorded once per procedure version, not once per proposal.
    identified: bool,
    /// Incremented whenever a patch is accepted; with the violation, it says whether the
    /// last request can be reused.
    procedure_version: usize,
    cached_request: Option<(usize, PatchRequest)>,
}

impl<'a> ExplorationLoop<'a> {
    /// Verifies the world model's procedure on the target, the starting point of the loop.
    fn new(world_model: &'a WorldModel, target: &'a Target, ablation: Ablation) -> Self {
        let goal = &world_model.goal;
        let procedure = world_model.procedure.clone();
        let mut cache = GroundingCache::default();
        let mut universe = loop_universe(&target.init, &procedure, goal, &target.task.objects);
        let report = verify(&target.init, &mut universe, &procedure, goal, &mut cache);
        let best = (progress(&report), procedure.clone());
        ExplorationLoop {
            target,
            goal,
            ablation,
            procedure,
            cache,
            universe,
            report,
            best,
            feedback: Vec::new(),
            last_violation: None,
            iteration: 0,
            revised: false,
            identified: false,
            procedure_version: 0,
            cached_request: None,
        }
    }

    /// Traces the current procedure's verification, once per procedure version, when
    /// identification or verification is on.
    fn record_identification(&mut self, trace: &mut Trace) {
        if (self.ablation.identification || self.ablation.verification) && !self.identified {
            self.identified = true;
            trace.events.push(TraceEvent::Identification {
                iteration: self.iteration,
                procedure: self.procedure.clone(),
                report: self.report.clone(),
            });
        }
    }

    /// The outcome when the loop stops now.
    fn finish(self) -> ExplorationResult {
        finish(
            self.procedure,
            self.report,
            self.best.1,
            self.last_violation,
            self.iteration,
        )
    }

    /// The patch request for `violation`, and the violation the reasoner is shown (none
    /// without identification). Feedback about an earlier violation is dropped first.
    fn next_request(&mut self, violation: ViolationInfo) -> (PatchRequest, ViolationInfo) {
        if self.last_violation.as_ref().is_some_and(|v| *v != violation) {
            self.feedback.clear();
        }
        // A rejected proposal leaves the procedure and the violation as they were: the next
        // request differs only in its iteration and feedback, so the previous one is reused
        // instead of copying the procedure again.
        let reusable = self.cached_request.take().filter(|(v, _)| {
            *v == self.procedure_version && self.last_violation.as_ref() == Some(&violation)
        });
        let request = match reusable {
            Some((_, mut request)) => {
                request.iteration = self.iteration;
                request.feedback = self.feedback.clone();
                request
            }
            None => patch_request(
                self.ablation.identification,
                self.iteration,
                self.target,
                &self.procedure,
                &violation,
                &self.feedback,
            ),
        };
        let visible = if self.ablation.identification {
            violation.clone()
        } else {
            unidentified(self.target)
        };
        self.last_violation = Some(violation);
        (request, visible)
    }

    /// Parses, applies and verifies the reply to proposal `this_iteration`, then accepts
    /// or rejects it.
    fn handle_reply(
        &mut self,
        this_iteration: usize,
        reply: String,
        visible: &ViolationInfo,
        trace: &mut Trace,
    ) {
        let parsed = parse_refinement_reply(&normalize_reply(&reply));
        let near = visible
            .failing_step
            .unwrap_or(if visible.kind == ViolationKind::Goal {
                self.procedure.len()
            } else {
                0
            });
        let attempt = self.try_reply(parsed.as_ref(), visible, near);
        let parsed = parsed.ok();
        match attempt {
            Ok((applied, new_report)) => {
                trace.events.push(TraceEvent::Proposal {
                    iteration: this_iteration,
                    reply,
                    parsed,
                    verdict: Verdict::Accepted {
                        checked: self.ablation.verification,
                    },
                    procedure_after: Some(applied.procedure.clone()),
                });
                self.accept(applied, new_report);
            }
            Err(problem) => {
                let fb = rejection(
                    this_iteration,
                    &reply,
                    parsed.as_ref(),
                    &self.procedure,
                    near,
                    problem,
                );
                self.feedback.push(fb.clone());
                trace.events.push(TraceEvent::Proposal {
                    iteration: this_iteration,
                    reply,
                    parsed,
                    verdict: Verdict::Rejected { feedback: fb },
                    procedure_after: None,
                });
            }
        }
    }

    /// The patched procedure and its report if the reply holds one patch, names only known
    /// symbols, applies near step `near` and passes [`check_proposal`]; else the problem.
    fn try_reply(
        &mut self,
        parsed: Result<&RefinementReply, &ParseError>,
        visible: &ViolationInfo,
        near: usize,
    ) -> Result<(AppliedPatch, Report), Problem> {
        let r = parsed.map_err(|e| Problem::Unparsable { error: e.clone() })?;
        if r.patches.len() > 1 {
            return Err(Problem::MultiplePatches {
                count: r.patches.len(),
            });
        }
        let inserted: Vec<&Operator> = r.patches[0].replace.iter().collect();
        self.check_symbols(&inserted)?;
        let applied = apply_patch(&self.procedure, &r.patches[0], near)
            .map_err(|error| Problem::PatchDidNotApply { error })?;
        let new_report = verify(
            &self.target.init,
            &mut self.universe,
            &applied.procedure,
            self.goal,
            &mut self.cache,
        );
        check_proposal(self.ablation, visible, &applied, &new_report, &self.report)?;
        Ok((applied, new_report))
    }

    /// Rejects inserted actions that name a predicate or object the target does not know.
    fn check_symbols(&self, inserted: &[&Operator]) -> Result<(), Problem> {
        let target = self.target;
        // Names: the scene's, the initial state's, and those the procedure already uses
        // (a patch may keep an action on an object the target no longer needs).
        let objects = (!target.scene_names.is_empty()).then(|| {
            known_objects(
                &target.scene_names,
                [&target.init],
                self.procedure.iter().flat_map(|op| op.constants()),
            )
        });
        let unknown = unknown_symbols(inserted, &target.task.vocabulary, objects.as_deref());
        if !unknown.is_empty() {
            return Err(Problem::UnknownSymbols { unknown });
        }
        Ok(())
    }

    /// Makes an accepted patch the current procedure, remembering it if it gets furthest.
    fn accept(&mut self, applied: AppliedPatch, new_report: Report) {
        self.procedure = applied.procedure;
        self.procedure_version += 1;
        self.report = new_report;
        self.revised = true;
        self.identified = false;
        self.feedback.clear();
        let p = progress(&self.report);
        if p > self.best.0 {
            self.best = (p, self.procedure.clone());
        }
    }
}

/// The outcome once the loop stops: adapted if the procedure is consistent and reaches the
/// goal, else unresolved with the best and the last procedure.
fn finish(
    procedure: Vec<Operator>,
    report: Report,
    best: Vec<Operator>,
    last_violation: Option<ViolationInfo>,
    iterations: usize,
) -> ExplorationResult {
    let outcome = if report.is_valid() {
        Outcome::Adapted {
            procedure,
            report,
            iterations,
        }
    } else {
        Outcome::Unresolved {
            best,
            last: procedure,
            last_violation,
            iterations,
        }
    };
    ExplorationResult { outcome }
}

/// What a request shows when identification is off (or found nothing): the procedure and
/// the initial state, no failing step and no unmet literals.
fn unidentified(target: &Target) -> ViolationInfo {
    ViolationInfo {
        kind: ViolationKind::Unidentified,
        failing_step: None,
        action: None,
        unmet: Vec::new(),
        state: target.init.clone(),
    }
}

/// The patch request for `violation`: split at the failing step with identification, the
/// whole procedure as "remaining" without it.
fn patch_request(
    identification: bool,
    iteration: usize,
    target: &Target,
    procedure: &[Operator],
    violation: &ViolationInfo,
    feedback: &[Feedback],
) -> PatchRequest {
    if identification {
        let split = violation.failing_step.unwrap_or(procedure.len());
        PatchRequest {
            iteration,
            task: target.task.clone(),
            kind: violation.kind,
            procedure: procedure.to_vec(),
            executed: procedure[..split].to_vec(),
            erroneous: violation.failing_step.map(|i| procedure[i].clone()),
            remaining: procedure.get(split + 1..).map(|r| r.to_vec()).unwrap_or_default(),
            failing_step: violation.failing_step,
            initial_state: target.init.clone(),
            error_state: violation.state.clone(),
            unmet: violation.unmet.clone(),
            feedback: feedback.to_vec(),
        }
    } else {
        PatchRequest {
            iteration,
            task: target.task.clone(),
            kind: ViolationKind::Unidentified,
            procedure: procedure.to_vec(),
            executed: Vec::new(),
            erroneous: None,
            remaining: procedure.to_vec(),
            failing_step: None,
            initial_state: target.init.clone(),
            error_state: target.init.clone(),
            unmet: Vec::new(),
            feedback: feedback.to_vec(),
        }
    }
}

/// The verification of an applied proposal (Eq. 8): with identification it must resolve the
/// violation it was asked about; without, it must make the executor get further. With
/// verification off every applied proposal passes.
fn check_proposal(
    ablation: Ablation,
    visible: &ViolationInfo,
    applied: &AppliedPatch,
    new_report: &Report,
    report: &Report,
) -> Result<(), Problem> {
    if !ablation.verification {
        return Ok(());
    }
    if ablation.identification {
        return resolves(visible, applied, new_report);
    }
    if progress(new_report) <= progress(report) {
        return Err(Problem::NotResolved {
            failing_step: new_report.first_failure,
            unmet: identify_unmet(new_report).unwrap_or_default(),
        });
    }
    Ok(())
}

/// The feedback for a rejected reply. A proposal that applied but did not resolve the
/// violation is described with the procedure it would have produced.
fn rejection(
    attempt: usize,
    reply: &str,
    parsed: Option<&RefinementReply>,
    procedure: &[Operator],
    near: usize,
    problem: Problem,
) -> Feedback {
    let candidate_procedure = match &problem {
        Problem::NotResolved { .. } => parsed
            .and_then(|r| apply_patch(procedure, &r.patches[0], near).ok())
            .map(|a| a.procedure)
            .unwrap_or_default(),
        _ => Vec::new(),
    };
    Feedback {
        attempt,
        reply: reply.to_owned(),
        message: describe(&problem, &candidate_procedure),
        problem,
    }
}
