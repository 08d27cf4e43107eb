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
}

/// One schema of the true domain: name, what it does, its parameters, and the part it
/// works on (handles, drawers).
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
use SchemaKind::{Box as B, Item as I, Surface as S};

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

/// The schema argument kind an object can fill, from its name: the world's fixed names are
/// surfaces, boxes or parts no schema takes as an argument; every other name is a loose item.
pub fn kind_of(object: &str) -> Option<SchemaKind> {
    match object {
        parts::FLOOR | parts::BOARD => Some(SchemaKind::Surface),
        parts::TOY_BOX | parts::LEFT_CHESS_BOX | parts::RIGHT_CHESS_BOX => Some(SchemaKind::Box),
        parts::GRIPPER | parts::VACUUM_GRIPPER => None,
        o if parts::HINGE_BOX_PARTS.contains(&o) || parts::DRAWER_CABINET_PARTS.contains(&o) => None,
        _ => Some(SchemaKind::Item),
    }
}
