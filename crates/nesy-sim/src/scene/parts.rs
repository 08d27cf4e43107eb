//! The names the world gives its fixed parts, and the one-dof joints of the articulated
//! assets with their limits and rest positions, in the benchmark's joint convention
//! (`docs/benchmark.md` §2.3–§2.4).
//!
//! Articulated kinds name their parts after their body: a hinge box whose entry is called
//! `hinge_body` has the parts `hinge_body`, `hinge_lid` and `hinge_handle`, and one called
//! `left_hinge_body` has `left_hinge_body`, `left_hinge_lid` and `left_hinge_handle`. A scene
//! may hold several articulated assets as long as their prefixes differ; the benchmark's
//! scenes use the bare names, which the API, the observer, the goal checks, the experts and
//! the template compiler name through these constants.
//!
//! ```
//! use nesy_sim::scene::parts::{self, Joint};
//!
//! assert_eq!(Joint::from_name(parts::HINGE_LID), Some(Joint::HingeLid));
//! assert_eq!(Joint::from_name("left_top_drawer"), Some(Joint::TopDrawer));
//! assert_eq!(Joint::from_name("left_top_drawer_handle"), None);
//! assert_eq!(Joint::HingeLid.limits(), (-0.785, 0.8));
//! assert_eq!(Joint::BottomDrawer.closed(), 0.0);
//! assert_eq!(parts::prefixed("left_", &parts::DRAWER_CABINET_PARTS)[1], "left_bottom_drawer");
//! assert_eq!(
//!     parts::sibling("left_top_drawer", parts::TOP_DRAWER, parts::BOTTOM_DRAWER_HANDLE).as_deref(),
//!     Some("left_bottom_drawer_handle")
//! );
//! ```

/// The table, as the API and the observer name it.
pub const FLOOR: &str = "floor";
/// The finger hand (with its fingers), as the API and the observer name it.
pub const GRIPPER: &str = "gripper";
/// The suction tool, as the API and the observer name it on the vacuum robot.
pub const VACUUM_GRIPPER: &str = "vacuum_gripper";

/// The hinge box's fixed body (also the name of its scene entry).
pub const HINGE_BODY: &str = "hinge_body";
/// The hinge box's lid, on a revolute joint.
pub const HINGE_LID: &str = "hinge_lid";
/// The handle on the lid's free edge.
pub const HINGE_HANDLE: &str = "hinge_handle";
/// The drawer cabinet's fixed body (also the name of its scene entry).
pub const DRAWER_BODY: &str = "drawer_body";
/// The cabinet's top drawer, on a prismatic joint.
pub const TOP_DRAWER: &str = "top_drawer";
/// The cabinet's bottom drawer, on a prismatic joint.
pub const BOTTOM_DRAWER: &str = "bottom_drawer";
/// The top drawer's handle.
pub const TOP_DRAWER_HANDLE: &str = "top_drawer_handle";
/// The bottom drawer's handle.
pub const BOTTOM_DRAWER_HANDLE: &str = "bottom_drawer_handle";
/// The chess board of the sweep subtask.
pub const BOARD: &str = "board";
/// The toy box of the pick-and-place subtask.
pub const TOY_BOX: &str = "toy_box";
/// The chess box for the white pieces (toward −y).
pub const LEFT_CHESS_BOX: &str = "left_chess_box";
/// The chess box for the black pieces (toward +y).
pub const RIGHT_CHESS_BOX: &str = "right_chess_box";

/// The hinge box's parts, base part first.
pub const HINGE_BOX_PARTS: [&str; 3] = [HINGE_BODY, HINGE_LID, HINGE_HANDLE];
/// The drawer cabinet's parts, base part first.
pub const DRAWER_CABINET_PARTS: [&str; 5] = [
    DRAWER_BODY,
    BOTTOM_DRAWER,
    TOP_DRAWER,
    BOTTOM_DRAWER_HANDLE,
    TOP_DRAWER_HANDLE,
];

