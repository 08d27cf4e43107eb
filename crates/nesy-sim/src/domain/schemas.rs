//! What each schema of the true domain does on the robot: the table the template compiler
//! maps actions through, and the argument kinds objects can fill.

use serde::{Deserialize, Serialize};

use crate::scene::parts;

/// What an action does, independent of the end effector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Motion {
    /// `move_gripper_to(item)`: around it (finger) or onto it (vacuum).
    MoveToObject,
    /// `close_gripper` / `activate_vacuum`.
    Take,
    /// `move_to_position` onto a free spot of a surface (table or board).
    CarryOnto,
    /// `move_to_position` into an open-topped box.
    CarryInto,
    /// `move_to_position` over the hinge box.
    CarryOverHinge,
    /// `move_to_position` over the bottom drawer.
    CarryOverDrawer,
    /// `open_gripper` / `deactivate_vacuum`.
    Release,
    /// `move_parallel` across the board into a box.
    Push,
    /// `move_parallel("up")`.
    Retreat,
    /// `move_gripper_to(handle)`.
    MoveToHandle,
    /// `grasp_handle` / `attach_vacuum_handle` (moving to the handle first if needed).
    GraspHandle,
    /// `move_to_position` swinging the lid open.
    OpenLid,
    /// `move_to_position` swinging the lid closed.
    CloseLid,
    /// `release_handle` / `detach_vacuum_handle`.
    ReleaseHandle,
    /// `move_parallel` pulling a drawer open.
    OpenDrawer,
    /// `move_parallel` pushing a drawer closed.
    CloseDrawer,
    /// `gather_with_hook`: the held hook's magnet swept over a fine-grained object's pieces.
    Gather,
}

/// Argument kinds of a schema (the domain's types).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SchemaKind {
    /// A loose object (`item`).
    Item,
    /// A surface things are put down on (`surface`).
    Surface,
    /// An open-topped box (`box`).
    Box,
    /// A magnetic hook (`tool`, a kind of item).
    Tool,
    /// A fine-grained object, too small to take one piece at a time (`pieces`).
    Pieces,
}

impl SchemaKind {
    /// Whether an object of kind `object` can fill a parameter of this kind: its own kind,
    /// or a tool where an item is asked for (the hand takes and carries a hook like any
    /// item).
    pub fn accepts(self, object: SchemaKind) -> bool {
        self == object || (self == SchemaKind::Item && object == SchemaKind::Tool)
    }
}

/// One schema of the true domain: name, what it does, its parameters, and the part it
/// works on (handles, drawers).
#[derive(Debug, PartialEq, Eq)]
pub struct Schema {
    /// The schema's name in the domain file, e.g. `carry-into`.
    pub name: &'static str,
    /// What it does on the robot.
    pub motion: Motion,
    /// Its parameters' kinds, in order.
    pub params: &'static [SchemaKind],
    /// The part it works on (a handle or a drawer), if any.
    pub part: Option<&'static str>,
}

/// A table row.
const fn s(
    name: &'static str,
    motion: Motion,
    params: &'static [SchemaKind],
    part: Option<&'static str>,
) -> Schema {
    Schema {
        name,
        motion,
        params,
        part,
    }
}

use Motion::*;
use SchemaKind::{Box as B, Item as I, Pieces as P, Surface as S, Tool as T};

