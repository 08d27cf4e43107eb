//! Builders for the benchmark's objects: geometry (primitive colliders in the part's
//! frame), colours, masses and, for articulated assets, their joints. Sizes follow `docs/benchmark.md` §2;
//! where the authors' meshes are missing the dimensions are our own and documented in the
//! crate README.

use rapier3d::prelude::{Pose, SharedShape, Vector};

use crate::scene::parts;
use crate::scene::{ColourSpec, NamedColour, ObjectKind, ObjectSpec, part_prefix};

/// Density of loose objects in kg/m³ (the authors' Genesis default).
pub const DENSITY: f32 = 200.0;
/// Friction coefficient of every object.
pub const FRICTION: f32 = 1.0;

/// Friction coefficient of chess pieces, combined with the other collider's by `Min`: a
/// pushed piece must slide across the board and into its box rather than tip over its
/// leading edge (with friction 1.0 the tall pieces tipped whenever the push started), while
/// 0.3 still lets them stop within a few millimetres once the push ends.
pub const PIECE_FRICTION: f32 = 0.3;

/// Density of a chess piece's base in kg/m³. Tournament pieces are weighted: a metal slug in
/// the base holds most of the mass, so a piece stands up to being pushed. At five times the
/// density of the rest, the base holds about three quarters of a rook's mass and the centre of
/// mass sits at about 27 % of the height instead of 47 %; a uniform piece pushed across the
/// board's step into its box tipped over its leading edge.
pub const PIECE_BASE_DENSITY: f32 = 5.0 * DENSITY;

/// Angular damping (1/s) of round objects' bodies. Rapier has no rolling resistance: a fruit
/// or a fallen cylinder touched by the arm or a neighbour rolled (or wobbled on its rounded
/// rim) for metres. Damping the spin makes the friction at the contact stop the roll within
/// a second; it does not slow free falls or slides. (Damping alone did not stop a fruit's
/// implicit round cylinder lying on its side, which is why fruits are hulls.)
pub const ROUND_ANGULAR_DAMPING: f32 = 50.0;

/// Angular damping of a kind's body.
pub fn angular_damping(kind: ObjectKind) -> f32 {
    match kind {
        ObjectKind::Apple | ObjectKind::Orange | ObjectKind::Lemon | ObjectKind::Cylinder => {
            ROUND_ANGULAR_DAMPING
        }
        _ => 0.0,
    }
}

/// Friction of a kind's colliders and how it combines with the other collider's.
pub fn friction(kind: ObjectKind) -> (f32, rapier3d::prelude::CoefficientCombineRule) {
    use rapier3d::prelude::CoefficientCombineRule;
    match kind {
        ObjectKind::Rook | ObjectKind::Knight | ObjectKind::Bishop => {
            (PIECE_FRICTION, CoefficientCombineRule::Min)
        }
        _ => (FRICTION, CoefficientCombineRule::Average),
    }
}

/// How a part moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PartMotion {
    /// Free rigid body under gravity.
    Dynamic,
    /// Fixed in the world.
    Fixed,
    /// Moved along its joint by the simulator (lid, drawer and the handles on them).
    Articulated,
}

/// What a part is, for the API's and the observer's rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartRole {
    /// A loose object that can be grasped and placed.
    Loose,
    /// A fixed object (containers, board).
    Fixed,
    /// The fixed body of an articulated asset (`hinge_body`, `drawer_body`).
    ArticulatedBody,
    /// A moving link (`hinge_lid`, `top_drawer`, `bottom_drawer`).
    Link,
    /// A handle on a moving link.
    Handle,
}

impl PartRole {
    /// True for the furniture the arm must not press into: fixed objects, articulated
    /// bodies and their moving links (not loose objects, and not the visual-only handles).
    pub fn is_furniture(self) -> bool {
        matches!(self, PartRole::Fixed | PartRole::ArticulatedBody | PartRole::Link)
    }
}

/// Surface pattern for the renderer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pattern {
    /// One colour.
    Plain,
    /// Checkerboard of `cells` squares along x with the given second colour.
    Checker {
        /// Number of squares along the board's x extent.
        cells: u32,
        /// Second colour.
        other: [f32; 3],
    },
}

