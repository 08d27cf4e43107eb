//! Lids and drawers meeting other furniture. Articulated links are kinematic bodies that the
//! simulator moves along their joints, and Rapier computes no contacts between kinematic
//! and fixed bodies, so a drawer pulled open would pass through a neighbouring cabinet.
//! Here the joint travels only as far as its link's solid colliders stay clear of every
//! other asset's fixed and articulated parts: a drawer opened into another one stops where
//! the two meet, as a real one does, and the arm that pulls it stops there too (the
//! motion ends with [`ApiError::Collision`], the way a real arm's protective stop ends it).
//!
//! Loose objects are not obstacles here: they are dynamic bodies, and the link pushes them
//! through the physics as it moves.

use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::prelude::{Pose, Shape};

use crate::api::ApiError;
use crate::world::Sim;
use crate::world::objects::{self, PartRole};

/// Joint resolution (m for drawers, rad for lids) to which the contact position is found.
pub(crate) const CONTACT_RESOLUTION: f64 = 1e-4;

/// A motion ended by contact: the moving link and the part it ran into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ContactStop {
    /// The link (part index) whose travel was stopped.
    pub moving: usize,
    /// The part (part index) it ran into.
    pub obstacle: usize,
}

impl ContactStop {
    /// The API error of the call `call` whose motion this stopped.
    pub(crate) fn into_error(self, sim: &Sim, call: &str) -> ApiError {
        ApiError::Collision {
            call: call.to_owned(),
            moving: sim.parts[self.moving].name.clone(),
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
    /// The solid colliders of every fixed part, articulated body and link that belongs to
    /// another scene object than articulation `ai`'s (a cabinet's drawers slide inside their
    /// own body without touching it).
    fn furniture_blockers(&self, ai: usize) -> Vec<Blocker<'_>> {
        let own = self.parts[self.articulations[ai].link].object;
        self.parts
            .iter()
            .enumerate()
            .filter(|(_, p)| {
                p.object != own
                    && matches!(
                        p.role,
                        PartRole::Fixed | PartRole::ArticulatedBody | PartRole::Link
                    )
            })
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
        let a = &self.articulations[ai];
        let body_pose = a.frame * objects::joint_motion(a.joint, q);
        for &part in &a.parts {
            for &c in &self.parts[part].colliders {
                let collider = &self.world.colliders[c];
                if collider.is_sensor() {
                    continue;
                }
                let local = collider.position_wrt_parent().copied().unwrap_or(Pose::IDENTITY);
                let pose = body_pose * local;
                let aabb = collider.shape().compute_aabb(&pose);
                for blocker in blockers {
                    if !aabb.intersects(&blocker.aabb) {
                        continue;
                    }
                    let touching = rapier3d::parry::query::intersection_test(
                        &pose,
                        collider.shape(),
                        &blocker.pose,
                        blocker.shape,
                    )
                    .is_ok_and(|hit| hit.intersecting);
                    if touching {
                        return Some(blocker.part);
                    }
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
            moving: link,
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
}