/// Every schema of `nesy-world.pddl` (finger, then vacuum); `tests/integration/codegen_domain.rs`
/// checks the table against the file.
const SCHEMAS: &[Schema] = &[
    s("move-to-surround", MoveToObject, &[I], None),
    s("grasp", Take, &[I], None),
    s("carry-onto", CarryOnto, &[I, S], None),
    s("carry-into", CarryInto, &[I, B], None),
    s("carry-over-hinge-body", CarryOverHinge, &[I], None),
    s("carry-over-bottom-drawer", CarryOverDrawer, &[I], None),
    s("put-down", Release, &[I, S], None),
    s("release-into", Release, &[I, B], None),
    s("drop-into-hinge-body", Release, &[I], None),
    s("drop-into-bottom-drawer", Release, &[I], None),
    s("sweep-into", Push, &[I, B], None),
    s("retreat", Retreat, &[], None),
    s(
        "move-to-hinge-handle",
        MoveToHandle,
        &[],
        Some(parts::HINGE_HANDLE),
    ),
    s("grasp-hinge-handle", GraspHandle, &[], Some(parts::HINGE_HANDLE)),
    s("open-hinge-lid", OpenLid, &[], None),
    s("close-hinge-lid", CloseLid, &[], None),
    s("release-hinge-handle", ReleaseHandle, &[], None),
    s(
        "move-to-bottom-drawer-handle",
        MoveToHandle,
        &[],
        Some(parts::BOTTOM_DRAWER_HANDLE),
    ),
    s(
        "grasp-bottom-drawer-handle",
        GraspHandle,
        &[],
        Some(parts::BOTTOM_DRAWER_HANDLE),
    ),
    s("open-bottom-drawer", OpenDrawer, &[], Some(parts::BOTTOM_DRAWER)),
    s(
        "close-bottom-drawer",
        CloseDrawer,
        &[],
        Some(parts::BOTTOM_DRAWER),
    ),
    s("release-bottom-drawer-handle", ReleaseHandle, &[], None),
    s(
        "move-to-top-drawer-handle",
        MoveToHandle,
        &[],
        Some(parts::TOP_DRAWER_HANDLE),
    ),
    s(
        "grasp-top-drawer-handle",
        GraspHandle,
        &[],
        Some(parts::TOP_DRAWER_HANDLE),
    ),
    s("open-top-drawer", OpenDrawer, &[], Some(parts::TOP_DRAWER)),
    s("close-top-drawer", CloseDrawer, &[], Some(parts::TOP_DRAWER)),
    s("release-top-drawer-handle", ReleaseHandle, &[], None),
    s("gather-with-hook", Gather, &[T, P], None),
    s("carry-hook-over-bottom-drawer", CarryOverDrawer, &[T], None),
    s("drop-hook-into-bottom-drawer", Release, &[T], None),
    s("move-to-align", MoveToObject, &[I], None),
    s("attach", Take, &[I], None),
    s("suction-carry-onto", CarryOnto, &[I, S], None),
    s("suction-carry-into", CarryInto, &[I, B], None),
    s("suction-carry-over-hinge-body", CarryOverHinge, &[I], None),
    s("suction-carry-over-bottom-drawer", CarryOverDrawer, &[I], None),
    s("suction-put-down", Release, &[I, S], None),
    s("suction-release-into", Release, &[I, B], None),
    s("suction-drop-into-hinge-body", Release, &[I], None),
    s("suction-drop-into-bottom-drawer", Release, &[I], None),
    s("slide-into", Push, &[I, B], None),
    s("suction-retreat", Retreat, &[], None),
    s(
        "suction-move-to-hinge-handle",
        MoveToHandle,
        &[],
        Some(parts::HINGE_HANDLE),
    ),
    s("attach-hinge-handle", GraspHandle, &[], Some(parts::HINGE_HANDLE)),
    s("suction-open-hinge-lid", OpenLid, &[], None),
    s("suction-close-hinge-lid", CloseLid, &[], None),
    s("detach-hinge-handle", ReleaseHandle, &[], None),
    s(
        "suction-move-to-bottom-drawer-handle",
        MoveToHandle,
        &[],
        Some(parts::BOTTOM_DRAWER_HANDLE),
    ),
    s(
        "attach-bottom-drawer-handle",
        GraspHandle,
        &[],
        Some(parts::BOTTOM_DRAWER_HANDLE),
    ),
    s(
        "suction-open-bottom-drawer",
        OpenDrawer,
        &[],
        Some(parts::BOTTOM_DRAWER),
    ),
    s(
        "suction-close-bottom-drawer",
        CloseDrawer,
        &[],
        Some(parts::BOTTOM_DRAWER),
    ),
    s("detach-bottom-drawer-handle", ReleaseHandle, &[], None),
    s(
        "suction-move-to-top-drawer-handle",
        MoveToHandle,
        &[],
        Some(parts::TOP_DRAWER_HANDLE),
    ),
    s(
        "attach-top-drawer-handle",
        GraspHandle,
        &[],
        Some(parts::TOP_DRAWER_HANDLE),
    ),
    s(
        "suction-open-top-drawer",
        OpenDrawer,
        &[],
        Some(parts::TOP_DRAWER),
    ),
    s(
        "suction-close-top-drawer",
        CloseDrawer,
        &[],
        Some(parts::TOP_DRAWER),
    ),
    s("detach-top-drawer-handle", ReleaseHandle, &[], None),
];

