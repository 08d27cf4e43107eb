//! `pick_place` (`docs/benchmark.md` §2.1): cubes around a spot in front of the toy box; obstruction
//! stacks two or three of them.

use std::f64::consts::PI;

use super::{REST_GAP, SubtaskLayout, layout_stream, object, obstruction_stream};
use crate::scene::{ObjectKind, SubtaskGoal, TABLE_TOP, parts};
use crate::tasks::SubtaskConfig;

/// Cube colours before shuffling (`docs/benchmark.md` §2.1).
pub(crate) const COLOURS: [&str; 5] = ["red", "blue", "yellow", "green", "purple"];
/// Cube edge (m).
const CUBE: f64 = 0.03;

pub(crate) fn layout(config: &SubtaskConfig, [ox, oy]: [f64; 2]) -> SubtaskLayout {
    let mut rng = layout_stream(config.kind, config.variant);
    let centre = [ox + 0.05, oy - 0.1];
    let mut spots: Vec<[f64; 2]> = (0..5)
        .map(|i| {
            let a = 2.0 * PI * i as f64 / 5.0;
            [centre[0] + 0.05 * a.cos(), centre[1] + 0.05 * a.sin()]
        })
        .collect();
    rng.shuffle(&mut spots);
    let mut colours = COLOURS;
    rng.shuffle(&mut colours);
    let yaws: Vec<f64> = (0..5).map(|_| rng.uniform(-45.0, 45.0).to_radians()).collect();

    let n = config.kind.object_count(config.multi_level);
    let mut cubes: Vec<(String, [f64; 3], f64)> = (0..n)
        .map(|i| {
            (
                format!("{}_cube", colours[i]),
                [spots[i][0], spots[i][1], TABLE_TOP],
                yaws[i],
            )
        })
        .collect();
    if config.obst_level > 0 {
        // A stack of obst + 1 cubes, each later member on the previous one.
        let height = (config.obst_level as usize + 1).min(n);
        let mut members = obstruction_stream(config.kind, config.variant).sample_indices(n, height);
        members.sort_unstable();
        for k in 1..members.len() {
            let below = cubes[members[k - 1]].1;
            cubes[members[k]].1 = [below[0], below[1], below[2] + CUBE + REST_GAP];
        }
    }
    let mut objects = vec![object(
        parts::TOY_BOX,
        ObjectKind::ToyBox,
        ox + 0.05,
        oy + 0.1,
        TABLE_TOP,
        0.0,
    )];
    objects.extend(
        cubes
            .iter()
            .map(|(name, [x, y, z], yaw)| object(name, ObjectKind::Cube, *x, *y, *z, *yaw)),
    );
    SubtaskLayout {
        objects,
        articulations: Vec::new(),
        goals: vec![SubtaskGoal::PickPlace {
            objects: cubes.into_iter().map(|(name, _, _)| name).collect(),
            container: parts::TOY_BOX.into(),
        }],
    }
}
