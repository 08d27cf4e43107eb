//! The true domain of the simulated world (`assets/pddl/nesy-world.pddl`): loading it with
//! the predicates' CamelCase spelling restored, typing a scene's objects, naming grounded
//! actions, and ([`schemas`]) what each schema does on the robot.
//!
//! The offline responder answers from it, the model-free `replan` control plans in it,
//! `nesy scenarios pddl` writes problems for it, and the template compiler maps its schemas
//! to robot-API calls.

mod plan;
mod schemas;

use std::sync::OnceLock;

use nesy_core::Atom;
use nesy_core::Operator;
use nesy_core::State;
use nesy_core::Symbol;
use nesy_core::builtin_predicates;
use nesy_core::pddl::{Domain, PredicateDecl, Problem, declared_predicate_spellings, parse_domain};
use nesy_core::text::ParseError;
use nesy_core::{AtomPattern, Effect, Formula};
use nesy_core::{TypeError, Universe};

use crate::api::Embodiment;
use crate::perception;
use crate::scene::parts;

/// The domain file as committed.
pub const NESY_WORLD_PDDL: &str = include_str!("../../../../assets/pddl/nesy-world.pddl");

pub use plan::{Planning, control_planner_config, plan_to_goal, printable};
pub use schemas::{
    Motion, Schema, SchemaInstance, SchemaKind, asset_of, asset_prefixes, instance_name, is_asset_part,
    kind_of, schema, schema_instance, schema_names, schemas, split_asset_part,
};

