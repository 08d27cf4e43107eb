//! MP4 files with an H.264 video track (what phones, webcams and RealSense recordings
//! write): read frame by frame with the `mp4` demuxer and Cisco's OpenH264 decoder, and
//! written the same way (the simulator's demonstration videos).

use std::io::{BufReader, Cursor};
use std::path::Path;

use nesy_sim::perception::render::Image;
use openh264::formats::YUVSource as _;

use crate::error::ImportError;

/// The file extensions read as video.
pub const VIDEO_EXTENSIONS: [&str; 3] = ["mp4", "m4v", "mov"];

/// Whether `path` names a video by its extension ([`VIDEO_EXTENSIONS`], any case).
pub fn is_video(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| VIDEO_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// An MP4 file's H.264 track: its size, and each frame's presentation time (seconds).
#[derive(Debug, Clone, PartialEq)]
pub struct VideoInfo {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Presentation time of each frame, in decoding order.
    pub times: Vec<f64>,
}

/// Reads the H.264 track of an MP4 file, calling `frame` with each decoded frame (RGB) and
/// its index, in order. A file that is not MP4, holds no H.264 track, is truncated or
/// decodes to nothing is an error naming it.
pub fn read_mp4(
    path: &Path,
    mut frame: impl FnMut(usize, Image) -> Result<(), ImportError>,
) -> Result<VideoInfo, ImportError> {
    let bad = |message: String| ImportError::invalid(path, message);
    let bytes =
        nesy_input::read_bytes(path, nesy_input::MAX_DEMO_BYTES).map_err(|e| ImportError::io(path, e))?;
    let size = bytes.len() as u64;
    // The demuxer is not hardened against every damaged file: a panic in it is a refusal.
    let demuxed = std::panic::catch_unwind(|| demux(&bytes, size));
    let (track, samples) = match demuxed {
        Ok(result) => result.map_err(bad)?,
        Err(_) => {
            return Err(bad(
                "a damaged MP4 container (the demuxer could not read it)".into()
            ));
        }
    };
    let mut decoder =
        openh264::decoder::Decoder::new().map_err(|e| bad(format!("starting the H.264 decoder: {e}")))?;
    let mut times = Vec::with_capacity(samples.len());
    let mut rgb = Vec::new();
    let (mut width, mut height) = (0u32, 0u32);
    let mut stream = Vec::new();
    for (i, sample) in samples.iter().enumerate() {
        stream.clear();
        if i == 0 {
            for parameter_set in [&track.sps, &track.pps] {
                stream.extend_from_slice(&[0, 0, 0, 1]);
                stream.extend_from_slice(parameter_set);
            }
        }
        annex_b(&sample.bytes, &mut stream).map_err(|m| bad(format!("frame {i}: {m}")))?;
        let decoded = decoder
            .decode(&stream)
            .map_err(|e| bad(format!("frame {i}: H.264: {e}")))?;
        let Some(yuv) = decoded else { continue };
        let (w, h) = yuv.dimensions();
        rgb.resize(w * h * 3, 0);
        yuv.write_rgb8(&mut rgb);
        width = w as u32;
        height = h as u32;
        times.push(sample.time);
        frame(
            times.len() - 1,
            Image {
                width,
                height,
                rgb: rgb.clone(),
            },
        )?;
    }
    if times.is_empty() {
        return Err(bad("the video track decodes to no frame".into()));
    }
    Ok(VideoInfo { width, height, times })
}

/// What the demuxer found: the parameter sets and the samples with their times.
struct Track {
    sps: Vec<u8>,
    pps: Vec<u8>,
}

struct Sample {
    time: f64,
    bytes: Vec<u8>,
}

fn demux(bytes: &[u8], size: u64) -> Result<(Track, Vec<Sample>), String> {
    let reader = BufReader::new(Cursor::new(bytes));
    let mut mp4 =
        mp4::Mp4Reader::read_header(reader, size).map_err(|e| format!("not a readable MP4 file: {e}"))?;
    let video = mp4
        .tracks()
        .iter()
        .filter(|(_, t)| t.media_type().is_ok_and(|m| m == mp4::MediaType::H264))
        .map(|(id, t)| {
            (
                *id,
                t.timescale(),
                t.sample_count(),
                t.sequence_parameter_set().map(<[u8]>::to_vec),
                t.picture_parameter_set().map(<[u8]>::to_vec),
            )
        })
        .min_by_key(|(id, ..)| *id);
    let Some((id, timescale, count, sps, pps)) = video else {
        return Err("expected an H.264 video track, found none".into());
    };
    let sps = sps.map_err(|e| format!("the H.264 track has no sequence parameter set: {e}"))?;
    let pps = pps.map_err(|e| format!("the H.264 track has no picture parameter set: {e}"))?;
    if timescale == 0 {
        return Err("the video track's timescale is 0".into());
    }
    let mut samples = Vec::with_capacity(count as usize);
    for sample_id in 1..=count {
        let sample = mp4
            .read_sample(id, sample_id)
            .map_err(|e| format!("frame {}: {e} (the file may be truncated)", sample_id - 1))?
            .ok_or_else(|| format!("frame {}: missing (the file may be truncated)", sample_id - 1))?;
        let time = (sample.start_time as f64 + f64::from(sample.rendering_offset)) / f64::from(timescale);
        samples.push(Sample {
            time,
            bytes: sample.bytes.to_vec(),
        });
    }
    Ok((Track { sps, pps }, samples))
}

/// Length-prefixed NAL units (4-byte lengths, as MP4 stores them) as an Annex B stream.
fn annex_b(mut sample: &[u8], out: &mut Vec<u8>) -> Result<(), String> {
    while !sample.is_empty() {
        let Some(length) = sample
            .get(..4)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize)
        else {
            return Err("a NAL unit's length is cut off".into());
        };
        let Some(nal) = sample.get(4..4 + length) else {
            return Err(format!("a NAL unit of {length} bytes runs past the sample's end"));
        };
        out.extend_from_slice(&[0, 0, 0, 1]);
        out.extend_from_slice(nal);
        sample = &sample[4 + length..];
    }
    Ok(())
}

