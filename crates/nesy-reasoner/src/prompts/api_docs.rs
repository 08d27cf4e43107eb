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

/// Tool-use functions, offered when the scene holds a magnetic hook.
pub const TOOL_FUNCTIONS: [&str; 1] = ["gather_with_hook"];

/// The end-effector functions that exist only on the finger gripper.
pub const FINGER_ONLY_FUNCTIONS: [&str; 4] =
    ["grasp_handle", "release_handle", "open_gripper", "close_gripper"];

/// Docstrings of the perception functions.
pub const PERCEPTION_DOCS: &str = include_str!("../../prompts/api/perception.py");
/// Docstrings of the motion and finger-gripper functions.
pub const FINGER_DOCS: &str = include_str!("../../prompts/api/finger.py");
/// Docstrings of the vacuum functions.
pub const VACUUM_DOCS: &str = include_str!("../../prompts/api/vacuum.py");
/// Docstrings of the tool-use functions.
pub const TOOL_DOCS: &str = include_str!("../../prompts/api/tools.py");

/// The four documentation files with their paths under `prompts/`.
pub const EMBEDDED: [(&str, &str); 4] = [
    ("api/perception.py", PERCEPTION_DOCS),
    ("api/finger.py", FINGER_DOCS),
    ("api/vacuum.py", VACUUM_DOCS),
    ("api/tools.py", TOOL_DOCS),
];

/// Every robot API function name: the 19 of the paper's tables, then the tool-use ones.
pub fn all_functions() -> impl Iterator<Item = &'static str> {
    PERCEPTION_FUNCTIONS
        .into_iter()
        .chain(FINGER_FUNCTIONS)
        .chain(VACUUM_FUNCTIONS)
        .chain(TOOL_FUNCTIONS)
}

/// Which optional groups of the robot API a prompt documents: the vacuum functions (the
/// extended prompt) and the tool-use functions (a scene with a magnetic hook). The paper's
/// perception, motion and finger functions are always there.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ApiOffer {
    /// Document the vacuum tool's functions.
    pub vacuum: bool,
    /// Document the tool-use functions.
    pub tools: bool,
}

/// One group of the robot API: its functions and the docstrings that document them.
struct Group {
    functions: &'static [&'static str],
    docs: &'static str,
}

impl ApiOffer {
    /// The groups offered, in prompt order: the import block and the docstring block both
    /// follow it, so a function is imported exactly when it is documented.
    fn groups(self) -> Vec<Group> {
        let group = |functions: &'static [&'static str], docs| Group { functions, docs };
        let mut groups = vec![
            group(&PERCEPTION_FUNCTIONS, PERCEPTION_DOCS),
            group(&FINGER_FUNCTIONS, FINGER_DOCS),
        ];
        if self.vacuum {
            groups.push(group(&VACUUM_FUNCTIONS, VACUUM_DOCS));
        }
        if self.tools {
            groups.push(group(&TOOL_FUNCTIONS, TOOL_DOCS));
        }
        groups
    }
}

/// The functions a prompt offers, in the order of the import block.
pub fn offered_functions(offer: ApiOffer) -> Vec<&'static str> {
    offer
        .groups()
        .iter()
        .flat_map(|g| g.functions.iter().copied())
        .collect()
}

/// The "already imported" block: numpy, math and the robot functions.
pub fn imports(offer: ApiOffer) -> String {
    let mut lines = vec![
        "import math".to_string(),
        "import numpy as np".to_string(),
        "from robot import (".to_string(),
    ];
    for group in offer.groups() {
        lines.push(format!("    {},", group.functions.join(", ")));
    }
    lines.push(")".to_string());
    lines.join("\n")
}

/// The docstring block: perception and finger functions, plus the groups `offer` adds.
pub fn docstrings(offer: ApiOffer) -> String {
    offer
        .groups()
        .iter()
        .map(|g| g.docs.trim_end())
        .collect::<Vec<_>>()
        .join("\n\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tool_functions_are_offered_only_when_asked_for() {
        let plain = ApiOffer::default();
        let tools = ApiOffer { tools: true, ..plain };
        assert!(!imports(plain).contains("gather_with_hook"));
        assert!(!docstrings(plain).contains("gather_with_hook"));
        assert!(!offered_functions(plain).contains(&"gather_with_hook"));
        assert!(imports(tools).contains("    gather_with_hook,\n)"));
        assert!(docstrings(tools).contains("def gather_with_hook(obj_name):"));
        assert_eq!(offered_functions(tools).last(), Some(&"gather_with_hook"));
        // The paper's functions keep their block and order either way.
        assert!(imports(tools).starts_with(&imports(plain)[..imports(plain).len() - 1]));
    }
}
