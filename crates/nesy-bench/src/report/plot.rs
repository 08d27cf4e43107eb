//! Small PNG charts for reports: grouped bars with error bars and lines with markers, drawn
//! into an RGB buffer with an 8×8 bitmap font and encoded with `png`. No font files, no
//! system libraries: the same bytes on every machine.

use std::path::Path;

use crate::error::BenchError;

/// An RGB colour.
pub type Rgb = [u8; 3];

/// The text with the typography the 8×8 font lacks spelled in ASCII.
fn ascii(text: &str) -> String {
    text.replace(['—', '–'], "-")
        .replace('±', "+-")
        .replace('×', "x")
        .replace('≥', ">=")
        .replace('≤', "<=")
        .replace('Σ', "sum ")
}

/// Series colours in order: the eight colour-blind-friendly ones, then four darker ones, so
/// that a run of every method and control (eleven series) repeats no colour.
pub const PALETTE: [Rgb; 12] = [
    [0, 114, 178],
    [230, 159, 0],
    [0, 158, 115],
    [204, 121, 167],
    [86, 180, 233],
    [213, 94, 0],
    [240, 228, 66],
    [80, 80, 80],
    [110, 60, 170],
    [140, 85, 35],
    [0, 80, 60],
    [180, 25, 60],
];

const WHITE: Rgb = [255, 255, 255];
const BLACK: Rgb = [20, 20, 20];
const GRID: Rgb = [225, 225, 225];
const AXIS: Rgb = [90, 90, 90];

/// An image being drawn.
pub struct Canvas {
    width: usize,
    height: usize,
    pixels: Vec<u8>,
}

impl Canvas {
    /// A white canvas.
    pub fn new(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            pixels: vec![255; width * height * 3],
        }
    }

    /// The canvas width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    fn put(&mut self, x: i64, y: i64, c: Rgb) {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return;
        }
        let i = (y as usize * self.width + x as usize) * 3;
        self.pixels[i..i + 3].copy_from_slice(&c);
    }

    /// A filled rectangle from (x0, y0) to (x1, y1), corners in any order.
    pub fn rect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: Rgb) {
        let (xa, xb) = (x0.min(x1), x0.max(x1));
        let (ya, yb) = (y0.min(y1), y0.max(y1));
        for y in ya..=yb {
            for x in xa..=xb {
                self.put(x, y, c);
            }
        }
    }

    /// A line (Bresenham), `thick` pixels wide.
    pub fn line(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: Rgb, thick: i64) {
        let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
        let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        let (mut x, mut y, mut err) = (x0, y0, dx + dy);
        loop {
            for t in 0..thick {
                let o = t - thick / 2;
                self.put(x + o, y, c);
                self.put(x, y + o, c);
            }
            if x == x1 && y == y1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }

    /// Text with its top-left corner at (x, y), each glyph `scale` × 8 pixels.
    pub fn text(&mut self, x: i64, y: i64, text: &str, c: Rgb, scale: i64) {
        let text = ascii(text);
        for (k, ch) in text.chars().enumerate() {
            let code = ch as usize;
            let glyph = if code < 128 {
                font8x8::legacy::BASIC_LEGACY[code]
            } else {
                font8x8::legacy::BASIC_LEGACY[b'?' as usize]
            };
            let gx = x + k as i64 * 8 * scale;
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits >> col & 1 == 1 {
                        let px = gx + col * scale;
                        let py = y + row as i64 * scale;
                        self.rect(px, py, px + scale - 1, py + scale - 1, c);
                    }
                }
            }
        }
    }

    /// Text centred horizontally on `cx`.
    pub fn text_centred(&mut self, cx: i64, y: i64, text: &str, c: Rgb, scale: i64) {
        let w = ascii(text).chars().count() as i64 * 8 * scale;
        self.text(cx - w / 2, y, text, c, scale);
    }

    /// Encodes the canvas as PNG.
    pub fn to_png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, self.width as u32, self.height as u32);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            if let Ok(mut writer) = encoder.write_header() {
                let _ = writer.write_image_data(&self.pixels);
            }
        }
        out
    }

    /// Writes the PNG.
    pub fn save(&self, path: &Path) -> Result<(), BenchError> {
        std::fs::write(path, self.to_png()).map_err(|e| BenchError::io(path, e))
    }
}

/// One value with its standard error; `None` draws nothing (no data).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Value {
    /// The mean.
    pub mean: f64,
    /// Its standard error (NaN: not drawn).
    pub se: f64,
}

