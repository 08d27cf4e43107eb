//! Operator induction from ground truth: the recorded API call of a demonstrated
//! transition selects the true domain's schemas for that call; the binding whose grounded
//! effects reproduce s_{t+1} (and whose preconditions hold in s_t) is the answer.

use nesy_core::ExecError;
use nesy_core::Operator;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::Universe;
use nesy_core::text::normalize_action_name;
use nesy_core::{Atom, apply};
use nesy_core::{AtomPattern, Effect, Formula};
use serde::{Deserialize, Serialize};

use nesy_core::Embodiment;
use nesy_reasoner::InductionContext;
use nesy_sim::api::ApiCall;
use nesy_sim::domain::{WorldDomain, schema_instance, semantic};

/// The robot API function a schema of the true domain stands for, on an end effector.
pub fn api_function(schema: &str, embodiment: Embodiment) -> Option<&'static str> {
    let vacuum = embodiment == Embodiment::Vacuum;
    // An asset's schema (`open-front-top-drawer`) calls what the table's schema calls.
    let schema = schema_instance(schema).map_or(schema, |i| i.schema.name);
    let s = schema.strip_prefix("suction-").unwrap_or(schema);
    let release = if vacuum {
        "deactivate_vacuum"
    } else {
        "open_gripper"
    };
    Some(match s {
        s if s.starts_with("move-to-") => "move_gripper_to",
        "grasp" => "close_gripper",
        "attach" => "activate_vacuum",
        s if s.starts_with("grasp-") => "grasp_handle",
        s if s.starts_with("attach-") => "attach_vacuum_handle",
        s if s.starts_with("carry-") || s == "open-hinge-lid" || s == "close-hinge-lid" => "move_to_position",
        "put-down" | "release-into" => release,
        s if s.starts_with("drop-") => release,
        "gather-with-hook" => "gather_with_hook",
        "sweep-into" | "slide-into" | "retreat" => "move_parallel",
        s if s.ends_with("-drawer") && (s.starts_with("open-") || s.starts_with("close-")) => "move_parallel",
        s if s.starts_with("release-") => "release_handle",
        s if s.starts_with("detach-") => "detach_vacuum_handle",
        _ => return None,
    })
}

/// Whether a schema can stand for a recorded call: its own API function or, while the tool
/// holds nothing, a `move_to_position` for the move-to schemas, since that call can place the
/// open tool around an object too (the scripted experts take round fruit that way, with a
/// turned wrist). While something is held, `move_to_position` carries it or swings the lid.
fn schema_fits_call(schema: &str, embodiment: Embodiment, function: &str, tool_free: bool) -> bool {
    let own = api_function(schema, embodiment);
    own == Some(function) || tool_free && function == "move_to_position" && own == Some("move_gripper_to")
}

/// The oracle's answer for one transition.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InducedAction {
    /// The schema chosen.
    pub schema: String,
    /// Its arguments.
    pub args: Vec<Symbol>,
    /// The action semantic written in the reply (`move to surround red cube`).
    pub semantic: String,
    /// The operator as the reply states it.
    pub operator: Operator,
    /// Whether the grounded schema alone reproduces s_{t+1}; when false the reply's
    /// effects are the observed changes instead.
    pub exact: bool,
    /// Atoms of s_{t+1} the grounded schema does not produce.
    pub missing: Vec<Atom>,
    /// Atoms the grounded schema produces that s_{t+1} does not hold.
    pub unexpected: Vec<Atom>,
    /// Schema preconditions that do not hold in s_t (left out of the reply).
    pub dropped_preconditions: Vec<String>,
    /// For a transition that holds two steps (a keyframe between them was not chosen), the
    /// schema of the first, a tool step; `schema` and `args` then name both.
    pub hidden_step: Option<String>,
}

/// Why the oracle could not answer a request.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InduceError {
    /// No schema of the domain stands for the recorded call.
    #[error("no schema of the nesy world domain stands for {call} on the {embodiment} robot")]
    NoSchema {
        /// The call.
        call: String,
        /// The end effector.
        embodiment: Embodiment,
    },
}

struct Candidate {
    schema: String,
    args: Vec<Symbol>,
    op: Operator,
    mismatch: usize,
    unmet: Vec<Formula>,
    missing: Vec<Atom>,
    unexpected: Vec<Atom>,
}