/// One collider of a part, in the part frame.
#[derive(Clone)]
pub struct ShapeBuild {
    /// The shape.
    pub shape: SharedShape,
    /// Its pose in the part frame.
    pub local: Pose,
    /// Colour for the renderer.
    pub colour: [f32; 3],
    /// Pattern for the renderer.
    pub pattern: Pattern,
    /// Density in kg/m³ (the part's mass and centre of mass follow from its shapes').
    pub density: f32,
}

/// The joint of an articulated part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointBuild {
    /// Rotation about the joint frame's +y axis by `q − closed_q` (hinge lid).
    Revolute {
        /// Joint position at which the part is in its build pose.
        closed_q: f64,
    },
    /// Translation along the joint frame's −y axis by `q` (drawers open toward −y).
    Prismatic,
}

/// One named part of an object.
#[derive(Clone)]
pub struct PartBuild {
    /// Name used by the API and observer.
    pub name: String,
    /// Role in the rules.
    pub role: PartRole,
    /// How it moves.
    pub motion: PartMotion,
    /// Pose of the part frame relative to the object frame (at the closed joint position
    /// for articulated parts; then it is the joint frame).
    pub offset: Pose,
    /// Colliders.
    pub shapes: Vec<ShapeBuild>,
    /// The joint, for moving links.
    pub joint: Option<JointBuild>,
    /// For handles: the link part they ride on (index in the object's part list).
    pub rides_on: Option<usize>,
    /// Yaw to add to the object's yaw when the fingers grasp it (handles: across the bar).
    pub grasp_yaw: f64,
    /// False for visual-only parts: their colliders are sensors that give the part its AABB
    /// and looks but touch nothing (the drawer handles, `docs/benchmark.md` §2.4).
    pub solid: bool,
}

fn v(x: f32, y: f32, z: f32) -> Vector {
    Vector::new(x, y, z)
}

fn at(x: f32, y: f32, z: f32) -> Pose {
    Pose::from_translation(v(x, y, z))
}

fn cuboid(size: [f32; 3], centre: [f32; 3], colour: [f32; 3]) -> ShapeBuild {
    ShapeBuild {
        shape: SharedShape::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0),
        local: at(centre[0], centre[1], centre[2]),
        colour,
        pattern: Pattern::Plain,
        density: DENSITY,
    }
}

/// A cylinder standing on z (parry cylinders are along y, so rotate).
fn upright_cylinder(radius: f32, z0: f32, z1: f32, colour: [f32; 3]) -> ShapeBuild {
    ShapeBuild {
        shape: SharedShape::cylinder((z1 - z0) / 2.0, radius),
        local: Pose::from_parts(v(0.0, 0.0, (z0 + z1) / 2.0), upright()),
        colour,
        pattern: Pattern::Plain,
        density: DENSITY,
    }
}

/// An upright "rounded" column built from `count` square cuboids turned by 90°/count
/// against each other (a star with `4·count` points on a circle of `radius`). Chess pieces use
/// it instead of cylinders: Rapier re-uses cylinder–box contact manifolds, normals included,
/// while the relative motion stays small, so a piece pushed along the board kept a tilted
/// normal, sank and tipped; box–box manifolds are exact every step.
fn upright_star(radius: f32, z0: f32, z1: f32, count: usize, colour: [f32; 3]) -> Vec<ShapeBuild> {
    let half = radius * std::f32::consts::FRAC_1_SQRT_2;
    (0..count)
        .map(|k| {
            let yaw = k as f32 * std::f32::consts::FRAC_PI_2 / count as f32;
            ShapeBuild {
                shape: SharedShape::cuboid(half, half, (z1 - z0) / 2.0),
                local: Pose::from_parts(
                    v(0.0, 0.0, (z0 + z1) / 2.0),
                    rapier3d::prelude::Rotation::from_rotation_z(yaw),
                ),
                colour,
                pattern: Pattern::Plain,
                density: DENSITY,
            }
        })
        .collect()
}

