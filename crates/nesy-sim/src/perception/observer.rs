//! The symbolic state observer (`docs/benchmark.md` §5): geometry to `nesy_core::State`.
//!
//! [`observe`] snapshots the simulator into a [`Snapshot`] and [`observe_snapshot`] applies
//! the predicate rules to it, so the rules can be tested on hand-made geometry. Every
//! threshold of the rules is one of the named constants below.

use nesy_core::{Atom, State};

use crate::api::Embodiment;
use crate::scene::parts;
use crate::world::Sim;
use crate::world::geometry::Aabb;
use crate::world::objects::PartRole;

/// A joint reads `Closed` at or below this fraction of its travel.
pub const CLOSED_PROGRESS: f64 = 0.3;
/// A joint reads `Open` at or above this fraction of its travel.
pub const OPEN_PROGRESS: f64 = 0.7;
/// A joint also reads closed (open) within `LIMIT_NEAR_BASE + LIMIT_NEAR_SCALE × |limit|` of
/// its lower (upper) limit.
pub const LIMIT_NEAR_BASE: f64 = 0.1;
/// See [`LIMIT_NEAR_BASE`].
pub const LIMIT_NEAR_SCALE: f64 = 0.3;
/// Least xy overlap (m, on both axes) between an object and what it rests on.
pub const SUPPORT_MIN_OVERLAP: f64 = 0.002;
/// How far (m) an object's bottom may sink below a support's top and still rest on it.
pub const SUPPORT_MAX_SINK: f64 = 0.003;
/// How far (m) above a support's top an object's bottom may float and still rest on it.
pub const SUPPORT_MAX_GAP: f64 = 0.01;
/// How far (m) an object's bottom may reach below a support's bottom (objects resting on a
/// thin plate, not beside a tall block).
pub const SUPPORT_BELOW_TOLERANCE: f64 = 0.01;
/// Supports whose tops are within this height (m) of the highest one all count.
pub const SUPPORT_TOP_TIE: f64 = 1e-5;
/// xy margin (m) within which the open top drawer covers the bottom drawer's handle, and a
/// held object is over something.
pub const OVER_XY_MARGIN: f64 = 0.005;
/// The gap (m) between a held object's bottom and what lies below it for `OverOf`.
pub const OVER_GAP: std::ops::RangeInclusive<f64> = 0.02..=0.30;

/// What the observer needs to know about one object.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectView {
    /// Name.
    pub name: String,
    /// World AABB.
    pub aabb: Aabb,
    /// Role in the rules.
    pub role: PartRole,
    /// Articulated group (objects of one asset share it; pairs within a group are dropped).
    pub group: Option<usize>,
    /// Joint position and limits for `hinge_lid`, `top_drawer`, `bottom_drawer`.
    pub joint: Option<(f64, f64, f64)>,
    /// True if it is in the grasp region (between the pads or under the cup).
    pub in_gripper: bool,
    /// For a fine-grained object (its pieces merged into this one view): whether they are
    /// gathered ([`GATHERED_SPREAD`]); `None` for every other object.
    pub gathered: Option<bool>,
    /// For a fine-grained object: the magnetic hook whose magnet every piece clings to
    /// ([`CLING_REACH`]), so that the pieces move with it; stated as [`ON_MAGNET`].
    pub on_magnet: Option<String>,
    /// True for a magnetic hook.
    pub magnetic: bool,
}

/// A fine-grained object is `Gathered` when every piece's centre lies within this distance
/// (m) of the pieces' mean: a pile that a hand or a magnet can take as one.
pub const GATHERED_SPREAD: f64 = 0.035;

/// A piece clings to a magnet when its centre lies within this distance (m) of the
/// magnet's centre: against the 2.5 cm block, under or beside it.
pub const CLING_REACH: f64 = 0.03;