/// A panel of grouped bars: one group per category, one bar per series.
pub struct Bars<'a> {
    /// The panel's title.
    pub title: &'a str,
    /// The y axis' label.
    pub y_label: &'a str,
    /// Upper end of the y axis.
    pub y_max: f64,
    /// Category names along x.
    pub categories: &'a [String],
    /// Series names (the legend).
    pub series: &'a [String],
    /// `values[series][category]`.
    pub values: &'a [Vec<Option<Value>>],
}

/// A panel of lines with markers: one line per series over the categories.
pub struct Lines<'a> {
    /// The panel's title.
    pub title: &'a str,
    /// The x axis' label.
    pub x_label: &'a str,
    /// The y axis' label.
    pub y_label: &'a str,
    /// Upper end of the y axis.
    pub y_max: f64,
    /// Category names along x.
    pub categories: &'a [String],
    /// Series names (the legend).
    pub series: &'a [String],
    /// `values[series][category]`.
    pub values: &'a [Vec<Option<Value>>],
}

/// Where a panel goes on the canvas.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// Left edge.
    pub x: i64,
    /// Top edge.
    pub y: i64,
    /// Width.
    pub w: i64,
    /// Height.
    pub h: i64,
}

const LEFT: i64 = 64;
const RIGHT: i64 = 16;
const TOP: i64 = 34;
const BOTTOM: i64 = 52;

/// Draws the frame's axes, grid and y ticks; returns the plot area (x0, y0, x1, y1) and a
/// function from a value to its pixel row.
fn axes(canvas: &mut Canvas, f: Frame, title: &str, y_label: &str, y_max: f64) -> (i64, i64, i64, i64) {
    let (x0, y0, x1, y1) = (f.x + LEFT, f.y + TOP, f.x + f.w - RIGHT, f.y + f.h - BOTTOM);
    canvas.text_centred((x0 + x1) / 2, f.y + 8, title, BLACK, 2);
    let ticks = 5;
    for k in 0..=ticks {
        let v = y_max * k as f64 / ticks as f64;
        let y = y1 - ((y1 - y0) as f64 * k as f64 / ticks as f64) as i64;
        canvas.line(x0, y, x1, y, GRID, 1);
        let label = format!("{v:.0}");
        canvas.text(x0 - 8 - label.len() as i64 * 8, y - 4, &label, AXIS, 1);
    }
    canvas.line(x0, y0, x0, y1, AXIS, 1);
    canvas.line(x0, y1, x1, y1, AXIS, 1);
    // The y label runs down the left margin, one character per line.
    for (k, ch) in y_label.chars().enumerate() {
        canvas.text(f.x + 4, y0 + k as i64 * 10, &ch.to_string(), AXIS, 1);
    }
    (x0, y0, x1, y1)
}

fn to_y(v: f64, y_max: f64, y0: i64, y1: i64) -> i64 {
    let t = (v / y_max).clamp(0.0, 1.0);
    y1 - ((y1 - y0) as f64 * t).round() as i64
}

/// Draws grouped bars into `f`.
pub fn draw_bars(canvas: &mut Canvas, f: Frame, bars: &Bars) {
    let (x0, y0, x1, y1) = axes(canvas, f, bars.title, bars.y_label, bars.y_max);
    let groups = bars.categories.len().max(1) as i64;
    let group_w = (x1 - x0) / groups;
    let n = bars.series.len().max(1) as i64;
    let bar_w = ((group_w - 10) / n).max(2);
    for (g, name) in bars.categories.iter().enumerate() {
        let gx = x0 + g as i64 * group_w + 5;
        for (s, column) in bars.values.iter().enumerate() {
            let Some(Some(v)) = column.get(g) else { continue };
            let colour = PALETTE[s % PALETTE.len()];
            let bx = gx + s as i64 * bar_w;
            let top = to_y(v.mean, bars.y_max, y0, y1);
            canvas.rect(bx, top, bx + bar_w - 2, y1 - 1, colour);
            if v.se.is_finite() && v.se > 0.0 {
                let (lo, hi) = (
                    to_y(v.mean - v.se, bars.y_max, y0, y1),
                    to_y(v.mean + v.se, bars.y_max, y0, y1),
                );
                let cx = bx + (bar_w - 2) / 2;
                canvas.line(cx, lo, cx, hi, BLACK, 1);
                canvas.line(cx - 2, hi, cx + 2, hi, BLACK, 1);
                canvas.line(cx - 2, lo, cx + 2, lo, BLACK, 1);
            }
        }
        canvas.text_centred(gx + group_w / 2 - 5, y1 + 8, name, BLACK, 1);
    }
}

