//! `scene.json`: the versioned description of one episode's world (embodiment, objects,
//! articulation states, subtask goals, instruction, seed), its JSON Schema, and loading
//! with errors that name the JSON path and the expected value.
//!
//! [`parts`] names the fixed parts and the articulated joints; `goals` holds the subtask
//! kinds and their goals.

mod goals;
pub mod parts;

pub use goals::{Placement, SubtaskGoal, SubtaskKind};

use std::collections::{BTreeMap, HashSet};
use std::path::Path;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::api::Embodiment;

/// The scene format version this build reads and writes.
pub const SCENE_SCHEMA_VERSION: u32 = 1;

/// Height of the table top in metres: objects resting on the table have their lowest point
/// here, and the robot's base stands at this height on its pedestal.
pub const TABLE_TOP: f64 = 0.5;

/// One episode's world.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Format version; must be 1.
    pub schema_version: u32,
    /// The robot's end effector.
    pub embodiment: Embodiment,
    /// When true the observer emits `(FingerGripper)` or `(VacuumSuction)` (the authors'
    /// `ee_set`, used when source and target embodiments may differ).
    #[serde(default)]
    pub embodiment_in_state: bool,
    /// The natural-language instruction.
    #[serde(default)]
    pub instruction: String,
    /// Seed the scene was generated from (informational; the simulator is deterministic).
    #[serde(default)]
    pub seed: u64,
    /// Objects, in scene order (perception lists them in this order after `floor`).
    pub objects: Vec<ObjectSpec>,
    /// Joint positions of articulated parts by part name (`hinge_lid`, `top_drawer`,
    /// `bottom_drawer`, after their asset's prefix if it has one), in the benchmark's
    /// convention: the hinge lid −0.785 closed to
    /// +0.785 open (limits −0.785..0.8); drawers 0 closed to 0.1232 open. Parts not listed
    /// start closed.
    #[serde(default)]
    pub articulations: BTreeMap<String, f64>,
    /// What the episode asks for, one entry per subtask, in label order.
    #[serde(default)]
    pub goals: Vec<SubtaskGoal>,
    /// Whether the robot's protective stop is on: a motion that presses the arm or what it
    /// carries more than 5 mm into furniture ends there with a collision error, as a real
    /// arm's collision detection stops it, and the scripted experts and the free-spot search
    /// move as a robot that knows its furniture. Off by default (the kinematic arm, which
    /// passes through furniture), so that every recorded run re-scores unchanged.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub protective_stop: bool,
}

/// One object of the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    /// Unique name, used by prompts, the API and the observer. Articulated kinds take the
    /// name of their base part, `hinge_body` for a hinge box and `drawer_body` for a drawer
    /// cabinet, optionally after a prefix ending in `_` that their other parts carry too
    /// (`left_drawer_body` has the drawers `left_top_drawer` and `left_bottom_drawer`).
    pub name: String,
    /// What it is.
    pub kind: ObjectKind,
    /// Where it is.
    pub pose: PoseSpec,
    /// Colour; when absent it is taken from the name's first word (`red_cube` is red) or
    /// the kind's default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour: Option<ColourSpec>,
    /// Overrides the kind's nominal outer size `[x, y, z]` in metres (before yaw).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f64; 3]>,
    /// Where the pieces of a fine-grained kind (`screws`) lie: `[x, y]` offsets in metres
    /// from `pose.position`, in the object's frame, one per piece. The pieces are separate
    /// bodies named `<name>_1`, `<name>_2`, …; perception reports them as the one object
    /// `<name>`. Default: [`DEFAULT_PIECES`] pieces in a row 3 cm apart.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pieces: Option<Vec<[f64; 2]>>,
}

/// How many pieces a fine-grained object has when its entry lists none.
pub const DEFAULT_PIECES: usize = 5;
/// Most pieces a fine-grained object may have.
pub const MAX_PIECES: usize = 40;
/// Farthest (m) a piece may lie from its object's position.
pub const MAX_PIECE_OFFSET: f64 = 0.3;

