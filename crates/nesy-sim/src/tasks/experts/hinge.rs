//! The `put_in_hinge` expert: fruits into the hinge box, the lid opened first if it is
//! closed and closed at the end.

use super::ExpertError;
use super::hand::{Hand, centre, overlaps_xy, size};
use crate::api::RobotApi;
use crate::scene::parts;
use crate::tasks::layout::{
    HINGE_DROP_CLEARANCE, HINGE_SPOTS, LID_CLOSING_ARC, LID_OPENING_ARC, hinge_drop_spot,
};
use crate::world::objects::HINGE_BOX_WALL;

/// Swings of the lid tried before the expert carries on regardless.
const SWING_ATTEMPTS: usize = 3;

/// Fruits into the hinge box: a fruit on the lid is moved to the table, a closed lid is
/// opened by its handle, the fruits are dropped in along the box, the lid is closed.
pub(super) fn run<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    fruits: &[String],
    body: &str,
    lid: &str,
) -> Result<(), ExpertError> {
    let lid_box = hand.bbox(lid)?;
    for fruit in fruits {
        let b = hand.bbox(fruit)?;
        if overlaps_xy(&b, &lid_box, 0.0) && (b[0][2] - lid_box[1][2]).abs() < 0.01 {
            hand.move_aside(fruit)?;
        }
    }
    // The hinge runs along y at the body's +x top edge (the box is never turned).
    let b = hand.bbox(body)?;
    let axis = [b[1][0], b[1][2]];
    let y = centre(&lid_box)[1];
    let reach = size(&lid_box)[0].max(size(&lid_box)[2]);
    // A closed lid lies flat (1 cm thick); an open one stands up.
    if size(&lid_box)[2] < 0.05 {
        swing_until(hand, lid, axis, y, reach, &LID_OPENING_ARC, true)?;
    }
    for (k, fruit) in fruits.iter().enumerate() {
        let b = hand.bbox(body)?;
        let c = centre(&b);
        let spot = drop_spot(
            hand,
            fruit,
            &fruits[k + 1..],
            &b,
            [c[0], c[1] + HINGE_SPOTS[k % HINGE_SPOTS.len()]],
        )?;
        let h = hand.pick_round(fruit)?;
        hand.put(spot[0], spot[1], b[1][2], h, HINGE_DROP_CLEARANCE)?;
    }
    swing_until(hand, lid, axis, y, reach, &LID_CLOSING_ARC, false)
}

/// Where to drop `fruit` into the hinge box (its box `b`): [`hinge_drop_spot`] from
/// `nominal`, given the loose objects lying in the box now and the fruits still to come.
fn drop_spot<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    fruit: &str,
    upcoming: &[String],
    b: &[[f64; 3]; 2],
    nominal: [f64; 2],
) -> Result<[f64; 2], ExpertError> {
    let wall = f64::from(HINGE_BOX_WALL);
    let inside = [[b[0][0] + wall, b[0][1] + wall], [b[1][0] - wall, b[1][1] - wall]];
    let footprint = |o: &[[f64; 3]; 2]| {
        let (c, s) = (centre(o), size(o));
        ([c[0], c[1]], s[0].max(s[1]) / 2.0)
    };
    let mut placed = Vec::new();
    for other in hand.robot.get_obj_names() {
        if other == fruit || !hand.is_loose(&other) {
            continue;
        }
        let o = hand.bbox(&other)?;
        let (c, r) = footprint(&o);
        let in_box = (inside[0][0]..=inside[1][0]).contains(&c[0])
            && (inside[0][1]..=inside[1][1]).contains(&c[1])
            && o[0][2] < b[1][2];
        if in_box {
            placed.push((c, r));
        }
    }
    let (_, radius) = footprint(&hand.bbox(fruit)?);
    let mut to_come = Vec::with_capacity(upcoming.len());
    for next in upcoming {
        to_come.push(footprint(&hand.bbox(next)?).1);
    }
    Ok(hinge_drop_spot(inside, radius, &placed, &to_come, nominal))
}

/// Swings the lid through `arc` by its handle until it is open (`open`) or closed, up to
/// [`SWING_ATTEMPTS`] times. A waypoint the arm cannot reach along a straight line falls back
/// to joint interpolation, on which the tool strays from the arc and the grasped lid follows
/// it back (a closing swing at the +y far slot left the lid at q = 0.29); the next swing
/// starts from another arm pose and lid angle.
fn swing_until<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    lid: &str,
    axis: [f64; 2],
    y: f64,
    reach: f64,
    arc: &[f64],
    open: bool,
) -> Result<(), ExpertError> {
    for _ in 0..SWING_ATTEMPTS {
        hand.grab_handle(parts::HINGE_HANDLE)?;
        hand.swing_lid(axis, y, reach, arc)?;
        hand.let_go_handle()?;
        // The closed lid lies flat (1 cm); the open one stands about 11 cm tall (10 cm
        // is q ≈ 0.32, the observer's Open).
        let height = size(&hand.bbox(lid)?)[2];
        if (open && height > 0.1) || (!open && height < 0.03) {
            break;
        }
    }
    Ok(())
}
