//! The template compiler (`--codegen template`): each verified symbolic action of an
//! adapted procedure, named after a schema of nesy's true domain
//! (`assets/pddl/nesy-world.pddl`), becomes fixed Python calls against the robot API of the
//! target end effector. The result is a complete program of the kind nesy-policy runs.
//!
//! Actions are recognised by name: the CamelCase form of a schema name followed by the
//! CamelCase forms of its arguments, e.g. `MoveToSurroundRedCube` is `move-to-surround`
//! bound to `red_cube` and `CarryIntoBlueCubeToyBox` is `carry-into` bound to
//! `(blue_cube, toy_box)` (the names the reference responder writes). Names joined by `Then`
//! (`GraspRedCubeThenCarryIntoRedCubeToyBox`, a transition that held two steps because no
//! keyframe was chosen between them) compile to each step in order. An action whose name
//! names no schema (a model naming its operators freely) is recognised by its effects and
//! preconditions instead ([`resolve_by_effects`]). A finger schema on the
//! vacuum robot, or the reverse, compiles to the same motion with the other end effector's
//! calls (`close_gripper` ↔ `activate_vacuum`, ...). The placement rules (box cells, drop
//! heights, drawer directions) are those of nesy-sim's scripted experts.

mod effects;

use std::collections::BTreeMap;
use std::fmt::Write as _;

use nesy_core::Operator;
use serde::{Deserialize, Serialize};

use crate::api::Embodiment;
use crate::api::MAX_FINGER_DEPTH;
use crate::domain::{
    Motion, Schema, SchemaInstance, SchemaKind as Kind, asset_of, asset_prefixes, instance_name, kind_of,
    schema_instance, schemas, split_asset_part,
};
use crate::robot::model::{HAND_HALF_LENGTH, HAND_HALF_WIDTH, PALM_ABOVE_TOOL};
use crate::scene::{TABLE_TOP, parts};
use crate::world::{FLOOR_AABB, FURNITURE_TOUCH_DEPTH};
use Motion::*;

// Where objects go and how the lid swings: the scripted experts' constants, shared so the
// compiled policies place objects exactly where the experts do.
use crate::tasks::layout::{
    BOXES_BESIDE_CABINETS, FOREARM_ABOVE, FOREARM_BELOW, FOREARM_REACH, FOREARM_SWING, WRIST_CLEARANCE,
};
use crate::tasks::layout::{
    DRAWER_DROP_CLEARANCE, DRAWER_PULL_FRACTION, DRAWER_RETREAT, DRAWER_SPOTS, DROP_CLEARANCE,
    HINGE_DROP_CLEARANCE, HINGE_SPOTS, LID_CLOSING_ARC, LID_OPENING_ARC, LID_SWING_MAX_X, PUSH_DEPTH_DIVISOR,
    PUSH_OVERSHOOT, TOY_BOX_CELLS,
};

/// How far inside the reachable table area ([`FLOOR_AABB`]) compiled targets are kept (m).
const REACH_MARGIN: f64 = 0.005;

/// The policy's clamp of computed targets into the reachable table area: the API refuses a
/// target outside it, and a spot computed beside a container near the edge (a drop cell, a
/// drawer spot, a lid waypoint) would otherwise end the run.
fn within_reach_helper() -> String {
    let [x0, y0, _] = FLOOR_AABB.min;
    let [x1, y1, _] = FLOOR_AABB.max;
    let m = REACH_MARGIN;
    format!(
        "\ndef within_reach(p):\n    # Targets stay inside the reachable table area, next to where they were computed.\n    return [min(max(p[0], {:.3}), {:.3}), min(max(p[1], {:.3}), {:.3}), p[2]]\n",
        x0 + m,
        x1 - m,
        y0 + m,
        y1 - m
    )
}

/// A `move_to_position` to the computed `target` (a Python list expression), clamped by
/// `within_reach`, with any further keyword arguments in `options` (`, angle=...`).
fn reachable_move(target: &str, options: &str) -> String {
    format!("move_to_position(within_reach({target}){options})")
}

/// A Python helper the finger programs use to pick up round fruit: the wrist turn (rad) at
/// which the open fingers point away from the nearest neighbour that stands above the
/// fruit's bottom. At turn 0 the fingers open along y, so the turn is the direction to the
/// neighbour. Fruits are yaw-free, but `move_gripper_to` turns the fingers to the fruit's
/// own yaw; with fruits in a row 8 cm apart that lands a finger on the next fruit and knocks
/// it away before its own pick.
const CLEAR_ANGLE_HELPER: &str = r#"
def clear_angle(name):
    centre = get_obj_pos(name)
    own = get_obj_bbox(name)
    angle, nearest = 0.0, 1e9
    for other in get_obj_names():
        if other == name or other == "floor" or "gripper" in other:
            continue
        b = get_obj_bbox(other)
        if b[1][2] < own[0][2] + 0.01:
            continue
        dx = min(max(centre[0], b[0][0]), b[1][0]) - centre[0]
        dy = min(max(centre[1], b[0][1]), b[1][1]) - centre[1]
        d = math.hypot(dx, dy)
        if 1e-6 < d < nearest:
            nearest = d
            angle = math.atan2(dy, dx)
    return angle
"#;