/// The relation between a fine-grained object and the magnetic hook its pieces cling to:
/// `(OnMagnet x h)`. The pieces go wherever the hook goes, so the observer relates them to
/// what is around them and never to the hook itself. Not one of the paper's fifteen
/// predicates: the hook-and-screws task declares it in its vocabulary file.
pub const ON_MAGNET: &str = "OnMagnet";

/// Everything the rules look at.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// `floor` (the table) first, then the objects in scene order.
    pub objects: Vec<ObjectView>,
    /// The robot's end effector.
    pub embodiment: Embodiment,
    /// Emit `(FingerGripper)`/`(VacuumSuction)`.
    pub embodiment_in_state: bool,
    /// Fingers closed or suction on.
    pub closed: bool,
    /// The welded object.
    pub held: Option<String>,
    /// The grasped handle.
    pub grasped_handle: Option<String>,
    /// Pairs of moving links where the first, open, stands in the way of the second's
    /// opening (two cabinets at right angles), stated as [`BLOCKS`].
    pub blocking: Vec<(String, String)>,
}

/// The relation between two moving links of different assets that open into each other's
/// way: `(Blocks a b)` when `a`, open, stops `b` from opening. It depends only on where the
/// assets stand, so it holds in every state of a scene. Not one of the paper's fifteen
/// predicates: a task whose scenes have it declares it in its vocabulary file.
pub const BLOCKS: &str = "Blocks";

/// How much (low, high) a container's box grows before `InsideOf` tests it
/// (`docs/benchmark.md` §5's table).
fn padding(name: &str) -> ([f64; 3], [f64; 3]) {
    match name {
        hinge if parts::has_part_suffix(hinge, parts::HINGE_BODY) => {
            ([-0.02, -0.02, -0.02], [0.02, 0.02, 0.05])
        }
        parts::TOY_BOX => ([-0.02, -0.02, -0.01], [0.02, 0.02, 0.05]),
        parts::LEFT_CHESS_BOX | parts::RIGHT_CHESS_BOX => ([-0.01, -0.01, -0.01], [0.01, 0.01, 0.05]),
        _ => ([-0.01, -0.01, -0.01], [0.01, 0.01, 0.02]),
    }
}

/// Takes a snapshot of the simulator.
pub fn snapshot(sim: &Sim) -> Snapshot {
    let floor = ObjectView {
        name: parts::FLOOR.into(),
        aabb: sim.object_aabb(parts::FLOOR).unwrap_or(Aabb::EMPTY),
        role: PartRole::Fixed,
        group: None,
        joint: None,
        in_gripper: false,
        gathered: None,
        on_magnet: None,
        magnetic: false,
    };
    let objects = std::iter::once(floor)
        .chain(
            sim.perceived_objects()
                .into_iter()
                .map(|(name, parts)| match parts.as_slice() {
                    [part] if !sim.parts()[*part].kind.is_fine_grained() => part_view(sim, *part),
                    pieces => pieces_view(sim, name, pieces),
                }),
        )
        .collect();
    Snapshot {
        objects,
        embodiment: sim.robot_embodiment(),
        embodiment_in_state: sim.scene().embodiment_in_state,
        closed: sim.is_closed(),
        held: sim.held_object().map(str::to_owned),
        grasped_handle: sim.grasped_handle().map(str::to_owned),
        blocking: sim.blocking_pairs(),
    }
}

/// The view of one part.
fn part_view(sim: &Sim, i: usize) -> ObjectView {
    let p = &sim.parts()[i];
    let joint = (p.role == PartRole::Link)
        .then(|| p.articulation.map(|a| &sim.articulations()[a]))
        .flatten()
        .map(|a| (a.q, a.limits.0, a.limits.1));
    let group = matches!(
        p.role,
        PartRole::ArticulatedBody | PartRole::Link | PartRole::Handle
    )
    .then_some(p.object);
    ObjectView {
        name: p.name.clone(),
        aabb: sim.part_aabb(i),
        role: p.role,
        group,
        joint,
        in_gripper: sim.part_in_gripper(i),
        gathered: None,
        on_magnet: None,
        magnetic: p.kind.is_tool(),
    }
}

