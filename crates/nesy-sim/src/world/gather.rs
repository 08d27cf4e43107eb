//! `gather_with_hook`: the held magnetic hook swept low over the pieces of a fine-grained
//! object. The call only moves the arm; the gathering itself is the magnet's pull
//! ([`crate::world::magnet`]) acting on the pieces the magnet passes within reach of, so a
//! piece the sweep cannot reach stays where it is.

use nalgebra::Vector3;

use super::Sim;
use super::geometry::array_to_na;
use crate::api::{ApiError, DEFAULT_LIFT_CLEARANCE, Direction};
use crate::robot::motion::{MOTION_SETTLE_STEPS, ToolGoal};
use crate::scene::ObjectKind;

/// The API name of the call, as traces and errors spell it.
const CALL: &str = "gather_with_hook";
/// Gap (m) between the tallest piece's top and the hook's underside during the sweep: low
/// enough for the magnet to reach pieces lying on the table, high enough not to plough
/// through them.
const SWEEP_GAP: f64 = 0.004;
/// A piece this close (m) to the magnet's centre already clings to it and is not visited.
const CLINGING: f64 = 0.02;

impl Sim {
    /// The motion of `gather_with_hook(obj_name)` (no trace entry): with a magnetic hook
    /// held, lift, move above the nearest piece, lower the hook until its underside is
    /// [`SWEEP_GAP`] above the pieces, pass the magnet over every piece (nearest first) and
    /// lift again by the default clearance.
    pub(crate) fn do_gather_with_hook(&mut self, obj_name: &str) -> Result<(), ApiError> {
        let pieces = self.pieces_of(obj_name);
        if pieces.is_empty() {
            self.aabb_or_unknown(obj_name)?;
            let reason = "it is one rigid object, not small pieces; grasp it instead";
            return Err(self.refusal(obj_name, reason.into()));
        }
        let Some(held) = self.held.map(|h| h.part) else {
            return Err(self.refusal(obj_name, "nothing is held; grasp a magnetic hook first".into()));
        };
        if self.parts[held].kind != ObjectKind::MagneticHook {
            let reason = format!(
                "the held {} is not a magnetic hook; put it down and grasp one",
                self.perceived_name(held)
            );
            return Err(self.refusal(obj_name, reason));
        }
        let Some(magnet) = self.magnet_of(held) else {
            return Err(self.refusal(obj_name, "the held hook has no magnet".into()));
        };
        let tool = self.tool_pose();
        let hook_bottom = self.part_aabb(held).min[2];
        // Under a pure translation the magnet keeps its offset from the tool point.
        let to_magnet = magnet - tool.translation.vector;
        let magnet_above_bottom = magnet.z - hook_bottom;
        let positions: Vec<Vector3<f64>> = pieces
            .iter()
            .map(|&p| self.part_pose(p).translation.vector)
            .filter(|p| (p - magnet).norm() > CLINGING)
            .collect();
        let pieces_top = pieces
            .iter()
            .map(|&p| self.part_aabb(p).max[2])
            .fold(f64::MIN, f64::max);
        let magnet_z = pieces_top + SWEEP_GAP + magnet_above_bottom;
        let tool_at = |xy: &Vector3<f64>, z: f64| Vector3::new(xy.x, xy.y, z) - to_magnet;
        let order = nearest_first(magnet, positions);
        let Some(first) = order.first() else {
            // Every piece already clings to the magnet: nothing to sweep.
            return Ok(());
        };
        let up = Vector3::z() * DEFAULT_LIFT_CLEARANCE;
        let mut waypoints = Vec::new();
        let rotation = tool.rotation;
        let goal = |position: Vector3<f64>| ToolGoal { position, rotation };
        if self.moved_since_reset {
            let lift = self.reachable_lift(
                tool.translation.vector,
                -Vector3::z(),
                &rotation,
                DEFAULT_LIFT_CLEARANCE,
            );
            waypoints.push(goal(tool.translation.vector + Vector3::z() * lift));
        }
        let transit = waypoints.len();
        waypoints.push(goal(tool_at(first, magnet_z) + up));
        waypoints.extend(order.iter().map(|p| goal(tool_at(p, magnet_z))));
        let last = waypoints
            .last()
            .map(|w| w.position)
            .unwrap_or(tool.translation.vector);
        waypoints.push(goal(last + up));
        for w in &waypoints {
            self.check_workspace([w.position.x, w.position.y, w.position.z])?;
        }
        let plan = self.plan(&waypoints, Direction::Down, Some(transit))?;
        let executed = self.execute(&plan, MOTION_SETTLE_STEPS);
        self.moved_since_reset = true;
        executed.map_err(|stop| stop.into_error(self, CALL))
    }

    fn refusal(&self, obj_name: &str, reason: String) -> ApiError {
        ApiError::Infeasible {
            call: CALL.into(),
            target: obj_name.into(),
            reason,
        }
    }

    /// The world position of the magnet of the hook that is part `hook`.
    fn magnet_of(&self, hook: usize) -> Option<Vector3<f64>> {
        self.magnets()
            .into_iter()
            .find(|(part, _)| *part == hook)
            .map(|(_, centre)| array_to_na(centre))
    }
}

/// The points in a greedy nearest-neighbour order from `start`: a short sweep that passes
/// each piece once.
fn nearest_first(start: Vector3<f64>, mut rest: Vec<Vector3<f64>>) -> Vec<Vector3<f64>> {
    let mut order = Vec::with_capacity(rest.len());
    let mut at = start;
    while !rest.is_empty() {
        let xy = |p: &Vector3<f64>| (p.x - at.x).hypot(p.y - at.y);
        let next = (0..rest.len())
            .min_by(|&a, &b| xy(&rest[a]).total_cmp(&xy(&rest[b])))
            .unwrap_or(0);
        at = rest.swap_remove(next);
        order.push(at);
    }
    order
}