/// Why the true domain could not be loaded (a defect of nesy's own files).
#[derive(Debug, Clone, thiserror::Error)]
pub enum DomainError {
    /// The PDDL does not parse.
    #[error("assets/pddl/nesy-world.pddl: {0}")]
    Parse(#[from] ParseError),
    /// A type declaration is inconsistent.
    #[error("assets/pddl/nesy-world.pddl: {0}")]
    Types(#[from] TypeError),
}

/// The true domain: schemas with the vocabulary's spelling, split by end effector.
#[derive(Debug, Clone)]
pub struct WorldDomain {
    /// The parsed domain (schemas re-cased).
    pub domain: Domain,
}

/// The embodiment a schema belongs to: vacuum schemas mention a vacuum predicate.
pub fn schema_embodiment(schema: &Operator) -> Embodiment {
    let mut atoms = Vec::new();
    schema.pre.iter().for_each(|f| collect_preds(f, &mut atoms));
    if atoms.iter().any(|p| p.as_str().starts_with("Vacuum")) {
        Embodiment::Vacuum
    } else {
        Embodiment::Finger
    }
}

fn collect_preds(f: &Formula, out: &mut Vec<Symbol>) {
    match f {
        Formula::Atom(p) => out.push(p.pred),
        Formula::Eq(..) => {}
        Formula::Not(x) => collect_preds(x, out),
        Formula::And(xs) | Formula::Or(xs) => xs.iter().for_each(|x| collect_preds(x, out)),
        Formula::Imply(a, b) => {
            collect_preds(a, out);
            collect_preds(b, out)
        }
        Formula::Forall(_, x) | Formula::Exists(_, x) => collect_preds(x, out),
    }
}

impl WorldDomain {
    /// Parses [`NESY_WORLD_PDDL`] (once per process).
    pub fn builtin() -> Result<&'static WorldDomain, DomainError> {
        static DOMAIN: OnceLock<Result<WorldDomain, DomainError>> = OnceLock::new();
        DOMAIN
            .get_or_init(|| WorldDomain::parse(NESY_WORLD_PDDL))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Parses a domain text and restores the predicates' spelling (PDDL names are read in
    /// lower case): the vocabulary's, and for predicates beyond it (`OnMagnet`) the one the
    /// text's `(:predicates ...)` block writes.
    pub fn parse(text: &str) -> Result<WorldDomain, DomainError> {
        let mut domain = parse_domain(text)?;
        let mut names: Vec<Symbol> = builtin_predicates().iter().map(|p| p.name).collect();
        names.extend(declared_predicate_spellings(text)?);
        let recase = |s: Symbol| {
            names
                .iter()
                .find(|n| n.as_str().eq_ignore_ascii_case(s.as_str()))
                .copied()
                .unwrap_or(s)
        };
        for action in &mut domain.actions {
            action.pre = action.pre.iter().map(|f| recase_formula(f, &recase)).collect();
            action.eff = action.eff.iter().map(|e| recase_effect(e, &recase)).collect();
        }
        for p in &mut domain.predicates {
            p.name = recase(p.name);
        }
        // Check the type declarations once, so universes built later cannot fail on them.
        let mut u = Universe::new();
        for (t, parent) in &domain.types {
            u.types.declare(*t, *parent)?;
        }
        Ok(WorldDomain { domain })
    }

    /// The schemas of one end effector for a scene: those whose constants are all objects
    /// of the scene, then, for each asset named with a prefix (`front_drawer_body`), the
    /// asset's schemas with its parts renamed ([`SchemaInstance`]). With two or more assets,
    /// opening a lid or drawer, and reaching for or taking its handle, also needs every
    /// other asset's moving link that would stand in its way to be shut: `(not (and (Blocks o x) (Open o)))` for each other link `o`
    /// (the observer states `Blocks` where the scene's geometry has it). A scene with one
    /// asset under the bare names gets the domain file's schemas unchanged.
    pub fn schemas_for(&self, embodiment: Embodiment, universe: &Universe) -> Vec<Operator> {
        let own: Vec<&Operator> = self
            .domain
            .actions
            .iter()
            .filter(|a| schema_embodiment(a) == embodiment)
            .collect();
        let mut out: Vec<Operator> = own
            .iter()
            .filter(|a| a.constants().iter().all(|c| universe.contains(*c)))
            .map(|a| (*a).clone())
            .collect();
        let names: Vec<&str> = universe.objects().iter().map(|(o, _)| o.as_str()).collect();
        for prefix in asset_prefixes(names.iter().copied()) {
            for action in &own {
                let Some((_, asset_parts)) = asset_of(&action.name) else {
                    continue;
                };
                let renamed = action.with_constants_renamed(instance_name(&action.name, &prefix), &|c| {
                    if asset_parts.contains(&c.as_str()) {
                        Symbol::new(&format!("{prefix}{c}"))
                    } else {
                        c
                    }
                });
                if renamed.constants().iter().all(|c| universe.contains(*c)) {
                    out.push(renamed);
                }
            }
        }
        let links: Vec<&str> = names
            .iter()
            .copied()
            .filter(|o| MOVING_LINKS.iter().any(|link| parts::has_part_suffix(o, link)))
            .collect();
        let assets = names
            .iter()
            .filter(|o| {
                [parts::HINGE_BODY, parts::DRAWER_BODY]
                    .iter()
                    .any(|b| parts::has_part_suffix(o, b))
            })
            .count();
        if assets >= 2 {
            for op in &mut out {
                add_blocking_preconditions(op, &links);
            }
        }
        out
    }

    /// The domain a scene's problem is planned in, as a PDDL domain any planner can take: the
    /// file's types, constants and predicates (with `Blocks` declared when a schema uses it)
    /// and the scene's schemas of both end effectors ([`WorldDomain::schemas_for`]). For a
    /// scene with one asset under the bare names its actions are the file's.
    pub fn scene_domain<'a>(&self, objects: impl IntoIterator<Item = &'a str>) -> Domain {
        let universe = self.universe(objects);
        let mut domain = self.domain.clone();
        domain.actions = [Embodiment::Finger, Embodiment::Vacuum]
            .into_iter()
            .flat_map(|e| self.schemas_for(e, &universe))
            .collect();
        let blocks = Symbol::new(perception::observer::BLOCKS);
        let uses_blocks = domain
            .actions
            .iter()
            .any(|a| a.patterns().iter().any(|p| p.pred == blocks));
        if uses_blocks && !domain.predicates.iter().any(|p| p.name == blocks) {
            let thing = Symbol::new("thing");
            domain.predicates.push(PredicateDecl {
                name: blocks,
                params: ["a", "b"]
                    .map(|v| nesy_core::TypedVar {
                        name: Symbol::new(v),
                        ty: thing,
                    })
                    .to_vec(),
            });
        }
        domain
    }

    /// A typed universe of the scene's objects (see [`object_type`]); the robot's own
    /// entry (`gripper`, `vacuum_gripper`) is left out.
    pub fn universe<'a>(&self, objects: impl IntoIterator<Item = &'a str>) -> Universe {
        let mut u = Universe::new();
        for (t, parent) in &self.domain.types {
            // Checked in `parse`.
            let _ = u.types.declare(*t, *parent);
        }
        for o in objects {
            if is_robot_entry(o) {
                continue;
            }
            let ty = object_type(o);
            // A name listed twice keeps its (identical) type.
            let _ = u.add(Symbol::new(o), Symbol::new(ty));
        }
        u
    }
}

