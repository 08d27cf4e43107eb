//! The `put_in_prismatic` expert: cylinders into the bottom drawer, the top drawer closed
//! and the bottom one opened first if needed, and the bottom drawer closed at the end.

use super::ExpertError;
use super::hand::{Bbox, Hand, centre, overlaps, overlaps_xy, size};
use crate::api::{ApiError, DEFAULT_LIFT_CLEARANCE, Direction, RobotApi};
use crate::domain::split_asset_part;
use crate::scene::parts;
use crate::tasks::layout::{
    BOXES_BESIDE_CABINETS, DRAWER_DROP_CLEARANCE, DRAWER_PULL_FRACTION, DRAWER_RETREAT, DRAWER_SPOTS,
    FOREARM_ABOVE, FOREARM_BELOW, FOREARM_REACH, FOREARM_SWING, WRIST_CLEARANCE,
};

/// How far (m) below the tool point the corridor reaches for a robot without the
/// protective stop: the hand's own half height.
const HAND_BELOW: f64 = 0.03;

/// Moves to the table the loose objects the arm would knock on its way to grasp `handle`
/// pointing along `pointing`. From above, the wrist passes within [`WRIST_CLEARANCE`] of the
/// handle in x and y (over the cabinet's front edge, where a cylinder may stand); pointing
/// sideways, the wrist and forearm trail up to [`FOREARM_REACH`] behind the handle (over the
/// hinge box's lid, where a fruit may lie).
fn clear_handle_approach<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    handle: &str,
    pointing: Direction,
) -> Result<(), ExpertError> {
    let corridor = approach_corridor(hand, handle, pointing)?;
    let names = hand.robot.get_obj_names();
    // An object inside a container lies below its walls, and the approach is chosen so the
    // arm does not pass through a container ([`furniture_in_the_way`]): it stays (a fruit in
    // the closed hinge box was taken back out to clear the way).
    let mut containers = Vec::new();
    for name in &names {
        if CONTAINERS.contains(&bare_name(name)) {
            containers.push(hand.bbox(name)?);
        }
    }
    for name in names {
        if !hand.is_loose(&name) {
            continue;
        }
        let b = hand.bbox(&name)?;
        let m = centre(&b);
        let shielded = containers
            .iter()
            .any(|c| (0..2).all(|i| c[0][i] < m[i] && m[i] < c[1][i]) && b[1][2] <= c[1][2] + 0.005);
        if overlaps(&b, &corridor) && !shielded {
            hand.move_aside(&name)?;
        }
    }
    Ok(())
}

/// The space the arm passes through to grasp `handle` pointing along `pointing` (see
/// [`clear_handle_approach`]).
fn approach_corridor<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    handle: &str,
    pointing: Direction,
) -> Result<Bbox, ExpertError> {
    let h = hand.bbox(handle)?;
    let c = centre(&h);
    let below = if hand.furniture_aware {
        FOREARM_BELOW
    } else {
        HAND_BELOW
    };
    Ok(match pointing {
        Direction::Down => [
            [c[0] - WRIST_CLEARANCE, c[1] - WRIST_CLEARANCE, h[1][2] + 0.02],
            [c[0] + WRIST_CLEARANCE, c[1] + WRIST_CLEARANCE, h[1][2] + 0.4],
        ],
        _ => {
            let back = -pointing.unit()[1] * FOREARM_REACH;
            [
                [c[0] - WRIST_CLEARANCE, c[1].min(c[1] + back), c[2] - below],
                [
                    c[0] + WRIST_CLEARANCE,
                    c[1].max(c[1] + back),
                    c[2] + FOREARM_ABOVE,
                ],
            ]
        }
    })
}

