//! Lids and drawers meeting other furniture. Articulated links are kinematic bodies that the
//! simulator moves along their joints, and Rapier computes no contacts between kinematic
//! and fixed bodies, so a drawer pulled open would pass through a neighbouring cabinet.
//! Here the joint travels only as far as its link's solid colliders stay clear of every
//! other asset's fixed and articulated parts: a drawer opened into another one stops where
//! the two meet, as a real one does, and the arm that pulls it stops there too (the
//! motion ends with [`ApiError::Collision`], the way a real arm's protective stop ends it).
//!
//! The arm is kinematic too, so nothing in the physics stops its links or the object it
//! carries at furniture. The protective stop does when it is on ([`Sim::set_protective_stop`];
//! the check is [`Sim::protective_stop`]), the way a real arm's collision reflex does: a motion that presses a link or the carried object more than
//! [`FURNITURE_TOUCH_DEPTH`] into a fixed part, an articulated body or a lid or drawer ends
//! there with [`ApiError::Collision`] naming both. One exemption stands for the authors'
//! handles: they are visual only and grasped by proximity, 2.5 cm in front of a drawer face
//! and over a lid, closer than a Panda hand fits, so while the hand reaches for a handle,
//! holds it, or leaves it, its overlap with that handle's own asset is not a stop (it is
//! measured all the same). [`FurnitureContactProbe`] measures every overlap: for every link
//! or carried object and every piece of furniture, the deepest overlap of an episode and
//! the call that made it.
//!
//! Loose objects are not obstacles here: they are dynamic bodies, and the arm and the links
//! push them through the physics as they move.

use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::prelude::{ColliderHandle, Pose, Shape};
use serde::Serialize;

use crate::api::ApiError;
use crate::api::TraceEntry;
use crate::world::objects;
use crate::world::{Part, Sim, SimHook};

/// Positions along a joint's travel at which [`Sim::articulation_blocking`] checks it
/// against another asset's open link (every 5 mm of a drawer's 12 cm).
const BLOCKING_SAMPLES: usize = 24;

/// Joint resolution (m for drawers, rad for lids) to which the contact position is found.
pub(crate) const CONTACT_RESOLUTION: f64 = 1e-4;

/// Overlap (m) of the arm, its fingers or a carried object with furniture below which it is
/// a touch or a brush (fingers grazing a box's wall on their way in) rather than a push into
/// the part that a real arm's protective stop would end.
pub const FURNITURE_TOUCH_DEPTH: f64 = 0.005;

/// How much deeper (m) than at the start of a motion a link already pressed into furniture
/// may go before the protective stop ends the motion: a hand leaving a part it rests
/// against slides along it without pushing further in.
const FURNITURE_STOP_SLACK: f64 = 0.001;

/// The furniture of a scene at one moment ([`Sim::furniture_snapshot`]): how deep the robot
/// would press into it at given joints.
pub(crate) struct FurnitureSnapshot<'a> {
    sim: &'a Sim,
    blockers: Vec<Blocker<'a>>,
}

impl FurnitureSnapshot<'_> {
    /// The deepest overlap (m) of the robot's links with any piece of furniture were the arm
    /// at joints `q` with finger travel `g` (0 when it touches none): what a grasp would
    /// press into before it is tried.
    pub(crate) fn arm_depth_at(&self, q: &[f64], g: f64) -> f64 {
        self.robot_depth_at(q, g, |_| true)
    }

    /// [`FurnitureSnapshot::arm_depth_at`] for the fingers alone.
    pub(crate) fn fingers_depth_at(&self, q: &[f64], g: f64) -> f64 {
        self.robot_depth_at(q, g, |c| self.sim.robot.gripper_colliders.contains(&c))
    }

    /// The deepest overlap (m) with furniture of the robot colliders that `keep` accepts,
    /// were the arm at `(q, g)`.
    fn robot_depth_at(&self, q: &[f64], g: f64, keep: impl Fn(ColliderHandle) -> bool) -> f64 {
        if self.blockers.is_empty() {
            return 0.0;
        }
        let poses = self.sim.robot.model.link_poses(q, g);
        let mut deepest = 0.0_f64;
        self.sim.visit_robot_shapes(&poses, |c, shape, pose| {
            if !keep(c) {
                return;
            }
            let aabb = shape.compute_aabb(&pose);
            for blocker in self.blockers.iter().filter(|b| aabb.intersects(&b.aabb)) {
                let contact =
                    rapier3d::parry::query::contact(&pose, shape, &blocker.pose, blocker.shape, 0.0);
                if let Ok(Some(contact)) = contact {
                    deepest = deepest.max(-f64::from(contact.dist));
                }
            }
        });
        deepest
    }
}

