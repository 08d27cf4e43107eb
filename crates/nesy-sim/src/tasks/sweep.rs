//! `sweep` (`docs/benchmark.md` §2.2): chess pieces in a row on the board between a white (left, −y) and
//! a black (right, +y) box; obstruction puts one piece, or one of each colour, in the
//! wrong box.

use super::{REST_GAP, SubtaskLayout, layout_stream, object, obstruction_stream};
use crate::scene::{ObjectKind, Placement, SubtaskGoal, TABLE_TOP, parts};
use crate::tasks::SubtaskConfig;

/// Distance of each box's centre line from the board's (m).
const BOX_OFFSET: f64 = 0.087;
/// Half the span of piece positions along x (m).
const ROW_HALF: f64 = 0.085;
/// Height of the board and of the boxes' floors (ours: the board mesh is missing; see the
/// crate README).
const BOARD_HEIGHT: f64 = crate::world::objects::CHESS_FLOOR;

const PIECES: [(&str, ObjectKind); 3] = [
    ("rook", ObjectKind::Rook),
    ("knight", ObjectKind::Knight),
    ("bishop", ObjectKind::Bishop),
];

/// A piece: colour and kind.
#[derive(Clone, Copy)]
struct Piece {
    white: bool,
    kind: usize,
}

impl Piece {
    fn name(self) -> String {
        let colour = if self.white { "white" } else { "black" };
        format!("{colour}_{}", PIECES[self.kind].0)
    }

    fn home_box(self) -> &'static str {
        if self.white {
            parts::LEFT_CHESS_BOX
        } else {
            parts::RIGHT_CHESS_BOX
        }
    }
}

pub(crate) fn layout(config: &SubtaskConfig, [ox, oy]: [f64; 2]) -> SubtaskLayout {
    let mut rng = layout_stream(config.kind, config.variant);
    let pool: Vec<Piece> = [true, false]
        .into_iter()
        .flat_map(|white| (0..3).map(move |kind| Piece { white, kind }))
        .collect();
    let n = config.kind.object_count(config.multi_level);
    let pieces: Vec<Piece> = if n == 1 {
        vec![pool[rng.index(pool.len())]]
    } else {
        // One of each colour, then the rest from what is left, then shuffled.
        let white = Piece {
            white: true,
            kind: rng.index(3),
        };
        let black = Piece {
            white: false,
            kind: rng.index(3),
        };
        let rest: Vec<Piece> = pool
            .iter()
            .copied()
            .filter(|p| !(p.white == white.white && p.kind == white.kind))
            .filter(|p| !(p.white == black.white && p.kind == black.kind))
            .collect();
        let mut chosen = vec![white, black];
        chosen.extend(rng.sample_indices(rest.len(), n - 2).into_iter().map(|i| rest[i]));
        rng.shuffle(&mut chosen);
        chosen
    };

    let board_top = TABLE_TOP + BOARD_HEIGHT;
    let box_y = |name: &str| {
        if name == parts::LEFT_CHESS_BOX {
            oy - BOX_OFFSET
        } else {
            oy + BOX_OFFSET
        }
    };
    // Row positions along x and the board's centre line in y.
    let mut places: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let x = ox - ROW_HALF + 2.0 * ROW_HALF * (i as f64 + 0.5) / n as f64;
            [x, oy, board_top]
        })
        .collect();
    let wrong_box = |p: Piece| {
        if p.white {
            parts::RIGHT_CHESS_BOX
        } else {
            parts::LEFT_CHESS_BOX
        }
    };
    let obstruct = |i: usize, places: &mut Vec<[f64; 3]>| {
        places[i] = [
            places[i][0],
            box_y(wrong_box(pieces[i])),
            TABLE_TOP + BOARD_HEIGHT + REST_GAP,
        ];
    };
    let mut orng = obstruction_stream(config.kind, config.variant);
    match config.obst_level {
        0 => {}
        1 => {
            let i = orng.index(n);
            obstruct(i, &mut places);
        }
        _ => {
            for white in [true, false] {
                let of_colour: Vec<usize> = (0..n).filter(|&i| pieces[i].white == white).collect();
                if let Some(&i) = orng.choose(&of_colour) {
                    obstruct(i, &mut places);
                }
            }
        }
    }

    let mut objects = vec![
        object(parts::BOARD, ObjectKind::ChessBoard, ox, oy, TABLE_TOP, 0.0),
        object(
            parts::LEFT_CHESS_BOX,
            ObjectKind::ChessBox,
            ox,
            oy - BOX_OFFSET,
            TABLE_TOP,
            0.0,
        ),
        // Turned so its open side faces the board, like the left one's.
        object(
            parts::RIGHT_CHESS_BOX,
            ObjectKind::ChessBox,
            ox,
            oy + BOX_OFFSET,
            TABLE_TOP,
            std::f64::consts::PI,
        ),
    ];
    for (piece, [x, y, z]) in pieces.iter().zip(&places) {
        objects.push(object(&piece.name(), PIECES[piece.kind].1, *x, *y, *z, 0.0));
    }
    SubtaskLayout {
        objects,
        articulations: Vec::new(),
        goals: vec![SubtaskGoal::Sweep {
            placements: pieces
                .iter()
                .map(|p| Placement {
                    object: p.name(),
                    container: p.home_box().into(),
                })
                .collect(),
        }],
    }
}
