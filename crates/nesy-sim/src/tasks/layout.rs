//! Where the scripted experts put things and how they move the articulated parts. The
//! template compiler emits the same numbers into its programs and the tests check against
//! them, so a compiled policy places objects where the expert does; the one difference is
//! that the expert moves a fruit's drop spot in the hinge box away from fruits that landed
//! off theirs ([`hinge_drop_spot`]), while a compiled policy drops at [`HINGE_SPOTS`].

use crate::scene::parts;
use crate::world::FLOOR_AABB;

/// Cells of the toy box the cubes are dropped into (offsets from its centre, m): three
/// along the long side, two across; placed cubes are square to the box (the wrist turns to
/// yaw 0 on the way), so they fit side by side.
pub const TOY_BOX_CELLS: [[f64; 2]; 6] = [
    [-0.042, -0.022],
    [0.0, -0.022],
    [0.042, -0.022],
    [-0.042, 0.022],
    [0.0, 0.022],
    [0.042, 0.022],
];

/// Fruit drop spots along the hinge box's long side (y offsets, m). The template compiler
/// drops at these; the scripted expert starts from them and then keeps clear of the fruits
/// already in the box ([`hinge_drop_spot`]).
pub const HINGE_SPOTS: [f64; 3] = [-0.06, 0.0, 0.06];

/// Clearance (m) a dropped fruit's footprint keeps from the hinge box's inner walls.
pub const HINGE_WALL_MARGIN: f64 = 0.003;

/// Where the expert drops a fruit of footprint radius `radius` into the hinge box whose inside
/// spans `inside` (`[[x_min, y_min], [x_max, y_max]]`), given the fruits already in the box
/// (footprint centre and radius each) and the radii of the fruits still to come after it, as
/// an `[x, y]` point.
///
/// Fixed spots 6 cm apart do not hold three fruits up to 6.4 cm across: a fruit that lands a
/// centimetre or two off its spot (it falls about 14 cm from above the rim) has the next one
/// dropped onto its edge, the pair stacks, and the closing lid comes down on the stack. So the
/// spot is chosen on a grid over the inside (the footprint kept [`HINGE_WALL_MARGIN`] inside
/// the walls) to leave the most room, both to the fruits where they actually lie and to the
/// fruits still to come (each placed in turn where it has the most room); with room enough
/// everywhere (the box empty), the point nearest `nominal` wins.
///
/// ```
/// use nesy_sim::tasks::layout::hinge_drop_spot;
/// let inside = [[0.0, 0.0], [0.0925, 0.195]];
/// // An empty box and nothing to follow: the nominal spot.
/// assert_eq!(hinge_drop_spot(inside, 0.03, &[], &[], [0.046, 0.04]), [0.046, 0.04]);
/// // An apple that landed in the middle: the next fruit goes to an end, not onto it.
/// let spot = hinge_drop_spot(inside, 0.03, &[([0.046, 0.0975], 0.029)], &[], [0.046, 0.0975]);
/// assert!((spot[1] - 0.0975).abs() > 0.059);
/// ```
pub fn hinge_drop_spot(
    inside: [[f64; 2]; 2],
    radius: f64,
    placed: &[([f64; 2], f64)],
    upcoming: &[f64],
    nominal: [f64; 2],
) -> [f64; 2] {
    let distance = |p: [f64; 2]| (p[0] - nominal[0]).powi(2) + (p[1] - nominal[1]).powi(2);
    let later: Vec<(f64, HingeGrid)> = upcoming.iter().map(|&r| (r, HingeGrid::new(inside, r))).collect();
    let score = |p: [f64; 2]| {
        let mut lying = placed.to_vec();
        let mut worst = room(p, radius, &lying);
        lying.push((p, radius));
        for (r, grid) in &later {
            let r = *r;
            // The later fruit where it has the most room (its own nominal spot is unknown here).
            let q = grid
                .points()
                .max_by(|a, b| room(*a, r, &lying).total_cmp(&room(*b, r, &lying)))
                .unwrap_or(p);
            worst = worst.min(room(q, r, &lying));
            lying.push((q, r));
        }
        worst.min(ENOUGH_ROOM)
    };
    let grid = HingeGrid::new(inside, radius);
    let mut best = grid.clamp(nominal);
    let mut best_key = (score(best), -distance(best));
    for p in grid.points() {
        let key = (score(p), -distance(p));
        if key > best_key {
            best = p;
            best_key = key;
        }
    }
    best
}

/// Room (m) beyond touching that counts as enough: a spot with this much to every other fruit
/// is as good as one with more, so the nominal spot is kept when it has it.
const ENOUGH_ROOM: f64 = 0.008;

/// Room (m) beyond touching between a fruit at `p` of radius `radius` and the nearest of
/// `lying` (infinite with none).
fn room(p: [f64; 2], radius: f64, lying: &[([f64; 2], f64)]) -> f64 {
    lying
        .iter()
        .map(|(c, r)| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() - r - radius)
        .fold(f64::INFINITY, f64::min)
}

/// The candidate centres of a fruit of one radius in the hinge box: a grid over the inside,
/// kept [`HINGE_WALL_MARGIN`] from the walls.
struct HingeGrid {
    lo: [f64; 2],
    hi: [f64; 2],
}