/// The schema names the compiler knows, in the domain file's order.
pub fn schema_names() -> impl Iterator<Item = &'static str> {
    SCHEMAS.iter().map(|s| s.name)
}

/// Every schema of the table, in the domain file's order.
pub fn schemas() -> &'static [Schema] {
    SCHEMAS
}

/// The table's schema called `name`; callers pass names the table resolved.
pub fn schema(name: &str) -> &'static Schema {
    SCHEMAS
        .iter()
        .find(|s| s.name == name)
        .expect("resolved actions name table schemas")
}

/// The schema argument kind an object can fill, from its name (the domain's type,
/// [`crate::domain::object_type`]): surfaces, boxes, tools and pieces by the world's names,
/// no kind for the robot's own entry and an articulated asset's parts (which no schema takes
/// as an argument), every other name a loose item.
pub fn kind_of(object: &str) -> Option<SchemaKind> {
    if object == parts::GRIPPER || object == parts::VACUUM_GRIPPER {
        return None;
    }
    match crate::domain::object_type(object) {
        "surface" => Some(SchemaKind::Surface),
        "box" => Some(SchemaKind::Box),
        "tool" => Some(SchemaKind::Tool),
        "pieces" => Some(SchemaKind::Pieces),
        "part" => None,
        _ => Some(SchemaKind::Item),
    }
}

/// True when `object` names a part of a hinge box or a drawer cabinet, bare or prefixed.
pub fn is_asset_part(object: &str) -> bool {
    parts::HINGE_BOX_PARTS
        .iter()
        .chain(&parts::DRAWER_CABINET_PARTS)
        .any(|part| parts::has_part_suffix(object, part))
}

/// An asset part's prefix and bare name (`front_top_drawer` → `("front_", "top_drawer")`);
/// `None` for every other object.
pub fn split_asset_part(object: &str) -> Option<(&str, &'static str)> {
    // Longest bare names first, so `top_drawer_handle` is not read as a `top_drawer`.
    let mut bare: Vec<&'static str> = parts::HINGE_BOX_PARTS
        .iter()
        .chain(&parts::DRAWER_CABINET_PARTS)
        .copied()
        .collect();
    bare.sort_by_key(|b| std::cmp::Reverse(b.len()));
    bare.into_iter()
        .find(|b| parts::has_part_suffix(object, b))
        .map(|b| (&object[..object.len() - b.len()], b))
}

/// The words by which a schema's name names the articulated asset it works on, with that
/// asset's parts (the constants its schemas mention).
const ASSET_WORDS: [(&str, &[&str]); 3] = [
    ("hinge", &parts::HINGE_BOX_PARTS),
    ("bottom-drawer", &parts::DRAWER_CABINET_PARTS),
    ("top-drawer", &parts::DRAWER_CABINET_PARTS),
];

/// Where a schema's name names its asset (byte offset of the asset word), and the asset's
/// parts; `None` for the schemas of loose objects.
pub fn asset_of(schema_name: &str) -> Option<(usize, &'static [&'static str])> {
    ASSET_WORDS
        .iter()
        .filter_map(|(word, asset_parts)| {
            let at = schema_name
                .match_indices(word)
                .map(|(i, _)| i)
                .find(|&i| i == 0 || schema_name.as_bytes()[i - 1] == b'-')?;
            Some((at, *asset_parts))
        })
        .min_by_key(|(at, _)| *at)
}