/// True when `name` is `part` or ends with `_` followed by `part` (an asset's prefixed part).
pub fn has_part_suffix(name: &str, part: &str) -> bool {
    name.strip_suffix(part)
        .is_some_and(|prefix| prefix.is_empty() || prefix.ends_with('_'))
}

/// The names of an asset's parts for a prefix (`""` or one ending in `_`), in the order of
/// `asset_parts` (one of [`HINGE_BOX_PARTS`] and [`DRAWER_CABINET_PARTS`]).
pub fn prefixed<const N: usize>(prefix: &str, asset_parts: &[&str; N]) -> [String; N] {
    asset_parts.map(|part| format!("{prefix}{part}"))
}

/// The prefix of a prefixed part name: what `name` carries before `part` (`"left_"` for
/// `left_top_drawer` and `top_drawer`), or `None` when it does not end with it.
pub fn prefix_of<'a>(name: &'a str, part: &str) -> Option<&'a str> {
    has_part_suffix(name, part).then(|| &name[..name.len() - part.len()])
}

/// The name of the same asset's `other` part, when `name` is its `part` (with the asset's
/// prefix, if any): `sibling("left_top_drawer", TOP_DRAWER, BOTTOM_DRAWER_HANDLE)` is
/// `left_bottom_drawer_handle`.
pub fn sibling(name: &str, part: &str, other: &str) -> Option<String> {
    prefix_of(name, part).map(|prefix| format!("{prefix}{other}"))
}

/// Lid joint position when open (the lid stands vertical).
pub const LID_OPEN: f64 = 0.785;
/// Lid joint position when closed (the lid lies flat on the body).
pub const LID_CLOSED: f64 = -0.785;
/// Upper limit of the lid joint (a little past vertical).
pub const LID_MAX: f64 = 0.8;
/// Full travel of a drawer (the authors' 0.88 × 0.14 scale).
pub const DRAWER_TRAVEL: f64 = 0.1232;
/// How far an open drawer is pulled out in the generated scenes (0.12 of the 0.1232
/// travel).
pub const DRAWER_OPEN: f64 = 0.12;

/// The one-dof joints of the articulated assets, named by their moving link.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Joint {
    /// The hinge lid: −0.785 closed (flat) to +0.785 open (vertical), limits −0.785..0.8.
    HingeLid,
    /// The top drawer: 0 closed to 0.1232 open.
    TopDrawer,
    /// The bottom drawer: 0 closed to 0.1232 open.
    BottomDrawer,
}

impl Joint {
    /// All three.
    pub const ALL: [Joint; 3] = [Joint::HingeLid, Joint::TopDrawer, Joint::BottomDrawer];

    /// The moving link's part name.
    pub fn name(self) -> &'static str {
        match self {
            Joint::HingeLid => HINGE_LID,
            Joint::TopDrawer => TOP_DRAWER,
            Joint::BottomDrawer => BOTTOM_DRAWER,
        }
    }

    /// The joint of a moving link's part name: the name is the link's own (`top_drawer`) or
    /// ends with it after an asset's prefix (`left_top_drawer`). The scene checks that such a
    /// name really is a link of one of its assets.
    pub fn from_name(name: &str) -> Option<Joint> {
        Joint::ALL.into_iter().find(|j| has_part_suffix(name, j.name()))
    }

    /// Lower and upper limit.
    pub fn limits(self) -> (f64, f64) {
        match self {
            Joint::HingeLid => (LID_CLOSED, LID_MAX),
            Joint::TopDrawer | Joint::BottomDrawer => (0.0, DRAWER_TRAVEL),
        }
    }

    /// The closed position, where a scene that does not list the joint starts.
    pub fn closed(self) -> f64 {
        match self {
            Joint::HingeLid => LID_CLOSED,
            Joint::TopDrawer | Joint::BottomDrawer => 0.0,
        }
    }
}
