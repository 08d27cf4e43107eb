//! `stow_tools`: the paper's real-world hook-and-screws task (Figures 1 and 5). A drawer
//! cabinet, a magnetic hook, screws (a fine-grained object) and one to three cubes, all to
//! go into the cabinet's bottom drawer, which must end closed.
//!
//! - Obstruction level 0 (the demonstration's setting): everything on the table, the drawer
//!   closed, the screws in a pile at the hook's magnet (they cling to it, so carrying the
//!   hook carries them).
//! - Level 1: the hook already lies in the open bottom drawer and the screws are scattered
//!   over the table, each out of the others' reach and too small to grasp: the hook must be
//!   taken out and swept over them (`gather_with_hook`) before it goes back in.
//! - Level 2: as level 1, with the first cube stacked on the hook in the drawer.
//!
//! Positions are drawn from the subtask's layout stream around fixed anchors.

use super::{REST_GAP, SubtaskLayout, layout_stream, object};
use crate::scene::parts::{self, DRAWER_OPEN};
use crate::scene::{ObjectKind, SubtaskGoal, TABLE_TOP};
use crate::tasks::SubtaskConfig;
use crate::tasks::pick_place::COLOURS;
use crate::world::objects::{hook_bar_side, magnet_centre};

/// The hook's name in the scenes.
pub(crate) const HOOK: &str = "magnetic_hook";
/// The screws' name in the scenes.
pub(crate) const SCREWS: &str = "black_screws";
/// The hook's outer size (m): 10 cm long, so that it and the screws on its magnet fit in the
/// bottom drawer (13.4 cm inside); its magnet block 4.5 cm tall, so that a hand taking the
/// hook by its middle from the open drawer (the Panda hand is 20 cm across, wider than the
/// drawer) keeps its palm above the drawer's side walls.
pub(crate) const HOOK_SIZE: [f64; 3] = [0.10, 0.025, 0.045];
/// Where the cabinet stands, relative to the subtask's offset (facing −y).
const CABINET_AT: [f64; 2] = [0.0, 0.19];
/// Largest shift (m) of the cabinet and the loose objects' anchors.
const JITTER: f64 = 0.02;
/// Where the hook lies on the table in the demonstration, relative to the offset.
const HOOK_AT: [f64; 2] = [-0.08, -0.17];
/// Where the scattered screws lie at deployment, relative to the offset.
const SCREWS_AT: [f64; 2] = [0.0, -0.24];
/// The scattered pieces' offsets from their anchor: each more than twice the magnet's
/// reach from the others, so no two start within a pile.
const SCATTER: [[f64; 2]; 4] = [[-0.07, 0.03], [-0.02, -0.05], [0.04, 0.04], [0.09, -0.03]];
/// The demonstration's pile, relative to the magnet's centre: close enough to cling to it.
const PILE: [[f64; 2]; 4] = [[0.0, -0.021], [0.0, 0.021], [0.026, -0.008], [0.026, 0.008]];
/// Where the cubes lie on the table, relative to the offset.
const CUBE_SPOTS: [[f64; 2]; 3] = [[0.10, -0.14], [0.13, -0.22], [-0.12, -0.27]];

