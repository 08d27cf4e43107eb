//! CPU ray-cast rendering of the three benchmark cameras (`docs/benchmark.md` §1) with Lambert shading and
//! per-object colours, the `_marked` variants with a label on every object, and PNG
//! encoding.

use rapier3d::prelude::{Ray, Vector};

use crate::world::Sim;
use crate::world::objects::Pattern;

/// A pinhole camera looking at a point with +z up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// View name (`top`, `front`, `back`).
    pub name: &'static str,
    /// Eye position.
    pub eye: [f64; 3],
    /// Look-at point.
    pub target: [f64; 3],
    /// Vertical field of view in degrees.
    pub fov_y_deg: f64,
}

/// The benchmark's three views (`docs/benchmark.md` §1).
pub const CAMERAS: [Camera; 3] = [
    Camera {
        name: "top",
        eye: [0.5, 0.0, 2.5],
        target: [0.49, 0.0, 0.0],
        fov_y_deg: 25.0,
    },
    Camera {
        name: "front",
        eye: [2.0, 0.0, 1.0],
        target: [0.0, 0.0, 0.5],
        fov_y_deg: 30.0,
    },
    Camera {
        name: "back",
        eye: [-1.0, 0.0, 1.0],
        target: [1.0, 0.0, 0.5],
        fov_y_deg: 30.0,
    },
];

/// A camera for filming demonstrations (`nesy record --video`), never one of the views the
/// model is shown: above and beyond the table's front-right corner, where a person filming
/// the robot at work would stand, so the hand is seen from the side rather than past the arm.
pub const CORNER_CAMERA: Camera = Camera {
    name: "corner",
    eye: [1.5, -1.1, 1.4],
    target: [0.45, 0.0, 0.55],
    fov_y_deg: 35.0,
};

/// The camera a demonstration video can be filmed with, by name: the benchmark's three and
/// [`CORNER_CAMERA`].
pub fn filming_camera(name: &str) -> Option<Camera> {
    CAMERAS
        .iter()
        .chain(std::iter::once(&CORNER_CAMERA))
        .find(|c| c.name == name)
        .copied()
}

/// Image side used by the benchmark.
pub const VIEW_SIZE: u32 = 384;

/// An RGB8 image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGB bytes.
    pub rgb: Vec<u8>,
}

impl Image {
    fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            rgb: vec![0; (width * height * 3) as usize],
        }
    }

    fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x >= 0 && y >= 0 && (x as u32) < self.width && (y as u32) < self.height {
            let i = ((y as u32 * self.width + x as u32) * 3) as usize;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// Encodes as JPEG at `quality` (1–100): a tenth of the PNG's size for a rendered frame,
    /// which is what a recording of many frames needs.
    pub fn to_jpeg(&self, quality: u8) -> Vec<u8> {
        let mut out = Vec::new();
        let (Ok(width), Ok(height)) = (u16::try_from(self.width), u16::try_from(self.height)) else {
            return out;
        };
        // Encoding into a Vec cannot fail for a buffer of width × height × 3 bytes.
        let _ = jpeg_encoder::Encoder::new(&mut out, quality.clamp(1, 100)).encode(
            &self.rgb,
            width,
            height,
            jpeg_encoder::ColorType::Rgb,
        );
        out
    }

    /// Encodes as PNG.
    pub fn to_png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_compression(png::Compression::Fast);
            // Writing into a Vec cannot fail for a well-formed header and buffer.
            if let Ok(mut writer) = encoder.write_header() {
                let _ = writer.write_image_data(&self.rgb);
            }
        }
        out
    }
}

/// One camera's plain and marked images.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct View {
    /// Camera name.
    pub camera: &'static str,
    /// Shaded image.
    pub image: Image,
    /// The same with object labels.
    pub marked: Image,
}

struct Basis {
    eye: Vector,
    forward: Vector,
    right: Vector,
    up: Vector,
    tan_half: f32,
    aspect: f32,
}

impl Basis {
    fn new(cam: &Camera, width: u32, height: u32) -> Basis {
        let v = |a: [f64; 3]| Vector::new(a[0] as f32, a[1] as f32, a[2] as f32);
        let eye = v(cam.eye);
        let forward = (v(cam.target) - eye).normalize();
        let right = forward.cross(Vector::Z).normalize();
        let up = right.cross(forward);
        Basis {
            eye,
            forward,
            right,
            up,
            tan_half: (cam.fov_y_deg.to_radians() as f32 / 2.0).tan(),
            aspect: width as f32 / height as f32,
        }
    }

