//! The robot API as the code-generation prompts show it: the import block and the
//! docstrings (`prompts/api/*.py`), in nesy's own words, matching nesy-sim's signatures and
//! defaults (`tests/integration/prompts.rs` checks them against the `robot` module nesy-policy
//! provides).

/// Perception functions, in the order of the paper's perception table.
pub const PERCEPTION_FUNCTIONS: [&str; 8] = [
    "is_obj_visible",
    "get_obj_names",
    "get_obj_pos",
    "get_obj_bbox",
    "get_obj_size",
    "gripper_is_open",
    "obj_in_gripper",
    "get_empty_floor_xy",
];

/// Motion functions (both end effectors) and the finger gripper's own functions.
pub const FINGER_FUNCTIONS: [&str; 7] = [
    "move_gripper_to",
    "move_to_position",
    "move_parallel",
    "grasp_handle",
    "release_handle",
    "open_gripper",
    "close_gripper",
];

/// The vacuum tool's own functions.
pub const VACUUM_FUNCTIONS: [&str; 4] = [
    "attach_vacuum_handle",
    "detach_vacuum_handle",
    "activate_vacuum",
    "deactivate_vacuum",
];

/// The end-effector functions that exist only on the finger gripper.
pub const FINGER_ONLY_FUNCTIONS: [&str; 4] =
    ["grasp_handle", "release_handle", "open_gripper", "close_gripper"];

/// Docstrings of the perception functions.
pub const PERCEPTION_DOCS: &str = include_str!("../../prompts/api/perception.py");
/// Docstrings of the motion and finger-gripper functions.
pub const FINGER_DOCS: &str = include_str!("../../prompts/api/finger.py");
/// Docstrings of the vacuum functions.
pub const VACUUM_DOCS: &str = include_str!("../../prompts/api/vacuum.py");

/// The three documentation files with their paths under `prompts/`.
pub const EMBEDDED: [(&str, &str); 3] = [
    ("api/perception.py", PERCEPTION_DOCS),
    ("api/finger.py", FINGER_DOCS),
    ("api/vacuum.py", VACUUM_DOCS),
];

/// Every robot API function name (the 19 of the paper's tables).
pub fn all_functions() -> impl Iterator<Item = &'static str> {
    PERCEPTION_FUNCTIONS
        .into_iter()
        .chain(FINGER_FUNCTIONS)
        .chain(VACUUM_FUNCTIONS)
}

/// The functions a prompt offers: perception and motion always, plus the finger functions
/// and, when `vacuum`, the vacuum functions.
pub fn offered_functions(vacuum: bool) -> Vec<&'static str> {
    let mut names: Vec<&str> = PERCEPTION_FUNCTIONS.into_iter().chain(FINGER_FUNCTIONS).collect();
    if vacuum {
        names.extend(VACUUM_FUNCTIONS);
    }
    names
}

/// The "already imported" block: numpy, math and the robot functions.
pub fn imports(vacuum: bool) -> String {
    let mut lines = vec![
        "import math".to_string(),
        "import numpy as np".to_string(),
        "from robot import (".to_string(),
    ];
    let mut groups: Vec<&[&str]> = vec![&PERCEPTION_FUNCTIONS, &FINGER_FUNCTIONS];
    if vacuum {
        groups.push(&VACUUM_FUNCTIONS);
    }
    for group in groups {
        lines.push(format!("    {},", group.join(", ")));
    }
    lines.push(")".to_string());
    lines.join("\n")
}

/// The docstring block: perception and finger functions, plus the vacuum ones when
/// `vacuum`.
pub fn docstrings(vacuum: bool) -> String {
    let mut parts = vec![PERCEPTION_DOCS.trim_end(), FINGER_DOCS.trim_end()];
    if vacuum {
        parts.push(VACUUM_DOCS.trim_end());
    }
    parts.join("\n\n")
}