impl ObjectSpec {
    /// The `[x, y]` offsets of a fine-grained object's pieces (the listed ones, else the
    /// default row); empty for other kinds.
    pub fn piece_offsets(&self) -> Vec<[f64; 2]> {
        if !self.kind.is_fine_grained() {
            return Vec::new();
        }
        match &self.pieces {
            Some(pieces) => pieces.clone(),
            None => (0..DEFAULT_PIECES)
                .map(|k| [0.03 * (k as f64 - (DEFAULT_PIECES - 1) as f64 / 2.0), 0.0])
                .collect(),
        }
    }
}

/// Position and heading of an object.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// `[x, y, z]` in metres: x, y of the object's centre and z of its lowest point (0.5 is
    /// the table top), so objects are placed resting, never interpenetrating.
    pub position: [f64; 3],
    /// Rotation about the world z axis in radians.
    #[serde(default)]
    pub yaw: f64,
}

/// Object kinds with their nominal sizes (`docs/benchmark.md` §2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ObjectKind {
    /// 3 cm cube block.
    Cube,
    /// Cylinder block, radius 1.5 cm, height 3 cm.
    Cylinder,
    /// Apple, about 5.7 cm across.
    Apple,
    /// Orange, about 6.4 cm across.
    Orange,
    /// Lemon, about 5.4 cm across.
    Lemon,
    /// Chess rook, 5.1 cm tall.
    Rook,
    /// Chess knight, 5.9 cm tall.
    Knight,
    /// Chess bishop, 6.5 cm tall.
    Bishop,
    /// Chess board between the two chess boxes (fixed).
    ChessBoard,
    /// Open chess box with thin walls (fixed).
    ChessBox,
    /// Open toy box, bottom plus four walls (fixed).
    ToyBox,
    /// Box with a lid on a revolute hinge: parts `hinge_body`, `hinge_lid`, `hinge_handle`.
    HingeBox,
    /// Cabinet with two prismatic drawers: parts `drawer_body`, `top_drawer`,
    /// `bottom_drawer`, `top_drawer_handle`, `bottom_drawer_handle`.
    DrawerCabinet,
    /// Magnetic pickup hook, 14 cm long: a grey bar with a magnet at its +x end that pulls
    /// the pieces of fine-grained objects within [`crate::world::magnet::MAGNET_RADIUS`].
    MagneticHook,
    /// Screws: several small steel pieces (each 2 × 0.6 × 0.6 cm), too small and scattered
    /// to grasp one by one; see [`ObjectSpec::pieces`].
    Screws,
}

impl ObjectKind {
    /// True for the kinds that move freely (picked, pushed, dropped).
    pub fn is_loose(self) -> bool {
        matches!(
            self,
            ObjectKind::Cube
                | ObjectKind::Cylinder
                | ObjectKind::Apple
                | ObjectKind::Orange
                | ObjectKind::Lemon
                | ObjectKind::Rook
                | ObjectKind::Knight
                | ObjectKind::Bishop
                | ObjectKind::MagneticHook
                | ObjectKind::Screws
        )
    }

    /// True for the kinds made of many small pieces (`Finegrained` in the states).
    pub fn is_fine_grained(self) -> bool {
        self == ObjectKind::Screws
    }

    /// True for the kinds a robot uses as a tool (the magnetic hook): a scene holding one is
    /// offered the tool-use calls of the robot API.
    pub fn is_tool(self) -> bool {
        self == ObjectKind::MagneticHook
    }

    /// The base part name an articulated kind's entry must end with (after an optional
    /// prefix ending in `_`).
    pub fn required_suffix(self) -> Option<&'static str> {
        match self {
            ObjectKind::HingeBox => Some(parts::HINGE_BODY),
            ObjectKind::DrawerCabinet => Some(parts::DRAWER_BODY),
            _ => None,
        }
    }
}