/// [`CLEAR_ANGLE_HELPER`] for a robot whose protective stop is on. The hand is 21 cm long
/// along the fingers' travel: when the turn away from the nearest neighbour would put it
/// into something standing higher than its palm by more than a touch (the hinge box, its
/// open lid or a cabinet beside the fruit), where the stop would end the descent, the helper takes the nearest
/// turn, in eighths of a half turn, that keeps it clear. (The helper without the stop is kept as it was, so that the
/// programs of runs made without the stop, and the policy line numbers their errors name,
/// stay the same.)
fn furniture_aware_clear_angle_helper() -> String {
    let steps = (HAND_HALF_LENGTH / HAND_STEP).round() as i32;
    // The helper above with the tall boxes collected on the way and the final turn checked.
    let replace_once = |text: String, from: &str, to: &str| {
        debug_assert_eq!(text.matches(from).count(), 1, "{from}");
        text.replacen(from, to, 1)
    };
    let helper = replace_once(
        CLEAR_ANGLE_HELPER.to_owned(),
        "    angle, nearest = 0.0, 1e9\n",
        &format!(
            "    palm = own[1][2] - min((own[1][2] - own[0][2]) / 2, {MAX_FINGER_DEPTH}) + {PALM_ABOVE_TOOL}\n    angle, nearest, tall = 0.0, 1e9, []\n"
        ),
    );
    let helper = replace_once(
        helper,
        "        b = get_obj_bbox(other)\n",
        &format!(
            "        b = get_obj_bbox(other)\n        if b[1][2] > palm + {FURNITURE_TOUCH_DEPTH}:\n            tall.append(b)\n"
        ),
    );
    let helper = replace_once(
        helper,
        "    return angle\n",
        "    for k in (0, 1, -1, 2, -2, 3, -3, 4):\n        if not hand_meets(centre, angle + k * math.pi / 8, tall):\n            return angle + k * math.pi / 8\n    return angle\n",
    );
    format!(
        r#"{helper}
def hand_meets(centre, turn, boxes):
    # Points {HAND_STEP} m apart along the hand's length, each with the hand's half-width around it.
    ux, uy = -math.sin(turn), math.cos(turn)
    for k in range(-{steps}, {steps} + 1):
        x, y = centre[0] + ux * {HAND_STEP} * k, centre[1] + uy * {HAND_STEP} * k
        for b in boxes:
            if b[0][0] - {HAND_HALF_WIDTH} < x < b[1][0] + {HAND_HALF_WIDTH} and b[0][1] - {HAND_HALF_WIDTH} < y < b[1][1] + {HAND_HALF_WIDTH}:
                return True
    return False
"#
    )
}

/// Spacing (m) of the points along the hand's length that `clear_angle` tests.
const HAND_STEP: f64 = 0.015;

/// One action recognised in a procedure.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ResolvedAction {
    /// The action's name as given (for one step of a joined action, the part naming it).
    pub name: String,
    /// The schema it names: the table's name, or for an asset named with a prefix the
    /// schema's name for that asset (`open-front-top-drawer`, see
    /// [`crate::domain::SchemaInstance`]).
    pub schema: String,
    /// What it does.
    pub motion: Motion,
    /// Its arguments.
    pub args: Vec<String>,
}

/// Why a procedure could not be compiled.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error, Serialize, Deserialize)]
pub enum CodegenError {
    /// An action's name names no schema of the true domain with objects of the scene, and
    /// its effects match none either.
    #[error(
        "action {index} ({name}) names no schema of the nesy world domain with objects of this scene, and its effects match none; expected a schema name followed by its arguments (e.g. MoveToSurroundRedCube) or physical effects in nesy's predicates"
    )]
    UnknownAction {
        /// 1-based position in the procedure.
        index: usize,
        /// Its name.
        name: String,
    },
}

/// The compiled program with the action each part came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompiledPolicy {
    /// The Python program.
    pub code: String,
    /// The recognised actions, in order.
    pub actions: Vec<ResolvedAction>,
    /// The end effector it was compiled for.
    pub embodiment: Embodiment,
}

fn camel(text: &str) -> String {
    text.split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(|w| {
            let mut cs = w.chars();
            cs.next()
                .map(|f| f.to_uppercase().chain(cs).collect::<String>())
                .unwrap_or_default()
        })
        .collect()
}

fn match_args(rest: &str, params: &[Kind], objects: &[String]) -> Option<Vec<String>> {
    let Some((first, more)) = params.split_first() else {
        return rest.is_empty().then(Vec::new);
    };
    // Longest names first, so `RedCube` never shadows `RedCubeTwo`.
    let mut candidates: Vec<&String> = objects
        .iter()
        .filter(|o| kind_of(o).is_some_and(|k| first.accepts(k)))
        .collect();
    candidates.sort_by_key(|o| std::cmp::Reverse(camel(o).len()));
    for o in candidates {
        if let Some(tail) = rest.strip_prefix(camel(o).as_str())
            && let Some(mut args) = match_args(tail, more, objects)
        {
            args.insert(0, o.clone());
            return Some(args);
        }
    }
    None
}

/// Recognises an action name (CamelCase or the semantic words) as a schema and its
/// arguments among `objects`.
pub fn resolve_action(name: &str, objects: &[String]) -> Option<ResolvedAction> {
    let key = camel(name);
    // The table's schemas, and each asset schema under the name it has for every asset of
    // the scene named with a prefix (`OpenFrontTopDrawer`).
    let prefixes = asset_prefixes(objects.iter().map(String::as_str));
    let mut named: Vec<(String, &Schema)> = schemas().iter().map(|s| (s.name.to_owned(), s)).collect();
    for prefix in &prefixes {
        named.extend(
            schemas()
                .iter()
                .filter(|s| asset_of(s.name).is_some())
                .map(|s| (instance_name(s.name, prefix), s)),
        );
    }
    named.sort_by_key(|(n, _)| std::cmp::Reverse(camel(n).len()));
    named.into_iter().find_map(|(schema_name, schema)| {
        let rest = key.strip_prefix(camel(&schema_name).as_str())?;
        let args = match_args(rest, schema.params, objects)?;
        Some(ResolvedAction {
            name: name.to_owned(),
            schema: schema_name,
            motion: schema.motion,
            args,
        })
    })
}

/// Recognises an action name as one schema ([`resolve_action`]) or as several joined by
/// `Then` (`GraspRedCubeThenCarryIntoRedCubeToyBox`: a transition that held two steps, named
/// by both), in order. Each part keeps its own name.
pub fn resolve_steps(name: &str, objects: &[String]) -> Option<Vec<ResolvedAction>> {
    if let Some(action) = resolve_action(name, objects) {
        return Some(vec![action]);
    }
    let key = camel(name);
    key.match_indices("Then").find_map(|(i, joint)| {
        let first = resolve_action(&key[..i], objects)?;
        let mut steps = resolve_steps(&key[i + joint.len()..], objects)?;
        steps.insert(0, first);
        Some(steps)
    })
}

