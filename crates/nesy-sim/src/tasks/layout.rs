//! Where the scripted experts put things and how they move the articulated parts. The
//! template compiler emits the same numbers into its programs and the tests check against
//! them, so a compiled policy places objects exactly where the expert does.

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

/// Fruit drop spots along the hinge box's long side (y offsets, m): fruits are round with a
/// flat base and do not roll aside when dropped onto each other.
pub const HINGE_SPOTS: [f64; 3] = [-0.06, 0.0, 0.06];

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