    fn ray(&self, px: f32, py: f32, width: u32, height: u32) -> Vector {
        let x = (2.0 * (px + 0.5) / width as f32 - 1.0) * self.tan_half * self.aspect;
        let y = (1.0 - 2.0 * (py + 0.5) / height as f32) * self.tan_half;
        (self.forward + self.right * x + self.up * y).normalize()
    }

    /// Pixel coordinates of a world point (None behind the camera).
    fn project(&self, p: [f64; 3], width: u32, height: u32) -> Option<(f32, f32)> {
        let d = Vector::new(p[0] as f32, p[1] as f32, p[2] as f32) - self.eye;
        let z = d.dot(self.forward);
        if z <= 1e-6 {
            return None;
        }
        let x = d.dot(self.right) / z / (self.tan_half * self.aspect);
        let y = d.dot(self.up) / z / self.tan_half;
        Some(((x + 1.0) / 2.0 * width as f32, (1.0 - y) / 2.0 * height as f32))
    }
}

const SKY: [f32; 3] = [0.82, 0.86, 0.9];
/// Screen tiles are this many pixels square; each lists the colliders whose projected
/// box touches it, so a pixel's ray is tested against a handful of shapes only.
const TILE: u32 = 16;

/// A collider prepared for ray casting: world pose, shape, world box, look.
struct Target<'a> {
    shape: &'a dyn rapier3d::prelude::Shape,
    pose: rapier3d::prelude::Pose,
    min: Vector,
    max: Vector,
    look: crate::world::Look,
}

/// Colliders per screen tile.
struct Tiles<'a> {
    targets: Vec<Target<'a>>,
    columns: u32,
    lists: Vec<Vec<u32>>,
    /// Distance from the eye to each target's box.
    depth: Vec<f32>,
}