/// Draws lines with markers and error bars into `f`.
pub fn draw_lines(canvas: &mut Canvas, f: Frame, lines: &Lines) {
    let (x0, y0, x1, y1) = axes(canvas, f, lines.title, lines.y_label, lines.y_max);
    let n = lines.categories.len().max(1) as i64;
    let step = (x1 - x0) / n;
    let x_of = |k: usize| x0 + step / 2 + k as i64 * step;
    for (k, name) in lines.categories.iter().enumerate() {
        canvas.text_centred(x_of(k), y1 + 8, name, BLACK, 1);
    }
    canvas.text_centred((x0 + x1) / 2, y1 + 26, lines.x_label, AXIS, 1);
    for (s, column) in lines.values.iter().enumerate() {
        let colour = PALETTE[s % PALETTE.len()];
        let mut last: Option<(i64, i64)> = None;
        for (k, v) in column.iter().enumerate() {
            let Some(v) = v else {
                last = None;
                continue;
            };
            let (x, y) = (x_of(k) + s as i64 * 3 - 6, to_y(v.mean, lines.y_max, y0, y1));
            if let Some((lx, ly)) = last {
                canvas.line(lx, ly, x, y, colour, 2);
            }
            if v.se.is_finite() && v.se > 0.0 {
                let (lo, hi) = (
                    to_y(v.mean - v.se, lines.y_max, y0, y1),
                    to_y(v.mean + v.se, lines.y_max, y0, y1),
                );
                canvas.line(x, lo, x, hi, colour, 1);
            }
            canvas.rect(x - 3, y - 3, x + 3, y + 3, colour);
            last = Some((x, y));
        }
    }
}

/// Height of one legend line, in pixels.
pub const LEGEND_LINE: i64 = 16;

/// `name` split at spaces into lines of at most `room` characters; a word longer than a
/// line is cut where the line ends.
fn wrap_name(name: &str, room: usize) -> Vec<String> {
    let room = room.max(1);
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in name.split(' ') {
        let mut word: Vec<char> = word.chars().collect();
        let used = line.chars().count();
        if used > 0 && used + 1 + word.len() > room {
            lines.push(std::mem::take(&mut line));
        }
        while word.len() > room {
            let rest = word.split_off(room);
            lines.push(word.into_iter().collect());
            word = rest;
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.extend(word);
    }
    lines.push(line);
    lines
}

/// Where each legend entry starts, relative to the legend's origin at `x` on a canvas
/// `width` wide, and its text lines: entries that would run past the right edge start a new
/// line, and a name wider than a whole line is wrapped onto lines of its own.
fn legend_layout(width: usize, x: i64, series: &[String]) -> Vec<(i64, i64, Vec<String>)> {
    let right = width as i64 - 8;
    let room = ((right - x - 16) / 8).max(1) as usize;
    let (mut cx, mut cy, mut row_lines) = (x, 0, 1);
    series
        .iter()
        .map(|name| {
            let lines = wrap_name(name, room);
            let widest = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0);
            let entry = 16 + widest as i64 * 8;
            if cx > x && cx + entry > right {
                cx = x;
                cy += row_lines * LEGEND_LINE;
                row_lines = 1;
            }
            row_lines = row_lines.max(lines.len() as i64);
            let at = (cx, cy, lines);
            cx += entry + 20;
            at
        })
        .collect()
}

/// How many lines the legend of `series` takes at `x` on a canvas `width` wide, so a
/// figure can make room for it before drawing.
fn legend_lines(width: usize, x: i64, series: &[String]) -> i64 {
    let layout = legend_layout(width, x, series);
    let Some((_, last_y, _)) = layout.last() else {
        return 0;
    };
    // The last row is as tall as its tallest entry.
    let last_row = layout
        .iter()
        .filter(|(_, y, _)| y == last_y)
        .map(|(_, _, lines)| lines.len() as i64)
        .max()
        .unwrap_or(1);
    last_y / LEGEND_LINE + last_row
}

/// The pixels a figure adds to its height so that the legend of `series` at `x` fits, when
/// its layout leaves room for `room` lines.
pub fn legend_overflow(width: usize, x: i64, series: &[String], room: i64) -> i64 {
    (legend_lines(width, x, series) - room).max(0) * LEGEND_LINE
}

/// Draws a legend of `series` in a row starting at (x, y).
///
/// Entries that would run past the canvas's right edge start a new line
/// [`LEGEND_LINE`] pixels lower, and a name wider than a whole line is wrapped, so long
/// labels stay readable instead of being clipped.
pub fn legend(canvas: &mut Canvas, x: i64, y: i64, series: &[String]) {
    for (s, (cx, dy, lines)) in legend_layout(canvas.width(), x, series).into_iter().enumerate() {
        let cy = y + dy;
        canvas.rect(cx, cy, cx + 12, cy + 10, PALETTE[s % PALETTE.len()]);
        for (i, line) in lines.iter().enumerate() {
            canvas.text(cx + 16, cy + 1 + i as i64 * LEGEND_LINE, line, BLACK, 1);
        }
    }
}

