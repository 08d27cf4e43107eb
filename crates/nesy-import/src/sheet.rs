//! The contact sheet: the chosen keyframes side by side, each captioned with its number and
//! time, so a person can check the choice at a glance.

use nesy_sim::perception::render::{Image, draw_label};

/// Width of one keyframe's picture on the sheet, in pixels.
pub const CELL_WIDTH: u32 = 240;
/// Keyframes per row.
pub const COLUMNS: usize = 4;
/// Height of the caption strip under each picture.
const CAPTION: u32 = 18;
/// Gap between cells.
const GAP: u32 = 6;

/// One picture per keyframe (all scaled to [`CELL_WIDTH`], the first one's aspect ratio),
/// [`COLUMNS`] per row, each over its caption.
pub fn contact_sheet(cells: &[(Image, String)]) -> Image {
    let Some((first, _)) = cells.first() else {
        return Image {
            width: 1,
            height: 1,
            rgb: vec![0; 3],
        };
    };
    let cell_height =
        ((u64::from(first.height) * u64::from(CELL_WIDTH)) / u64::from(first.width.max(1))).max(1) as u32;
    let columns = cells.len().min(COLUMNS) as u32;
    let rows = cells.len().div_ceil(COLUMNS) as u32;
    let width = columns * (CELL_WIDTH + GAP) + GAP;
    let height = rows * (cell_height + CAPTION + GAP) + GAP;
    let mut sheet = Image {
        width,
        height,
        rgb: [40u8, 40, 40].repeat((width * height) as usize),
    };
    for (i, (picture, caption)) in cells.iter().enumerate() {
        let (col, row) = ((i % COLUMNS) as u32, (i / COLUMNS) as u32);
        let (x0, y0) = (
            GAP + col * (CELL_WIDTH + GAP),
            GAP + row * (cell_height + CAPTION + GAP),
        );
        for y in 0..cell_height {
            let sy = (u64::from(y) * u64::from(picture.height) / u64::from(cell_height)) as u32;
            for x in 0..CELL_WIDTH {
                let sx = (u64::from(x) * u64::from(picture.width) / u64::from(CELL_WIDTH)) as u32;
                let from = ((sy * picture.width + sx) * 3) as usize;
                let to = (((y0 + y) * width + x0 + x) * 3) as usize;
                if let Some(pixel) = picture.rgb.get(from..from + 3) {
                    sheet.rgb[to..to + 3].copy_from_slice(pixel);
                }
            }
        }
        draw_label(
            &mut sheet,
            caption,
            i64::from(x0 + CELL_WIDTH / 2),
            i64::from(y0 + cell_height + CAPTION / 2),
        );
    }
    sheet
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn six_keyframes_make_two_rows() {
        let picture = Image {
            width: 120,
            height: 60,
            rgb: vec![200; 120 * 60 * 3],
        };
        let cells: Vec<(Image, String)> = (0..6)
            .map(|k| (picture.clone(), format!("#{k} {k}.0 s")))
            .collect();
        let sheet = contact_sheet(&cells);
        assert_eq!(sheet.width, 4 * (CELL_WIDTH + GAP) + GAP);
        assert_eq!(sheet.height, 2 * (120 + CAPTION + GAP) + GAP);
        let pixel = |x: u32, y: u32| sheet.rgb[((y * sheet.width + x) * 3) as usize];
        assert_eq!(pixel(GAP + 10, GAP + 10), 200, "a picture");
        assert_eq!(pixel(1, 1), 40, "the background");
    }
}