/// Whether grasping `handle` pointing along `pointing` would put the arm through a container
/// standing in the way (the hinge box beside the cabinet's front: the suction tool's wrist,
/// 21.5 cm behind its tip, would be inside it at the grasp).
fn furniture_in_the_way<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    handle: &str,
    pointing: Direction,
) -> Result<bool, ExpertError> {
    let mut corridor = approach_corridor(hand, handle, pointing)?;
    if hand.furniture_aware && pointing != Direction::Down {
        // The elbow swings the forearm out of the tool's line on the way to a sideways grasp.
        corridor[0][0] -= FOREARM_SWING;
        corridor[1][0] += FOREARM_SWING;
    }
    for name in hand.robot.get_obj_names() {
        if BOXES_BESIDE_CABINETS.contains(&bare_name(&name)) && overlaps(&hand.bbox(&name)?, &corridor) {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The containers whose walls shield what lies inside them from a passing arm (bare names;
/// an asset named with a prefix has them under its prefix).
const CONTAINERS: [&str; 6] = [
    parts::HINGE_BODY,
    parts::TOY_BOX,
    parts::TOP_DRAWER,
    parts::BOTTOM_DRAWER,
    parts::LEFT_CHESS_BOX,
    parts::RIGHT_CHESS_BOX,
];

/// A name without the prefix of the asset it belongs to (`front_top_drawer` → `top_drawer`).
fn bare_name(name: &str) -> &str {
    split_asset_part(name).map_or(name, |(_, bare)| bare)
}

/// One cabinet as the expert sees it: its parts' prefix and the way its drawers slide out.
struct Cabinet {
    /// The prefix of its part names (`""` or ending in `_`).
    prefix: String,
    /// The axis its drawers slide along (0: x, 1: y).
    axis: usize,
    /// The sign of the way out along that axis.
    outward: f64,
}

impl Cabinet {
    /// The cabinet whose bottom drawer is `drawer`: drawers open toward the side their
    /// handles are on.
    fn of<R: RobotApi + ?Sized>(hand: &mut Hand<'_, R>, drawer: &str) -> Result<Cabinet, ExpertError> {
        let prefix = drawer
            .strip_suffix(parts::BOTTOM_DRAWER)
            .unwrap_or_default()
            .to_owned();
        let body = centre(&hand.bbox(&format!("{prefix}{}", parts::DRAWER_BODY))?);
        let handle = centre(&hand.bbox(&format!("{prefix}{}", parts::BOTTOM_DRAWER_HANDLE))?);
        let axis = if (handle[1] - body[1]).abs() >= (handle[0] - body[0]).abs() {
            1
        } else {
            0
        };
        let outward = if handle[axis] < body[axis] { -1.0 } else { 1.0 };
        Ok(Cabinet {
            prefix,
            axis,
            outward,
        })
    }

    /// One of its parts, by its bare name.
    fn part(&self, bare: &str) -> String {
        format!("{}{bare}", self.prefix)
    }

    /// The direction that pulls its drawers open, and the one that pushes them shut.
    fn directions(&self) -> (Direction, Direction) {
        match (self.axis, self.outward < 0.0) {
            (1, true) => (Direction::Left, Direction::Right),
            (1, false) => (Direction::Right, Direction::Left),
            (_, true) => (Direction::Back, Direction::Front),
            (_, false) => (Direction::Front, Direction::Back),
        }
    }

    /// Toward the cabinet, the pointing that keeps the hand in front of a handle; only a
    /// cabinet whose drawers slide along y can be reached that way (the tool points down,
    /// left or right).
    fn sideways(&self) -> Option<Direction> {
        (self.axis == 1).then_some(if self.outward < 0.0 {
            Direction::Right
        } else {
            Direction::Left
        })
    }

    /// Whether a drawer with box `b` stands open out of the body with box `body`.
    fn is_open(&self, body: &Bbox, b: &Bbox) -> bool {
        if self.outward < 0.0 {
            b[0][self.axis] < body[0][self.axis] - 0.03
        } else {
            b[1][self.axis] > body[1][self.axis] + 0.03
        }
    }

    /// Whether the drawer `name` stands open.
    fn drawer_open<R: RobotApi + ?Sized>(
        &self,
        hand: &mut Hand<'_, R>,
        name: &str,
    ) -> Result<bool, ExpertError> {
        let body = hand.bbox(&self.part(parts::DRAWER_BODY))?;
        Ok(self.is_open(&body, &hand.bbox(name)?))
    }

    /// How far a drawer is pulled or pushed.
    fn travel<R: RobotApi + ?Sized>(&self, hand: &mut Hand<'_, R>, drawer: &str) -> Result<f64, ExpertError> {
        Ok(size(&hand.bbox(drawer)?)[self.axis] * DRAWER_PULL_FRACTION)
    }

    /// The pointing the bottom handle is grasped with: the fingers from above, as in the
    /// authors' demo; the suction tool pointing at the cabinet, because from above its wrist
    /// (6 cm above the tip and wider than the 2.5 cm between the handle and the cabinet face)
    /// pushed cylinders standing at the cabinet's front edge down through its top. Where a
    /// container stands in the sideways corridor, the suction tool comes from above too,
    /// after the corridor above the handle is cleared.
    fn bottom_pointing<R: RobotApi + ?Sized>(
        &self,
        hand: &mut Hand<'_, R>,
    ) -> Result<Direction, ExpertError> {
        Ok(match self.sideways() {
            Some(sideways)
                if hand.vacuum
                    && !furniture_in_the_way(hand, &self.part(parts::BOTTOM_DRAWER_HANDLE), sideways)? =>
            {
                sideways
            }
            _ => Direction::Down,
        })
    }
}

/// Clears the way to `handle` and grasps it pointing along `pointing`; when a sideways
/// approach is stopped by furniture on the way (the forearm coming down on a box beside the
/// cabinet), grasps it from above instead. Returns the pointing it was grasped with.
fn grab_handle<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    handle: &str,
    pointing: Direction,
) -> Result<Direction, ExpertError> {
    clear_handle_approach(hand, handle, pointing)?;
    match hand.grab_handle_pointing(handle, pointing) {
        Err(e)
            if hand.furniture_aware
                && pointing != Direction::Down
                && matches!(e.error, ApiError::Collision { .. }) =>
        {
            clear_handle_approach(hand, handle, Direction::Down)?;
            hand.grab_handle_pointing(handle, Direction::Down)?;
            Ok(Direction::Down)
        }
        grasped => grasped.map(|()| pointing),
    }
}

/// Makes the cabinet's bottom drawer ready to fill: an open top drawer (which covers the
/// bottom handle) is closed, a closed bottom drawer opened.
fn open_bottom<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    cabinet: &Cabinet,
    drawer: &str,
) -> Result<(), ExpertError> {
    let (open_dir, close_dir) = cabinet.directions();
    let travel = cabinet.travel(hand, drawer)?;
    let top = cabinet.part(parts::TOP_DRAWER);
    let top_handle = cabinet.part(parts::TOP_DRAWER_HANDLE);
    // The open top drawer is closed with the tool pointing at the cabinet: from above, the
    // finger hand, wide along the bar, swept cylinders off the cabinet top on the way in.
    if cabinet.drawer_open(hand, &top)? {
        let pointing = match cabinet.sideways() {
            Some(sideways) if !furniture_in_the_way(hand, &top_handle, sideways)? => sideways,
            _ => Direction::Down,
        };
        let pointing = grab_handle(hand, &top_handle, pointing)?;
        hand.slide_pointing(close_dir, travel, pointing)?;
        hand.let_go_handle()?;
    }
    let pointing = cabinet.bottom_pointing(hand)?;
    if !cabinet.drawer_open(hand, drawer)? {
        let handle = cabinet.part(parts::BOTTOM_DRAWER_HANDLE);
        let pointing = grab_handle(hand, &handle, pointing)?;
        hand.slide_pointing(open_dir, travel, pointing)?;
        hand.let_go_handle()?;
        hand.slide_pointing(Direction::Up, DRAWER_RETREAT, pointing)?;
    }
    Ok(())
}

/// Drops the objects into the open drawer, one spot each; an object something rests on is
/// uncovered first. A magnetic hook is first swept over the fine-grained objects to go in
/// with it, unless they already cling to its magnet (they ride along), and goes in the
/// drawer's middle; the fine-grained objects are not picked themselves.
fn fill<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    cabinet: &Cabinet,
    objects: &[String],
    drawer: &str,
) -> Result<(), ExpertError> {
    // The spots are handed out in turn to the objects dropped at one; the hook goes in the
    // middle and the screws ride on it, so neither takes a spot.
    let mut dropped = 0usize;
    for object in objects {
        if hand.is_fine_grained(object) {
            continue;
        }
        uncover(hand, object)?;
        let h = hand.pick(object)?;
        let hook = hand.is_hook(object);
        if hook {
            let fine: Vec<&String> = objects.iter().filter(|o| hand.is_fine_grained(o)).collect();
            for pieces in fine {
                // A pile already on the magnet rides along without a sweep.
                if hand.clings_to(pieces, object)? {
                    continue;
                }
                hand.robot
                    .gather_with_hook(pieces)
                    .map_err(|e| hand.fail(format!("gather_with_hook({pieces})"), e))?;
            }
        }
        let b = hand.bbox(drawer)?;
        let (c, s) = (centre(&b), size(&b));
        // A spot is an offset across the cabinet and one along the way its drawers open.
        let [across, along] = if hook {
            [0.0, 0.0]
        } else {
            let spot = DRAWER_SPOTS[dropped % DRAWER_SPOTS.len()];
            dropped += 1;
            spot
        };
        let (x, y) = if cabinet.axis == 1 {
            (c[0] + across, c[1] + along * cabinet.outward)
        } else {
            (c[0] + along * cabinet.outward, c[1] + across)
        };
        hand.move_to(
            [x, y, c[2] + s[2] + h + DRAWER_DROP_CLEARANCE],
            DEFAULT_LIFT_CLEARANCE,
        )?;
        hand.release()?;
    }
    Ok(())
}

/// The least height (m) above a hook's underside at which something overlapping it rests on
/// its bar rather than beside it.
const HOOK_BAR_MIN: f64 = 0.005;

/// Moves aside, topmost first, every loose object that rests on `object`.
fn uncover<R: RobotApi + ?Sized>(hand: &mut Hand<'_, R>, object: &str) -> Result<(), ExpertError> {
    loop {
        let me = hand.bbox(object)?;
        let mut above = None;
        for other in hand.robot.get_obj_names() {
            if other == object || !hand.is_loose(&other) {
                continue;
            }
            let b = hand.bbox(&other)?;
            // On the object's top, or (a hook, whose bar is lower than its magnet block)
            // lower down on it, but not beside it on what it stands on.
            let on_top = (b[0][2] - me[1][2]).abs() < 0.01;
            let on_bar = hand.is_hook(object) && b[0][2] > me[0][2] + HOOK_BAR_MIN && b[0][2] < me[1][2];
            let resting = (on_top || on_bar) && overlaps_xy(&b, &me, 0.0);
            if resting {
                above = Some(other);
                break;
            }
        }
        match above {
            Some(top) => {
                uncover(hand, &top)?;
                hand.move_aside(&top)?;
            }
            None => return Ok(()),
        }
    }
}

/// Pushes the cabinet's bottom drawer shut.
fn close_bottom<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    cabinet: &Cabinet,
    drawer: &str,
) -> Result<(), ExpertError> {
    let (_, close_dir) = cabinet.directions();
    let travel = cabinet.travel(hand, drawer)?;
    let pointing = cabinet.bottom_pointing(hand)?;
    let handle = cabinet.part(parts::BOTTOM_DRAWER_HANDLE);
    let pointing = grab_handle(hand, &handle, pointing)?;
    hand.slide_pointing(close_dir, travel, pointing)?;
    hand.let_go_handle()
}