fn upright() -> rapier3d::prelude::Rotation {
    rapier3d::prelude::Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2)
}

/// An open box (bottom plus four walls) of outer size `s`, wall thickness `t`.
fn open_box(s: [f32; 3], t: f32, colour: [f32; 3]) -> Vec<ShapeBuild> {
    let [sx, sy, sz] = s;
    vec![
        cuboid([sx, sy, t], [0.0, 0.0, t / 2.0], colour),
        cuboid([t, sy, sz], [-(sx - t) / 2.0, 0.0, sz / 2.0], colour),
        cuboid([t, sy, sz], [(sx - t) / 2.0, 0.0, sz / 2.0], colour),
        cuboid([sx - 2.0 * t, t, sz], [0.0, -(sy - t) / 2.0, sz / 2.0], colour),
        cuboid([sx - 2.0 * t, t, sz], [0.0, (sy - t) / 2.0, sz / 2.0], colour),
    ]
}

/// A chess box: a tray whose floor is just below the chess board's top, walled on three
/// sides and open on its local +y side, which faces the board (the right box is turned by
/// π). Pieces swept off the board slide straight in; a step down would make them tip.
fn chess_box(s: [f32; 3], colour: [f32; 3]) -> Vec<ShapeBuild> {
    let t = 0.003_f32;
    let [sx, sy, sz] = s;
    let floor = (CHESS_FLOOR - CHESS_BOX_STEP) as f32;
    vec![
        cuboid([sx, sy, floor], [0.0, 0.0, floor / 2.0], colour),
        cuboid([t, sy, sz], [-(sx - t) / 2.0, 0.0, sz / 2.0], colour),
        cuboid([t, sy, sz], [(sx - t) / 2.0, 0.0, sz / 2.0], colour),
        cuboid([sx - 2.0 * t, t, sz], [0.0, -(sy - t) / 2.0, sz / 2.0], colour),
    ]
}

/// Height of the chess board's top above the table (m).
pub const CHESS_FLOOR: f64 = 0.007;
/// How far a chess box's floor lies below the board's top (m): a flush seam catches the
/// leading edge of a sliding piece and tips it, while a small step lets the base drop onto
/// the floor as it slides in (3 mm is the value the sweep tests were tuned with).
pub const CHESS_BOX_STEP: f64 = 0.003;

/// Nominal outer size of a kind `[x, y, z]`.
pub fn nominal_size(kind: ObjectKind) -> [f64; 3] {
    match kind {
        ObjectKind::Cube => [0.03, 0.03, 0.03],
        ObjectKind::Cylinder => [0.03, 0.03, 0.03],
        ObjectKind::Apple => [0.057, 0.057, 0.055],
        ObjectKind::Orange => [0.064, 0.064, 0.06],
        ObjectKind::Lemon => [0.054, 0.054, 0.05],
        ObjectKind::Rook => [0.0295, 0.0295, 0.051],
        ObjectKind::Knight => [0.0295, 0.0295, 0.059],
        ObjectKind::Bishop => [0.0295, 0.0295, 0.065],
        ObjectKind::ChessBoard => [0.17, 0.094, CHESS_FLOOR],
        ObjectKind::ChessBox => [0.16, 0.08, 0.0245],
        ObjectKind::ToyBox => [0.139, 0.0985, 0.045],
        ObjectKind::HingeBox => [0.1025, 0.205, 0.1165],
        ObjectKind::DrawerCabinet => [0.154, 0.148, 0.194],
        ObjectKind::MagneticHook => [0.14, 0.03, 0.025],
        ObjectKind::Screws => SCREW_SIZE,
    }
}

fn default_colour(kind: ObjectKind) -> NamedColour {
    match kind {
        ObjectKind::Apple => NamedColour::Red,
        ObjectKind::Orange => NamedColour::Orange,
        ObjectKind::Lemon => NamedColour::Yellow,
        ObjectKind::ToyBox | ObjectKind::ChessBoard => NamedColour::Brown,
        ObjectKind::HingeBox | ObjectKind::DrawerCabinet => NamedColour::Grey,
        _ => NamedColour::Grey,
    }
}