/// Recognises an action by its effects and preconditions (the `effects` module) when its name
/// names no schema: how operators named freely by a model are compiled.
pub fn resolve_by_effects(op: &Operator, objects: &[String]) -> Option<ResolvedAction> {
    let (name, args) = effects::schema_by_effects(op, objects)?;
    let schema = schema_instance(&name)?.schema;
    (schema.params.len() == args.len()).then(|| ResolvedAction {
        name: op.name.clone(),
        schema: name,
        motion: schema.motion,
        args,
    })
}

/// Compiles a verified procedure into a policy program for `embodiment`, on a robot whose
/// protective stop is on or off (`protective_stop`: where the program chooses a wrist turn,
/// it then keeps the hand off tall furniture).
pub fn compile_policy(
    procedure: &[Operator],
    objects: &[String],
    embodiment: Embodiment,
    protective_stop: bool,
) -> Result<CompiledPolicy, CodegenError> {
    let actions: Vec<ResolvedAction> = procedure
        .iter()
        .enumerate()
        .map(|(i, op)| {
            resolve_steps(&op.name, objects)
                .or_else(|| resolve_by_effects(op, objects).map(|a| vec![a]))
                .ok_or_else(|| CodegenError::UnknownAction {
                    index: i + 1,
                    name: op.name.clone(),
                })
        })
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .flatten()
        .collect();
    let code = emit(&actions, objects, embodiment, protective_stop);
    Ok(CompiledPolicy {
        code,
        actions,
        embodiment,
    })
}

struct Emitter<'a> {
    out: String,
    vacuum: bool,
    /// Drops so far per container (for cells and spots).
    drops: BTreeMap<String, usize>,
    /// The tool points sideways (`pointing` in the program) since the last handle approach.
    pointing: bool,
    /// The whole procedure (some actions look at their neighbours).
    actions: &'a [ResolvedAction],
    /// The objects carried over the hinge body (round fruit).
    fruits: Vec<&'a str>,
    /// The robot's protective stop is on: motions keep the hand off furniture.
    protective_stop: bool,
    /// The scene's boxes that may stand beside a cabinet (see [`BOXES_BESIDE_CABINETS`]).
    boxes: Vec<String>,
}

impl Emitter<'_> {
    fn line(&mut self, text: &str) {
        self.out.push_str(text);
        self.out.push('\n');
    }

    /// How far below the tool point a held object's bottom hangs (`h` is a Python
    /// expression for its height): the fingers hold it at mid-height, suction by its top.
    fn hang(&self, h: &str) -> String {
        if self.vacuum {
            h.to_owned()
        } else {
            format!("{h} / 2")
        }
    }

    fn next_drop(&mut self, container: &str) -> usize {
        let n = self.drops.entry(container.to_owned()).or_insert(0);
        *n += 1;
        *n - 1
    }

    fn take(&self) -> &'static str {
        if self.vacuum {
            "activate_vacuum()"
        } else {
            "close_gripper()"
        }
    }

    fn release(&self) -> &'static str {
        if self.vacuum {
            "deactivate_vacuum()"
        } else {
            "open_gripper()"
        }
    }

    fn move_to_handle(&mut self, asset: &SchemaInstance, handle: &str, sideways: bool) {
        if sideways {
            // The suction tool reaches the bottom handle pointing at the cabinet: from above
            // its wrist would sweep cylinders off the cabinet's front edge (as the expert).
            self.line(&format!(
                "pointing = \"right\" if get_obj_pos({:?})[1] < get_obj_pos({:?})[1] else \"left\"",
                asset.asset_part(parts::BOTTOM_DRAWER_HANDLE),
                asset.asset_part(parts::DRAWER_BODY)
            ));
            if self.protective_stop {
                // Pointing sideways, the wrist and forearm trail behind the tool and the elbow
                // swings the forearm out to either side: with a box standing in that lane the
                // tool comes from above (as the expert does), and when the stop still ends the
                // sideways approach, it comes from above then.
                if !self.boxes.is_empty() {
                    self.line(&format!("h = get_obj_bbox({handle:?})"));
                    self.line("c = [(h[0][i] + h[1][i]) / 2 for i in range(3)]");
                    self.line(&format!(
                        "back = -{FOREARM_REACH} if pointing == \"right\" else {FOREARM_REACH}"
                    ));
                    self.line(&format!(
                        "lane = [[c[0] - {lane}, min(c[1], c[1] + back), c[2] - {FOREARM_BELOW}], [c[0] + {lane}, max(c[1], c[1] + back), c[2] + {FOREARM_ABOVE}]]",
                        lane = WRIST_CLEARANCE + FOREARM_SWING
                    ));
                    self.line(&format!("for box in {:?}:", self.boxes));
                    self.line("    b = get_obj_bbox(box)");
                    self.line("    if all(b[0][i] < lane[1][i] and lane[0][i] < b[1][i] for i in range(3)):");
                    self.line("        pointing = \"down\"");
                }
                self.line("try:");
                self.line(&format!("    move_gripper_to({handle:?}, pointing_to=pointing)"));
                self.line("except robot.CollisionError:");
                self.line("    pointing = \"down\"");
                self.line(&format!("    move_gripper_to({handle:?}, pointing_to=pointing)"));
            } else {
                self.line(&format!("move_gripper_to({handle:?}, pointing_to=pointing)"));
            }
            self.pointing = true;
        } else if self.vacuum {
            self.pointing = false;
            self.line(&format!("move_gripper_to({handle:?})"));
        } else {
            self.line(&format!("move_gripper_to({handle:?}, depth=0.0)"));
        }
    }

    /// A move that holds `x` just above the bounding box in the policy variable `bbox`, at
    /// the box's middle y and at `x`'s own x clamped 2.5 cm inside the box (pieces pushed
    /// straight across keep distinct x; a piece knocked off to one side is brought back in).
    fn over_at_own_x(&mut self, x: &str, bbox: &str, hang: &str) {
        self.line(&reachable_move(
            &format!(
                "[min(max(get_obj_pos({x:?})[0], {bbox}[0][0] + 0.025), {bbox}[1][0] - 0.025), ({bbox}[0][1] + {bbox}[1][1]) / 2, {bbox}[1][2] + {hang} + {DROP_CLEARANCE}]"
            ),
            "",
        ));
    }

    fn carry_onto(&mut self, x: &str, surface: &str) {
        let hang = self.hang(&format!("get_obj_size({x:?})[2]"));
        if surface == parts::FLOOR {
            self.line(&format!("spot = get_empty_floor_xy({x:?})"));
            self.line(&reachable_move(
                &format!("[spot[0], spot[1], {TABLE_TOP} + {hang} + {DROP_CLEARANCE}]"),
                "",
            ));
        } else {
            // The piece keeps its own x (the sweep pushes it straight across), but a piece no
            // longer above the board (knocked beside it) is put down on it: clamped into the
            // board's extent, as a carry into a chess box is clamped into the box.
            self.line(&format!("surface = get_obj_bbox({surface:?})"));
            self.over_at_own_x(x, "surface", &hang);
        }
    }

    /// The policy variables `along_y` (the cabinet's drawers slide along y) and `outward`
    /// (the sign of the direction they open in along that axis): drawers slide out toward
    /// the side their handles are on (as the expert decides).
    fn drawer_axis(&mut self, asset: &SchemaInstance) {
        self.line(&format!(
            "handle = get_obj_pos({:?})",
            asset.asset_part(parts::BOTTOM_DRAWER_HANDLE)
        ));
        self.line(&format!(
            "cabinet = get_obj_pos({:?})",
            asset.asset_part(parts::DRAWER_BODY)
        ));
        self.line("along_y = abs(handle[1] - cabinet[1]) >= abs(handle[0] - cabinet[0])");
        self.line("outward = -1.0 if handle[1 if along_y else 0] < cabinet[1 if along_y else 0] else 1.0");
    }

    fn drawer_directions(&mut self, asset: &SchemaInstance) {
        self.drawer_axis(asset);
        self.line("if along_y:");
        self.line("    open_dir = \"left\" if outward < 0 else \"right\"");
        self.line("else:");
        self.line("    open_dir = \"back\" if outward < 0 else \"front\"");
        self.line(
            "close_dir = {\"left\": \"right\", \"right\": \"left\", \"back\": \"front\", \"front\": \"back\"}[open_dir]",
        );
        self.line(&format!(
            "travel = get_obj_size({:?})[1 if along_y else 0] * {DRAWER_PULL_FRACTION}",
            asset.asset_part(parts::BOTTOM_DRAWER)
        ));
    }
}