impl WorldDomain {
    /// A PDDL problem over this domain: the scene's objects (those the domain declares as
    /// constants left out, the robot's own entry too) typed by [`object_type`], an initial
    /// state and a goal. Written out, it is a problem file any PDDL planner can take together
    /// with [`NESY_WORLD_PDDL`].
    pub fn problem<'a>(
        &self,
        name: &str,
        objects: impl IntoIterator<Item = &'a str>,
        init: State,
        goal: Formula,
    ) -> Problem {
        let mut seen = std::collections::BTreeSet::new();
        let objects = objects
            .into_iter()
            .filter(|o| !is_robot_entry(o))
            .filter(|o| !self.domain.constants.iter().any(|(c, _)| c.as_str() == *o))
            .filter(|o| seen.insert(*o))
            .map(|o| (Symbol::new(o), Symbol::new(object_type(o))))
            .collect();
        Problem {
            name: Symbol::new(name),
            domain: self.domain.name,
            objects,
            init,
            goal,
        }
    }
}

/// The moving links of the articulated assets (bare names).
const MOVING_LINKS: [&str; 3] = [parts::HINGE_LID, parts::TOP_DRAWER, parts::BOTTOM_DRAWER];

/// Adds to a schema that opens a lid or drawer `x`, or reaches for or takes `x`'s handle,
/// the precondition that no other asset's moving link `o` among `links` that stands in its
/// way is open: `(not (and (Blocks o x) (Open o)))`. A handle sits on the face that moves
/// along `x`'s travel, so the hand reaching it goes where the open `o` stands.
fn add_blocking_preconditions(op: &mut Operator, links: &[&str]) {
    let Some(instance) = schema_instance(&op.name) else {
        return;
    };
    let opened = match instance.schema.motion {
        Motion::OpenDrawer => instance.part(),
        Motion::OpenLid => Some(instance.asset_part(parts::HINGE_LID)),
        Motion::MoveToHandle | Motion::GraspHandle => instance
            .schema
            .part
            .and_then(handle_link)
            .map(|link| instance.asset_part(link)),
        _ => None,
    };
    let Some(opened) = opened else {
        return;
    };
    let prefix_of = |link: &str| split_asset_part(link).map(|(prefix, _)| prefix.to_owned());
    let own = prefix_of(&opened);
    let mut pre: Vec<Formula> = op.pre.to_vec();
    for other in links.iter().filter(|o| prefix_of(o) != own) {
        let blocks = Atom::new(perception::observer::BLOCKS, &[*other, opened.as_str()]);
        let open = Atom::new("Open", &[other]);
        pre.push(Formula::Not(Box::new(Formula::And(vec![
            Formula::atom(blocks),
            Formula::atom(open),
        ]))));
    }
    op.pre = pre.into();
}