/// What was moving when a motion was stopped by contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mover {
    /// A scene part (part index): a lid or drawer the arm drives, or an object it carries.
    Part(usize),
    /// A link of the robot (link index in its model).
    RobotLink(usize),
}

/// A motion ended by contact: what was moving and the part it ran into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ContactStop {
    /// What was stopped.
    pub moving: Mover,
    /// The part (part index) it ran into.
    pub obstacle: usize,
}

impl ContactStop {
    /// The API error of the call `call` whose motion this stopped.
    pub(crate) fn into_error(self, sim: &Sim, call: &str) -> ApiError {
        ApiError::Collision {
            call: call.to_owned(),
            moving: sim.mover_name(self.moving),
            obstacle: sim.parts[self.obstacle].name.clone(),
        }
    }
}

/// A solid collider that a link may not enter, with its part, world pose and box.
struct Blocker<'a> {
    part: usize,
    shape: &'a dyn Shape,
    pose: Pose,
    aabb: rapier3d::parry::bounding_volume::Aabb,
}

impl Sim {
    /// How errors and reports name what moved: the part's name, or `the robot's <link>`.
    fn mover_name(&self, mover: Mover) -> String {
        match mover {
            Mover::Part(part) => self.parts[part].name.clone(),
            Mover::RobotLink(link) => format!("the robot's {}", self.robot.model.links[link].name),
        }
    }

