//! `put_in_prismatic` (`docs/benchmark.md` §2.4): cylinders on top of the drawer cabinet; obstruction
//! closes the bottom drawer and (level 2) opens the top one over its handle.

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use super::{REST_GAP, SubtaskLayout, layout_stream, object};
use crate::scene::parts::{self, DRAWER_OPEN};
use crate::scene::{ObjectKind, SubtaskGoal, TABLE_TOP};
use crate::tasks::SubtaskConfig;
use crate::tasks::pick_place::COLOURS;

/// Cabinet height (m).
const CABINET_HEIGHT: f64 = 0.194;

pub(crate) fn layout(config: &SubtaskConfig, [ox, oy]: [f64; 2]) -> SubtaskLayout {
    let reflect = oy < 0.0;
    let mut rng = layout_stream(config.kind, config.variant);
    // Facing −y (toward y = 0) normally, +y when reflected: the drawers open toward the
    // middle of the table either way.
    let (centre, yaw) = if reflect {
        ([ox, oy - 0.05], PI)
    } else {
        ([ox, oy + 0.05], 0.0)
    };
    let mut spots: Vec<[f64; 2]> = (0..4)
        .map(|k| {
            let a = FRAC_PI_4 + k as f64 * FRAC_PI_2;
            [centre[0] + 0.055 * a.cos(), centre[1] + 0.055 * a.sin()]
        })
        .collect();
    rng.shuffle(&mut spots);
    let mut colours = COLOURS;
    rng.shuffle(&mut colours);
    let yaws: Vec<f64> = (0..4)
        .map(|_| rng.uniform(-45.0, 45.0).to_radians() + yaw)
        .collect();
    let n = config.kind.object_count(config.multi_level);
    let names: Vec<String> = (0..n).map(|i| format!("{}_cylinder", colours[i])).collect();
    let (bottom, top) = match config.obst_level {
        0 => (DRAWER_OPEN, 0.0),
        1 => (0.0, 0.0),
        _ => (0.0, DRAWER_OPEN),
    };
    let mut objects = vec![object(
        parts::DRAWER_BODY,
        ObjectKind::DrawerCabinet,
        centre[0],
        centre[1],
        TABLE_TOP,
        yaw,
    )];
    for (i, name) in names.iter().enumerate() {
        objects.push(object(
            name,
            ObjectKind::Cylinder,
            spots[i][0],
            spots[i][1],
            TABLE_TOP + CABINET_HEIGHT + REST_GAP,
            yaws[i],
        ));
    }
    SubtaskLayout {
        objects,
        articulations: vec![
            (parts::BOTTOM_DRAWER.into(), bottom),
            (parts::TOP_DRAWER.into(), top),
        ],
        goals: vec![SubtaskGoal::PutInPrismatic {
            objects: names,
            drawer: parts::BOTTOM_DRAWER.into(),
        }],
    }
}