/// Whether the handle action at `i` is followed, before any other handle is taken, by
/// pulling the bottom drawer open.
fn opens_bottom_drawer(actions: &[ResolvedAction], i: usize) -> bool {
    let asset = instance(&actions[i]);
    let handle = asset.part();
    asset.schema.part == Some(parts::BOTTOM_DRAWER_HANDLE)
        && actions[i + 1..]
            .iter()
            .take_while(|a| a.motion != GraspHandle || instance(a).part() == handle)
            .any(|a| {
                a.motion == OpenDrawer && instance(a).part() == Some(asset.asset_part(parts::BOTTOM_DRAWER))
            })
}

/// The schema instance a resolved action names (resolution only makes names that have one).
fn instance(action: &ResolvedAction) -> SchemaInstance {
    schema_instance(&action.schema).expect("resolved actions name schema instances")
}

fn emit(
    actions: &[ResolvedAction],
    objects: &[String],
    embodiment: Embodiment,
    protective_stop: bool,
) -> String {
    let vacuum = embodiment == Embodiment::Vacuum;
    // The hinge task's fruits (what is carried over the hinge body) are round: the fingers
    // take them at the turn that keeps clear of their neighbours.
    let fruits: Vec<&str> = actions
        .iter()
        .filter(|a| a.motion == CarryOverHinge)
        .filter_map(|a| a.args.first().map(String::as_str))
        .collect();
    let mut e = Emitter {
        out: String::new(),
        vacuum,
        drops: BTreeMap::new(),
        pointing: false,
        actions,
        fruits,
        protective_stop,
        boxes: objects
            .iter()
            .filter(|o| {
                let bare = split_asset_part(o).map_or(o.as_str(), |(_, bare)| bare);
                BOXES_BESIDE_CABINETS.contains(&bare)
            })
            .cloned()
            .collect(),
    };
    let _ = writeln!(
        e.out,
        "# Compiled by nesy's template compiler from {} verified action(s) for the {} robot.",
        actions.len(),
        embodiment
    );
    e.line("import math");
    e.out.push_str(&within_reach_helper());
    if !vacuum && !e.fruits.is_empty() {
        if protective_stop {
            e.out.push_str(&furniture_aware_clear_angle_helper());
        } else {
            e.out.push_str(CLEAR_ANGLE_HELPER);
        }
    }
    for (i, a) in actions.iter().enumerate() {
        let _ = writeln!(e.out, "\n# {}. {}", i + 1, a.name);
        e.action(i, a);
    }
    e.out
}