/// Objects into the bottom drawers of one or more cabinets, `(objects, drawer)` per cabinet:
/// for each, an open top drawer (which covers the bottom handle) is closed, a closed bottom
/// drawer opened, the objects dropped in, the drawer closed. Cabinets standing side by side
/// (every bottom drawer sliding out the same way, so none opens into another's way) are loaded
/// the way a person sorts things into them: every drawer opened first, then each one filled,
/// then every one closed.
pub(super) fn run<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    loads: &[(&[String], &str)],
) -> Result<(), ExpertError> {
    let mut cabinets = Vec::with_capacity(loads.len());
    for (_, drawer) in loads {
        cabinets.push(Cabinet::of(hand, drawer)?);
    }
    let loads: Vec<(&Cabinet, &[String], &str)> = cabinets
        .iter()
        .zip(loads)
        .map(|(cabinet, (objects, drawer))| (cabinet, *objects, *drawer))
        .collect();
    if loads.len() > 1 && side_by_side(&cabinets) {
        for (cabinet, _, drawer) in &loads {
            open_bottom(hand, cabinet, drawer)?;
        }
        for (cabinet, objects, drawer) in &loads {
            fill(hand, cabinet, objects, drawer)?;
        }
        for (cabinet, _, drawer) in &loads {
            close_bottom(hand, cabinet, drawer)?;
        }
    } else {
        for (cabinet, objects, drawer) in &loads {
            open_bottom(hand, cabinet, drawer)?;
            fill(hand, cabinet, objects, drawer)?;
            close_bottom(hand, cabinet, drawer)?;
        }
    }
    Ok(())
}

/// Whether the cabinets are distinct and all their bottom drawers slide out the same way.
fn side_by_side(cabinets: &[Cabinet]) -> bool {
    let distinct = cabinets
        .iter()
        .enumerate()
        .all(|(i, c)| cabinets[..i].iter().all(|o| o.prefix != c.prefix));
    distinct
        && cabinets
            .windows(2)
            .all(|w| w[0].axis == w[1].axis && (w[0].outward > 0.0) == (w[1].outward > 0.0))
}