/// The handle a handle schema works with, from its name (`grasp-hinge-handle` →
/// `hinge_handle`, `grasp-front-top-drawer-handle` → `front_top_drawer_handle`); the schemas
/// cannot say it in the vocabulary, which has no predicate for "the tool is at the handle".
pub(crate) fn schema_handle(schema: &str) -> Option<String> {
    let instance = schema_instance(schema)?;
    ["hinge_handle", "bottom_drawer_handle", "top_drawer_handle"]
        .into_iter()
        .find(|h| instance.schema.name.contains(&h.replace('_', "-")))
        .map(|h| instance.asset_part(h))
}

/// The loose object a call works on: the one `move_gripper_to` names, else the one held
/// after the call (taking), else the one held or surrounded before it (carrying,
/// releasing, pushing).
fn focus_object(call: Option<&ApiCall>, prev: &State, next: &State) -> Option<Symbol> {
    if let Some(c) = call
        && c.name() == "move_gripper_to"
    {
        return c.object().map(Symbol::new);
    }
    let find = |s: &State, preds: &[&str]| {
        s.iter()
            .find(|a| preds.contains(&a.pred().as_str()) && a.args().len() == 1)
            .map(|a| a.args()[0])
    };
    let holding = ["GripperHolding", "VacuumAttached"];
    let around = ["GripperSurrounding", "VacuumAligned"];
    match call.map(ApiCall::name) {
        Some("close_gripper" | "activate_vacuum") => find(next, &holding),
        // A move works on what it carries, if anything; what the open tool surrounded before
        // it is left behind, and the object it moves to is found by the bindings.
        Some("move_to_position") => find(prev, &holding),
        _ => find(prev, &holding).or_else(|| find(prev, &around)),
    }
}

/// Every type-correct binding of `schema`'s parameters; `focus`, the object the call works on,
/// fixes the first parameter when that is an item (or a kind of item, such as a tool).
fn bindings(schema: &Operator, universe: &Universe, focus: Option<Symbol>) -> Vec<Vec<Symbol>> {
    let item = Symbol::new("item");
    let item_first = schema
        .params
        .first()
        .is_some_and(|p| universe.types.is_subtype(p.ty, item));
    let focus = focus.filter(|_| item_first);
    let mut out = vec![Vec::new()];
    for (i, p) in schema.params.iter().enumerate() {
        let objects = universe.objects_of(p.ty).unwrap_or_default();
        let mut next = Vec::new();
        for prefix in &out {
            for o in &objects {
                // The object the call works on is the schema's first (item) parameter.
                if i == 0 && focus.is_some_and(|f| f != *o) {
                    continue;
                }
                let mut b = prefix.clone();
                b.push(*o);
                next.push(b);
            }
        }
        out = next;
    }
    out
}

fn evaluate(
    schema: &Operator,
    args: Vec<Symbol>,
    universe: &Universe,
    prev: &State,
    next: &State,
) -> Option<Candidate> {
    let (op, unmet, produced) = step(schema, &args, universe, prev)?;
    let d = produced.diff(next);
    Some(Candidate {
        schema: schema.name.clone(),
        args,
        mismatch: d.added.len() + d.removed.len(),
        unmet,
        missing: d.added,
        unexpected: d.removed,
        op,
    })
}

/// The lid schema a transition can stand for, when the lid's state changes. A lid swing is
/// recorded one waypoint at a time, and a waypoint half-way leaves the lid neither open nor
/// closed: where the lid's state changes, the change decides between the opening and
/// closing schemas; where it does not (`None`), the scores do.
fn lid_direction(previous: &State, next: &State) -> Option<&'static str> {
    let lid = Symbol::new("hinge_lid");
    let has = |s: &State, p: &str| s.contains(&nesy_core::Atom::from_symbols(Symbol::new(p), [lid]));
    let (p_open, p_closed) = (has(previous, "Open"), has(previous, "Closed"));
    let (n_open, n_closed) = (has(next, "Open"), has(next, "Closed"));
    if (n_open && !p_open) || (p_closed && !n_closed) {
        Some("open-hinge-lid")
    } else if (n_closed && !p_closed) || (p_open && !n_open) {
        Some("close-hinge-lid")
    } else {
        None
    }
}