/// The one view of a fine-grained object's pieces: their combined box, in the grasp region
/// if any piece is, and gathered when every piece's centre lies within [`GATHERED_SPREAD`]
/// of their mean; on a magnet when every piece's centre lies within [`CLING_REACH`] of it.
fn pieces_view(sim: &Sim, name: &str, pieces: &[usize]) -> ObjectView {
    let boxes: Vec<Aabb> = pieces.iter().map(|&p| sim.part_aabb(p)).collect();
    let centres: Vec<[f64; 3]> = boxes.iter().map(Aabb::centre).collect();
    let n = centres.len() as f64;
    let mean = [0, 1, 2].map(|k| centres.iter().map(|c| c[k]).sum::<f64>() / n);
    let spread = centres
        .iter()
        .map(|c| (0..3).map(|k| (c[k] - mean[k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    ObjectView {
        name: name.to_owned(),
        aabb: boxes.iter().fold(Aabb::EMPTY, |acc, b| acc.union(b)),
        role: PartRole::Loose,
        group: None,
        joint: None,
        in_gripper: pieces.iter().any(|&p| sim.part_in_gripper(p)),
        gathered: Some(spread <= GATHERED_SPREAD),
        on_magnet: sim
            .magnets()
            .into_iter()
            .find(|(_, m)| {
                centres
                    .iter()
                    .all(|c| (0..3).map(|k| (c[k] - m[k]).powi(2)).sum::<f64>().sqrt() <= CLING_REACH)
            })
            .map(|(hook, _)| sim.perceived_name(hook).to_owned()),
        magnetic: false,
    }
}

/// The symbolic state of the simulator now.
pub fn observe(sim: &Sim) -> State {
    observe_snapshot(&snapshot(sim))
}

/// Open/Closed of a joint: Closed if its progress is at most [`CLOSED_PROGRESS`] or it is
/// near the lower limit, else Open if its progress is at least [`OPEN_PROGRESS`] or it is
/// near the upper limit, else neither.
fn open_closed(q: f64, lo: f64, hi: f64) -> Option<&'static str> {
    let progress = (q - lo) / (hi - lo);
    let near = |limit: f64| (q - limit).abs() <= LIMIT_NEAR_BASE + LIMIT_NEAR_SCALE * limit.abs();
    if progress <= CLOSED_PROGRESS || near(lo) {
        Some("Closed")
    } else if progress >= OPEN_PROGRESS || near(hi) {
        Some("Open")
    } else {
        None
    }
}

/// Applies the observer's rules to a snapshot.
pub fn observe_snapshot(s: &Snapshot) -> State {
    let mut atoms: Vec<Atom> = Vec::new();
    let preds = EffectorPredicates::of(s.embodiment);
    push_effector_and_joints(s, &preds, &mut atoms);
    push_holding(s, &preds, &mut atoms);
    let inside = push_inside_of(s, &mut atoms);
    let on_top = push_on_top_of(s, &inside, &mut atoms);
    push_drawer_over_handle(s, &mut atoms);
    push_over_of(s, &inside, &on_top, &mut atoms);
    push_fine_grained(s, &mut atoms);
    for (a, b) in &s.blocking {
        atoms.push(Atom::new(BLOCKS, &[a, b]));
    }
    State::from_atoms(atoms)
}

/// Adds `Finegrained` for every object made of small pieces, `Gathered` while its pieces
/// lie together, and [`ON_MAGNET`] while they cling to a hook's magnet.
fn push_fine_grained(s: &Snapshot, atoms: &mut Vec<Atom>) {
    for o in &s.objects {
        if let Some(gathered) = o.gathered {
            atoms.push(Atom::new("Finegrained", &[&o.name]));
            if gathered {
                atoms.push(Atom::new("Gathered", &[&o.name]));
            }
        }
        if let Some(hook) = &o.on_magnet {
            atoms.push(Atom::new(ON_MAGNET, &[&o.name, hook]));
        }
    }
}

/// The end effector's four state predicates, whose names depend on the embodiment.
struct EffectorPredicates {
    open: &'static str,
    closed: &'static str,
    holding: &'static str,
    surrounding: &'static str,
}

impl EffectorPredicates {
    /// The finger gripper's names or the suction cup's.
    fn of(embodiment: Embodiment) -> Self {
        if embodiment == Embodiment::Finger {
            EffectorPredicates {
                open: "GripperOpen",
                closed: "GripperClosed",
                holding: "GripperHolding",
                surrounding: "GripperSurrounding",
            }
        } else {
            EffectorPredicates {
                open: "VacuumInactive",
                closed: "VacuumActive",
                holding: "VacuumAttached",
                surrounding: "VacuumAligned",
            }
        }
    }
}

/// True if both objects belong to one articulated asset (pairs within an asset are dropped).
fn same_group(a: &ObjectView, b: &ObjectView) -> bool {
    a.group.is_some() && a.group == b.group
}

/// True if one of the two is a fine-grained object clinging to the other's magnet: the
/// pieces hang on the hook, so neither holds, carries or lies over the other.
fn on_magnet_pair(a: &ObjectView, b: &ObjectView) -> bool {
    a.on_magnet.as_deref() == Some(b.name.as_str()) || b.on_magnet.as_deref() == Some(a.name.as_str())
}

/// Adds the effector's open/closed atom, its embodiment (when the scene asks for it) and
/// every joint's `Open`/`Closed`.
fn push_effector_and_joints(s: &Snapshot, preds: &EffectorPredicates, atoms: &mut Vec<Atom>) {
    atoms.push(Atom::new(if s.closed { preds.closed } else { preds.open }, &[]));
    if s.embodiment_in_state {
        atoms.push(Atom::new(s.embodiment.state_predicate(), &[]));
    }
    for o in &s.objects {
        if let Some((q, lo, hi)) = o.joint
            && let Some(p) = open_closed(q, lo, hi)
        {
            atoms.push(Atom::new(p, &[&o.name]));
        }
    }
}

/// Adds holding (the welded object or the grasped handle, while closed) or, with the
/// effector open and nothing welded, surrounding (the first object by name in the grasp
/// region, leaving out the table, handles and articulated bodies).
fn push_holding(s: &Snapshot, preds: &EffectorPredicates, atoms: &mut Vec<Atom>) {
    if s.closed {
        let mut held: Vec<&str> = s
            .held
            .iter()
            .chain(&s.grasped_handle)
            .map(String::as_str)
            .collect();
        held.sort_unstable();
        if let Some(first) = held.first() {
            atoms.push(Atom::new(preds.holding, &[first]));
        }
    } else if s.held.is_none() {
        let mut around: Vec<&str> = s
            .objects
            .iter()
            .filter(|o| {
                o.in_gripper
                    && o.name != parts::FLOOR
                    && !matches!(o.role, PartRole::Handle | PartRole::ArticulatedBody)
            })
            .map(|o| o.name.as_str())
            .collect();
        around.sort_unstable();
        if let Some(first) = around.first() {
            atoms.push(Atom::new(preds.surrounding, &[first]));
        }
    }
}

/// Adds `InsideOf` for each object and the smallest container whose padded box holds it;
/// returns that container's index per object, which the later rules consult.
fn push_inside_of(s: &Snapshot, atoms: &mut Vec<Atom>) -> Vec<Option<usize>> {
    let mut inside: Vec<Option<usize>> = vec![None; s.objects.len()];
    for (i, a) in s.objects.iter().enumerate() {
        let mut best: Option<(f64, usize)> = None;
        for (j, c) in s.objects.iter().enumerate() {
            // A hook has no inside: what lies on its bar, beside the taller magnet block,
            // sits within its box yet rests on it.
            if i == j || same_group(a, c) || on_magnet_pair(a, c) || c.magnetic {
                continue;
            }
            let (lo, hi) = padding(&c.name);
            if c.aabb.padded(lo, hi).contains_box(&a.aabb) {
                let v = c.aabb.volume();
                if best.is_none_or(|(bv, _)| v < bv) {
                    best = Some((v, j));
                }
            }
        }
        if let Some((_, j)) = best {
            inside[i] = Some(j);
            atoms.push(Atom::new("InsideOf", &[&a.name, &s.objects[j].name]));
        }
    }
    inside
}

/// Adds `OnTopOf` for each object not inside another and the highest supporting surface(s)
/// it rests on, and for an object inside a container that rests on a magnetic hook, that
/// hook (a tool under a stack must be uncovered before it is taken); returns whether each
/// object rests on something.
fn push_on_top_of(s: &Snapshot, inside: &[Option<usize>], atoms: &mut Vec<Atom>) -> Vec<bool> {
    let is_inside_pair = |i: usize, j: usize| inside[i] == Some(j) || inside[j] == Some(i);
    let mut on_top = vec![false; s.objects.len()];
    for (i, a) in s.objects.iter().enumerate() {
        let contained = inside[i].is_some();
        let supports = |o: &ObjectView| {
            let c = &o.aabb;
            let overlaps =
                a.aabb.overlap(c, 0) > SUPPORT_MIN_OVERLAP && a.aabb.overlap(c, 1) > SUPPORT_MIN_OVERLAP;
            // A hook is no box: its bar is lower than its magnet block, so what lies on the
            // bar rests below the box's top, yet clear of what the hook lies on.
            let rests = if o.magnetic {
                a.aabb.min[2] - c.min[2] >= SUPPORT_MAX_SINK && a.aabb.min[2] - c.max[2] <= SUPPORT_MAX_GAP
            } else {
                (-SUPPORT_MAX_SINK..=SUPPORT_MAX_GAP).contains(&(a.aabb.min[2] - c.max[2]))
                    && a.aabb.min[2] >= c.min[2] - SUPPORT_BELOW_TOLERANCE
            };
            overlaps && rests && a.aabb.max[2] > c.max[2]
        };
        let candidates: Vec<(usize, f64)> = s
            .objects
            .iter()
            .enumerate()
            .filter(|&(j, c)| {
                j != i
                    && (!contained || c.magnetic)
                    && !is_inside_pair(i, j)
                    && !on_magnet_pair(a, c)
                    && supports(c)
            })
            .map(|(j, c)| (j, c.aabb.max[2]))
            .collect();
        let top = candidates.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
        for (j, h) in candidates {
            if (h - top).abs() <= SUPPORT_TOP_TIE && !same_group(a, &s.objects[j]) {
                atoms.push(Atom::new("OnTopOf", &[&a.name, &s.objects[j].name]));
                on_top[i] = true;
            }
        }
    }
    on_top
}

/// Special rule: a cabinet's open top drawer lies over its bottom drawer's handle (they
/// belong to one asset, so the general rule never pairs them).
fn push_drawer_over_handle(s: &Snapshot, atoms: &mut Vec<Atom>) {
    for top in s.objects.iter().filter(|o| o.role == PartRole::Link) {
        let Some(handle_name) = parts::sibling(&top.name, parts::TOP_DRAWER, parts::BOTTOM_DRAWER_HANDLE)
        else {
            continue;
        };
        if let Some(handle) = s
            .objects
            .iter()
            .find(|o| o.name == handle_name && o.group == top.group)
            && top.aabb.overlaps_xy(&handle.aabb, OVER_XY_MARGIN)
        {
            atoms.push(Atom::new("OnTopOf", &[&top.name, &handle.name]));
        }
    }
}

/// Adds `OverOf` for the held object, when it is neither inside nor on anything, and the
/// nearest thing below it.
fn push_over_of(s: &Snapshot, inside: &[Option<usize>], on_top: &[bool], atoms: &mut Vec<Atom>) {
    if let Some(held) = &s.held
        && let Some(w) = s.objects.iter().position(|o| &o.name == held)
        && inside[w].is_none()
        && !on_top[w]
    {
        let wa = &s.objects[w].aabb;
        let nearest = s
            .objects
            .iter()
            .enumerate()
            .filter(|&(j, o)| j != w && o.role != PartRole::Handle && !on_magnet_pair(&s.objects[w], o))
            .map(|(_, o)| o)
            .filter_map(|o| {
                let gap = wa.min[2] - o.aabb.max[2];
                (wa.overlap(&o.aabb, 0) > -OVER_XY_MARGIN
                    && wa.overlap(&o.aabb, 1) > -OVER_XY_MARGIN
                    && OVER_GAP.contains(&gap))
                .then_some((gap, o.name.as_str()))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((_, o)) = nearest {
            atoms.push(Atom::new("OverOf", &[held, o]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obj(name: &str, min: [f64; 3], max: [f64; 3], role: PartRole) -> ObjectView {
        ObjectView {
            name: name.into(),
            aabb: Aabb { min, max },
            role,
            group: None,
            joint: None,
            in_gripper: false,
            gathered: None,
            on_magnet: None,
            magnetic: false,
        }
    }

    fn snap(objects: Vec<ObjectView>) -> Snapshot {
        let floor = obj("floor", [0.0, -1.0, 0.0], [1.0, 1.0, 0.5], PartRole::Fixed);
        Snapshot {
            objects: std::iter::once(floor).chain(objects).collect(),
            embodiment: Embodiment::Finger,
            embodiment_in_state: false,
            closed: false,
            held: None,
            grasped_handle: None,
            blocking: Vec::new(),
        }
    }

    #[test]
    fn joint_thresholds_match_spec() {
        // Hinge: Closed when q ≤ −0.31, Open when q ≥ 0.3245 (progress 0.7).
        assert_eq!(open_closed(-0.785, -0.785, 0.8), Some("Closed"));
        assert_eq!(open_closed(-0.31, -0.785, 0.8), Some("Closed"));
        assert_eq!(open_closed(0.0, -0.785, 0.8), None);
        assert_eq!(open_closed(0.32, -0.785, 0.8), None);
        assert_eq!(open_closed(0.325, -0.785, 0.8), Some("Open"));
        // Drawer: Closed when q ≤ 0.10.
        assert_eq!(open_closed(0.10, 0.0, 0.1232), Some("Closed"));
        assert_eq!(open_closed(0.11, 0.0, 0.1232), Some("Open"));
    }

    #[test]
    fn stack_inside_and_smallest_container() {
        let s = snap(vec![
            obj("toy_box", [0.4, 0.0, 0.5], [0.54, 0.1, 0.545], PartRole::Fixed),
            obj(
                "red_cube",
                [0.45, 0.03, 0.504],
                [0.48, 0.06, 0.534],
                PartRole::Loose,
            ),
            obj("blue_cube", [0.2, 0.0, 0.5], [0.23, 0.03, 0.53], PartRole::Loose),
            obj(
                "green_cube",
                [0.2, 0.0, 0.53],
                [0.23, 0.03, 0.56],
                PartRole::Loose,
            ),
        ]);
        let state = observe_snapshot(&s);
        let text = state.to_string();
        assert!(text.contains("(InsideOf red_cube toy_box)"), "{text}");
        assert!(text.contains("(OnTopOf green_cube blue_cube)"), "{text}");
        assert!(!text.contains("(OnTopOf red_cube"), "{text}");
        assert!(text.contains("(OnTopOf blue_cube floor)"), "{text}");
        assert!(text.contains("(GripperOpen)"), "{text}");
    }
}