/// A full-width note at the bottom of a canvas (the synthetic banner, a definition).
pub fn footnote(canvas: &mut Canvas, y: i64, text: &str) {
    canvas.text(8, y, text, AXIS, 1);
}

/// A white canvas with a one-line header.
pub fn canvas_with_header(width: usize, height: usize, header: &str, banner: Option<&str>) -> Canvas {
    let mut c = Canvas::new(width, height);
    c.rect(0, 0, width as i64 - 1, 0, WHITE);
    c.text(8, 6, header, BLACK, 2);
    if let Some(b) = banner {
        c.rect(0, 26, width as i64 - 1, 40, [255, 236, 200]);
        c.text(8, 30, b, [150, 60, 0], 1);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn charts_encode_to_png_of_the_right_size() {
        let mut c = canvas_with_header(400, 300, "test", Some("SYNTHETIC"));
        let cats = vec!["Low".to_owned(), "High".to_owned()];
        let series = vec!["a".to_owned(), "b".to_owned()];
        let values = vec![
            vec![Some(Value { mean: 50.0, se: 5.0 }), None],
            vec![
                Some(Value {
                    mean: 80.0,
                    se: f64::NAN,
                }),
                Some(Value { mean: 10.0, se: 1.0 }),
            ],
        ];
        draw_bars(
            &mut c,
            Frame {
                x: 0,
                y: 40,
                w: 200,
                h: 240,
            },
            &Bars {
                title: "SR",
                y_label: "%",
                y_max: 100.0,
                categories: &cats,
                series: &series,
                values: &values,
            },
        );
        draw_lines(
            &mut c,
            Frame {
                x: 200,
                y: 40,
                w: 200,
                h: 240,
            },
            &Lines {
                title: "PD",
                x_label: "level",
                y_label: "%",
                y_max: 100.0,
                categories: &cats,
                series: &series,
                values: &values,
            },
        );
        legend(&mut c, 10, 285, &series);
        let png = c.to_png();
        assert_eq!(&png[..8], &[0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A]);
        let decoder = png::Decoder::new(std::io::Cursor::new(png));
        let reader = decoder.read_info().unwrap();
        assert_eq!((reader.info().width, reader.info().height), (400, 300));
    }

    #[test]
    fn a_legend_wraps_at_the_right_edge_and_says_how_many_lines_it_needs() {
        let short: Vec<String> = ["a", "b"].map(String::from).to_vec();
        assert_eq!(legend_lines(400, 10, &short), 1);
        assert_eq!(legend_lines(400, 10, &[]), 0);
        // Each 40-character name is 336 px with its swatch: one per line on a 400 px canvas.
        let long: Vec<String> = (0..3).map(|i| format!("{i:0>40}")).collect();
        assert_eq!(legend_lines(400, 10, &long), 3);
        assert_eq!(legend_overflow(400, 10, &long, 2), LEGEND_LINE);
        assert_eq!(legend_overflow(400, 10, &short, 2), 0);
        let at = legend_layout(400, 10, &long);
        assert!(at.iter().all(|(x, _, _)| *x == 10), "{at:?}");
        assert_eq!(
            at.iter().map(|(_, y, _)| *y).collect::<Vec<_>>(),
            vec![0, LEGEND_LINE, 2 * LEGEND_LINE]
        );
    }

    #[test]
    fn a_name_wider_than_a_line_wraps_onto_lines_of_its_own() {
        // 45 characters fit beside the swatch on a 400 px canvas at x = 10.
        let name = format!("NeSyCR [{}, {}]", "x".repeat(30), "y".repeat(60));
        let series = vec![name.clone(), "after".to_owned()];
        let at = legend_layout(400, 10, &series);
        let lines = &at[0].2;
        assert_eq!(lines.len(), 3, "{lines:?}");
        assert!(lines.iter().all(|l| l.chars().count() <= 45), "{lines:?}");
        assert_eq!(lines.concat().replace(' ', ""), name.replace(' ', ""));
        // The next entry starts below the wrapped one, and the legend counts every line.
        assert_eq!((at[1].0, at[1].1), (10, 3 * LEGEND_LINE));
        assert_eq!(legend_lines(400, 10, &series), 4);
    }
}