/// Answers an induction request from the transition's recorded call (when the
/// demonstration has one) and the true domain.
pub fn induce(
    world: &WorldDomain,
    ctx: &InductionContext,
    call: Option<&ApiCall>,
) -> Result<InducedAction, InduceError> {
    let req = &ctx.request;
    let mut names: Vec<Symbol> = req.task.objects.clone();
    names.extend(req.previous.objects());
    names.extend(req.next.objects());
    let universe = world.universe(names.iter().map(|s| s.as_str()));
    let call_object = call.and_then(ApiCall::object);
    let tool_free = !holds_something(&req.previous);
    let schemas: Vec<Operator> = world
        .schemas_for(ctx.embodiment, &universe)
        .into_iter()
        .filter(|s| call.is_none_or(|c| schema_fits_call(&s.name, ctx.embodiment, c.name(), tool_free)))
        .filter(|s| match schema_handle(&s.name) {
            // Handle schemas need their handle in the scene, and the call's handle when it
            // names one (move_gripper_to, grasp_handle, attach_vacuum_handle).
            Some(h) => {
                universe.contains(Symbol::new(&h))
                    && (!s.name.contains("move-to-")
                        && !s.name.starts_with("grasp-")
                        && !s.name.starts_with("attach-")
                        || call_object.is_none_or(|o| o == h))
            }
            None => true,
        })
        .collect();
    let direction = lid_direction(&req.previous, &req.next);
    let schemas: Vec<Operator> = schemas
        .into_iter()
        .filter(|s| {
            let base = schema_instance(&s.name).map_or(s.name.as_str(), |i| i.schema.name);
            let name = base.strip_prefix("suction-").unwrap_or(base);
            match (name, direction) {
                ("open-hinge-lid" | "close-hinge-lid", Some(d)) => name == d,
                _ => true,
            }
        })
        .collect();
    let focus = focus_object(call, &req.previous, &req.next);
    let mut best: Option<Candidate> = None;
    for schema in &schemas {
        for args in bindings(schema, &universe, focus) {
            let Some(c) = evaluate(schema, args, &universe, &req.previous, &req.next) else {
                continue;
            };
            // Observer effects and unmet preconditions weigh the same; ties go to the
            // binding whose preconditions hold.
            let key = |c: &Candidate| (c.mismatch + c.unmet.len(), c.unmet.len());
            let better = best.as_ref().is_none_or(|b| key(&c) < key(b));
            if better {
                best = Some(c);
            }
        }
    }
    let Some(best) = best else {
        return Err(InduceError::NoSchema {
            call: call.map_or_else(|| "an unrecorded call".to_owned(), |c| c.name().to_owned()),
            embodiment: ctx.embodiment,
        });
    };
    let single = best.mismatch + best.unmet.len();
    if best.mismatch > 0
        && let Some(action) = two_steps(world, ctx, &universe, call, &schemas, single)
    {
        return Ok(action);
    }
    let exact = best.mismatch == 0;
    let pre: Vec<Formula> = best
        .op
        .pre
        .iter()
        .filter(|f| !best.unmet.contains(f))
        .cloned()
        .collect();
    let eff = if exact {
        best.op.eff.to_vec()
    } else {
        observed_changes(&req.previous, &req.next)
    };
    let text = semantic(&best.schema, &best.args);
    let name = normalize_action_name(&text).unwrap_or_else(|| best.schema.clone());
    Ok(InducedAction {
        schema: best.schema,
        args: best.args,
        semantic: text,
        operator: Operator::new(name, pre, eff),
        exact,
        missing: best.missing,
        unexpected: best.unexpected,
        dropped_preconditions: best.unmet.iter().map(|f| f.to_string()).collect(),
        hidden_step: None,
    })
}

/// Whether the end effector holds something in `state` (fingers or suction).
fn holds_something(state: &State) -> bool {
    state
        .iter()
        .any(|a| matches!(a.pred().as_str(), "GripperHolding" | "VacuumAttached"))
}

