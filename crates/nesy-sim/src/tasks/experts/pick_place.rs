//! The `pick_place` expert: cubes into the toy box.

use super::ExpertError;
use super::hand::{Hand, centre, overlaps_xy};
use crate::api::RobotApi;
use crate::tasks::layout::{DROP_CLEARANCE, TOY_BOX_CELLS};

/// Cubes into the box in label order; whatever rests on a cube is moved to the table first,
/// top down.
pub(super) fn run<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    cubes: &[String],
    container: &str,
) -> Result<(), ExpertError> {
    for (k, cube) in cubes.iter().enumerate() {
        loop {
            let me = hand.bbox(cube)?;
            let mut above = Vec::new();
            for other in cubes.iter().filter(|c| *c != cube) {
                let b = hand.bbox(other)?;
                if overlaps_xy(&b, &me, 0.005) && b[0][2] >= me[1][2] - 0.004 {
                    above.push((b[0][2], other.clone()));
                }
            }
            // The highest one first.
            let Some((_, top)) = above.into_iter().max_by(|a, b| a.0.total_cmp(&b.0)) else {
                break;
            };
            hand.move_aside(&top)?;
        }
        let h = hand.pick(cube)?;
        let b = hand.bbox(container)?;
        let c = centre(&b);
        let cell = TOY_BOX_CELLS[k % TOY_BOX_CELLS.len()];
        hand.put(c[0] + cell[0], c[1] + cell[1], b[1][2], h, DROP_CLEARANCE)?;
    }
    Ok(())
}