    /// The solid colliders of every fixed part, articulated body and link that belongs to
    /// another scene object than articulation `ai`'s (a cabinet's drawers slide inside their
    /// own body without touching it).
    fn furniture_blockers(&self, ai: usize) -> Vec<Blocker<'_>> {
        let own = self.parts[self.articulations[ai].link].object;
        self.furniture_colliders(|part| part.object != own)
    }

    /// The solid colliders of every fixed part, articulated body and link that `keep`
    /// accepts.
    fn furniture_colliders(&self, keep: impl Fn(&Part) -> bool) -> Vec<Blocker<'_>> {
        self.parts
            .iter()
            .enumerate()
            .filter(|(_, p)| keep(p) && p.role.is_furniture())
            .flat_map(|(i, p)| {
                p.colliders.iter().filter_map(move |&c| {
                    let collider = &self.world.colliders[c];
                    (!collider.is_sensor()).then(|| Blocker {
                        part: i,
                        shape: collider.shape(),
                        pose: *collider.position(),
                        aabb: collider.compute_aabb(),
                    })
                })
            })
            .collect()
    }

    /// The first blocker that articulation `ai`'s solid moving colliders would overlap at
    /// joint position `q`.
    fn blocked_at(&self, ai: usize, q: f64, blockers: &[Blocker<'_>]) -> Option<usize> {
        for moving in self.articulation_colliders_at(ai, q) {
            for blocker in blockers {
                if !moving.aabb.intersects(&blocker.aabb) {
                    continue;
                }
                let touching = rapier3d::parry::query::intersection_test(
                    &moving.pose,
                    moving.shape,
                    &blocker.pose,
                    blocker.shape,
                )
                .is_ok_and(|hit| hit.intersecting);
                if touching {
                    return Some(blocker.part);
                }
            }
        }
        None
    }

    /// How far articulation `ai` gets on its way from its current position to `wanted`:
    /// `wanted` when the way is clear, else the last clear position (to
    /// [`CONTACT_RESOLUTION`]) and the part it meets there. A link that already touches
    /// something may still move toward closed, the way it came in.
    pub(crate) fn travel_until_contact(&self, ai: usize, wanted: f64) -> (f64, Option<ContactStop>) {
        let a = &self.articulations[ai];
        let (from, link) = (a.q, a.link);
        let closed = a.limits.0;
        if (wanted - from).abs() < 1e-12 {
            return (wanted, None);
        }
        let blockers = self.furniture_blockers(ai);
        let Some(obstacle) = self.blocked_at(ai, wanted, &blockers) else {
            return (wanted, None);
        };
        let stop = |obstacle| ContactStop {
            moving: Mover::Part(link),
            obstacle,
        };
        if self.blocked_at(ai, from, &blockers).is_some() {
            let toward_closed = (wanted - closed).abs() < (from - closed).abs();
            return if toward_closed {
                (wanted, None)
            } else {
                (from, Some(stop(obstacle)))
            };
        }
        // `clear` is free and `hit` overlaps: halve the gap until it is below the resolution.
        let (mut clear, mut hit) = (from, wanted);
        let mut obstacle = obstacle;
        while (hit - clear).abs() > CONTACT_RESOLUTION {
            let mid = (clear + hit) / 2.0;
            match self.blocked_at(ai, mid, &blockers) {
                Some(part) => {
                    hit = mid;
                    obstacle = part;
                }
                None => clear = mid,
            }
        }
        (clear, Some(stop(obstacle)))
    }

    /// The solid colliders of articulation `ai`'s moving parts posed at joint position `q`.
    fn articulation_colliders_at(&self, ai: usize, q: f64) -> impl Iterator<Item = Blocker<'_>> {
        let a = &self.articulations[ai];
        let body_pose = a.frame * objects::joint_motion(a.joint, q);
        a.parts.iter().flat_map(move |&part| {
            self.parts[part].colliders.iter().filter_map(move |&c| {
                let collider = &self.world.colliders[c];
                if collider.is_sensor() {
                    return None;
                }
                let local = collider.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
                let pose = body_pose * local;
                Some(Blocker {
                    part,
                    shape: collider.shape(),
                    pose,
                    aabb: collider.shape().compute_aabb(&pose),
                })
            })
        })
    }

    /// Pairs of moving links (part indices) of different assets where the first, fully
    /// open, stands in the way of the second: the second cannot travel from closed to open
    /// without meeting it (two cabinets at right angles whose drawers open into each other's
    /// way). The pairs are what the observer states as `Blocks`; the contact itself is
    /// simulated while a drawer moves ([`Sim::travel_until_contact`]).
    pub(crate) fn articulation_blocking(&self) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        for (ai, a) in self.articulations.iter().enumerate() {
            let owner = self.parts[a.link].object;
            let others: Vec<usize> = (0..self.articulations.len())
                .filter(|&bi| self.parts[self.articulations[bi].link].object != owner)
                .collect();
            // A scene with one asset (every benchmark scene) has nothing to check.
            if others.is_empty() {
                continue;
            }
            let open: Vec<Blocker<'_>> = self.articulation_colliders_at(ai, a.limits.1).collect();
            for bi in others {
                let b = &self.articulations[bi];
                let (closed, full) = b.limits;
                let meets = (1..=BLOCKING_SAMPLES).any(|k| {
                    let q = closed + (full - closed) * k as f64 / BLOCKING_SAMPLES as f64;
                    self.blocked_at(bi, q, &open).is_some()
                });
                if meets {
                    pairs.push((a.link, b.link));
                }
            }
        }
        pairs
    }

    /// The pairs of moving links of different assets that stand in the way of one another's
    /// opening, by name: `(a, b)` when `a`, fully open, leaves `b` no way from closed to
    /// open (found when the scene is built; the observer states them as `Blocks`).
    pub fn blocking_pairs(&self) -> Vec<(String, String)> {
        self.blocking
            .iter()
            .map(|&(a, b)| (self.parts[a].name.clone(), self.parts[b].name.clone()))
            .collect()
    }

    /// The scene object (index) that articulation `ai` belongs to.
    pub(crate) fn articulation_asset(&self, ai: usize) -> usize {
        self.parts[self.articulations[ai].link].object
    }

    /// The scene objects (indices) the protective stop lets the arm overlap: the asset whose
    /// handle the hand is reaching for or holding, and the one whose handle it let go of
    /// and has not yet left.
    fn handled_assets(&self) -> [Option<usize>; 2] {
        let operated = self.handle_approach.or_else(|| {
            self.handle_grasp
                .map(|grasp| self.articulation_asset(grasp.articulation))
        });
        [operated, self.leaving_asset]
    }

    /// Forgets the asset the hand let go of once no link of the arm overlaps it any more.
    pub(crate) fn note_left_asset(&mut self) {
        let Some(asset) = self.leaving_asset else { return };
        let still_in = self
            .arm_furniture_depths()
            .iter()
            .any(|((_, part), _)| self.parts[*part].object == asset);
        if !still_in {
            self.leaving_asset = None;
        }
    }

    /// The overlaps with furniture, deeper than a touch, that a motion starting now may keep
    /// without being stopped (a hand that let go of a handle leaves the lid it rests on).
    pub(crate) fn furniture_overlaps_at_start(&self) -> Vec<((Mover, usize), f64)> {
        let mut depths = self.arm_furniture_depths();
        depths.retain(|(_, depth)| *depth > FURNITURE_TOUCH_DEPTH);
        depths
    }

    /// The protective stop: the deepest overlap of a robot link or the carried object with a
    /// piece of furniture that is deeper than [`FURNITURE_TOUCH_DEPTH`] and deeper (by
    /// [`FURNITURE_STOP_SLACK`]) than the same pair was at the motion's start (`at_start`, from
    /// [`Sim::furniture_overlaps_at_start`]). The asset whose handle the hand is reaching
    /// for or holding is exempt (see the module's documentation).
    pub(crate) fn protective_stop(&self, at_start: &[((Mover, usize), f64)]) -> Option<ContactStop> {
        let handled = self.handled_assets();
        self.arm_furniture_depths()
            .into_iter()
            .filter(|((_, part), _)| !handled.contains(&Some(self.parts[*part].object)))
            .filter(|(key, depth)| {
                let before = at_start
                    .iter()
                    .find(|(k, _)| k == key)
                    .map_or(0.0, |(_, d)| *d + FURNITURE_STOP_SLACK);
                *depth > FURNITURE_TOUCH_DEPTH.max(before)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|((moving, obstacle), _)| ContactStop { moving, obstacle })
    }

    /// Every piece of furniture's solid colliders as they stand now, to weigh arm poses
    /// against (built once for the several poses a decision compares).
    pub(crate) fn furniture_snapshot(&self) -> FurnitureSnapshot<'_> {
        FurnitureSnapshot {
            sim: self,
            blockers: self.furniture_colliders(|_| true),
        }
    }

    /// How deep each of the robot's links and the carried object presses into each piece of
    /// furniture it overlaps, at the bodies' current poses.
    pub(crate) fn arm_furniture_depths(&self) -> Vec<((Mover, usize), f64)> {
        let blockers = self.furniture_colliders(|_| true);
        if blockers.is_empty() {
            return Vec::new();
        }
        let links = self
            .robot
            .bodies
            .iter()
            .map(|&(link, body)| (Mover::RobotLink(link), body));
        let held = self
            .held
            .map(|held| (Mover::Part(held.part), self.parts[held.part].body));
        let mut depths: Vec<((Mover, usize), f64)> = Vec::new();
        // The hand holding a handle closes around it, against the lid or drawer front it is
        // mounted on: that link is not an obstacle to the gripper's own colliders.
        let grasped_link = self
            .handle_grasp
            .map(|grasp| self.articulations[grasp.articulation].link);
        for (mover, body) in links.chain(held) {
            for &c in self.world.bodies[body].colliders() {
                let collider = &self.world.colliders[c];
                if collider.is_sensor() {
                    continue;
                }
                let (shape, pose) = (collider.shape(), collider.position());
                let aabb = collider.compute_aabb();
                let gripping = self.robot.gripper_colliders.contains(&c);
                for blocker in &blockers {
                    if !aabb.intersects(&blocker.aabb) || (gripping && Some(blocker.part) == grasped_link) {
                        continue;
                    }
                    let contact =
                        rapier3d::parry::query::contact(pose, shape, &blocker.pose, blocker.shape, 0.0);
                    let Ok(Some(contact)) = contact else { continue };
                    let depth = -f64::from(contact.dist);
                    if depth <= 0.0 {
                        continue;
                    }
                    let key = (mover, blocker.part);
                    match depths.iter_mut().find(|(k, _)| *k == key) {
                        Some((_, deepest)) => *deepest = deepest.max(depth),
                        None => depths.push((key, depth)),
                    }
                }
            }
        }
        depths
    }
}

