//! `put_in_hinge` (`docs/benchmark.md` §2.3): fruits in a row beside the hinge box; obstruction closes the
//! lid and (level 2) puts one of the fruits on it.

use super::{REST_GAP, SubtaskLayout, layout_stream, object, obstruction_stream};
use crate::scene::parts::{self, LID_CLOSED, LID_OPEN};
use crate::scene::{ObjectKind, SubtaskGoal, TABLE_TOP};
use crate::tasks::SubtaskConfig;

/// Height of the closed lid's top surface above the table (body 0.1165 + lid 0.01).
const LID_TOP: f64 = 0.1265;

const FRUITS: [(&str, ObjectKind); 3] = [
    ("apple", ObjectKind::Apple),
    ("orange", ObjectKind::Orange),
    ("lemon", ObjectKind::Lemon),
];

pub(crate) fn layout(config: &SubtaskConfig, [ox, oy]: [f64; 2]) -> SubtaskLayout {
    let reflect = oy < 0.0;
    let mut rng = layout_stream(config.kind, config.variant);
    let mut ys = [oy - 0.08, oy, oy + 0.08];
    rng.shuffle(&mut ys);
    let n = config.kind.object_count(config.multi_level);
    let chosen: Vec<usize> = rng.sample_indices(FRUITS.len(), n);
    let yaw_turn = if reflect { std::f64::consts::PI } else { 0.0 };
    let yaws: Vec<f64> = (0..n)
        .map(|_| rng.uniform(-10.0, 10.0).to_radians() + yaw_turn)
        .collect();
    // The box sits 2 cm off the row's centre, toward y = 0 when reflected; its orientation
    // is the same either way (the authors do not rotate it).
    let body = [ox, if reflect { oy + 0.02 } else { oy - 0.02 }];
    let mut fruits: Vec<(usize, [f64; 3], f64)> = chosen
        .iter()
        .enumerate()
        .map(|(i, &f)| (f, [ox - 0.14, ys[i], TABLE_TOP], yaws[i]))
        .collect();
    let lid = if config.obst_level == 0 {
        LID_OPEN
    } else {
        LID_CLOSED
    };
    if config.obst_level >= 2 {
        let i = obstruction_stream(config.kind, config.variant).index(n);
        fruits[i].1 = [body[0], body[1], TABLE_TOP + LID_TOP + REST_GAP];
    }
    let mut objects = vec![object(
        parts::HINGE_BODY,
        ObjectKind::HingeBox,
        body[0],
        body[1],
        TABLE_TOP,
        0.0,
    )];
    objects.extend(
        fruits
            .iter()
            .map(|(f, [x, y, z], yaw)| object(FRUITS[*f].0, FRUITS[*f].1, *x, *y, *z, *yaw)),
    );
    SubtaskLayout {
        objects,
        articulations: vec![(parts::HINGE_LID.into(), lid)],
        goals: vec![SubtaskGoal::PutInHinge {
            objects: fruits.iter().map(|(f, _, _)| FRUITS[*f].0.to_owned()).collect(),
            container: parts::HINGE_BODY.into(),
            lid: parts::HINGE_LID.into(),
        }],
    }
}
