//! The `sweep` expert: chess pieces pushed (finger) or carried (suction) into their boxes.

use super::ExpertError;
use super::hand::{Hand, centre, size};
use crate::api::{Direction, RobotApi};
use crate::scene::parts;
use crate::tasks::layout::{DROP_CLEARANCE, PUSH_DEPTH_DIVISOR, PUSH_OVERSHOOT};

/// Pieces pushed (finger) or carried (suction) across into their boxes; a piece found in a
/// box is first lifted back onto the board at its x.
pub(super) fn run<R: RobotApi + ?Sized>(
    hand: &mut Hand<'_, R>,
    pieces: &[(&str, &str)],
) -> Result<(), ExpertError> {
    let board = hand.bbox(parts::BOARD)?;
    let board_y = centre(&board)[1];
    for &(piece, home) in pieces {
        let b = hand.bbox(piece)?;
        // By the piece's centre: a box's floor lies only 3 mm below the board's top, and a
        // piece in a box whose bounding box grazed the board's edge passed for one on the
        // board; pushed from the box, it caught the step and toppled.
        let c = centre(&b);
        let on_board =
            b[0][2] >= board[1][2] - 0.005 && (0..2).all(|i| (board[0][i]..=board[1][i]).contains(&c[i]));
        if !on_board {
            let h = hand.pick(piece)?;
            let x = centre(&b)[0];
            hand.put(x, board_y, board[1][2], h, DROP_CLEARANCE)?;
        }
        let h = size(&hand.bbox(piece)?)[2];
        hand.move_to_object(piece, h / PUSH_DEPTH_DIVISOR)?;
        if hand.vacuum {
            hand.grasp()?;
        }
        let py = centre(&hand.bbox(piece)?)[1];
        let by = centre(&hand.bbox(home)?)[1];
        let dir = if py > by {
            Direction::Left
        } else {
            Direction::Right
        };
        hand.slide(dir, (py - by).abs() + PUSH_OVERSHOOT)?;
        if hand.vacuum {
            hand.release()?;
        }
    }
    Ok(())
}
