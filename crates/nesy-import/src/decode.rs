//! Pictures decoded to RGB8 (PNG with the `png` crate, JPEG with `zune-jpeg`), and the small
//! grey thumbnails keyframe detection compares.

use nesy_sim::demo::ImageFormat;
use nesy_sim::perception::render::Image;

/// Decodes a PNG or JPEG file's bytes to RGB8; the error says what is wrong with them.
pub fn decode(bytes: &[u8]) -> Result<Image, String> {
    match ImageFormat::of(bytes) {
        Some(ImageFormat::Png) => decode_png(bytes),
        Some(ImageFormat::Jpeg) => decode_jpeg(bytes),
        None => Err("not a PNG or JPEG image".into()),
    }
}

fn decode_png(bytes: &[u8]) -> Result<Image, String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder.read_info().map_err(|e| format!("PNG: {e}"))?;
    let size = reader.output_buffer_size().ok_or("PNG: the image is too large")?;
    let mut buffer = vec![0; size];
    let info = reader.next_frame(&mut buffer).map_err(|e| format!("PNG: {e}"))?;
    buffer.truncate(info.buffer_size());
    let rgb = match info.color_type {
        png::ColorType::Rgb => buffer,
        png::ColorType::Rgba => buffer.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect(),
        png::ColorType::Grayscale => buffer.iter().flat_map(|&g| [g, g, g]).collect(),
        png::ColorType::GrayscaleAlpha => buffer.chunks_exact(2).flat_map(|p| [p[0], p[0], p[0]]).collect(),
        png::ColorType::Indexed => return Err("PNG: an indexed image was not expanded".into()),
    };
    Ok(Image {
        width: info.width,
        height: info.height,
        rgb,
    })
}

fn decode_jpeg(bytes: &[u8]) -> Result<Image, String> {
    use zune_core::bytestream::ZCursor;
    use zune_core::colorspace::ColorSpace;
    use zune_core::options::DecoderOptions;
    let options = DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::RGB);
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    let rgb = decoder.decode().map_err(|e| format!("JPEG: {e:?}"))?;
    let info = decoder.info().ok_or("JPEG: no frame header")?;
    let (width, height) = (u32::from(info.width), u32::from(info.height));
    if rgb.len() != (width * height * 3) as usize {
        return Err(format!(
            "JPEG: decoded {} bytes for a {width}x{height} RGB image",
            rgb.len()
        ));
    }
    Ok(Image { width, height, rgb })
}

/// Width of the grey thumbnails frames are compared at: enough to see a gripper close,
/// small enough that a minute of video compares in milliseconds.
pub const THUMBNAIL_WIDTH: u32 = 128;

/// Side of the square blocks two thumbnails are compared by (see [`Thumbnail::difference`]).
pub const BLOCK: u32 = 4;

/// A small grey picture of a frame (box-filtered), for comparing frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Thumbnail {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major luma, 0–255.
    pub luma: Vec<f32>,
}

impl Thumbnail {
    /// The thumbnail of `image`, [`THUMBNAIL_WIDTH`] wide (or narrower for a smaller image),
    /// keeping the aspect ratio.
    pub fn of(image: &Image) -> Thumbnail {
        let width = image.width.clamp(1, THUMBNAIL_WIDTH);
        let height =
            ((u64::from(image.height) * u64::from(width)) / u64::from(image.width.max(1))).max(1) as u32;
        let mut sums = vec![0.0f32; (width * height) as usize];
        let mut counts = vec![0u32; (width * height) as usize];
        for y in 0..image.height {
            let ty = (u64::from(y) * u64::from(height) / u64::from(image.height)) as u32;
            for x in 0..image.width {
                let tx = (u64::from(x) * u64::from(width) / u64::from(image.width)) as u32;
                let i = ((y * image.width + x) * 3) as usize;
                let [r, g, b] = [image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]].map(f32::from);
                let cell = (ty * width + tx) as usize;
                sums[cell] += 0.299 * r + 0.587 * g + 0.114 * b;
                counts[cell] += 1;
            }
        }
        let luma = sums
            .iter()
            .zip(&counts)
            .map(|(s, &c)| if c == 0 { 0.0 } else { s / c as f32 })
            .collect();
        Thumbnail { width, height, luma }
    }

    /// How much `other` differs, in luma (0–255): the mean absolute difference over the
    /// [`BLOCK`]-pixel square where it is largest, so that a small change (fingers closing,
    /// one object moved) counts in a large picture while pixel noise averages out. `None`
    /// when the sizes differ.
    pub fn difference(&self, other: &Thumbnail) -> Option<f32> {
        if (self.width, self.height) != (other.width, other.height) {
            return None;
        }
        let (bw, bh) = (self.width.div_ceil(BLOCK), self.height.div_ceil(BLOCK));
        let mut sums = vec![0.0f32; (bw * bh) as usize];
        let mut counts = vec![0u32; (bw * bh) as usize];
        for y in 0..self.height {
            for x in 0..self.width {
                let i = (y * self.width + x) as usize;
                let block = ((y / BLOCK) * bw + x / BLOCK) as usize;
                sums[block] += (self.luma[i] - other.luma[i]).abs();
                counts[block] += 1;
            }
        }
        Some(
            sums.iter()
                .zip(&counts)
                .map(|(s, &c)| if c == 0 { 0.0 } else { s / c as f32 })
                .fold(0.0, f32::max),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn picture(width: u32, height: u32, value: impl Fn(u32, u32) -> u8) -> Image {
        let mut rgb = Vec::with_capacity((width * height * 3) as usize);
        for y in 0..height {
            for x in 0..width {
                let v = value(x, y);
                rgb.extend([v, v, v]);
            }
        }
        Image { width, height, rgb }
    }

    #[test]
    fn png_and_jpeg_decode_to_the_same_picture() {
        let image = picture(40, 30, |x, y| ((x * 5 + y * 3) % 256) as u8);
        assert_eq!(decode(&image.to_png()).unwrap(), image);
        let mut jpeg = Vec::new();
        jpeg_encoder::Encoder::new(&mut jpeg, 95)
            .encode(&image.rgb, 40, 30, jpeg_encoder::ColorType::Rgb)
            .unwrap();
        let decoded = decode(&jpeg).unwrap();
        assert_eq!((decoded.width, decoded.height), (40, 30));
        let error = Thumbnail::of(&decoded)
            .difference(&Thumbnail::of(&image))
            .unwrap();
        assert!(
            error < 3.0,
            "JPEG at quality 95 is close to the original: {error}"
        );
        assert!(decode(&jpeg[..jpeg.len() / 3]).is_err() || decode(&jpeg[..40]).is_err());
        assert_eq!(decode(b"GIF89a").unwrap_err(), "not a PNG or JPEG image");
    }

    #[test]
    fn thumbnails_average_and_compare() {
        let dark = picture(256, 128, |_, _| 10);
        let spot = picture(256, 128, |x, y| {
            if (16..24).contains(&x) && (8..16).contains(&y) {
                210
            } else {
                10
            }
        });
        let (a, b) = (Thumbnail::of(&dark), Thumbnail::of(&spot));
        assert_eq!((a.width, a.height), (128, 64));
        assert_eq!(a.difference(&a), Some(0.0));
        // An 8-pixel spot is a 4-pixel block of the thumbnail: found at full strength.
        assert!((a.difference(&b).unwrap() - 200.0).abs() < 1e-3);
        assert_eq!(a.difference(&Thumbnail::of(&picture(10, 10, |_, _| 0))), None);
    }
}
