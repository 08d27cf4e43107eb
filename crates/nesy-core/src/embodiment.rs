//! The robot's end effector. It lives here, below the simulator and the VLM layer, because
//! both name it (scenes and API calls; prompts and task contexts) and neither depends on the
//! other.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize};

/// The robot's end effector.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
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

    /// The unary predicate that holds of the object it holds: `GripperHolding` or
    /// `VacuumAttached`.
    pub fn holding_predicate(self) -> &'static str {
        match self {
            Embodiment::Finger => "GripperHolding",
            Embodiment::Vacuum => "VacuumAttached",
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

/// The names [`Embodiment::as_str`] gives, in declaration order.
const EMBODIMENT_NAMES: [&str; 2] = ["finger", "vacuum"];

// By hand rather than derived: serde's derived unit-enum reader reports a number or a list
// as only "expected value", which names neither the field's kind nor its choices. (The
// example lives here, not on the type, whose doc becomes the JSON schemas' description.)
/// Read from its name; anything else is refused with the two names it could be
/// ("invalid type: integer `5`, expected `finger` or `vacuum`").
///
/// ```
/// use nesy_core::Embodiment;
///
/// let vacuum: Embodiment = serde_json::from_str("\"vacuum\"").unwrap();
/// assert_eq!(vacuum, Embodiment::Vacuum);
/// let err = serde_json::from_str::<Embodiment>("5").unwrap_err().to_string();
/// assert!(err.contains("expected `finger` or `vacuum`"), "{err}");
/// ```
impl<'de> Deserialize<'de> for Embodiment {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Name;
        impl serde::de::Visitor<'_> for Name {
            type Value = Embodiment;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("`finger` or `vacuum`")
            }

            fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<Embodiment, E> {
                match name {
                    "finger" => Ok(Embodiment::Finger),
                    "vacuum" => Ok(Embodiment::Vacuum),
                    other => Err(E::unknown_variant(other, &EMBODIMENT_NAMES)),
                }
            }
        }
        deserializer.deserialize_str(Name)
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