/// Writes `frames` (all of one size, even width and height) as an MP4 file with one H.264
/// track at `fps` frames per second.
pub fn write_mp4(path: &Path, frames: &[Image], fps: f64) -> Result<(), ImportError> {
    let mut writer = VideoWriter::create(path, fps)?;
    for image in frames {
        writer.push(image)?;
    }
    writer.finish().map(|_| ())
}

/// The MP4 track's time units per second.
const TIMESCALE: u32 = 90_000;

/// An MP4 file with one H.264 track, written a frame at a time (a long video is never held
/// in memory): [`VideoWriter::create`], [`VideoWriter::push`] each frame, then
/// [`VideoWriter::finish`].
pub struct VideoWriter {
    path: std::path::PathBuf,
    encoder: openh264::encoder::Encoder,
    /// The file until the first frame gives the track its size and parameter sets.
    file: Option<std::fs::File>,
    writer: Option<mp4::Mp4Writer<std::io::BufWriter<std::fs::File>>>,
    size: (u32, u32),
    tick: u32,
    frames: usize,
}

impl VideoWriter {
    /// Creates `path` for a video at `fps` frames per second.
    pub fn create(path: &Path, fps: f64) -> Result<VideoWriter, ImportError> {
        let fail = |message: String| ImportError::invalid(path, message);
        if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
            return Err(fail(format!(
                "the frame rate must be positive and at most 1000, got {fps}"
            )));
        }
        let config = openh264::encoder::EncoderConfig::new()
            .max_frame_rate(openh264::encoder::FrameRate::from_hz(fps as f32))
            .bitrate(openh264::encoder::BitRate::from_bps(4_000_000));
        let encoder =
            openh264::encoder::Encoder::with_api_config(openh264::OpenH264API::from_source(), config)
                .map_err(|e| fail(format!("starting the H.264 encoder: {e}")))?;
        let file = std::fs::File::create(path).map_err(|e| ImportError::io(path, e))?;
        Ok(VideoWriter {
            path: path.to_owned(),
            encoder,
            file: Some(file),
            writer: None,
            size: (0, 0),
            tick: (f64::from(TIMESCALE) / fps).round() as u32,
            frames: 0,
        })
    }

    fn fail(&self, message: String) -> ImportError {
        ImportError::invalid(&self.path, message)
    }

    /// Encodes and writes the next frame; every frame has the first one's size, which must
    /// be even.
    pub fn push(&mut self, image: &Image) -> Result<(), ImportError> {
        let i = self.frames;
        let (width, height) = (image.width, image.height);
        if i == 0 {
            if width == 0
                || height == 0
                || width % 2 != 0
                || height % 2 != 0
                || width > u32::from(u16::MAX)
                || height > u32::from(u16::MAX)
            {
                return Err(self.fail(format!("H.264 needs an even frame size, got {width}x{height}")));
            }
            self.size = (width, height);
        } else if (width, height) != self.size {
            return Err(self.fail(format!(
                "frame {i} is {width}x{height}, the video {}x{}",
                self.size.0, self.size.1
            )));
        }
        let source = openh264::formats::RgbSliceU8::new(&image.rgb, (width as usize, height as usize));
        let yuv = openh264::formats::YUVBuffer::from_rgb_source(source);
        let stream = self
            .encoder
            .encode(&yuv)
            .map_err(|e| ImportError::invalid(&self.path, format!("frame {i}: H.264: {e}")))?
            .to_vec();
        let mut sample = Vec::with_capacity(stream.len());
        let mut sync = false;
        let (mut sps, mut pps) = (None, None);
        for nal in openh264::nal_units(&stream) {
            let body = strip_start_code(nal);
            match body.first().map(|b| b & 0x1f) {
                Some(7) => sps = Some(body.to_vec()),
                Some(8) => pps = Some(body.to_vec()),
                Some(kind) => {
                    sync |= kind == 5;
                    sample.extend_from_slice(&(body.len() as u32).to_be_bytes());
                    sample.extend_from_slice(body);
                }
                None => {}
            }
        }
        if self.writer.is_none() {
            let (Some(sps), Some(pps), Some(file)) = (sps, pps, self.file.take()) else {
                return Err(self.fail("the encoder gave no parameter sets with the first frame".into()));
            };
            self.writer = Some(self.start(file, sps, pps)?);
        }
        let sample = mp4::Mp4Sample {
            start_time: i as u64 * u64::from(self.tick),
            duration: self.tick,
            rendering_offset: 0,
            is_sync: sync,
            bytes: sample.into(),
        };
        let written = match self.writer.as_mut() {
            Some(writer) => writer.write_sample(1, &sample),
            None => Ok(()),
        };
        written.map_err(|e| self.fail(format!("writing frame {i}: {e}")))?;
        self.frames += 1;
        Ok(())
    }

    /// Starts the MP4 file with its one video track.
    fn start(
        &self,
        file: std::fs::File,
        sps: Vec<u8>,
        pps: Vec<u8>,
    ) -> Result<mp4::Mp4Writer<std::io::BufWriter<std::fs::File>>, ImportError> {
        let config = mp4::Mp4Config {
            major_brand: "isom".parse().map_err(|e| self.fail(format!("{e}")))?,
            minor_version: 512,
            compatible_brands: ["isom", "iso2", "avc1", "mp41"]
                .iter()
                .filter_map(|b| b.parse().ok())
                .collect(),
            timescale: 1000,
        };
        let (width, height) = self.size;
        let start = || -> Result<_, mp4::Error> {
            let mut writer = mp4::Mp4Writer::write_start(std::io::BufWriter::new(file), &config)?;
            writer.add_track(&mp4::TrackConfig {
                track_type: mp4::TrackType::Video,
                timescale: TIMESCALE,
                language: "und".into(),
                media_conf: mp4::MediaConfig::AvcConfig(mp4::AvcConfig {
                    width: width as u16,
                    height: height as u16,
                    seq_param_set: sps,
                    pic_param_set: pps,
                }),
            })?;
            Ok(writer)
        };
        start().map_err(|e| self.fail(format!("writing MP4: {e}")))
    }

    /// Finishes the file (its index goes at the end) and returns the number of frames.
    pub fn finish(mut self) -> Result<usize, ImportError> {
        let Some(mut writer) = self.writer.take() else {
            return Err(self.fail("no frame to write".into()));
        };
        writer
            .write_end()
            .map_err(|e| self.fail(format!("writing MP4: {e}")))?;
        use std::io::Write as _;
        writer
            .into_writer()
            .flush()
            .map_err(|e| ImportError::io(&self.path, e))?;
        Ok(self.frames)
    }
}

/// A NAL unit without its Annex B start code (`00 00 01` or `00 00 00 01`).
fn strip_start_code(nal: &[u8]) -> &[u8] {
    let zeros = nal.iter().take_while(|&&b| b == 0).count();
    if zeros >= 2 && nal.get(zeros) == Some(&1) {
        &nal[zeros + 1..]
    } else {
        nal
    }
}
