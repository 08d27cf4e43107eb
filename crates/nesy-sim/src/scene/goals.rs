//! What an episode asks for: the four subtask kinds and one typed goal per subtask, with
//! the goal label the procedure deviation is measured against (`docs/benchmark.md` §2–§3).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The benchmark's four subtask types, and the real-world tasks' subtasks (not part of the
/// 440; see [`SubtaskKind::ALL`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SubtaskKind {
    /// Cubes into the toy box.
    PickPlace,
    /// Chess pieces pushed into the box of their colour.
    Sweep,
    /// Fruits into the hinge box, lid closed.
    PutInHinge,
    /// Cylinders into the bottom drawer, drawer closed.
    PutInPrismatic,
    /// Cubes sorted into the bottom drawers of two cabinets, both drawers closed: the paper's
    /// real-world drawers task (Table 2). Its goals are one `put_in_prismatic` per cabinet.
    SortIntoDrawers,
    /// A magnetic hook, screws and cubes into the bottom drawer, drawer closed: the paper's
    /// real-world hook-and-screws task (Figures 1 and 5). The screws are fine-grained: they
    /// go in on the hook's magnet.
    StowTools,
}

impl SubtaskKind {
    /// The benchmark's four, in the authors' order (the real-world tasks' subtasks are not
    /// among them).
    pub const ALL: [SubtaskKind; 4] = [
        SubtaskKind::PickPlace,
        SubtaskKind::Sweep,
        SubtaskKind::PutInHinge,
        SubtaskKind::PutInPrismatic,
    ];

    /// The real-world tasks' subtasks (the families of `tasks::scenario::Family`).
    pub const REAL_WORLD: [SubtaskKind; 2] = [SubtaskKind::SortIntoDrawers, SubtaskKind::StowTools];

    /// The subtask called `name`, among the benchmark's and the real-world tasks'.
    pub fn from_name(name: &str) -> Option<SubtaskKind> {
        SubtaskKind::ALL
            .into_iter()
            .chain(SubtaskKind::REAL_WORLD)
            .find(|k| k.as_str() == name)
    }

    /// The snake_case name (`pick_place`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            SubtaskKind::PickPlace => "pick_place",
            SubtaskKind::Sweep => "sweep",
            SubtaskKind::PutInHinge => "put_in_hinge",
            SubtaskKind::PutInPrismatic => "put_in_prismatic",
            SubtaskKind::SortIntoDrawers => "sort_into_drawers",
            SubtaskKind::StowTools => "stow_tools",
        }
    }

    /// The subtask's instruction (`docs/benchmark.md` §2, the authors' wording).
    pub fn instruction(self) -> &'static str {
        match self {
            SubtaskKind::PickPlace => "Place the cube blocks in to the box.",
            SubtaskKind::Sweep => "Sweep the chess pieces into their corresponding boxes.",
            SubtaskKind::PutInHinge => "Put the fruits in the hinge box.",
            SubtaskKind::PutInPrismatic => "Place all cylinder blocks in the prismatic drawer.",
            SubtaskKind::SortIntoDrawers => {
                "Sort the cubes into the bottom drawers of the two cabinets and close both drawers."
            }
            SubtaskKind::StowTools => {
                "Put the magnetic hook, the screws and the cubes in the bottom drawer and close it."
            }
        }
    }

    /// True for the subtasks with an articulated container (they take the far offsets).
    pub fn is_articulated(self) -> bool {
        matches!(
            self,
            SubtaskKind::PutInHinge
                | SubtaskKind::PutInPrismatic
                | SubtaskKind::SortIntoDrawers
                | SubtaskKind::StowTools
        )
    }

    /// Object count for a multi level (`docs/benchmark.md` §2: 3/4/5 cubes, 1/2/3 of the
    /// others; 2/3/4 cubes to sort into two drawers).
    pub fn object_count(self, multi_level: u8) -> usize {
        let base = match self {
            SubtaskKind::PickPlace => 3,
            SubtaskKind::SortIntoDrawers => 2,
            _ => 1,
        };
        base + multi_level as usize
    }
}

impl std::fmt::Display for SubtaskKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One subtask's goal. Kept small and typed; the task layer adds checks on top.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "subtask", rename_all = "snake_case", deny_unknown_fields)]
pub enum SubtaskGoal {
    /// Put `objects` into `container` (toy box), in this order.
    PickPlace {
        /// Objects to place, in label order.
        objects: Vec<String>,
        /// The container.
        container: String,
    },
    /// Push each piece into its box.
    Sweep {
        /// `(piece, box)` pairs in label order.
        placements: Vec<Placement>,
    },
    /// Put `objects` into the hinge box, then close `lid`.
    PutInHinge {
        /// Objects, in label order.
        objects: Vec<String>,
        /// The container part (`hinge_body`).
        container: String,
        /// The lid that must end closed (`hinge_lid`).
        lid: String,
    },
    /// Put `objects` into `drawer`, then close it.
    PutInPrismatic {
        /// Objects, in label order.
        objects: Vec<String>,
        /// The drawer (`bottom_drawer`).
        drawer: String,
    },
}