/// The colour of an object: explicit, else its name's first word, else the kind's default.
pub fn object_colour(spec: &ObjectSpec) -> [f32; 3] {
    let rgb = match spec.colour {
        Some(c) => c.rgb(),
        None => {
            let first = spec.name.split('_').next().unwrap_or("");
            let named = match (spec.kind, first) {
                // Chess boxes are named by side; the white pieces go left, black right.
                (ObjectKind::ChessBox, "left") => Some(NamedColour::White),
                (ObjectKind::ChessBox, "right") => Some(NamedColour::Black),
                _ => NamedColour::from_name(first),
            };
            ColourSpec::Named(named.unwrap_or(default_colour(spec.kind))).rgb()
        }
    };
    [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32]
}

fn loose(name: &str, shapes: Vec<ShapeBuild>) -> Vec<PartBuild> {
    vec![PartBuild {
        name: name.to_owned(),
        role: PartRole::Loose,
        motion: PartMotion::Dynamic,
        offset: Pose::IDENTITY,
        shapes,
        joint: None,
        rides_on: None,
        grasp_yaw: 0.0,
        solid: true,
    }]
}

fn fixed(name: &str, role: PartRole, shapes: Vec<ShapeBuild>) -> PartBuild {
    PartBuild {
        name: name.to_owned(),
        role,
        motion: PartMotion::Fixed,
        offset: Pose::IDENTITY,
        shapes,
        joint: None,
        rides_on: None,
        grasp_yaw: 0.0,
        solid: true,
    }
}

/// Points around the circle at each ring of the fruit's hull.
const FRUIT_HULL_SEGMENTS: usize = 16;
/// Rings over each quarter-round border of the fruit's hull.
const FRUIT_HULL_RINGS: usize = 3;

fn round_fruit(size: [f32; 3], colour: [f32; 3]) -> ShapeBuild {
    // A round-edged cylinder: round from above and the side, with a small flat base so
    // fruit rests instead of rolling away (rapier has no rolling resistance). It is built as
    // a convex hull sampled on that surface rather than rapier's implicit round cylinder: a
    // round or plain cylinder lying on its side on a box gains spin from its contact manifold
    // and keeps rolling at a few cm/s whatever the damping, while the polyhedron comes to rest.
    let radius = size[0].min(size[1]) / 2.0;
    let half_h = size[2] / 2.0;
    let border = (radius * 0.6).min(half_h * 0.9);
    let mut points = Vec::with_capacity(2 * FRUIT_HULL_SEGMENTS * (FRUIT_HULL_RINGS + 1));
    for ring in 0..=FRUIT_HULL_RINGS {
        // From the equator of the border (phi = 0) to the edge of the flat face (phi = pi/2).
        let phi = std::f32::consts::FRAC_PI_2 * ring as f32 / FRUIT_HULL_RINGS as f32;
        let ring_radius = radius - border + border * phi.cos();
        let ring_height = half_h - border + border * phi.sin();
        for segment in 0..FRUIT_HULL_SEGMENTS {
            let theta = std::f32::consts::TAU * segment as f32 / FRUIT_HULL_SEGMENTS as f32;
            let (x, z) = (ring_radius * theta.cos(), ring_radius * theta.sin());
            // The cylinder's axis is y in the shape's frame, as for parry's cylinders.
            points.push(v(x, ring_height, z));
            points.push(v(x, -ring_height, z));
        }
    }
    // A hull of points too close to tell apart (a sub-micron fruit) falls back to the
    // implicit shape rather than failing the scene.
    let shape = SharedShape::convex_hull(&points)
        .unwrap_or_else(|| SharedShape::round_cylinder(half_h - border, radius - border, border));
    ShapeBuild {
        shape,
        local: Pose::from_parts(v(0.0, 0.0, half_h), upright()),
        colour,
        pattern: Pattern::Plain,
        density: DENSITY,
    }
}