impl HingeGrid {
    /// Points along x and y.
    const STEPS: [usize; 2] = [7, 33];

    fn new(inside: [[f64; 2]; 2], radius: f64) -> Self {
        let lo = [0, 1].map(|k| inside[0][k] + radius + HINGE_WALL_MARGIN);
        let hi = [0, 1].map(|k| (inside[1][k] - radius - HINGE_WALL_MARGIN).max(lo[k]));
        HingeGrid { lo, hi }
    }

    fn clamp(&self, p: [f64; 2]) -> [f64; 2] {
        [0, 1].map(|k| p[k].clamp(self.lo[k], self.hi[k]))
    }

    fn points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        let at = |k: usize, i: usize| {
            self.lo[k] + (self.hi[k] - self.lo[k]) * i as f64 / (Self::STEPS[k] - 1) as f64
        };
        (0..Self::STEPS[0]).flat_map(move |i| (0..Self::STEPS[1]).map(move |j| [at(0, i), at(1, j)]))
    }
}

/// Cylinder drop spots in the bottom drawer (x offset, outward y offset from the drawer's
/// centre, m). They are 5 cm or more apart, because a cylinder dropped onto another one tips
/// over and, lying on its side, rolls on without stopping (Rapier has no rolling
/// resistance); and 1.5 cm or more inside the walls, because a cylinder falling 19 cm that
/// clips a wall's top edge is flung out of the drawer.
pub const DRAWER_SPOTS: [[f64; 2]; 3] = [[-0.035, -0.005], [0.035, -0.005], [0.0, 0.035]];

/// Waypoints of the tool around the hinge axis when opening the lid (degrees from +x in
/// the x–z plane; the closed lid points at 180°, the open one at 90°). A grasped lid follows
/// the tool's angle about the axis, and the handle slips when the tool gets more than
/// 10 cm from it: a single straight move (the authors' recipe) cuts the arc short, and with
/// the tool holding the handle a little above its centre it left the lid short of vertical or
/// lost the handle. Short arcs keep the tool near the handle; the last one is 30° past
/// vertical so the lid stops at its limit (q = 0.8).
pub const LID_OPENING_ARC: [f64; 3] = [135.0, 90.0, 60.0];

/// Largest x (m) of a lid-swing waypoint: at the far offsets the hinge is 2 cm inside the
/// workspace's +x edge, so the last waypoint comes in along x there, still past vertical.
pub const LID_SWING_MAX_X: f64 = FLOOR_AABB.max[0] - 0.005;

/// Waypoints when closing the lid (the last one is the authors' target, the body's −x top
/// edge).
pub const LID_CLOSING_ARC: [f64; 2] = [135.0, 180.0];

/// Height (m) above the release point at which a carried object is let go over the table,
/// the board or the toy box.
pub const DROP_CLEARANCE: f64 = 0.01;

/// Height (m) above the hinge box's top at which a fruit is let go.
pub const HINGE_DROP_CLEARANCE: f64 = 0.03;

/// The boxes that may stand in the lane of an arm reaching a drawer handle sideways: the
/// containers other than the drawers themselves (bare part names).
pub const BOXES_BESIDE_CABINETS: [&str; 4] = [
    parts::HINGE_BODY,
    parts::TOY_BOX,
    parts::LEFT_CHESS_BOX,
    parts::RIGHT_CHESS_BOX,
];
/// Reach (m) of the finger hand's wrist around the tool point when it grasps a drawer
/// handle from above.
pub const WRIST_CLEARANCE: f64 = 0.07;
/// How far (m) the wrist and forearm trail behind the tool point when the hand grasps a
/// handle pointing sideways.
pub const FOREARM_REACH: f64 = 0.3;
/// How far (m) below the tool point the wrist hangs when the hand points sideways: joint 6's
/// housing (a 5 cm capsule 8.8 cm off the last joint's axis) swings below the forearm, and
/// came down on the closed lid of a hinge box standing behind the cabinet.
pub const FOREARM_BELOW: f64 = 0.1;
/// How far (m) above the tool point the forearm rises when the hand points sideways.
pub const FOREARM_ABOVE: f64 = 0.3;
/// How far (m) to either side of the wrist's corridor the elbow swings the forearm on the
/// way to a sideways grasp (it came down on a toy box 20–30 cm beside the bottom handle).
pub const FOREARM_SWING: f64 = 0.3;

/// Height (m) above the bottom drawer's rim at which a cylinder is let go: high enough that
/// the hand clears the cylinders still standing on the cabinet.
pub const DRAWER_DROP_CLEARANCE: f64 = 0.05;

/// A piece is pushed with the fingers (or carried by the cup) at its height divided by this
/// below its top: the authors' `depth = h / 1.3`.
pub const PUSH_DEPTH_DIVISOR: f64 = 1.3;

/// How far (m) a push carries a piece past its box's centre line.
pub const PUSH_OVERSHOOT: f64 = 0.02;

/// How far (m) the hand rises after letting go of an opened drawer's handle, so it clears
/// the drawer's front on the way to the next object.
pub const DRAWER_RETREAT: f64 = 0.05;

/// The fraction of the bottom drawer's depth (along its travel) a drawer is pulled open or
/// pushed closed by.
pub const DRAWER_PULL_FRACTION: f64 = 0.85;
