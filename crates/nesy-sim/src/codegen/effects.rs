//! Recognising an action by what it does when its name names no schema: a model free to
//! name its operators (`PickUpTheApple`, `PlaceCubeInBin`) still states the physical
//! effects and preconditions in nesy's predicates, and those identify the schema of the
//! true domain the action performs (an action that adds `(InsideOf x toy_box)` while
//! `(GripperHolding x)` holds carries `x` into the box; one that deletes
//! `(GripperHolding x)` and adds `(OnTopOf x floor)` puts it down).
//!
//! Only the top-level literals with object arguments are read (quantified clearing
//! effects say nothing about which schema it is). The finger schema is returned; the
//! compiler turns it into the target end effector's calls either way.

use nesy_core::Operator;
use nesy_core::{Effect, Formula};

use crate::domain::{SchemaKind as Kind, instance_name, kind_of, schemas, split_asset_part};
use crate::scene::parts;

/// A ground literal: predicate and arguments.
type Lit = (String, Vec<String>);

fn lits(effects: &[Effect], want_add: bool) -> Vec<Lit> {
    effects
        .iter()
        .filter_map(|e| match e {
            Effect::Add(p) if want_add => p.as_atom(),
            Effect::Del(p) if !want_add => p.as_atom(),
            _ => None,
        })
        .map(|a| {
            (
                a.pred().as_str().to_owned(),
                a.args().iter().map(|s| s.as_str().to_owned()).collect(),
            )
        })
        .collect()
}

fn positive_pre(pre: &[Formula]) -> Vec<Lit> {
    let mut out = Vec::new();
    for f in pre {
        match f {
            Formula::Atom(p) => {
                if let Some(a) = p.as_atom() {
                    out.push((
                        a.pred().as_str().to_owned(),
                        a.args().iter().map(|s| s.as_str().to_owned()).collect(),
                    ));
                }
            }
            Formula::And(xs) => out.extend(positive_pre(xs)),
            _ => {}
        }
    }
    out
}

/// The handles, the part each one moves (the observer may name either) and the schemas'
/// word for it (bare names; an asset named with a prefix has them under its prefix).
const HANDLES: [(&str, &str, &str); 3] = [
    (parts::HINGE_HANDLE, parts::HINGE_LID, "hinge"),
    (parts::BOTTOM_DRAWER_HANDLE, parts::BOTTOM_DRAWER, "bottom-drawer"),
    (parts::TOP_DRAWER_HANDLE, parts::TOP_DRAWER, "top-drawer"),
];

fn is_holding(pred: &str) -> bool {
    pred == "GripperHolding" || pred == "VacuumAttached"
}

fn is_surrounding(pred: &str) -> bool {
    pred == "GripperSurrounding" || pred == "VacuumAligned"
}

/// The schema name and arguments an operator performs, judged from its effects and
/// preconditions; `None` if they match no schema (e.g. an action without physical effects).
pub(super) fn schema_by_effects(op: &Operator, objects: &[String]) -> Option<(String, Vec<String>)> {
    let ev = Evidence {
        adds: lits(&op.eff, true),
        dels: lits(&op.eff, false),
        pre: positive_pre(&op.pre),
        objects,
    };
    // The first rule that recognises the operator decides, so their order is part of the
    // judgement.
    if let Some(verdict) = ev
        .gathering()
        .or_else(|| ev.articulation_change())
        .or_else(|| ev.handle_action())
        .or_else(|| ev.release_of_item())
        .or_else(|| ev.grasp_or_approach())
        .or_else(|| ev.carry_to_place())
        .or_else(|| ev.lift_off_to_floor())
    {
        return verdict;
    }
    // Only quantified clearing effects, no relation of its own: the hand only moves (a
    // retreat, or an approach to a handle, which the grasp that follows makes itself). An
    // operator with no effects at all says nothing and stays unknown.
    if ev.adds.is_empty() && ev.dels.is_empty() && !op.eff.is_empty() {
        return Some(("retreat".to_owned(), Vec::new()));
    }
    None
}

/// A schema name (for an asset named with a prefix, the schema's name for it) with its
/// arguments, or `None` when the operator matches no schema.
type Verdict = Option<(String, Vec<String>)>;

/// A verdict for the table's schema `name` working on no asset, or on the asset of `part`.
fn named(name: &str, part: Option<&str>, args: Vec<String>) -> Verdict {
    let prefix = part.and_then(split_asset_part).map_or("", |(prefix, _)| prefix);
    Some((instance_name(name, prefix), args))
}

/// True if the object is a loose one the robot picks and places (a hook too).
fn is_item(o: &str) -> bool {
    kind_of(o).is_some_and(|k| Kind::Item.accepts(k))
}