/// The moving link (bare name) a handle (bare name) is mounted on.
fn handle_link(handle: &str) -> Option<&'static str> {
    match handle {
        parts::HINGE_HANDLE => Some(parts::HINGE_LID),
        parts::TOP_DRAWER_HANDLE => Some(parts::TOP_DRAWER),
        parts::BOTTOM_DRAWER_HANDLE => Some(parts::BOTTOM_DRAWER),
        _ => None,
    }
}

/// The robot's own entry in a scene's object list (`gripper` or `vacuum_gripper`), which is
/// not an object of the domain.
fn is_robot_entry(name: &str) -> bool {
    name == "gripper" || name == "vacuum_gripper"
}

/// The domain type of a scene object, by the benchmark's naming: `floor` and `board` are
/// surfaces, `toy_box` and the chess boxes open-topped boxes, the hinge box and drawer
/// cabinet parts `part`s, a magnetic hook (`…hook`) a `tool` (an item the hand takes like
/// any other), screws (`…screws`, too small to take one by one) `pieces`, and everything
/// else (cubes, cylinders, fruits, chess pieces) a loose `item`.
pub fn object_type(name: &str) -> &'static str {
    match name {
        "floor" | "board" => "surface",
        "toy_box" => "box",
        n if n.ends_with("chess_box") => "box",
        n if is_asset_part(n) => "part",
        n if n.ends_with("hook") => "tool",
        n if n.ends_with("screws") => "pieces",
        _ => "item",
    }
}

/// The action semantic of a grounded schema as the oracle writes it: the schema's words
/// and the objects' words, e.g. `move to surround red cube`, which nesy-core normalises to
/// `MoveToSurroundRedCube`.
pub fn semantic(schema: &str, args: &[Symbol]) -> String {
    let mut words: Vec<String> = schema.split(['-', '_']).map(str::to_owned).collect();
    for a in args {
        words.extend(a.as_str().split('_').map(str::to_owned));
    }
    words.join(" ")
}

fn recase_pattern(p: &AtomPattern, recase: &impl Fn(Symbol) -> Symbol) -> AtomPattern {
    let mut q = p.clone();
    q.pred = recase(q.pred);
    q
}

fn recase_formula(f: &Formula, recase: &impl Fn(Symbol) -> Symbol) -> Formula {
    match f {
        Formula::Atom(p) => Formula::Atom(recase_pattern(p, recase)),
        Formula::Eq(a, b) => Formula::Eq(*a, *b),
        Formula::Not(x) => Formula::Not(Box::new(recase_formula(x, recase))),
        Formula::And(xs) => Formula::And(xs.iter().map(|x| recase_formula(x, recase)).collect()),
        Formula::Or(xs) => Formula::Or(xs.iter().map(|x| recase_formula(x, recase)).collect()),
        Formula::Imply(a, b) => Formula::Imply(
            Box::new(recase_formula(a, recase)),
            Box::new(recase_formula(b, recase)),
        ),
        Formula::Forall(v, x) => Formula::Forall(v.clone(), Box::new(recase_formula(x, recase))),
        Formula::Exists(v, x) => Formula::Exists(v.clone(), Box::new(recase_formula(x, recase))),
    }
}

fn recase_effect(e: &Effect, recase: &impl Fn(Symbol) -> Symbol) -> Effect {
    match e {
        Effect::Add(p) => Effect::Add(recase_pattern(p, recase)),
        Effect::Del(p) => Effect::Del(recase_pattern(p, recase)),
        Effect::Forall(v, es) => {
            Effect::Forall(v.clone(), es.iter().map(|x| recase_effect(x, recase)).collect())
        }
        Effect::When(c, es) => Effect::When(
            recase_formula(c, recase),
            es.iter().map(|x| recase_effect(x, recase)).collect(),
        ),
    }
}