fn chess_piece(kind: ObjectKind, size: [f32; 3], colour: [f32; 3]) -> Vec<ShapeBuild> {
    let r = size[0].min(size[1]) / 2.0;
    let h = size[2];
    let base = 0.22 * h;
    let neck_r = r * 0.62;
    let mut shapes = upright_star(r, 0.0, base, 3, colour);
    for s in &mut shapes {
        s.density = PIECE_BASE_DENSITY;
    }
    match kind {
        ObjectKind::Rook => {
            shapes.extend(upright_star(neck_r, base, h * 0.75, 2, colour));
            shapes.extend(upright_star(r * 0.85, h * 0.75, h, 2, colour));
        }
        ObjectKind::Knight => {
            shapes.extend(upright_star(neck_r, base, h * 0.6, 2, colour));
            shapes.push(cuboid(
                [r * 1.3, r * 1.9, h * 0.4],
                [0.0, r * 0.25, h * 0.8],
                colour,
            ));
        }
        _ => {
            shapes.extend(upright_star(neck_r * 0.9, base, h * 0.7, 2, colour));
            // No wider than the neck, so a finger pushing the neck does not catch the head.
            let head = neck_r * 0.9;
            shapes.push(ShapeBuild {
                shape: SharedShape::ball(head),
                local: at(0.0, 0.0, h - head),
                colour,
                pattern: Pattern::Plain,
                density: DENSITY,
            });
        }
    }
    shapes
}

/// Builds the parts of one scene object. Part poses are relative to the object frame
/// (position `x, y, z_bottom`, yaw about z).
pub fn build_object(spec: &ObjectSpec) -> Vec<PartBuild> {
    let size = spec.size.unwrap_or_else(|| nominal_size(spec.kind));
    let s = [size[0] as f32, size[1] as f32, size[2] as f32];
    let colour = object_colour(spec);
    match spec.kind {
        ObjectKind::Cube => loose(&spec.name, vec![cuboid(s, [0.0, 0.0, s[2] / 2.0], colour)]),
        ObjectKind::Cylinder => loose(
            &spec.name,
            vec![upright_cylinder(s[0].min(s[1]) / 2.0, 0.0, s[2], colour)],
        ),
        ObjectKind::Apple | ObjectKind::Orange | ObjectKind::Lemon => {
            loose(&spec.name, vec![round_fruit(s, colour)])
        }
        ObjectKind::Rook | ObjectKind::Knight | ObjectKind::Bishop => {
            loose(&spec.name, chess_piece(spec.kind, s, colour))
        }
        ObjectKind::ChessBoard => {
            let mut board = cuboid(s, [0.0, 0.0, s[2] / 2.0], [0.92, 0.86, 0.72]);
            board.pattern = Pattern::Checker {
                cells: 8,
                other: [0.35, 0.22, 0.12],
            };
            vec![fixed(&spec.name, PartRole::Fixed, vec![board])]
        }
        ObjectKind::ChessBox => vec![fixed(&spec.name, PartRole::Fixed, chess_box(s, colour))],
        ObjectKind::ToyBox => vec![fixed(&spec.name, PartRole::Fixed, open_box(s, 0.004, colour))],
        ObjectKind::HingeBox => hinge_box(part_prefix(spec), colour),
        ObjectKind::DrawerCabinet => drawer_cabinet(part_prefix(spec), colour),
        ObjectKind::MagneticHook => loose(&spec.name, magnetic_hook(s, colour)),
        ObjectKind::Screws => screws(spec, s, colour),
    }
}

/// Size `[x, y, z]` (m) of one screw, lying along x.
pub const SCREW_SIZE: [f64; 3] = [0.02, 0.006, 0.006];
/// Density of steel (kg/m³): screws and the hook's magnet.
pub const STEEL_DENSITY: f32 = 7800.0;