/// Whether a schema only works the tool (closes or opens it, takes or lets go of a handle)
/// without moving the arm.
fn tool_step(schema: &str, embodiment: Embodiment) -> bool {
    matches!(
        api_function(schema, embodiment),
        Some(
            "close_gripper"
                | "open_gripper"
                | "activate_vacuum"
                | "deactivate_vacuum"
                | "grasp_handle"
                | "attach_vacuum_handle"
                | "release_handle"
                | "detach_vacuum_handle"
        )
    )
}

/// A transition no one schema explains, read as two steps: a tool step, then a step that
/// fits the recorded call (from `second`). Keyframes chosen from a video can miss a grasp or
/// a release (the fingers close behind the object, suction shows nothing) but not an arm
/// motion, so the hidden step is looked for among the tool steps only. The pair must
/// reproduce s_{t+1} exactly, the second step must hold what it moves once the first is done,
/// and the two must leave fewer preconditions unmet than `single` (the best one schema's
/// observer mismatches and unmet preconditions); the best such pair is the answer.
fn two_steps(
    world: &WorldDomain,
    ctx: &InductionContext,
    universe: &Universe,
    call: Option<&ApiCall>,
    second: &[Operator],
    single: usize,
) -> Option<InducedAction> {
    let (previous, next) = (&ctx.request.previous, &ctx.request.next);
    let first_focus = focus_object(None, previous, next);
    let mut best: Option<(usize, FirstStep, Candidate)> = None;
    for first in world.schemas_for(ctx.embodiment, universe) {
        if !tool_step(&first.name, ctx.embodiment) {
            continue;
        }
        for first_args in bindings(&first, universe, first_focus) {
            let Some((op1, unmet1, middle)) = step(&first, &first_args, universe, previous) else {
                continue;
            };
            if middle == *previous || unmet1.len() >= single {
                continue;
            }
            let tool_free = !holds_something(&middle);
            let focus = focus_object(call, &middle, next);
            for schema in second {
                if call.is_some_and(|c| !schema_fits_call(&schema.name, ctx.embodiment, c.name(), tool_free))
                {
                    continue;
                }
                for args in bindings(schema, universe, focus) {
                    let Some(c) = evaluate(schema, args, universe, &middle, next) else {
                        continue;
                    };
                    // The recorded call's step must move nothing the hand does not hold once
                    // the hidden step is done: a pair that carries an object never taken
                    // explains the state by accident, e.g. an object a closing lid pushed,
                    // read as carried.
                    if c.unmet.iter().any(|u| needs_holding(u, ctx.embodiment)) {
                        continue;
                    }
                    let score = unmet1.len() + c.unmet.len();
                    if c.mismatch == 0 && score < single && best.as_ref().is_none_or(|b| score < b.0) {
                        let step = FirstStep {
                            schema: first.name.clone(),
                            args: first_args.clone(),
                            op: op1.clone(),
                            unmet: unmet1.clone(),
                        };
                        best = Some((score, step, c));
                    }
                }
            }
        }
    }
    let (_, first, second) = best?;
    Some(joined(previous, next, first, second))
}

/// Whether `literal` says the end effector holds something (`GripperHolding ?x`,
/// `VacuumAttached ?x`).
fn needs_holding(literal: &Formula, embodiment: Embodiment) -> bool {
    matches!(literal, Formula::Atom(atom) if atom.pred.as_str() == embodiment.holding_predicate())
}

/// The hidden tool step of a two-step transition, grounded.
struct FirstStep {
    schema: String,
    args: Vec<Symbol>,
    op: Operator,
    /// Its preconditions that do not hold before it.
    unmet: Vec<Formula>,
}

/// A schema grounded on `args`, the preconditions it leaves unmet in `from`, and the state
/// its effects make of `from` (applied whether or not the preconditions hold).
fn step(
    schema: &Operator,
    args: &[Symbol],
    universe: &Universe,
    from: &State,
) -> Option<(Operator, Vec<Formula>, State)> {
    let op = schema.instantiate(args, universe).ok()?;
    let unmet = match apply(from, &op) {
        Ok(_) => Vec::new(),
        Err(ExecError::Violation(v)) => v.unmet.into_iter().map(|u| u.literal).collect(),
        Err(ExecError::Ground(_)) => return None,
    };
    let unchecked = Operator::new(op.name.clone(), Vec::new(), op.eff.clone());
    let produced = apply(from, &unchecked).ok()?;
    Some((op, unmet, produced))
}