/// A colour by name or as linear RGB in 0..1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(untagged)]
pub enum ColourSpec {
    /// One of the benchmark's colour names.
    Named(NamedColour),
    /// `[r, g, b]`, each in 0..1.
    Rgb([f64; 3]),
}

/// The benchmark's colour names (`docs/benchmark.md` §2) plus a few for furniture and fruit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[allow(missing_docs)]
pub enum NamedColour {
    Red,
    Green,
    Blue,
    Yellow,
    Purple,
    White,
    Black,
    Orange,
    Brown,
    Grey,
}

impl NamedColour {
    /// RGB values (`docs/benchmark.md` §2's table for the block colours).
    pub fn rgb(self) -> [f64; 3] {
        match self {
            NamedColour::Red => [0.8, 0.2, 0.2],
            NamedColour::Green => [0.2, 0.8, 0.2],
            NamedColour::Blue => [0.2, 0.2, 0.8],
            NamedColour::Yellow => [0.95, 0.85, 0.2],
            NamedColour::Purple => [0.6, 0.3, 0.8],
            NamedColour::White => [0.95, 0.95, 0.95],
            NamedColour::Black => [0.1, 0.1, 0.1],
            NamedColour::Orange => [0.95, 0.55, 0.1],
            NamedColour::Brown => [0.55, 0.38, 0.22],
            NamedColour::Grey => [0.6, 0.6, 0.6],
        }
    }

    /// Parses a lower-case colour name.
    pub fn from_name(name: &str) -> Option<NamedColour> {
        serde_json::from_value(serde_json::Value::String(name.to_owned())).ok()
    }
}

impl ColourSpec {
    /// RGB values in 0..1.
    pub fn rgb(self) -> [f64; 3] {
        match self {
            ColourSpec::Named(n) => n.rgb(),
            ColourSpec::Rgb(c) => c,
        }
    }
}

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("cannot read scene {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The JSON did not parse or did not match the format.
    #[error("{origin}: at {path} (line {line}, column {column}): {message}")]
    Json {
        /// File name or `<string>`.
        origin: String,
        /// JSON path of the offending value, e.g. `objects[2].kind`.
        path: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What serde expected.
        message: String,
    },
    /// The JSON parsed but a value is not acceptable.
    #[error("{origin}: at {path}: expected {expected}, found {found}")]
    Invalid {
        /// File name or `<string>`.
        origin: String,
        /// JSON path of the offending value.
        path: String,
        /// What would have been acceptable.
        expected: String,
        /// What was there.
        found: String,
    },
}

impl SceneError {
    /// The JSON path the error points at, if any.
    pub fn json_path(&self) -> Option<&str> {
        match self {
            SceneError::Io { .. } => None,
            SceneError::Json { path, .. } | SceneError::Invalid { path, .. } => Some(path),
        }
    }

    pub(crate) fn invalid(
        path: impl Into<String>,
        expected: impl Into<String>,
        found: impl Into<String>,
    ) -> Self {
        SceneError::Invalid {
            origin: "<scene>".into(),
            path: path.into(),
            expected: expected.into(),
            found: found.into(),
        }
    }

    /// The same error attributed to `name` (a file path) instead of `<scene>`.
    pub fn with_origin(mut self, name: &str) -> Self {
        match &mut self {
            SceneError::Json { origin, .. } | SceneError::Invalid { origin, .. } => *origin = name.to_owned(),
            SceneError::Io { .. } => {}
        }
        self
    }
}

/// Names of the parts an object entry creates, base part first.
pub fn part_names(spec: &ObjectSpec) -> Vec<String> {
    match spec.kind {
        ObjectKind::HingeBox => parts::prefixed(part_prefix(spec), &parts::HINGE_BOX_PARTS).to_vec(),
        ObjectKind::DrawerCabinet => {
            parts::prefixed(part_prefix(spec), &parts::DRAWER_CABINET_PARTS).to_vec()
        }
        kind if kind.is_fine_grained() => (1..=spec.piece_offsets().len())
            .map(|k| format!("{}_{k}", spec.name))
            .collect(),
        _ => vec![spec.name.clone()],
    }
}