/// The deepest overlap of one link or carried object with one piece of furniture during an
/// episode.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FurnitureContact {
    /// What overlapped: `the robot's <link>` or the carried object's name.
    pub moving: String,
    /// The furniture part.
    pub obstacle: String,
    /// The deepest overlap (m).
    pub depth: f64,
    /// The API call during which it was deepest, as `name #index` in the trace.
    pub call: String,
}

/// A hook that measures, after every control step, how deep the robot's links and the
/// object it carries overlap every fixed part, articulated body and link (the hand and a lid
/// or drawer whose handle it holds excepted), and keeps the deepest overlap of each pair.
///
/// ```
/// use nesy_core::Embodiment;
/// use nesy_sim::api::{Direction, RobotApi};
/// use nesy_sim::scene::SubtaskKind;
/// use nesy_sim::tasks::TaskConfig;
/// use nesy_sim::world::{FurnitureContactProbe, Sim};
///
/// let task = TaskConfig::single(SubtaskKind::PickPlace, 3, 0, 0, Embodiment::Finger)
///     .generate()
///     .unwrap();
/// let mut sim = Sim::new(&task.scene).unwrap();
/// sim.add_hook(Box::new(FurnitureContactProbe::default()));
/// sim.move_to_position([0.4, 0.0, 0.6], Direction::Down, 0.0, 0.0).unwrap();
/// let probe = sim.hook::<FurnitureContactProbe>().unwrap();
/// assert!(probe.contacts().is_empty(), "a move through free space touches nothing");
/// ```
#[derive(Debug, Default)]
pub struct FurnitureContactProbe {
    /// One entry per pair that overlapped; names are made when a pair is first seen.
    deepest: Vec<DeepestOverlap>,
}

