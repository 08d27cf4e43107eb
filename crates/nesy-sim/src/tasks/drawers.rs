//! `sort_into_drawers`: the paper's real-world drawers task (Table 2). Two drawer cabinets,
//! `front_` and `side_`, and two to four cubes, the first half for the front cabinet's
//! bottom drawer and the rest for the side cabinet's.
//!
//! - Obstruction level 0 (the demonstration's setting): the cabinets stand side by side,
//!   both facing −y, so both drawers can stand open at once.
//! - Level 1: the side cabinet is turned a quarter turn and stands at the front cabinet's
//!   far corner, so that each cabinet's drawers open into the way of the other's drawers at
//!   the same height: one bottom drawer cannot open while the other stands open.
//! - Level 2: as level 1, and each side-cabinet cube is stacked on a front-cabinet cube, so
//!   the cubes must be handled in order (the side cabinet's first).
//!
//! Positions are drawn from the subtask's layout stream around fixed anchors (the paper
//! randomises every trial): the cabinets by up to ±2 cm, the cubes over a free band of the
//! table in front of the cabinets.

use std::f64::consts::FRAC_PI_2;

use super::{REST_GAP, SubtaskLayout, layout_stream, object};
use crate::scene::parts::{self, DRAWER_CABINET_PARTS};
use crate::scene::{ObjectKind, SubtaskGoal, TABLE_TOP};
use crate::tasks::SubtaskConfig;
use crate::tasks::pick_place::COLOURS;

/// Prefix of the cabinet that faces −y in every setting.
pub(crate) const FRONT: &str = "front_";
/// Prefix of the cabinet that stands beside it, or turned at its corner.
pub(crate) const SIDE: &str = "side_";
/// Cube edge (m).
const CUBE: f64 = 0.03;
/// Where the front cabinet stands, relative to the subtask's offset.
const FRONT_AT: [f64; 2] = [-0.04, 0.19];
/// Where the side cabinet stands beside it (level 0), relative to the front cabinet.
const SIDE_BESIDE: [f64; 2] = [0.165, 0.0];
/// Where the side cabinet stands turned at its corner (levels 1 and 2), relative to the
/// front cabinet: turned a quarter turn clockwise, its drawers open toward −x, across the
/// front drawers' way. It stands at the far corner, so that the free table between the robot
/// and the furniture (where `get_empty_floor_xy` looks) stays within easy reach.
const SIDE_TURNED: [f64; 2] = [0.16, -0.19];
/// Largest shift (m) of a cabinet from its anchor.
const CABINET_JITTER: f64 = 0.02;
/// The band of the table the cubes are laid out in, relative to the offset: clear of both
/// cabinets and of the drawers' travel in every setting.
const CUBE_BAND: ([f64; 2], [f64; 2]) = ([-0.07, -0.29], [0.13, -0.15]);
/// Least distance (m) in y from the turned cabinet's centre to a cube's centre. Its drawer
/// face stands 7.7 cm from its centre; with a cube closer than 18 cm, the arm coming down on
/// the cube meets the cabinet whichever way the hand turns: lying along y, the 20 cm hand;
/// lying along x, the wrist, which trails 9 cm off the hand's axis (measured with the
/// protective stop: 13.6 to 15.6 cm stopped, and 16.6 cm stopped in one scene and not in
/// another).
const TURNED_CLEARANCE: f64 = 0.18;
/// Least distance (m) between two cubes' centres on the table.
const CUBE_SPACING: f64 = 0.065;

pub(crate) fn layout(config: &SubtaskConfig, [ox, oy]: [f64; 2]) -> SubtaskLayout {
    let mut rng = layout_stream(config.kind, config.variant);
    let shift: [f64; 2] = std::array::from_fn(|_| rng.uniform(-CABINET_JITTER, CABINET_JITTER));
    let front = [ox + FRONT_AT[0] + shift[0], oy + FRONT_AT[1] + shift[1]];
    let turned = config.obst_level > 0;
    let (side, side_yaw) = if turned {
        ([front[0] + SIDE_TURNED[0], front[1] + SIDE_TURNED[1]], -FRAC_PI_2)
    } else {
        ([front[0] + SIDE_BESIDE[0], front[1] + SIDE_BESIDE[1]], 0.0)
    };
    let mut colours = COLOURS;
    rng.shuffle(&mut colours);
    let n = config.kind.object_count(config.multi_level);
    // Candidate spots on a grid over the band, shuffled; taken while they keep their spacing.
    let ([x0, y0], [x1, y1]) = CUBE_BAND;
    let mut grid: Vec<[f64; 2]> = Vec::new();
    let steps = 6;
    for i in 0..=steps {
        for j in 0..=steps {
            let t = [i as f64 / steps as f64, j as f64 / steps as f64];
            grid.push([ox + x0 + (x1 - x0) * t[0], oy + y0 + (y1 - y0) * t[1]]);
        }
    }
    rng.shuffle(&mut grid);
    let mut spots: Vec<[f64; 2]> = Vec::new();
    for spot in grid {
        if turned && spot[1] > side[1] - TURNED_CLEARANCE {
            continue;
        }
        let apart = spots
            .iter()
            .all(|s| (s[0] - spot[0]).hypot(s[1] - spot[1]) >= CUBE_SPACING);
        if apart {
            spots.push(spot);
        }
        if spots.len() == n {
            break;
        }
    }
    let mut yaws: Vec<f64> = (0..n).map(|_| rng.uniform(-30.0, 30.0).to_radians()).collect();
    let names: Vec<String> = (0..n).map(|i| format!("{}_cube", colours[i])).collect();
    let for_front = n.div_ceil(2);
    let mut positions: Vec<[f64; 3]> = spots.iter().map(|s| [s[0], s[1], TABLE_TOP]).collect();
    if config.obst_level >= 2 {
        // Each side-cabinet cube on a front-cabinet cube.
        for k in for_front..n {
            let below = positions[k - for_front];
            positions[k] = [below[0], below[1], below[2] + CUBE + REST_GAP];
            // Squarely on the one below it.
            yaws[k] = yaws[k - for_front];
        }
    }
    let cabinet = |prefix: &str| format!("{prefix}{}", DRAWER_CABINET_PARTS[0]);
    let bottom = |prefix: &str| format!("{prefix}{}", parts::BOTTOM_DRAWER);
    let mut objects = vec![
        object(
            &cabinet(FRONT),
            ObjectKind::DrawerCabinet,
            front[0],
            front[1],
            TABLE_TOP,
            0.0,
        ),
        object(
            &cabinet(SIDE),
            ObjectKind::DrawerCabinet,
            side[0],
            side[1],
            TABLE_TOP,
            side_yaw,
        ),
    ];
    for ((name, [x, y, z]), yaw) in names.iter().zip(&positions).zip(&yaws) {
        objects.push(object(name, ObjectKind::Cube, *x, *y, *z, *yaw));
    }
    SubtaskLayout {
        objects,
        articulations: Vec::new(),
        goals: vec![
            SubtaskGoal::PutInPrismatic {
                objects: names[..for_front].to_vec(),
                drawer: bottom(FRONT),
            },
            SubtaskGoal::PutInPrismatic {
                objects: names[for_front..].to_vec(),
                drawer: bottom(SIDE),
            },
        ],
    }
}