/// The magnetic hook in its frame (origin at the centre of its footprint, on the table): a
/// bar along x and, at its +x end, the magnet block, as wide as the whole and the full
/// height. `s` is the outer size.
fn magnetic_hook(s: [f32; 3], colour: [f32; 3]) -> Vec<ShapeBuild> {
    let magnet_len = s[0] * MAGNET_LENGTH_FRACTION as f32;
    let bar_len = s[0] - magnet_len;
    let bar_side = hook_bar_side(s.map(f64::from)) as f32;
    // The block sits where the magnet's pull is centred.
    let centre = magnet_centre(s.map(f64::from)).map(|v| v as f32);
    let mut magnet = cuboid([magnet_len, s[1], s[2]], centre, [0.12, 0.12, 0.14]);
    magnet.density = STEEL_DENSITY;
    vec![
        cuboid(
            [bar_len, bar_side, bar_side],
            [-s[0] / 2.0 + bar_len / 2.0, 0.0, bar_side / 2.0],
            colour,
        ),
        magnet,
    ]
}

/// The side (m) of a magnetic hook's square bar, for outer size `size`: lower and narrower
/// than the magnet block, so what lies on the hook rests on the bar beside the block.
pub fn hook_bar_side(size: [f64; 3]) -> f64 {
    size[1].min(size[2]) * 0.7
}

/// Share of the hook's length taken by its magnet block.
pub const MAGNET_LENGTH_FRACTION: f64 = 0.25;

/// The centre of a magnetic hook's magnet in the hook's frame, for outer size `size`.
pub fn magnet_centre(size: [f64; 3]) -> [f64; 3] {
    let magnet_len = size[0] * MAGNET_LENGTH_FRACTION;
    [size[0] / 2.0 - magnet_len / 2.0, 0.0, size[2] / 2.0]
}

/// One loose part per piece of a fine-grained object, each at its offset in the object's
/// frame and named `<name>_<k>`.
fn screws(spec: &ObjectSpec, s: [f32; 3], colour: [f32; 3]) -> Vec<PartBuild> {
    crate::scene::part_names(spec)
        .into_iter()
        .zip(spec.piece_offsets())
        .map(|(name, [dx, dy])| {
            let mut piece = cuboid(s, [0.0, 0.0, s[2] / 2.0], colour);
            piece.density = STEEL_DENSITY;
            let mut part = loose(&name, vec![piece]).remove(0);
            part.offset = at(dx as f32, dy as f32, 0.0);
            part
        })
        .collect()
}

/// Wall thickness (m) of the hinge box's body.
pub const HINGE_BOX_WALL: f32 = 0.005;

/// Hinge box geometry: body 0.1025 × 0.205 × 0.1165 open at the top; lid 0.109 × 0.21 ×
/// 0.01 hinged about y at the body's far (+x) top edge; a handle block on the lid's free
/// (−x) edge. Part names carry `prefix` (`docs/benchmark.md` §2.3).
fn hinge_box(prefix: &str, colour: [f32; 3]) -> Vec<PartBuild> {
    let [body_name, lid_name, handle_name] = parts::prefixed(prefix, &parts::HINGE_BOX_PARTS);
    let [bx, by, bz] = [0.1025_f32, 0.205, 0.1165];
    let body = fixed(
        &body_name,
        PartRole::ArticulatedBody,
        open_box([bx, by, bz], HINGE_BOX_WALL, colour),
    );
    let lid_len = 0.109_f32;
    let lid_colour = [colour[0] * 0.8, colour[1] * 0.8, colour[2] * 0.9];
    let hinge = at(bx / 2.0, 0.0, bz);
    let lid = PartBuild {
        name: lid_name,
        role: PartRole::Link,
        motion: PartMotion::Articulated,
        offset: hinge,
        shapes: vec![cuboid(
            [lid_len, 0.21, 0.01],
            [-lid_len / 2.0, 0.0, 0.005],
            lid_colour,
        )],
        joint: Some(JointBuild::Revolute {
            closed_q: parts::LID_CLOSED,
        }),
        rides_on: None,
        grasp_yaw: 0.0,
        solid: true,
    };
    let handle = PartBuild {
        name: handle_name,
        role: PartRole::Handle,
        motion: PartMotion::Articulated,
        offset: hinge,
        shapes: vec![cuboid(
            [0.012, 0.03, 0.015],
            [-lid_len + 0.0045, 0.0, 0.0175],
            [0.15, 0.15, 0.15],
        )],
        joint: Some(JointBuild::Revolute {
            closed_q: parts::LID_CLOSED,
        }),
        rides_on: Some(1),
        // Fingers close along x, across the handle's thin side.
        grasp_yaw: std::f64::consts::FRAC_PI_2,
        solid: true,
    };
    vec![body, lid, handle]
}