impl<'a> Tiles<'a> {
    fn new(sim: &'a Sim, basis: &Basis, width: u32, height: u32) -> Tiles<'a> {
        let looks = sim.looks();
        let targets: Vec<Target<'a>> = sim
            .physics()
            .colliders
            .iter()
            .map(|(_, c)| {
                let aabb = c.compute_aabb();
                Target {
                    shape: c.shape(),
                    pose: *c.position(),
                    min: aabb.mins,
                    max: aabb.maxs,
                    look: looks[c.user_data as usize],
                }
            })
            .collect();
        let columns = width.div_ceil(TILE);
        let rows = height.div_ceil(TILE);
        let mut lists = vec![Vec::new(); (columns * rows) as usize];
        for (i, t) in targets.iter().enumerate() {
            let mut lo = (f32::INFINITY, f32::INFINITY);
            let mut hi = (f32::NEG_INFINITY, f32::NEG_INFINITY);
            let mut everywhere = false;
            for k in 0..8 {
                let corner = [
                    if k & 1 == 0 { t.min.x } else { t.max.x } as f64,
                    if k & 2 == 0 { t.min.y } else { t.max.y } as f64,
                    if k & 4 == 0 { t.min.z } else { t.max.z } as f64,
                ];
                match basis.project(corner, width, height) {
                    Some((x, y)) => {
                        lo = (lo.0.min(x), lo.1.min(y));
                        hi = (hi.0.max(x), hi.1.max(y));
                    }
                    None => everywhere = true,
                }
            }
            let (c0, c1, r0, r1) = if everywhere {
                (0, columns - 1, 0, rows - 1)
            } else {
                let clamp_c = |v: f32| ((v.max(0.0) as u32) / TILE).min(columns - 1);
                let clamp_r = |v: f32| ((v.max(0.0) as u32) / TILE).min(rows - 1);
                if hi.0 < 0.0 || hi.1 < 0.0 || lo.0 >= width as f32 || lo.1 >= height as f32 {
                    continue;
                }
                (
                    clamp_c(lo.0 - 1.0),
                    clamp_c(hi.0 + 1.0),
                    clamp_r(lo.1 - 1.0),
                    clamp_r(hi.1 + 1.0),
                )
            };
            for r in r0..=r1 {
                for c in c0..=c1 {
                    lists[(r * columns + c) as usize].push(i as u32);
                }
            }
        }
        // Front to back, so the nearest hit is found early and the box test rejects the rest.
        let eye = basis.eye;
        let depth: Vec<f32> = targets
            .iter()
            .map(|t| (eye.clamp(t.min, t.max) - eye).length())
            .collect();
        for list in &mut lists {
            list.sort_by(|a, b| depth[*a as usize].total_cmp(&depth[*b as usize]));
        }
        Tiles {
            targets,
            columns,
            lists,
            depth,
        }
    }

    /// The nearest hit along a unit ray: (target index, distance, normal).
    fn cast(&self, px: u32, py: u32, ray: &Ray) -> Option<(usize, f32, Vector)> {
        let list = &self.lists[((py / TILE) * self.columns + px / TILE) as usize];
        let inv = Vector::new(1.0 / ray.dir.x, 1.0 / ray.dir.y, 1.0 / ray.dir.z);
        let mut best: Option<(usize, f32, Vector)> = None;
        let mut limit = 10.0_f32;
        for &i in list {
            let t = &self.targets[i as usize];
            // Slab test against the world box before the exact shape.
            let a = (t.min - ray.origin) * inv;
            let b = (t.max - ray.origin) * inv;
            let near = a.min(b).max_element();
            let far = a.max(b).min_element();
            if self.depth[i as usize] > limit {
                // Lists are sorted by the distance from the eye to each box, a lower bound
                // of any hit on it: no later box can beat the hit already found.
                break;
            }
            if far < near.max(0.0) || near > limit {
                continue;
            }
            if let Some(hit) = t.shape.cast_ray_and_get_normal(&t.pose, ray, limit, true) {
                limit = hit.time_of_impact;
                best = Some((i as usize, hit.time_of_impact, hit.normal));
            }
        }
        best
    }
}

fn shade_rows(
    tiles: &Tiles,
    basis: &Basis,
    width: u32,
    height: u32,
    rows: std::ops::Range<u32>,
    out: &mut [u8],
) {
    let light = Vector::new(0.35, -0.25, 1.0).normalize();
    for (r, py) in rows.enumerate() {
        for px in 0..width {
            let dir = basis.ray(px as f32, py as f32, width, height);
            let ray = Ray::new(basis.eye, dir);
            let colour = match tiles.cast(px, py, &ray) {
                Some((i, toi, normal)) => {
                    let target = &tiles.targets[i];
                    let look = target.look;
                    let n = if normal.dot(dir) > 0.0 { -normal } else { normal };
                    let base = match look.pattern {
                        Pattern::Plain => look.colour,
                        Pattern::Checker { cells, other } => {
                            let local = target.pose.inverse_transform_point(ray.point_at(toi));
                            let [hx, hy] = look.pattern_half_extent;
                            let cell = 2.0 * hx / cells as f32;
                            let i = ((local.x + hx) / cell).floor() as i64;
                            let j = ((local.y + hy) / cell).floor() as i64;
                            if (i + j).rem_euclid(2) == 0 {
                                look.colour
                            } else {
                                other
                            }
                        }
                    };
                    let lambert = n.dot(light).max(0.0);
                    let head = n.dot(-dir).max(0.0);
                    let k = 0.28 + 0.55 * lambert + 0.2 * head;
                    [base[0] * k, base[1] * k, base[2] * k]
                }
                None => SKY,
            };
            let i = ((r as u32 * width + px) * 3) as usize;
            for c in 0..3 {
                out[i + c] = (colour[c].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            }
        }
    }
}

/// Renders one camera, splitting rows over `threads` threads.
pub fn render_camera(sim: &Sim, camera: &Camera, width: u32, height: u32, threads: usize) -> Image {
    if width == 0 || height == 0 {
        return Image::new(width, height);
    }
    let basis = Basis::new(camera, width, height);
    let tiles = Tiles::new(sim, &basis, width, height);
    let mut image = Image::new(width, height);
    let threads = threads.clamp(1, height as usize);
    let rows_per = height.div_ceil(threads as u32);
    let row_bytes = (width * 3) as usize;
    std::thread::scope(|scope| {
        for (t, chunk) in image.rgb.chunks_mut(rows_per as usize * row_bytes).enumerate() {
            let start = t as u32 * rows_per;
            let end = (start + rows_per).min(height);
            let (basis, tiles) = (&basis, &tiles);
            if threads == 1 {
                shade_rows(tiles, basis, width, height, start..end, chunk);
            } else {
                scope.spawn(move || shade_rows(tiles, basis, width, height, start..end, chunk));
            }
        }
    });
    image
}

/// Draws the label of every object as perception names it (the pieces of screws under one
/// label) at its projected AABB centre, 20 px lower,
/// clipped to the frame (`docs/benchmark.md` §1), as red text on a black box. Where a label would cover
/// an earlier one it is nudged up or down in 11 px steps so every name stays readable.
pub fn mark(sim: &Sim, camera: &Camera, image: &Image) -> Image {
    let mut out = image.clone();
    let basis = Basis::new(camera, image.width, image.height);
    let (w, h) = (image.width as f32, image.height as f32);
    let mut placed: Vec<[i64; 4]> = Vec::new();
    for (name, parts) in sim.perceived_objects() {
        let Some((x, y)) = basis.project(sim.parts_aabb(&parts).centre(), image.width, image.height) else {
            continue;
        };
        // `max` keeps the range valid on frames narrower than a label margin (--size 32).
        let x = x.clamp(24.0, (w - 21.0).max(24.0)) as i64;
        let y = (y + 20.0).clamp(24.0, (h - 21.0).max(24.0)) as i64;
        let width = label_width(name);
        let boxed = |cy: i64| [x - width / 2 - 2, cy - 6, x + width / 2 + 2, cy + 6];
        let overlaps = |b: &[i64; 4]| {
            placed
                .iter()
                .any(|p| b[0] < p[2] && p[0] < b[2] && b[1] < p[3] && p[1] < b[3])
        };
        let cy = (0..12)
            .map(|k| {
                y + if k % 2 == 0 {
                    11 * (k / 2)
                } else {
                    -11 * (k / 2 + 1)
                }
            })
            .filter(|cy| (6..image.height as i64 - 6).contains(cy))
            .find(|&cy| !overlaps(&boxed(cy)))
            .unwrap_or(y);
        placed.push(boxed(cy));
        draw_label(&mut out, name, x, cy);
    }
    out
}

const GLYPH_ADVANCE: i64 = 7;

fn label_width(text: &str) -> i64 {
    text.chars().count() as i64 * GLYPH_ADVANCE
}

/// Red 8×8-font text on a filled black box centred at `(cx, cy)`.
pub fn draw_label(image: &mut Image, text: &str, cx: i64, cy: i64) {
    let tw = label_width(text);
    let (x0, y0) = (cx - tw / 2, cy - 4);
    for y in y0 - 2..y0 + 10 {
        for x in x0 - 2..x0 + tw + 2 {
            image.put(x, y, [0, 0, 0]);
        }
    }
    for (k, ch) in text.chars().enumerate() {
        let glyph = font8x8::legacy::BASIC_LEGACY
            .get(ch as usize)
            .copied()
            .unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 1 {
                    image.put(x0 + k as i64 * GLYPH_ADVANCE + col, y0 + row as i64, [255, 0, 0]);
                }
            }
        }
    }
}

/// Renders the three benchmark views at `size`², plain and marked, on `threads` threads.
pub fn render_views(sim: &Sim, size: u32, threads: usize) -> Vec<View> {
    CAMERAS
        .iter()
        .map(|camera| {
            let image = render_camera(sim, camera, size, size, threads);
            let marked = mark(sim, camera, &image);
            View {
                camera: camera.name,
                image,
                marked,
            }
        })
        .collect()
}

/// Most render threads a caller may ask for: a view is split into rows, so more threads than
/// this only add start-up cost.
pub const MAX_RENDER_THREADS: usize = 64;

/// Number of threads the renderer uses by default: the available cores, at most 4.
pub fn default_threads() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .min(4)
}

/// Writes `<camera>.png` and `<camera>_marked.png` for each view into `dir`.
pub fn write_views(views: &[View], dir: &std::path::Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    for v in views {
        for (suffix, img) in [("", &v.image), ("_marked", &v.marked)] {
            let path = dir.join(format!("{}{suffix}.png", v.camera));
            std::fs::write(&path, img.to_png())?;
            written.push(path);
        }
    }
    Ok(written)
}