/// The prefix an articulated object's parts carry: its name before the base part's name
/// (`""` for `drawer_body`, `"left_"` for `left_drawer_body`); `""` for other kinds.
pub fn part_prefix(spec: &ObjectSpec) -> &str {
    spec.kind
        .required_suffix()
        .and_then(|suffix| parts::prefix_of(&spec.name, suffix))
        .unwrap_or("")
}

impl SceneSpec {
    /// True when the scene holds a tool (a magnetic hook), so that policies for it are
    /// offered the tool-use calls (`gather_with_hook`).
    pub fn holds_tool(&self) -> bool {
        self.objects.iter().any(|o| o.kind.is_tool())
    }

    /// Parses and validates scene JSON; `origin` names the source in errors.
    pub fn from_json_str(text: &str, origin: &str) -> Result<SceneSpec, SceneError> {
        let de = &mut serde_json::Deserializer::from_str(text);
        let spec: SceneSpec = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let message = inner.to_string();
            // serde_json appends " at line L column C"; the position is reported separately.
            let message = match message.rfind(" at line ") {
                Some(i) => message[..i].to_owned(),
                None => message,
            };
            SceneError::Json {
                origin: origin.to_owned(),
                path,
                line: inner.line(),
                column: inner.column(),
                message,
            }
        })?;
        spec.validate().map_err(|e| e.with_origin(origin))?;
        Ok(spec)
    }

    /// Reads, parses and validates a scene file.
    pub fn from_file(path: &Path) -> Result<SceneSpec, SceneError> {
        let text =
            nesy_input::read_text(path, nesy_input::MAX_JSON_BYTES).map_err(|source| SceneError::Io {
                path: path.display().to_string(),
                source,
            })?;
        SceneSpec::from_json_str(&text, &path.display().to_string())
    }

    /// The scene's goal as ground atoms in the paper's predicates: every subtask's atoms
    /// ([`SubtaskGoal::symbolic_goal`]) and the end effector released at the end
    /// (`GripperOpen` or `VacuumInactive`), as the goal checks require.
    pub fn symbolic_goal(&self) -> Vec<nesy_core::Atom> {
        self.goals
            .iter()
            .flat_map(SubtaskGoal::symbolic_goal)
            .chain([nesy_core::Atom::new(self.embodiment.released_predicate(), &[])])
            .collect()
    }

    /// Pretty JSON.
    pub fn to_json_pretty(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// All part names in scene order.
    pub fn part_names(&self) -> Vec<String> {
        self.objects.iter().flat_map(part_names).collect()
    }

    /// Checks everything serde cannot: version, finite and positive numbers, unique names,
    /// fixed part names, articulation names and ranges, goal references. (Interpenetration
    /// needs geometry and is checked when the world is built.)
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_header()?;
        let reserved = [parts::FLOOR, parts::GRIPPER, parts::VACUUM_GRIPPER];
        let mut seen: HashSet<String> = reserved.iter().map(|s| s.to_string()).collect();
        for (i, o) in self.objects.iter().enumerate() {
            validate_object_names(i, o, &mut seen)?;
            validate_object_numbers(i, o)?;
        }
        let links: HashSet<String> = self
            .objects
            .iter()
            .filter(|o| o.kind.required_suffix().is_some())
            .flat_map(part_names)
            .filter(|part| parts::Joint::from_name(part).is_some())
            .collect();
        self.validate_articulations(&links)?;
        self.validate_goals(&seen, &reserved)
    }

    /// Checks the format version and the object count.
    fn validate_header(&self) -> Result<(), SceneError> {
        if self.schema_version != SCENE_SCHEMA_VERSION {
            return Err(SceneError::invalid(
                "schema_version",
                format!("{SCENE_SCHEMA_VERSION}"),
                self.schema_version.to_string(),
            ));
        }
        if self.objects.len() > MAX_SCENE_OBJECTS {
            return Err(SceneError::invalid(
                "objects",
                format!("at most {MAX_SCENE_OBJECTS} objects"),
                format!("{} objects", self.objects.len()),
            ));
        }
        Ok(())
    }

    /// Checks that each articulation names a moving link of an asset in the scene (`links`
    /// holds their names) and lies within that joint's limits.
    fn validate_articulations(&self, links: &HashSet<String>) -> Result<(), SceneError> {
        for (part, q) in &self.articulations {
            let at = format!("articulations.{part}");
            let Some((lo, hi)) = parts::Joint::from_name(part).map(parts::Joint::limits) else {
                return Err(SceneError::invalid(
                    at,
                    "one of hinge_lid, top_drawer, bottom_drawer (after an asset's prefix, if it has one)",
                    format!("{part:?}"),
                ));
            };
            if !links.contains(part) {
                return Err(SceneError::invalid(
                    at,
                    "a lid or drawer of an asset in the scene",
                    format!("{part:?}, which no asset provides"),
                ));
            }
            if !(q.is_finite() && *q >= lo - 1e-9 && *q <= hi + 1e-9) {
                return Err(SceneError::invalid(
                    at,
                    format!("a joint position in [{lo}, {hi}]"),
                    q.to_string(),
                ));
            }
        }
        Ok(())
    }

    /// Checks that every goal moves something and names only scene objects (`seen` holds
    /// every part name, `reserved` the names no goal may use).
    fn validate_goals(&self, seen: &HashSet<String>, reserved: &[&str]) -> Result<(), SceneError> {
        for (g, goal) in self.goals.iter().enumerate() {
            let (field, moved) = match goal {
                SubtaskGoal::Sweep { placements } => ("placements", placements.len()),
                SubtaskGoal::PickPlace { objects, .. }
                | SubtaskGoal::PutInHinge { objects, .. }
                | SubtaskGoal::PutInPrismatic { objects, .. } => ("objects", objects.len()),
            };
            if moved == 0 {
                // An empty goal would be met by doing nothing.
                return Err(SceneError::invalid(
                    format!("goals[{g}].{field}"),
                    "at least one object",
                    "an empty list",
                ));
            }
            for (field, name) in goal.referenced_names() {
                if !seen.contains(name) || reserved.contains(&name) {
                    return Err(SceneError::invalid(
                        format!("goals[{g}].{field}"),
                        "the name of a scene object",
                        format!("{name:?}"),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// Checks object `i`'s name (its characters, the fixed name of an articulated kind) and
/// records its part names in `seen`, rejecting any already taken.
fn validate_object_names(i: usize, o: &ObjectSpec, seen: &mut HashSet<String>) -> Result<(), SceneError> {
    let at = |field: &str| format!("objects[{i}].{field}");
    if o.name.is_empty() || o.name.chars().any(|c| !(c.is_ascii_alphanumeric() || c == '_')) {
        return Err(SceneError::invalid(
            at("name"),
            "a non-empty name of [A-Za-z0-9_]",
            format!("{:?}", o.name),
        ));
    }
    if let Some(required) = o.kind.required_suffix()
        && !parts::has_part_suffix(&o.name, required)
    {
        return Err(SceneError::invalid(
            at("name"),
            format!(
                "\"{required}\" or a prefix ending in '_' before it, such as \"left_{required}\" (a {:?}'s parts are named after it)",
                o.kind
            ),
            format!("{:?}", o.name),
        ));
    }
    // A fine-grained object's pieces are `<name>_<k>`, and perception reports them under
    // `<name>`, which no other object may take.
    let fine_grained_name = o.kind.is_fine_grained().then(|| o.name.clone());
    for part in part_names(o).into_iter().chain(fine_grained_name) {
        if !seen.insert(part.clone()) {
            return Err(SceneError::invalid(
                at("name"),
                "a name not used by another object",
                format!("duplicate {part:?}"),
            ));
        }
    }
    Ok(())
}

/// Checks object `i`'s numbers: position within the bounds, finite yaw, size override
/// (only on kinds that allow one) and RGB colour.
fn validate_object_numbers(i: usize, o: &ObjectSpec) -> Result<(), SceneError> {
    let at = |field: &str| format!("objects[{i}].{field}");
    for (k, v) in o.pose.position.iter().enumerate() {
        let (lo, hi) = SCENE_POSITION_BOUNDS[k];
        if !(v.is_finite() && (lo..=hi).contains(v)) {
            return Err(SceneError::invalid(
                at(&format!("pose.position[{k}]")),
                format!("a position in metres from {lo} to {hi} (the table and the space around it)"),
                v.to_string(),
            ));
        }
    }
    if !o.pose.yaw.is_finite() {
        return Err(SceneError::invalid(
            at("pose.yaw"),
            "a finite number",
            o.pose.yaw.to_string(),
        ));
    }
    if let Some(size) = o.size {
        if matches!(o.kind, ObjectKind::HingeBox | ObjectKind::DrawerCabinet) {
            return Err(SceneError::invalid(
                at("size"),
                "no size override (articulated assets have fixed geometry)",
                format!("{size:?}"),
            ));
        }
        for (k, v) in size.iter().enumerate() {
            if !(v.is_finite() && (MIN_OBJECT_SIZE..=2.0).contains(v)) {
                return Err(SceneError::invalid(
                    at(&format!("size[{k}]")),
                    format!("a size in metres from {MIN_OBJECT_SIZE} to 2"),
                    v.to_string(),
                ));
            }
        }
    }
    if let Some(pieces) = &o.pieces {
        if !o.kind.is_fine_grained() {
            return Err(SceneError::invalid(
                at("pieces"),
                "no pieces (only fine-grained kinds such as screws have them)",
                format!("{} pieces on a {:?}", pieces.len(), o.kind),
            ));
        }
        if pieces.is_empty() || pieces.len() > MAX_PIECES {
            return Err(SceneError::invalid(
                at("pieces"),
                format!("1 to {MAX_PIECES} pieces"),
                format!("{} pieces", pieces.len()),
            ));
        }
        for (k, piece) in pieces.iter().enumerate() {
            if !piece.iter().all(|v| v.is_finite() && v.abs() <= MAX_PIECE_OFFSET) {
                return Err(SceneError::invalid(
                    at(&format!("pieces[{k}]")),
                    format!("an [x, y] offset within {MAX_PIECE_OFFSET} m of the object's position"),
                    format!("{piece:?}"),
                ));
            }
        }
    }
    if let Some(ColourSpec::Rgb(c)) = o.colour {
        for (k, v) in c.iter().enumerate() {
            if !(v.is_finite() && (0.0..=1.0).contains(v)) {
                return Err(SceneError::invalid(
                    at(&format!("colour[{k}]")),
                    "a value in 0..1",
                    v.to_string(),
                ));
            }
        }
    }
    Ok(())
}

/// Most objects a scene may hold (the benchmark's largest has 16, with 26 parts).
pub const MAX_SCENE_OBJECTS: usize = 100;

/// Range (m) of each coordinate of an object's position: x and y within 2 m of the robot's
/// base (the table is 1 m deep), z from the ground to 2 m above it. Anything outside is a
/// typing error, and far-off values overflow the simulator's single-precision floats.
pub const SCENE_POSITION_BOUNDS: [(f64, f64); 3] = [(-2.0, 2.0), (-2.0, 2.0), (0.0, 2.0)];

/// Smallest side (m) of an object: 1 mm. Smaller shapes make the contact solver diverge.
pub const MIN_OBJECT_SIZE: f64 = 0.001;

/// The JSON Schema of [`SceneSpec`], pretty-printed (committed at
/// `assets/schema/scene.schema.json`).
pub fn json_schema() -> String {
    let schema = schemars::schema_for!(SceneSpec);
    let mut text = serde_json::to_string_pretty(&schema).unwrap_or_default();
    text.push('\n');
    text
}