pub(crate) fn layout(config: &SubtaskConfig, [ox, oy]: [f64; 2]) -> SubtaskLayout {
    let mut rng = layout_stream(config.kind, config.variant);
    let mut shift = || [rng.uniform(-JITTER, JITTER), rng.uniform(-JITTER, JITTER)];
    let [cx, cy] = {
        let s = shift();
        [ox + CABINET_AT[0] + s[0], oy + CABINET_AT[1] + s[1]]
    };
    let hook_shift = shift();
    let screws_shift = shift();
    let cube_shifts: Vec<[f64; 2]> = (0..CUBE_SPOTS.len()).map(|_| shift()).collect();
    let hook_yaw = rng.uniform(-20.0, 20.0).to_radians();
    let mut colours = COLOURS;
    rng.shuffle(&mut colours);
    let cubes = config.kind.object_count(config.multi_level);
    let cube_names: Vec<String> = (0..cubes).map(|i| format!("{}_cube", colours[i])).collect();

    let deployed = config.obst_level > 0;
    // The open bottom drawer's floor, where the hook lies at deployment (the drawer box sits
    // 5.5 mm above the table with a 4 mm floor, and slides out toward −y).
    let drawer_floor = TABLE_TOP + 0.0055 + 0.004;
    let drawer_centre = [cx, cy - 0.003 - DRAWER_OPEN];
    // At deployment the hook lies along the drawer's travel: across it, the fingers (closing
    // across the hook's narrow side) would turn the hand's length toward the cabinet, under
    // its middle shelf.
    let (hook_at, hook_z, hook_yaw) = if deployed {
        (
            drawer_centre,
            drawer_floor + REST_GAP,
            std::f64::consts::FRAC_PI_2,
        )
    } else {
        (
            [ox + HOOK_AT[0] + hook_shift[0], oy + HOOK_AT[1] + hook_shift[1]],
            TABLE_TOP,
            hook_yaw,
        )
    };
    let mut hook = object(
        HOOK,
        ObjectKind::MagneticHook,
        hook_at[0],
        hook_at[1],
        hook_z,
        hook_yaw,
    );
    hook.size = Some(HOOK_SIZE);
    let (screws_at, pieces) = if deployed {
        (
            [
                ox + SCREWS_AT[0] + screws_shift[0],
                oy + SCREWS_AT[1] + screws_shift[1],
            ],
            SCATTER.to_vec(),
        )
    } else {
        // The pile at the magnet: the magnet's centre in the hook's frame, turned with it.
        let m = magnet_centre(HOOK_SIZE);
        let (s, c) = hook_yaw.sin_cos();
        let pile = [hook_at[0] + m[0] * c, hook_at[1] + m[0] * s];
        let turned: Vec<[f64; 2]> = PILE.iter().map(|[x, y]| [x * c - y * s, x * s + y * c]).collect();
        (pile, turned)
    };
    let mut screws = object(
        SCREWS,
        ObjectKind::Screws,
        screws_at[0],
        screws_at[1],
        TABLE_TOP,
        0.0,
    );
    screws.pieces = Some(pieces);

    let mut objects = vec![
        object(
            parts::DRAWER_BODY,
            ObjectKind::DrawerCabinet,
            cx,
            cy,
            TABLE_TOP,
            0.0,
        ),
        hook,
        screws,
    ];
    for (k, name) in cube_names.iter().enumerate() {
        let on_hook = config.obst_level >= 2 && k == 0;
        let (x, y, z) = if on_hook {
            // On the bar, beside the taller magnet block.
            (
                hook_at[0],
                hook_at[1],
                hook_z + hook_bar_side(HOOK_SIZE) + REST_GAP,
            )
        } else {
            let s = cube_shifts[k];
            (
                ox + CUBE_SPOTS[k][0] + s[0],
                oy + CUBE_SPOTS[k][1] + s[1],
                TABLE_TOP,
            )
        };
        objects.push(object(name, ObjectKind::Cube, x, y, z, 0.0));
    }
    // The label lists the objects in the order they come to lie in the drawer: in the
    // demonstration the screws, hanging under the magnet, enter it just before the hook; at
    // deployment the hook (and the cube on it) are in it from the start.
    let mut goal_objects = if deployed {
        vec![HOOK.to_owned()]
    } else {
        vec![SCREWS.to_owned(), HOOK.to_owned()]
    };
    let mut rest = cube_names.into_iter();
    if config.obst_level >= 2 {
        goal_objects.extend(rest.next());
    }
    if deployed {
        goal_objects.push(SCREWS.to_owned());
    }
    goal_objects.extend(rest);
    SubtaskLayout {
        objects,
        articulations: vec![
            (
                parts::BOTTOM_DRAWER.into(),
                if deployed { DRAWER_OPEN } else { 0.0 },
            ),
            (parts::TOP_DRAWER.into(), 0.0),
        ],
        goals: vec![SubtaskGoal::PutInPrismatic {
            objects: goal_objects,
            drawer: parts::BOTTOM_DRAWER.into(),
        }],
    }
}
