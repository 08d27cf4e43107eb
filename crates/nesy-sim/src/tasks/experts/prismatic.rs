//! The `put_in_prismatic` expert: cylinders into the bottom drawer, the top drawer closed
//! and the bottom one opened first if needed, and the bottom drawer closed at the end.

use super::ExpertError;
use super::hand::{Bbox, Hand, centre, overlaps, size};
use crate::api::{DEFAULT_LIFT_CLEARANCE, Direction, RobotApi};
use crate::scene::parts;
use crate::tasks::layout::{DRAWER_DROP_CLEARANCE, DRAWER_PULL_FRACTION, DRAWER_RETREAT, DRAWER_SPOTS};

/// Reach (m) of the finger hand's wrist around the tool point when it grasps a drawer
/// handle from above.
const WRIST_CLEARANCE: f64 = 0.07;
/// How far (m) the wrist and forearm trail behind the tool point when the hand grasps a
/// handle pointing sideways.
const FOREARM_REACH: f64 = 0.3;

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
        if CONTAINERS.contains(&name.as_str()) {
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
    Ok(match pointing {
        Direction::Down => [
            [c[0] - WRIST_CLEARANCE, c[1] - WRIST_CLEARANCE, h[1][2] + 0.02],
            [c[0] + WRIST_CLEARANCE, c[1] + WRIST_CLEARANCE, h[1][2] + 0.4],
        ],
        _ => {
            let back = -pointing.unit()[1] * FOREARM_REACH;
            [
                [c[0] - WRIST_CLEARANCE, c[1].min(c[1] + back), c[2] - 0.03],
                [c[0] + WRIST_CLEARANCE, c[1].max(c[1] + back), c[2] + 0.3],
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
    let corridor = approach_corridor(hand, handle, pointing)?;
    for name in hand.robot.get_obj_names() {
        let drawer = name == parts::TOP_DRAWER || name == parts::BOTTOM_DRAWER;
        if CONTAINERS.contains(&name.as_str()) && !drawer && overlaps(&hand.bbox(&name)?, &corridor) {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The containers whose walls shield what lies inside them from a passing arm.
const CONTAINERS: [&str; 6] = [
    parts::HINGE_BODY,
    parts::TOY_BOX,
    parts::TOP_DRAWER,
    parts::BOTTOM_DRAWER,
    parts::LEFT_CHESS_BOX,
    parts::RIGHT_CHESS_BOX,
];

/// Cylinders into the bottom drawer: an open top drawer (which covers the bottom handle) is
/// closed, a closed bottom drawer opened, the cylinders dropped in, the drawer closed.
pub(super) fn run<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    cylinders: &[String],
    drawer: &str,
) -> Result<(), ExpertError> {
    let body = hand.bbox(parts::DRAWER_BODY)?;
    let body_y = centre(&body)[1];
    let handle_y = centre(&hand.bbox(parts::BOTTOM_DRAWER_HANDLE)?)[1];
    // Drawers open toward the side their handles are on.
    let (open_dir, close_dir, outward) = if handle_y < body_y {
        (Direction::Left, Direction::Right, -1.0)
    } else {
        (Direction::Right, Direction::Left, 1.0)
    };
    let is_open = |b: &Bbox| {
        if outward < 0.0 {
            b[0][1] < body[0][1] - 0.03
        } else {
            b[1][1] > body[1][1] + 0.03
        }
    };
    let travel = size(&hand.bbox(drawer)?)[1] * DRAWER_PULL_FRACTION;
    // Toward the cabinet: the pointing that keeps the hand in front of the handle.
    let sideways = if outward < 0.0 {
        Direction::Right
    } else {
        Direction::Left
    };
    // The open top drawer is closed with the tool pointing at the cabinet: from above, the
    // finger hand, wide along the bar, swept cylinders off the cabinet top on the way in.
    if is_open(&hand.bbox(parts::TOP_DRAWER)?) {
        let pointing = if furniture_in_the_way(hand, parts::TOP_DRAWER_HANDLE, sideways)? {
            Direction::Down
        } else {
            sideways
        };
        clear_handle_approach(hand, parts::TOP_DRAWER_HANDLE, pointing)?;
        hand.grab_handle_pointing(parts::TOP_DRAWER_HANDLE, pointing)?;
        hand.slide_pointing(close_dir, travel, pointing)?;
        hand.let_go_handle()?;
    }
    // The bottom handle: the fingers from above, as in the authors' demo; the suction tool
    // pointing at the cabinet, because from above its wrist (6 cm above the tip and wider
    // than the 2.5 cm between the handle and the cabinet face) pushed cylinders standing at
    // the cabinet's front edge down through its top.
    // Where a container stands in the sideways corridor, the suction tool comes from above
    // too, after the corridor above the handle is cleared.
    let pointing = if hand.vacuum && !furniture_in_the_way(hand, parts::BOTTOM_DRAWER_HANDLE, sideways)? {
        sideways
    } else {
        Direction::Down
    };
    if !is_open(&hand.bbox(drawer)?) {
        clear_handle_approach(hand, parts::BOTTOM_DRAWER_HANDLE, pointing)?;
        hand.grab_handle_pointing(parts::BOTTOM_DRAWER_HANDLE, pointing)?;
        hand.slide_pointing(open_dir, travel, pointing)?;
        hand.let_go_handle()?;
        hand.slide_pointing(Direction::Up, DRAWER_RETREAT, pointing)?;
    }
    for (k, cylinder) in cylinders.iter().enumerate() {
        let h = hand.pick(cylinder)?;
        let b = hand.bbox(drawer)?;
        let (c, s) = (centre(&b), size(&b));
        let [dx, dy] = DRAWER_SPOTS[k % DRAWER_SPOTS.len()];
        let x = c[0] + dx;
        let y = c[1] + dy * outward;
        hand.move_to(
            [x, y, c[2] + s[2] + h + DRAWER_DROP_CLEARANCE],
            DEFAULT_LIFT_CLEARANCE,
        )?;
        hand.release()?;
    }
    clear_handle_approach(hand, parts::BOTTOM_DRAWER_HANDLE, pointing)?;
    hand.grab_handle_pointing(parts::BOTTOM_DRAWER_HANDLE, pointing)?;
    hand.slide_pointing(close_dir, travel, pointing)?;
    hand.let_go_handle()
}