/// The one action two steps make: named by both semantics joined by `then`, holding the
/// first's preconditions and those of the second that already hold before it (unmet ones
/// left out, as for one schema), with both steps' effects (or the observed changes, should
/// the joined effects not reproduce them).
fn joined(previous: &State, next: &State, first: FirstStep, second: Candidate) -> InducedAction {
    let FirstStep {
        schema: first_schema,
        args: first_args,
        op: op1,
        unmet: unmet1,
    } = first;
    let mut pre: Vec<Formula> = op1.pre.iter().filter(|f| !unmet1.contains(f)).cloned().collect();
    for f in second.op.pre.iter() {
        let holds = apply(previous, &Operator::new("check", vec![f.clone()], Vec::new())).is_ok();
        if holds && !pre.contains(f) {
            pre.push(f.clone());
        }
    }
    let mut eff: Vec<Effect> = op1.eff.to_vec();
    eff.extend(second.op.eff.iter().cloned());
    let together = Operator::new("together", Vec::new(), eff.clone());
    if apply(previous, &together).ok().as_ref() != Some(next) {
        eff = observed_changes(previous, next);
    }
    let text = format!(
        "{} then {}",
        semantic(&first_schema, &first_args),
        semantic(&second.schema, &second.args)
    );
    let name =
        normalize_action_name(&text).unwrap_or_else(|| format!("{first_schema}-then-{}", second.schema));
    let mut args = first_args;
    args.extend(second.args);
    let dropped = unmet1
        .iter()
        .chain(&second.unmet)
        .map(|f| f.to_string())
        .collect();
    InducedAction {
        schema: format!("{first_schema} then {}", second.schema),
        args,
        semantic: text,
        operator: Operator::new(name, pre, eff),
        exact: true,
        missing: Vec::new(),
        unexpected: Vec::new(),
        dropped_preconditions: dropped,
        hidden_step: Some(first_schema),
    }
}

/// The observed changes as effects; an unchanged state is restated by one of its atoms (an
/// effect list may not be empty, and re-adding a true atom changes nothing).
pub(crate) fn observed_changes(prev: &State, next: &State) -> Vec<Effect> {
    let d = prev.diff(next);
    let mut eff: Vec<Effect> = d
        .added
        .iter()
        .map(|a| Effect::Add(AtomPattern::ground(*a)))
        .chain(d.removed.iter().map(|a| Effect::Del(AtomPattern::ground(*a))))
        .collect();
    if eff.is_empty()
        && let Some(a) = next.sorted_by_text().first()
    {
        eff.push(Effect::Add(AtomPattern::ground(**a)));
    }
    eff
}

/// The reply in the Action Prediction format.
pub(crate) fn format_reply(action: &InducedAction, call: Option<&ApiCall>) -> String {
    let call_text = call.map_or_else(
        || "no recorded call".to_owned(),
        |c| match c.object() {
            Some(o) => format!("{}({o})", c.name()),
            None => format!("{}()", c.name()),
        },
    );
    let fit = if action.hidden_step.is_some() {
        "the transition holds two steps (no keyframe between them), a tool step and then the recorded call, and together they reproduce the current state exactly".to_owned()
    } else if action.exact {
        "its effects reproduce the current state exactly".to_owned()
    } else {
        format!(
            "the observer also reported changes the schema does not model ({} missing, {} unexpected), so the effects list the observed changes",
            action.missing.len(),
            action.unexpected.len()
        )
    };
    let mut out = String::new();
    out.push_str("* Prediction Rationale:\n");
    out.push_str(&format!(
        "- Reference answer from the simulator: the recorded call {call_text} is the domain schema {} bound to ({}); {fit}.\n",
        action.schema,
        action.args.iter().map(|a| a.as_str()).collect::<Vec<_>>().join(" ")
    ));
    out.push_str("* Predicted Action:\nAction Semantic:\n");
    out.push_str(&format!("- {}\n", action.semantic));
    out.push_str("Precondition:\n");
    if action.operator.pre.is_empty() {
        out.push_str("None\n");
    }
    for p in action.operator.pre.iter() {
        out.push_str(&format!("- {p}\n"));
    }
    out.push_str("Effect:\n");
    for e in action.operator.eff.iter() {
        out.push_str(&format!("- {e}\n"));
    }
    out
}
