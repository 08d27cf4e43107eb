//! The robot's end effector. It lives here, below the simulator and the VLM layer, because
//! both name it (scenes and API calls; prompts and task contexts) and neither depends on the
//! other.

use std::fmt;

use serde::{Deserialize, Serialize};

/// The robot's end effector.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schemars", derive(schemars::JsonSchema))]
#[serde(rename_all = "snake_case")]
pub enum Embodiment {
    /// Franka hand with two prismatic fingers (9 DoF in all).
    Finger,
    /// Suction tool on link 7 (7 DoF in all).
    Vacuum,
}

impl Embodiment {
    /// Lower-case name as used in scene files and prompts: `finger` or `vacuum`.
    pub fn as_str(self) -> &'static str {
        match self {
            Embodiment::Finger => "finger",
            Embodiment::Vacuum => "vacuum",
        }
    }

    /// How prompts name it.
    pub fn description(self) -> &'static str {
        match self {
            Embodiment::Finger => "two-finger gripper",
            Embodiment::Vacuum => "vacuum suction tool",
        }
    }

    /// The nullary predicate that names it in a symbolic state: `FingerGripper` or
    /// `VacuumSuction` (the world domain's schemas are split by end effector on it).
    pub fn state_predicate(self) -> &'static str {
        match self {
            Embodiment::Finger => "FingerGripper",
            Embodiment::Vacuum => "VacuumSuction",
        }
    }

    /// The nullary predicate that holds when it is released, as every goal ends:
    /// `GripperOpen` or `VacuumInactive`.
    pub fn released_predicate(self) -> &'static str {
        match self {
            Embodiment::Finger => "GripperOpen",
            Embodiment::Vacuum => "VacuumInactive",
        }
    }
}

impl fmt::Display for Embodiment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Embodiment {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "finger" | "gripper" => Ok(Embodiment::Finger),
            "vacuum" | "suction" => Ok(Embodiment::Vacuum),
            other => Err(format!("unknown embodiment {other:?}; expected finger or vacuum")),
        }
    }
}