/// One object-to-container assignment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    /// The object.
    pub object: String,
    /// Its container.
    pub container: String,
}

impl SubtaskGoal {
    /// The subtask type.
    pub fn kind(&self) -> SubtaskKind {
        match self {
            SubtaskGoal::PickPlace { .. } => SubtaskKind::PickPlace,
            SubtaskGoal::Sweep { .. } => SubtaskKind::Sweep,
            SubtaskGoal::PutInHinge { .. } => SubtaskKind::PutInHinge,
            SubtaskGoal::PutInPrismatic { .. } => SubtaskKind::PutInPrismatic,
        }
    }

    /// The objects to be placed, in label order.
    pub fn objects(&self) -> Vec<&str> {
        match self {
            SubtaskGoal::PickPlace { objects, .. }
            | SubtaskGoal::PutInHinge { objects, .. }
            | SubtaskGoal::PutInPrismatic { objects, .. } => objects.iter().map(String::as_str).collect(),
            SubtaskGoal::Sweep { placements } => placements.iter().map(|p| p.object.as_str()).collect(),
        }
    }

    /// The name recorded when the articulated container is closed after its objects:
    /// `hinge` for the hinge box, the drawer's name (`bottom_drawer`) for the cabinet.
    pub fn closure_label(&self) -> Option<&str> {
        match self {
            SubtaskGoal::PutInHinge { .. } => Some("hinge"),
            SubtaskGoal::PutInPrismatic { drawer, .. } => Some(drawer),
            _ => None,
        }
    }

    /// The goal label of `docs/benchmark.md` §2: the objects in order, then the closure for the
    /// articulated subtasks.
    pub fn label(&self) -> Vec<String> {
        self.objects()
            .into_iter()
            .chain(self.closure_label())
            .map(str::to_owned)
            .collect()
    }

    /// The goal as ground atoms in the paper's predicates: every object `InsideOf` its
    /// container, and the lid or drawer `Closed` for the articulated subtasks.
    pub fn symbolic_goal(&self) -> Vec<nesy_core::Atom> {
        use nesy_core::Atom;
        let inside = |o: &str, c: &str| Atom::new("InsideOf", &[o, c]);
        match self {
            SubtaskGoal::PickPlace { objects, container } => {
                objects.iter().map(|o| inside(o, container)).collect()
            }
            SubtaskGoal::Sweep { placements } => placements
                .iter()
                .map(|p| inside(&p.object, &p.container))
                .collect(),
            SubtaskGoal::PutInHinge {
                objects,
                container,
                lid,
            } => objects
                .iter()
                .map(|o| inside(o, container))
                .chain([Atom::new("Closed", &[lid])])
                .collect(),
            SubtaskGoal::PutInPrismatic { objects, drawer } => objects
                .iter()
                .map(|o| inside(o, drawer))
                .chain([Atom::new("Closed", &[drawer])])
                .collect(),
        }
    }

    /// Every object name the goal refers to, with the JSON field holding it.
    pub fn referenced_names(&self) -> Vec<(String, &str)> {
        match self {
            SubtaskGoal::PickPlace { objects, container } => objects
                .iter()
                .enumerate()
                .map(|(i, o)| (format!("objects[{i}]"), o.as_str()))
                .chain([("container".to_owned(), container.as_str())])
                .collect(),
            SubtaskGoal::Sweep { placements } => placements
                .iter()
                .enumerate()
                .flat_map(|(i, p)| {
                    [
                        (format!("placements[{i}].object"), p.object.as_str()),
                        (format!("placements[{i}].container"), p.container.as_str()),
                    ]
                })
                .collect(),
            SubtaskGoal::PutInHinge {
                objects,
                container,
                lid,
            } => objects
                .iter()
                .enumerate()
                .map(|(i, o)| (format!("objects[{i}]"), o.as_str()))
                .chain([
                    ("container".to_owned(), container.as_str()),
                    ("lid".to_owned(), lid.as_str()),
                ])
                .collect(),
            SubtaskGoal::PutInPrismatic { objects, drawer } => objects
                .iter()
                .enumerate()
                .map(|(i, o)| (format!("objects[{i}]"), o.as_str()))
                .chain([("drawer".to_owned(), drawer.as_str())])
                .collect(),
        }
    }
}