/// A pair's deepest overlap so far.
#[derive(Debug)]
struct DeepestOverlap {
    /// What moved and the part (index) it overlapped.
    key: (Mover, usize),
    /// Their names, made when the pair is first seen.
    moving: String,
    obstacle: String,
    /// The deepest overlap (m).
    depth: f64,
    /// The call during which the overlap was deepest, once that call has returned.
    call: Option<String>,
}

impl FurnitureContactProbe {
    /// Every pair that overlapped, deepest first.
    pub fn contacts(&self) -> Vec<FurnitureContact> {
        let mut contacts: Vec<FurnitureContact> = self
            .deepest
            .iter()
            .map(|d| FurnitureContact {
                moving: d.moving.clone(),
                obstacle: d.obstacle.clone(),
                depth: d.depth,
                call: d
                    .call
                    .clone()
                    .unwrap_or_else(|| "(after the last call)".to_owned()),
            })
            .collect();
        contacts.sort_by(|a, b| b.depth.total_cmp(&a.depth));
        contacts
    }
}

impl SimHook for FurnitureContactProbe {
    fn step_interval(&self) -> Option<u64> {
        Some(1)
    }

    fn on_step(&mut self, sim: &Sim) {
        for (key, depth) in sim.arm_furniture_depths() {
            match self.deepest.iter_mut().find(|d| d.key == key) {
                Some(deepest) if deepest.depth >= depth => {}
                Some(deepest) => {
                    deepest.depth = depth;
                    deepest.call = None;
                }
                None => self.deepest.push(DeepestOverlap {
                    key,
                    moving: sim.mover_name(key.0),
                    obstacle: sim.parts[key.1].name.clone(),
                    depth,
                    call: None,
                }),
            }
        }
    }

    fn on_call(&mut self, _sim: &Sim, entry: &TraceEntry) {
        for pending in self.deepest.iter_mut().filter(|d| d.call.is_none()) {
            pending.call = Some(format!("{} #{}", entry.call.name(), entry.index));
        }
    }
}