/// Distance of a drawer handle's bar in front of its drawer's face (m).
const HANDLE_STANDOFF: f32 = 0.025;

/// Drawer cabinet geometry: body 0.154 × 0.148 × 0.194 open at the front (−y) with a
/// middle shelf; two drawers (open boxes 0.142 × 0.142, 0.085 tall with a front panel)
/// sliding out toward −y by up to 0.1232; a visual-only bar handle 2.5 cm in front of each
/// face. Part names carry `prefix`.
/// How far (m) a drawer's floor plate reaches below the drawer's base height, under its
/// 4 mm top: the plate is 8 mm thick. Light pieces squeezed under a heavy load (screws under
/// the hook's steel magnet) are pushed a few millimetres into a kinematic drawer's floor;
/// through a 4 mm plate that push crossed its middle and the contact then drove them down
/// through it. The bottom drawer's plate still clears the table by 1.5 mm.
pub const DRAWER_FLOOR_DEPTH: f32 = 0.004;

fn drawer_cabinet(prefix: &str, colour: [f32; 3]) -> Vec<PartBuild> {
    let [body_name, bottom, top, bottom_handle, top_handle] =
        parts::prefixed(prefix, &parts::DRAWER_CABINET_PARTS);
    let [sx, sy, sz] = [0.154_f32, 0.148, 0.194];
    let t = 0.005_f32;
    let body_shapes = vec![
        cuboid([t, sy, sz], [-(sx - t) / 2.0, 0.0, sz / 2.0], colour),
        cuboid([t, sy, sz], [(sx - t) / 2.0, 0.0, sz / 2.0], colour),
        cuboid([sx - 2.0 * t, t, sz], [0.0, (sy - t) / 2.0, sz / 2.0], colour),
        // No bottom plate: the cabinet stands on the table and the bottom drawer slides just
        // above it, so nothing catches the bottom edge of objects riding in the drawer.
        cuboid([sx - 2.0 * t, sy - t, t], [0.0, -t / 2.0, 0.097], colour),
        cuboid([sx - 2.0 * t, sy - t, t], [0.0, -t / 2.0, sz - t / 2.0], colour),
    ];
    let body = fixed(&body_name, PartRole::ArticulatedBody, body_shapes);
    let front = -sy / 2.0;
    let drawer = |name: &str, z0: f32, tint: [f32; 3]| -> PartBuild {
        let (w, d, h, wt) = (0.142_f32, 0.142_f32, 0.085_f32, 0.004_f32);
        let yc = front + d / 2.0;
        PartBuild {
            name: name.into(),
            role: PartRole::Link,
            motion: PartMotion::Articulated,
            offset: Pose::IDENTITY,
            shapes: vec![
                // The floor's top is `wt` above `z0`; its plate reaches
                // `DRAWER_FLOOR_DEPTH` below `z0`, as a real drawer's bottom board does.
                cuboid(
                    [w, d, wt + DRAWER_FLOOR_DEPTH],
                    [0.0, yc, z0 + (wt - DRAWER_FLOOR_DEPTH) / 2.0],
                    tint,
                ),
                cuboid([w, 0.006, h], [0.0, front + 0.003, z0 + h / 2.0], tint),
                cuboid([w, wt, h * 0.7], [0.0, front + d - wt / 2.0, z0 + h * 0.35], tint),
                cuboid([wt, d, h * 0.7], [-(w - wt) / 2.0, yc, z0 + h * 0.35], tint),
                cuboid([wt, d, h * 0.7], [(w - wt) / 2.0, yc, z0 + h * 0.35], tint),
            ],
            joint: Some(JointBuild::Prismatic),
            rides_on: None,
            grasp_yaw: 0.0,
            solid: true,
        }
    };
    let handle = |name: &str, z: f32, link: usize| -> PartBuild {
        let dark = [0.15, 0.15, 0.15];
        PartBuild {
            name: name.into(),
            role: PartRole::Handle,
            motion: PartMotion::Articulated,
            offset: Pose::IDENTITY,
            shapes: vec![
                cuboid([0.09, 0.01, 0.01], [0.0, front - HANDLE_STANDOFF, z], dark),
                cuboid(
                    [0.008, HANDLE_STANDOFF, 0.008],
                    [-0.035, front - HANDLE_STANDOFF / 2.0, z],
                    dark,
                ),
                cuboid(
                    [0.008, HANDLE_STANDOFF, 0.008],
                    [0.035, front - HANDLE_STANDOFF / 2.0, z],
                    dark,
                ),
            ],
            joint: Some(JointBuild::Prismatic),
            rides_on: Some(link),
            // The bar runs along x, so the fingers close along y.
            grasp_yaw: 0.0,
            // Visual only, as in the authors' asset: grasping is the proximity rule, and a
            // solid bar standing out over the open drawer below would catch dropped objects.
            solid: false,
        }
    };
    let tint = [colour[0] * 0.85 + 0.1, colour[1] * 0.85 + 0.05, colour[2] * 0.85];
    vec![
        body,
        drawer(&bottom, 0.0055, tint),
        drawer(&top, 0.1, tint),
        handle(&bottom_handle, 0.0055 + 0.06, 1),
        handle(&top_handle, 0.1 + 0.06, 2),
    ]
}