impl Emitter<'_> {
    /// The calls for action `i` of the procedure.
    fn action(&mut self, i: usize, a: &ResolvedAction) {
        let arg = |k: usize| a.args.get(k).map(String::as_str).unwrap_or_default();
        let asset = instance(a);
        let part = asset.part().unwrap_or_default();
        let part = part.as_str();
        match a.motion {
            MoveToObject => self.move_to_object(i, arg(0)),
            Take => {
                let t = self.take();
                self.line(t);
            }
            Release => self.release_object(i, a),
            CarryOnto => {
                // The following put-down names the surface the object comes to rest on (the
                // carry itself may leave it just above either surface).
                let surface = match self.actions.get(i + 1) {
                    Some(n) if n.schema.ends_with("put-down") && n.args.first() == a.args.first() => {
                        n.args.get(1).map(String::as_str).unwrap_or(arg(1))
                    }
                    _ => arg(1),
                };
                self.carry_onto(arg(0), surface);
            }
            CarryInto => self.carry_into(arg(0), arg(1)),
            CarryOverHinge => self.carry_over_hinge(&asset, arg(0)),
            CarryOverDrawer => self.carry_over_drawer(&asset, arg(0)),
            Gather => self.line(&format!("gather_with_hook({:?})", arg(1))),
            Push => self.push(i, arg(0), arg(1)),
            Retreat => {
                let up = format!("move_parallel(\"up\", {DRAWER_RETREAT}");
                if self.pointing {
                    self.line(&format!("{up}, pointing_to=pointing)"));
                } else {
                    self.line(&format!("{up})"));
                }
            }
            MoveToHandle => {
                let sideways = self.vacuum && opens_bottom_drawer(self.actions, i);
                self.move_to_handle(&asset, part, sideways)
            }
            GraspHandle => self.grasp_handle(i, &asset, part),
            OpenLid | CloseLid => self.swing_lid(i, &asset, a.motion),
            ReleaseHandle => {
                if self.vacuum {
                    self.line("detach_vacuum_handle()");
                } else {
                    self.line("release_handle()");
                }
            }
            OpenDrawer | CloseDrawer => {
                self.drawer_directions(&asset);
                let dir = if a.motion == OpenDrawer {
                    "open_dir"
                } else {
                    "close_dir"
                };
                if self.pointing {
                    self.line(&format!("move_parallel({dir}, travel, pointing_to=pointing)"));
                } else {
                    self.line(&format!("move_parallel({dir}, travel)"));
                }
            }
        }
    }

    fn move_to_object(&mut self, i: usize, x: &str) {
        self.pointing = false;
        if self.vacuum {
            self.line(&format!("move_gripper_to({x:?})"));
            return;
        }
        // Deep enough to push the object when a sweep follows, else mid-height.
        let pushes = self
            .actions
            .get(i + 1)
            .is_some_and(|n| n.motion == Push && n.args.first().map(String::as_str) == Some(x));
        if self.fruits.contains(&x) && !pushes {
            // `move_gripper_to`'s tool point (the top less the depth, capped as the API caps
            // it), with the fingers turned clear of the neighbours.
            self.line(&format!("fb = get_obj_bbox({x:?})"));
            self.line(&reachable_move(
                &format!(
                    "[(fb[0][0] + fb[1][0]) / 2, (fb[0][1] + fb[1][1]) / 2, fb[1][2] - min(get_obj_size({x:?})[2] / 2, {MAX_FINGER_DEPTH})]"
                ),
                &format!(", angle=clear_angle({x:?})"),
            ));
        } else {
            let div = if pushes {
                PUSH_DEPTH_DIVISOR.to_string()
            } else {
                "2".to_owned()
            };
            self.line(&format!(
                "move_gripper_to({x:?}, depth=get_obj_size({x:?})[2] / {div})"
            ));
        }
    }

    fn release_object(&mut self, i: usize, a: &ResolvedAction) {
        // A put-down says where the object comes to rest; without a carry to that surface
        // just before it, the carry is part of it.
        let put_down = a.schema.ends_with("put-down");
        let carried = i > 0
            && self.actions[i - 1].motion == CarryOnto
            && self.actions[i - 1].args.first() == a.args.first();
        if put_down && !carried {
            let (x, surface) = (
                a.args.first().map(String::as_str).unwrap_or_default(),
                a.args.get(1).map(String::as_str).unwrap_or_default(),
            );
            self.carry_onto(x, surface);
        }
        let r = self.release();
        self.line(r);
    }

    fn carry_into(&mut self, x: &str, b: &str) {
        let k = self.next_drop(b);
        let [dx, dy] = if b == parts::TOY_BOX {
            TOY_BOX_CELLS[k % TOY_BOX_CELLS.len()]
        } else {
            [0.0, 0.0]
        };
        let hang = self.hang(&format!("get_obj_size({x:?})[2]"));
        self.line(&format!("box = get_obj_bbox({b:?})"));
        if b == parts::LEFT_CHESS_BOX || b == parts::RIGHT_CHESS_BOX {
            // Every piece into the box's centre would land the second on the first: a piece
            // keeps its own x (distinct per piece, as the sweep pushes them straight across),
            // kept inside the box.
            self.over_at_own_x(x, "box", &hang);
        } else {
            self.line(&reachable_move(
                &format!(
                    "[(box[0][0] + box[1][0]) / 2 + {dx}, (box[0][1] + box[1][1]) / 2 + {dy}, box[1][2] + {hang} + {DROP_CLEARANCE}]"
                ),
                "",
            ));
        }
    }

    fn carry_over_hinge(&mut self, asset: &SchemaInstance, x: &str) {
        let body = asset.asset_part(parts::HINGE_BODY);
        let k = self.next_drop(&body);
        let dy = HINGE_SPOTS[k % HINGE_SPOTS.len()];
        let hang = self.hang(&format!("get_obj_size({x:?})[2]"));
        self.line(&format!("body = get_obj_bbox({body:?})"));
        self.line(&reachable_move(
            &format!(
                "[(body[0][0] + body[1][0]) / 2, (body[0][1] + body[1][1]) / 2 + {dy}, body[1][2] + {hang} + {HINGE_DROP_CLEARANCE}]"
            ),
            "",
        ));
    }

    fn carry_over_drawer(&mut self, asset: &SchemaInstance, x: &str) {
        let drawer = asset.asset_part(parts::BOTTOM_DRAWER);
        // A spot is an offset across the cabinet and one along the way its drawers open. A
        // 10 cm hook fits the drawer only along its middle; the others take the spots.
        let [across, along] = if kind_of(x) == Some(Kind::Tool) {
            [0.0, 0.0]
        } else {
            let k = self.next_drop(&drawer);
            DRAWER_SPOTS[k % DRAWER_SPOTS.len()]
        };
        self.drawer_axis(asset);
        self.line(&format!("drawer = get_obj_pos({drawer:?})"));
        self.line(&reachable_move(
            &format!(
                "[drawer[0] + ({across} if along_y else {along} * outward), drawer[1] + ({along} * outward if along_y else {across}), drawer[2] + get_obj_size({drawer:?})[2] + get_obj_size({x:?})[2] + {DRAWER_DROP_CLEARANCE}]"
            ),
            "",
        ));
    }

    fn push(&mut self, i: usize, x: &str, b: &str) {
        // A push starts low around the piece. After a put-down the fingers are still open
        // around it, but at the carry height and with the piece loose between them: from
        // there the slide leaves it short of its box. Approach it again, as the expert does
        // before every push.
        let approached = i > 0
            && self.actions[i - 1].motion == MoveToObject
            && self.actions[i - 1].args.first().map(String::as_str) == Some(x);
        if !self.vacuum && !approached {
            self.line(&format!(
                "move_gripper_to({x:?}, depth=get_obj_size({x:?})[2] / {PUSH_DEPTH_DIVISOR})"
            ));
        }
        self.line(&format!("piece_y = get_obj_pos({x:?})[1]"));
        self.line(&format!("box_y = get_obj_pos({b:?})[1]"));
        self.line(&format!(
            "move_parallel(\"left\" if piece_y > box_y else \"right\", abs(piece_y - box_y) + {PUSH_OVERSHOOT})"
        ));
    }

    fn grasp_handle(&mut self, i: usize, asset: &SchemaInstance, part: &str) {
        let moved = i > 0
            && self.actions[i - 1].motion == MoveToHandle
            && instance(&self.actions[i - 1]).part().as_deref() == Some(part);
        if !moved {
            let sideways = self.vacuum && opens_bottom_drawer(self.actions, i);
            self.move_to_handle(asset, part, sideways);
        }
        if self.vacuum {
            self.line(&format!("attach_vacuum_handle({part:?})"));
        } else {
            self.line(&format!("grasp_handle({part:?})"));
        }
    }

    fn swing_lid(&mut self, i: usize, asset: &SchemaInstance, motion: Motion) {
        // A demonstration records one action per waypoint of a swing, and a waypoint that has
        // not moved the lid yet may read either way: a run of lid actions is one arc, in the
        // direction of the run's last action.
        let is_swing = |m: Motion| m == OpenLid || m == CloseLid;
        if self.actions.get(i + 1).is_some_and(|n| is_swing(n.motion)) {
            self.line("# (one swing with the next action)");
            return;
        }
        let arc: &[f64] = if motion == OpenLid {
            &LID_OPENING_ARC
        } else {
            &LID_CLOSING_ARC
        };
        self.line(&format!(
            "body = get_obj_bbox({:?})",
            asset.asset_part(parts::HINGE_BODY)
        ));
        self.line(&format!(
            "lid = get_obj_bbox({:?})",
            asset.asset_part(parts::HINGE_LID)
        ));
        self.line("lid_y = (lid[0][1] + lid[1][1]) / 2");
        self.line("reach = max(lid[1][0] - lid[0][0], lid[1][2] - lid[0][2])");
        self.line(&format!("for degrees in {arc:?}:"));
        self.line("    a = math.radians(degrees)");
        self.line(&format!(
            "    x = min(body[1][0] + reach * math.cos(a), {})",
            LID_SWING_MAX_X
        ));
        self.line(&format!(
            "    {}",
            reachable_move(
                "[x, lid_y, body[1][2] + reach * math.sin(a)]",
                ", lift_clearance=0.0, angle=math.pi / 2"
            )
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    fn objects() -> Vec<String> {
        names(&[
            "floor",
            "toy_box",
            "red_cube",
            "red_cube_two",
            "board",
            "left_chess_box",
            "hinge_handle",
        ])
    }

    #[test]
    fn joined_names_resolve_to_their_steps_in_order() {
        let o = objects();
        let steps = resolve_steps("GraspRedCubeThenCarryIntoRedCubeToyBox", &o).unwrap();
        let parts: Vec<(&str, &str, Vec<String>)> = steps
            .iter()
            .map(|a| (a.name.as_str(), a.schema.as_str(), a.args.clone()))
            .collect();
        assert_eq!(
            parts,
            [
                ("GraspRedCube", "grasp", names(&["red_cube"])),
                (
                    "CarryIntoRedCubeToyBox",
                    "carry-into",
                    names(&["red_cube", "toy_box"])
                ),
            ]
        );
        assert_eq!(resolve_steps("MoveToSurroundRedCube", &o).unwrap().len(), 1);
        assert!(resolve_steps("GraspRedCubeThen", &o).is_none());
        assert!(resolve_steps("GraspRedCubeThenFly", &o).is_none());
        let procedure = [Operator::new(
            "grasp red cube then carry into red cube toy box",
            Vec::new(),
            Vec::new(),
        )];
        let policy = compile_policy(&procedure, &o, Embodiment::Finger, false).unwrap();
        let close = policy.code.find("close_gripper()").unwrap();
        let carry = policy.code.find("move_to_position(").unwrap();
        assert!(close < carry, "{}", policy.code);
    }

    #[test]
    fn names_resolve_to_schemas_and_arguments() {
        let o = objects();
        let a = resolve_action("MoveToSurroundRedCube", &o).unwrap();
        assert_eq!(
            (a.schema.as_str(), a.args.clone()),
            ("move-to-surround", vec!["red_cube".to_string()])
        );
        let a = resolve_action("MoveToSurroundRedCubeTwo", &o).unwrap();
        assert_eq!(a.args, vec!["red_cube_two".to_string()]);
        let a = resolve_action("carry into red cube toy box", &o).unwrap();
        assert_eq!((a.schema.as_str(), a.args.len()), ("carry-into", 2));
        let a = resolve_action("GraspHingeHandle", &o).unwrap();
        assert_eq!((a.schema.as_str(), a.motion), ("grasp-hinge-handle", GraspHandle));
        let a = resolve_action("SuctionCarryOntoRedCubeFloor", &o).unwrap();
        assert_eq!(a.motion, CarryOnto);
        assert!(resolve_action("GraspBlueCube", &o).is_none());
        assert!(resolve_action("OpenGripperToDropRedCube", &o).is_none());
    }

    fn ops(names: &[&str]) -> Vec<Operator> {
        names
            .iter()
            .map(|n| Operator::new(*n, Vec::new(), Vec::new()))
            .collect()
    }

    #[test]
    fn fruits_are_taken_with_the_fingers_turned_clear_of_their_neighbours() {
        let o = names(&["floor", "apple", "red_cube", "hinge_body", "hinge_lid"]);
        let procedure = ops(&[
            "MoveToSurroundRedCube",
            "GraspRedCube",
            "PutDownRedCubeFloor",
            "MoveToSurroundApple",
            "GraspApple",
            "CarryOverHingeBodyApple",
            "DropIntoHingeBodyApple",
        ]);
        let finger = compile_policy(&procedure, &o, Embodiment::Finger, false)
            .unwrap()
            .code;
        assert!(finger.contains("def clear_angle(name):"), "{finger}");
        assert!(finger.contains("angle=clear_angle(\"apple\")"), "{finger}");
        assert!(finger.contains("move_gripper_to(\"red_cube\""), "{finger}");
        assert!(!finger.contains("move_gripper_to(\"apple\""), "{finger}");
        let vacuum = compile_policy(&procedure, &o, Embodiment::Vacuum, false)
            .unwrap()
            .code;
        assert!(!vacuum.contains("clear_angle"), "{vacuum}");
    }

    #[test]
    fn with_the_protective_stop_a_sideways_suction_approach_checks_its_lane_and_comes_from_above() {
        let o = names(&[
            "floor",
            "hinge_body",
            "drawer_body",
            "bottom_drawer",
            "bottom_drawer_handle",
        ]);
        let procedure = ops(&[
            "AttachBottomDrawerHandle",
            "SuctionOpenBottomDrawer",
            "DetachBottomDrawerHandle",
        ]);
        let compiled = |stop| {
            compile_policy(&procedure, &o, Embodiment::Vacuum, stop)
                .unwrap()
                .code
        };
        let on = compiled(true);
        assert!(on.contains("for box in [\"hinge_body\"]:"), "{on}");
        assert!(
            on.contains("try:\n    move_gripper_to(\"bottom_drawer_handle\", pointing_to=pointing)\nexcept robot.CollisionError:\n    pointing = \"down\""),
            "{on}"
        );
        let off = compiled(false);
        assert!(!off.contains("for box in") && !off.contains("except"), "{off}");
        assert!(
            off.contains("move_gripper_to(\"bottom_drawer_handle\", pointing_to=pointing)"),
            "{off}"
        );
    }

    #[test]
    fn carried_pieces_keep_their_own_place_along_the_chess_box() {
        let o = names(&[
            "floor",
            "board",
            "white_rook",
            "white_bishop",
            "left_chess_box",
            "toy_box",
            "red_cube",
        ]);
        let procedure = ops(&[
            "MoveToSurroundWhiteRook",
            "GraspWhiteRook",
            "CarryIntoWhiteRookLeftChessBox",
            "MoveToSurroundRedCube",
            "GraspRedCube",
            "CarryIntoRedCubeToyBox",
        ]);
        let code = compile_policy(&procedure, &o, Embodiment::Vacuum, false)
            .unwrap()
            .code;
        // The piece's own x, clamped inside the box (two pieces at the centre would stack);
        // the cube still goes to the toy box's centre.
        assert!(
            code.contains("get_obj_pos(\"white_rook\")[0], box[0][0] + 0.025), box[1][0] - 0.025)"),
            "{code}"
        );
        assert!(!code.contains("get_obj_pos(\"red_cube\")[0]"), "{code}");
    }

    #[test]
    fn a_piece_carried_onto_the_board_is_put_down_within_the_board() {
        let o = names(&["floor", "board", "white_bishop", "left_chess_box"]);
        let procedure = ops(&[
            "MoveToSurroundWhiteBishop",
            "GraspWhiteBishop",
            "CarryOntoWhiteBishopBoard",
            "PutDownWhiteBishopBoard",
            "SweepIntoWhiteBishopLeftChessBox",
        ]);
        for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
            let code = compile_policy(&procedure, &o, embodiment, false).unwrap().code;
            // A piece knocked beside the board (affo_medium_00_s0: x 0.238 beside a board from
            // 0.265) keeps its own x only inside the board's extent.
            assert!(
                code.contains(
                    "move_to_position(within_reach([min(max(get_obj_pos(\"white_bishop\")[0], surface[0][0] + 0.025), surface[1][0] - 0.025), (surface[0][1] + surface[1][1]) / 2"
                ),
                "{code}"
            );
        }
    }

    #[test]
    fn a_push_right_after_a_put_down_approaches_the_piece_first() {
        let o = names(&["floor", "board", "white_rook", "left_chess_box"]);
        let procedure = ops(&[
            "MoveToSurroundWhiteRook",
            "GraspWhiteRook",
            "CarryOntoWhiteRookBoard",
            "PutDownWhiteRookBoard",
            "SweepIntoWhiteRookLeftChessBox",
            "MoveToSurroundWhiteRook",
            "SweepIntoWhiteRookLeftChessBox",
        ]);
        let code = compile_policy(&procedure, &o, Embodiment::Finger, false)
            .unwrap()
            .code;
        let approach = "move_gripper_to(\"white_rook\", depth=get_obj_size(\"white_rook\")[2] / 1.3)";
        // Once inserted after the put-down, once from the procedure's own approach.
        assert_eq!(code.matches(approach).count(), 2, "{code}");
    }

    #[test]
    fn freely_named_operators_are_recognised_by_their_effects() {
        use nesy_core::Atom;
        use nesy_core::{AtomPattern, Effect, Formula};
        let lit = |p: &str, args: &[&str]| AtomPattern::ground(Atom::new(p, args));
        let holds = |p: &str, args: &[&str]| Formula::Atom(lit(p, args));
        let mut o = objects();
        o.push("hinge_lid".into());
        let procedure = vec![
            Operator::new(
                "ReachForTheRedBlock",
                vec![holds("GripperOpen", &[])],
                vec![Effect::Add(lit("GripperSurrounding", &["red_cube"]))],
            ),
            Operator::new(
                "PinchIt",
                vec![holds("GripperSurrounding", &["red_cube"])],
                vec![
                    Effect::Add(lit("GripperHolding", &["red_cube"])),
                    Effect::Add(lit("GripperClosed", &[])),
                    Effect::Del(lit("GripperOpen", &[])),
                ],
            ),
            Operator::new(
                "BringOverTheBin",
                vec![holds("GripperHolding", &["red_cube"])],
                vec![
                    Effect::Del(lit("OnTopOf", &["red_cube", "floor"])),
                    Effect::Add(lit("InsideOf", &["red_cube", "toy_box"])),
                ],
            ),
            Operator::new(
                "LetGo",
                vec![
                    holds("GripperHolding", &["red_cube"]),
                    holds("InsideOf", &["red_cube", "toy_box"]),
                ],
                vec![
                    Effect::Del(lit("GripperHolding", &["red_cube"])),
                    Effect::Add(lit("GripperOpen", &[])),
                ],
            ),
            Operator::new(
                "PullTheLidUp",
                vec![holds("GripperHolding", &["hinge_handle"])],
                vec![
                    Effect::Add(lit("Open", &["hinge_lid"])),
                    Effect::Del(lit("Closed", &["hinge_lid"])),
                ],
            ),
        ];
        let policy = compile_policy(&procedure, &o, Embodiment::Finger, false).unwrap();
        let schemas: Vec<&str> = policy.actions.iter().map(|a| a.schema.as_str()).collect();
        assert_eq!(
            schemas,
            [
                "move-to-surround",
                "grasp",
                "carry-into",
                "release-into",
                "open-hinge-lid"
            ]
        );
        assert_eq!(policy.actions[2].args, ["red_cube", "toy_box"]);
        assert!(
            policy.code.contains("box = get_obj_bbox(\"toy_box\")"),
            "{}",
            policy.code
        );
        // Names that resolve keep the name route; an action without physical effects is
        // still unknown.
        let err = compile_policy(
            &[Operator::new(
                "Wave",
                vec![],
                vec![Effect::Add(lit("GripperOpen", &[]))],
            )],
            &o,
            Embodiment::Finger,
            false,
        )
        .unwrap_err();
        assert!(err.to_string().contains("action 1 (Wave)"), "{err}");
    }

    #[test]
    fn the_same_procedure_compiles_for_either_end_effector() {
        let o = objects();
        let ops: Vec<Operator> = [
            "MoveToSurroundRedCube",
            "GraspRedCube",
            "CarryIntoRedCubeToyBox",
            "ReleaseIntoRedCubeToyBox",
        ]
        .iter()
        .map(|n| Operator::new(*n, Vec::new(), Vec::new()))
        .collect();
        let finger = compile_policy(&ops, &o, Embodiment::Finger, false).unwrap();
        assert!(finger.code.contains("close_gripper()") && finger.code.contains("open_gripper()"));
        assert!(
            finger.code.contains("depth=get_obj_size(\"red_cube\")[2] / 2"),
            "{}",
            finger.code
        );
        let vacuum = compile_policy(&ops, &o, Embodiment::Vacuum, false).unwrap();
        assert!(vacuum.code.contains("activate_vacuum()") && !vacuum.code.contains("close_gripper"));
        let err = compile_policy(
            &[Operator::new("Dance", vec![], vec![])],
            &o,
            Embodiment::Finger,
            false,
        )
        .unwrap_err();
        assert!(err.to_string().contains("action 1 (Dance)"), "{err}");
    }

    #[test]
    fn every_computed_target_is_kept_within_reach() {
        let o = names(&[
            "floor",
            "toy_box",
            "red_cube",
            "apple",
            "green_cylinder",
            "board",
            "white_rook",
            "left_chess_box",
            "hinge_body",
            "hinge_lid",
            "hinge_handle",
            "drawer_body",
            "bottom_drawer",
            "bottom_drawer_handle",
        ]);
        let procedure = ops(&[
            "MoveToSurroundRedCube",
            "GraspRedCube",
            "CarryIntoRedCubeToyBox",
            "ReleaseIntoRedCubeToyBox",
            "MoveToSurroundWhiteRook",
            "GraspWhiteRook",
            "CarryOntoWhiteRookBoard",
            "PutDownWhiteRookBoard",
            "GraspHingeHandle",
            "OpenHingeLid",
            "ReleaseHingeHandle",
            "MoveToSurroundApple",
            "GraspApple",
            "CarryOverHingeBodyApple",
            "DropIntoHingeBodyApple",
            "GraspBottomDrawerHandle",
            "OpenBottomDrawer",
            "ReleaseBottomDrawerHandle",
            "MoveToSurroundGreenCylinder",
            "GraspGreenCylinder",
            "CarryOverBottomDrawerGreenCylinder",
            "DropIntoBottomDrawerGreenCylinder",
            "MoveToSurroundRedCube",
            "GraspRedCube",
            "PutDownRedCubeFloor",
        ]);
        for embodiment in [Embodiment::Finger, Embodiment::Vacuum] {
            let code = compile_policy(&procedure, &o, embodiment, false).unwrap().code;
            let calls = code.matches("move_to_position(").count();
            assert!(calls >= 6, "{code}");
            assert_eq!(
                code.matches("move_to_position(within_reach(").count(),
                calls,
                "every target the compiler computes is clamped:\n{code}"
            );
            // The clamp is the API's own workspace, shrunk by the margin.
            let bound = format!(
                "min(max(p[0], {:.3}), {:.3})",
                FLOOR_AABB.min[0] + REACH_MARGIN,
                FLOOR_AABB.max[0] - REACH_MARGIN
            );
            assert!(code.contains(&bound), "{code}");
        }
    }
}