/// An operator's top-level literals over the scene's objects, which every rule reads.
/// Each rule returns `Some(verdict)` when it decides, `None` to leave it to the next.
struct Evidence<'a> {
    /// Added literals.
    adds: Vec<Lit>,
    /// Deleted literals.
    dels: Vec<Lit>,
    /// Positive preconditions.
    pre: Vec<Lit>,
    /// The scene's object names.
    objects: &'a [String],
}

impl Evidence<'_> {
    /// True if the name is one of the scene's objects.
    fn known(&self, o: &str) -> bool {
        self.objects.iter().any(|x| x == o)
    }

    /// The object of the first added one-argument literal whose predicate passes `pred`.
    fn add1(&self, pred: &dyn Fn(&str) -> bool) -> Option<String> {
        self.adds
            .iter()
            .find(|(p, a)| pred(p) && a.len() == 1 && self.known(&a[0]))
            .map(|(_, a)| a[0].clone())
    }

    /// The argument pairs of every added `name` literal over known objects.
    fn add2(&self, name: &str) -> Vec<(String, String)> {
        self.adds
            .iter()
            .filter(|(p, a)| p == name && a.len() == 2 && a.iter().all(|o| self.known(o)))
            .map(|(_, a)| (a[0].clone(), a[1].clone()))
            .collect::<Vec<_>>()
    }

    /// The object of the first deleted one-argument `name` literal.
    fn del1(&self, name: &str) -> Option<String> {
        self.dels
            .iter()
            .find(|(p, a)| p == name && a.len() == 1 && self.known(&a[0]))
            .map(|(_, a)| a[0].clone())
    }

    /// True if the preconditions state that `x` is held.
    fn held(&self, x: &str) -> bool {
        self.pre
            .iter()
            .any(|(p, a)| is_holding(p) && a.len() == 1 && a[0] == x)
    }

    /// Gathering: a fine-grained object's pieces brought onto a held hook's magnet
    /// (`OnMagnet`), or gathered while a hook is held.
    fn gathering(&self) -> Option<Verdict> {
        let pieces = |o: &str| kind_of(o) == Some(Kind::Pieces);
        let hook = |o: &str| kind_of(o) == Some(Kind::Tool);
        if let Some((x, h)) = self
            .add2(crate::perception::observer::ON_MAGNET)
            .into_iter()
            .find(|(x, h)| pieces(x) && hook(h))
        {
            return Some(named("gather-with-hook", None, vec![h, x]));
        }
        let x = self.add1(&|p| p == "Gathered").filter(|x| pieces(x))?;
        let held = self
            .pre
            .iter()
            .find(|(p, a)| is_holding(p) && a.len() == 1 && hook(&a[0]))
            .map(|(_, a)| a[0].clone())?;
        Some(named("gather-with-hook", None, vec![held, x]))
    }

    /// Articulations: a lid or a drawer opened or closed (a swing waypoint may only state
    /// that it is no longer closed, or no longer open).
    fn articulation_change(&self) -> Option<Verdict> {
        let changes = [
            (self.add1(&|p| p == "Open"), true),
            (self.add1(&|p| p == "Closed"), false),
            (self.del1("Closed"), true),
            (self.del1("Open"), false),
        ];
        for (x, opened) in changes {
            if let Some(x) = x {
                let bare = split_asset_part(&x).map(|(_, bare)| bare);
                let schema = match (bare, opened) {
                    (Some(parts::HINGE_LID), true) => "open-hinge-lid",
                    (Some(parts::HINGE_LID), false) => "close-hinge-lid",
                    (Some(parts::BOTTOM_DRAWER), true) => "open-bottom-drawer",
                    (Some(parts::BOTTOM_DRAWER), false) => "close-bottom-drawer",
                    (Some(parts::TOP_DRAWER), true) => "open-top-drawer",
                    (Some(parts::TOP_DRAWER), false) => "close-top-drawer",
                    _ => continue,
                };
                return Some(named(schema, Some(&x), Vec::new()));
            }
        }
        None
    }

    /// Handles: approached, grasped, let go.
    fn handle_action(&self) -> Option<Verdict> {
        for (handle, part, what) in HANDLES {
            let of_it = |o: &str| split_asset_part(o).is_some_and(|(_, bare)| bare == handle || bare == part);
            let on = |v: &[Lit], pred: fn(&str) -> bool| {
                v.iter()
                    .find(|(p, a)| pred(p) && a.len() == 1 && of_it(&a[0]))
                    .map(|(_, a)| a[0].clone())
            };
            let schema = if let Some(o) = on(&self.adds, is_holding) {
                Some((format!("grasp-{what}-handle"), o))
            } else if let Some(o) = on(&self.dels, is_holding) {
                Some((format!("release-{what}-handle"), o))
            } else {
                on(&self.adds, is_surrounding).map(|o| (format!("move-to-{what}-handle"), o))
            };
            if let Some((name, object)) = schema {
                return Some(
                    schemas()
                        .iter()
                        .find(|s| s.name == name)
                        .and_then(|s| named(s.name, Some(&object), Vec::new())),
                );
            }
        }
        None
    }

    /// Letting go of a held item: where it comes to rest names the schema (and nowhere
    /// stated means no schema).
    fn release_of_item(&self) -> Option<Verdict> {
        let (_, a) = self
            .dels
            .iter()
            .find(|(p, a)| is_holding(p) && a.len() == 1 && is_item(&a[0]))?;
        let x = a[0].clone();
        let Some(rest) = self
            .add2("InsideOf")
            .into_iter()
            .chain(self.add2("OnTopOf"))
            .chain(
                self.pre
                    .iter()
                    .filter(|(p, a)| (p == "InsideOf" || p == "OverOf") && a.len() == 2)
                    .map(|(_, a)| (a[0].clone(), a[1].clone())),
            )
            .find(|(y, _)| *y == x)
            .map(|(_, place)| place)
        else {
            return Some(None);
        };
        let bare = split_asset_part(&rest).map(|(_, bare)| bare);
        Some(match (bare, kind_of(&rest)) {
            (Some(parts::HINGE_BODY), _) => named("drop-into-hinge-body", Some(&rest), vec![x]),
            (Some(parts::BOTTOM_DRAWER), _) if kind_of(&x) == Some(Kind::Tool) => {
                named("drop-hook-into-bottom-drawer", Some(&rest), vec![x])
            }
            (Some(parts::BOTTOM_DRAWER), _) => named("drop-into-bottom-drawer", Some(&rest), vec![x]),
            (_, Some(Kind::Surface)) => named("put-down", None, vec![x, rest]),
            (_, Some(Kind::Box)) => named("release-into", None, vec![x, rest]),
            _ => None,
        })
    }

    /// An item grasped, or the hand brought around one.
    fn grasp_or_approach(&self) -> Option<Verdict> {
        if let Some(x) = self.add1(&|p| is_holding(p)).filter(|x| is_item(x)) {
            return Some(named("grasp", None, vec![x]));
        }
        if let Some(x) = self.add1(&|p| is_surrounding(p)).filter(|x| is_item(x)) {
            return Some(named("move-to-surround", None, vec![x]));
        }
        None
    }

    /// An item brought over, into or onto a place.
    fn carry_to_place(&self) -> Option<Verdict> {
        if let Some((x, place)) = self.add2("OverOf").into_iter().find(|(x, _)| is_item(x)) {
            return Some(match split_asset_part(&place).map(|(_, bare)| bare) {
                Some(parts::HINGE_BODY) => named("carry-over-hinge-body", Some(&place), vec![x]),
                Some(parts::BOTTOM_DRAWER) if kind_of(&x) == Some(Kind::Tool) => {
                    named("carry-hook-over-bottom-drawer", Some(&place), vec![x])
                }
                Some(parts::BOTTOM_DRAWER) => named("carry-over-bottom-drawer", Some(&place), vec![x]),
                _ => None,
            });
        }
        if let Some((x, b)) = self
            .add2("InsideOf")
            .into_iter()
            .find(|(x, b)| is_item(x) && kind_of(b) == Some(Kind::Box))
        {
            // Chess pieces reach their boxes by a push across the board; anything held is
            // carried in.
            return Some(
                if b == parts::LEFT_CHESS_BOX || b == parts::RIGHT_CHESS_BOX || !self.held(&x) {
                    named("sweep-into", None, vec![x, b])
                } else {
                    named("carry-into", None, vec![x, b])
                },
            );
        }
        if let Some((x, s)) = self
            .add2("OnTopOf")
            .into_iter()
            .find(|(x, s)| is_item(x) && kind_of(s) == Some(Kind::Surface) && self.held(x))
        {
            return Some(named("carry-onto", None, vec![x, s]));
        }
        None
    }

    /// A held item lifted off what it stood on or in, with nowhere new stated: a carry to
    /// the table (the put-down that follows names the surface it comes to rest on).
    fn lift_off_to_floor(&self) -> Option<Verdict> {
        if let Some((_, a)) = self.dels.iter().find(|(p, a)| {
            matches!(p.as_str(), "OnTopOf" | "InsideOf" | "OverOf")
                && a.len() == 2
                && is_item(&a[0])
                && self.held(&a[0])
        }) && self.objects.iter().any(|o| o == parts::FLOOR)
        {
            return Some(named(
                "carry-onto",
                None,
                vec![a[0].clone(), parts::FLOOR.to_owned()],
            ));
        }
        None
    }
}