/// Pose of an articulated part's frame for joint position `q`, relative to its build
/// (closed) pose in the object frame.
pub fn joint_motion(joint: JointBuild, q: f64) -> Pose {
    match joint {
        JointBuild::Revolute { closed_q } => Pose::from_rotation(
            rapier3d::prelude::Rotation::from_rotation_y((q - closed_q) as f32),
        ),
        JointBuild::Prismatic => Pose::from_translation(v(0.0, -(q as f32), 0.0)),
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::SceneSpec;
    use crate::world::Sim;
    use rapier3d::prelude::{Rotation, Vector};

    /// A fruit knocked onto its side, rolling slowly as the arm left it: Rapier's implicit
    /// round cylinder kept rolling at about 2 cm/s (its contact with the table fed the spin
    /// back in whatever the damping) until it left the table; the hull comes to rest.
    #[test]
    fn a_fruit_lying_on_its_side_comes_to_rest() {
        for kind in ["apple", "orange", "lemon"] {
            let scene = serde_json::json!({
                "schema_version": 1,
                "embodiment": "finger",
                "objects": [{"name": kind, "kind": kind, "pose": {"position": [0.45, 0.1, 0.5], "yaw": 0.0}}],
                "goals": []
            });
            let scene = SceneSpec::from_json_str(&scene.to_string(), "fruit").unwrap();
            let mut sim = Sim::new(&scene).unwrap();
            let part = sim.part_index(kind).unwrap();
            let radius = sim.part_aabb(part).size()[0] / 2.0;
            let handle = sim.parts()[part].body;
            let body = &mut sim.world.bodies[handle];
            // Lying with its axis along y, centre one radius above the table, rolling along
            // -x (the state a traced run left an orange in).
            body.set_translation(Vector::new(0.45, 0.1, 0.5 + radius as f32 + 1e-4), true);
            body.set_rotation(Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2), true);
            body.set_linvel(Vector::new(-0.022, -0.003, 0.0), true);
            body.set_angvel(Vector::new(0.09, -0.69, 0.0), true);
            sim.step_idle(500);
            let speed = sim.part_velocity(part).iter().map(|v| v * v).sum::<f64>().sqrt();
            let p = sim.part_pose(part).translation.vector;
            assert!(speed < 1e-3, "{kind} still moves at {speed:.4} m/s");
            assert!(
                (p.x - 0.45).abs() < 0.05 && (p.y - 0.1).abs() < 0.05,
                "{kind} rolled to {p:?}"
            );
        }
    }
}
