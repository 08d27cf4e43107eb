//! `get_empty_floor_xy`: a free table spot for putting an object down (`docs/benchmark.md` §4), with the
//! authors' variable-shadowing bugs fixed (see the crate README).

use nesy_core::Embodiment;

use crate::api::{Direction, MAX_FINGER_DEPTH};
use crate::robot::model::{HAND_HALF_LENGTH, HAND_HALF_WIDTH, PALM_ABOVE_TOOL};
use crate::scene::TABLE_TOP;
use crate::world::geometry::Aabb;
use crate::world::objects::PartRole;
use crate::world::{FLOOR_AABB, Sim};

/// Obstacle padding in xy (m).
const PAD: f64 = 0.02;
/// Upper x bound of the search region before articulated assets cut it.
const REGION_X_MAX: f64 = 0.53;
/// y bounds of the search region.
const REGION_Y: (f64, f64) = (-0.15, 0.16);

/// Finds a free xy for `part`: on a grid of step 0.6 × its larger footprint side over the
/// region x ∈ [0.11 + hx, min(0.53, every hinge/drawer body's min x) − hx], y ∈ [−0.15 + hy,
/// 0.16 − hy]; free means its padded footprint meets no other object's padded footprint.
/// With the protective stop on, the finger hand setting the object down must fit as well:
/// a spot is free only if the hand, at the default angle above it with the object held at
/// mid-height on the table, keeps its length off every piece of furniture standing higher
/// than its palm (else the stop would end the set-down at an open lid or drawer), and the
/// arm must be able to take it again from there: for some grasp spin, nothing of the arm
/// touches furniture on the way down to it.
/// The current spot wins if it is free; otherwise the candidate nearest the object's
/// current position.
pub(crate) fn empty_floor_xy(sim: &Sim, part: usize) -> Option<[f64; 2]> {
    let me = sim.part_aabb(part);
    let size = me.size();
    let (hx, hy) = (size[0] / 2.0, size[1] / 2.0);
    let mut x_max = REGION_X_MAX;
    for (i, _) in sim
        .parts()
        .iter()
        .enumerate()
        .filter(|(_, p)| p.role == PartRole::ArticulatedBody)
    {
        x_max = x_max.min(sim.part_aabb(i).min[0]);
    }
    let (x_lo, x_hi) = (FLOOR_AABB.min[0] + hx, x_max - hx);
    let (y_lo, y_hi) = (REGION_Y.0 + hy, REGION_Y.1 - hy);
    if x_lo > x_hi || y_lo > y_hi {
        return None;
    }
    let held = sim.held_object();
    let obstacles: Vec<Aabb> = (0..sim.parts().len())
        .filter(|&i| i != part && Some(sim.parts()[i].name.as_str()) != held)
        .map(|i| sim.part_aabb(i).padded([-PAD, -PAD, 0.0], [PAD, PAD, 0.0]))
        .collect();
    let palm_underside = TABLE_TOP + size[2] / 2.0 + PALM_ABOVE_TOOL;
    let furniture: Vec<Aabb> = if sim.protective_stop && sim.scene.embodiment == Embodiment::Finger {
        (0..sim.parts().len())
            .filter(|&i| sim.parts()[i].role.is_furniture())
            .map(|i| sim.part_aabb(i))
            .filter(|b| b.max[2] > palm_underside)
            .collect()
    } else {
        Vec::new()
    };
    let free = |x: f64, y: f64| {
        let foot = Aabb {
            min: [x - hx - PAD, y - hy - PAD, 0.0],
            max: [x + hx + PAD, y + hy + PAD, 0.0],
        };
        let hand = Aabb {
            min: [x - HAND_HALF_WIDTH, y - HAND_HALF_LENGTH, 0.0],
            max: [x + HAND_HALF_WIDTH, y + HAND_HALF_LENGTH, 0.0],
        };
        obstacles.iter().all(|o| !foot.overlaps_xy(o, 0.0))
            && furniture.iter().all(|f| !hand.overlaps_xy(f, 0.0))
    };
    // With the stop on, the arm must also be able to take the object again from there: for
    // some grasp spin, the wrist and forearm above the hand clear the furniture on the way
    // down (the hand's footprint alone let a cube be set down where the wrist then met a
    // cabinet beside it). Checked last, by inverse kinematics, on the nearest free spots.
    let snapshot = (!furniture.is_empty()).then(|| sim.furniture_snapshot());
    let grasp_z = TABLE_TOP + size[2] - (size[2] / 2.0).min(MAX_FINGER_DEPTH);
    let spins = match snapshot {
        Some(_) => {
            let (angle, step) = sim.finger_grasp_spins(part);
            sim.spins_by_nearness(Direction::Down, angle, step)
        }
        None => Vec::new(),
    };
    let retakable = |x: f64, y: f64| {
        let Some(snapshot) = &snapshot else {
            return true;
        };
        spins.iter().any(|&spin| {
            let rotation = Sim::pointing(Direction::Down, spin);
            sim.descent_into_furniture(snapshot, part, [x, y], grasp_z, rotation) == 0.0
        })
    };
    let c = me.centre();
    if (x_lo..=x_hi).contains(&c[0])
        && (y_lo..=y_hi).contains(&c[1])
        && free(c[0], c[1])
        && retakable(c[0], c[1])
    {
        return Some([c[0], c[1]]);
    }
    let step = 0.6 * size[0].max(size[1]).max(0.01);
    let nx = ((x_hi - x_lo) / step).floor() as usize;
    let ny = ((y_hi - y_lo) / step).floor() as usize;
    let mut candidates: Vec<(f64, [f64; 2])> = (0..=nx)
        .flat_map(|i| (0..=ny).map(move |j| [x_lo + i as f64 * step, y_lo + j as f64 * step]))
        .filter(|&[x, y]| free(x, y))
        .map(|[x, y]| ((x - c[0]).powi(2) + (y - c[1]).powi(2), [x, y]))
        .collect();
    // Nearest first; among equals, grid order (the stable sort keeps it).
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    candidates
        .into_iter()
        .map(|(_, xy)| xy)
        .find(|&[x, y]| retakable(x, y))
}