/// A schema of the table working on one articulated asset of a scene. The benchmark's
/// assets carry the bare part names (`top_drawer`); a scene with several names each asset's
/// parts with a prefix (`front_top_drawer`), and the schema for that asset is named with the
/// prefix's words before the asset word: `open-front-top-drawer` is `open-top-drawer` for
/// the cabinet whose parts start with `front_`.
///
/// ```
/// use nesy_sim::domain::{instance_name, schema_instance};
///
/// assert_eq!(instance_name("open-top-drawer", "front_"), "open-front-top-drawer");
/// let open = schema_instance("suction-open-front-top-drawer").unwrap();
/// assert_eq!((open.schema.name, open.prefix.as_str()), ("suction-open-top-drawer", "front_"));
/// assert_eq!(open.part().as_deref(), Some("front_top_drawer"));
/// assert_eq!(schema_instance("grasp").unwrap().prefix, "");
/// assert!(schema_instance("open-front-drawer").is_none());
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SchemaInstance {
    /// The table's schema.
    pub schema: &'static Schema,
    /// The prefix of the asset's part names (`""` for the bare names, else ending in `_`).
    pub prefix: String,
}

impl SchemaInstance {
    /// The part it works on, with the asset's prefix.
    pub fn part(&self) -> Option<String> {
        self.schema.part.map(|part| self.asset_part(part))
    }

    /// A part of the same asset, by its bare name (`parts::BOTTOM_DRAWER`), with the prefix.
    pub fn asset_part(&self, part: &str) -> String {
        format!("{}{part}", self.prefix)
    }

    /// Its name in the scene's domain.
    pub fn name(&self) -> String {
        instance_name(self.schema.name, &self.prefix)
    }
}

/// The name of schema `schema_name` for the asset whose parts carry `prefix` (`""` or ending
/// in `_`): the prefix's words go before the asset word. Schemas of loose objects and the bare
/// prefix keep their name.
pub fn instance_name(schema_name: &str, prefix: &str) -> String {
    match asset_of(schema_name) {
        Some((at, _)) if !prefix.is_empty() => format!(
            "{}{}{}",
            &schema_name[..at],
            prefix.replace('_', "-"),
            &schema_name[at..]
        ),
        _ => schema_name.to_owned(),
    }
}

/// The table's schema and asset prefix a schema name stands for (see [`SchemaInstance`]);
/// `None` when it names no schema of the table for any asset.
pub fn schema_instance(name: &str) -> Option<SchemaInstance> {
    if let Some(schema) = SCHEMAS.iter().find(|s| s.name == name) {
        return Some(SchemaInstance {
            schema,
            prefix: String::new(),
        });
    }
    SCHEMAS.iter().find_map(|schema| {
        let (at, _) = asset_of(schema.name)?;
        let (head, tail) = schema.name.split_at(at);
        let middle = name.strip_prefix(head)?.strip_suffix(tail)?;
        let words_only = middle.len() > 1
            && middle.ends_with('-')
            && !middle.starts_with('-')
            && !middle.contains("--")
            && middle.chars().all(|c| c.is_ascii_alphanumeric() || c == '-');
        words_only.then(|| SchemaInstance {
            schema,
            prefix: middle.replace('-', "_"),
        })
    })
}

/// The prefixes of the articulated assets among `objects` that are named with one (their base
/// part, `front_drawer_body` or `left_hinge_body`, gives it), in the order listed.
pub fn asset_prefixes<'a>(objects: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let mut prefixes = Vec::new();
    for object in objects {
        for base in [parts::HINGE_BODY, parts::DRAWER_BODY] {
            if let Some(prefix) = object.strip_suffix(base)
                && prefix.ends_with('_')
                && !prefixes.iter().any(|p| p == prefix)
            {
                prefixes.push(prefix.to_owned());
            }
        }
    }
    prefixes
}
