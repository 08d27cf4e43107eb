//! Demonstrations: what a recorded (or real-world) demo holds, and how it is stored.
//!
//! A [`Demo`] is its metadata (instruction, objects, embodiment, scenario, version, and
//! optionally the target scene it is meant to be adapted to) plus its keyframes. A keyframe
//! is the initial state or the state after one completed action call (the authors'
//! definition, `docs/benchmark.md` §7); it carries its camera views (plain and labelled), the
//! ground-truth symbolic state when one is known, and the API call that led to it.
//!
//! Two storage layouts are read by [`read`]:
//! - `demo.mcap` (written by [`write_mcap`] / `nesy record`): the topics are listed in
//!   [`mcap_format`] and in the crate README;
//! - a folder with `manifest.json` and `frames/NNNN_<view>.{png,jpg}` ([`read_folder`],
//!   [`write_folder`]), the path for real-world demos: any number of named camera views,
//!   usually no ground-truth states, and possibly a person as the demonstrator.

mod folder;
pub mod mcap_format;
mod record;
mod video;

use std::path::{Path, PathBuf};

use nesy_core::State;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::api::{Embodiment, TraceEntry};
use crate::scene::SceneSpec;

pub use folder::{
    DemoEmbodiment, Manifest, ManifestKeyframe, ViewResolution, frame_file_name, is_view_name,
    manifest_schema, read_folder, view_order_key, write_folder,
};
pub use mcap_format::{read_mcap, read_mcap_bytes, write_mcap, write_mcap_file};
pub use record::{
    ExecutionRecording, ExpertRun, RecordError, RecordOptions, Recording, ReplayDivergence, record_scene,
    record_scene_video, replay_execution, run_expert,
};
pub use video::{
    StateSpan, TrueKeyframe, VIDEO_TRUTH_FILE, VIDEO_TRUTH_VERSION, VideoFrame, VideoOptions, VideoTruth,
    control_rate,
};

/// Version of nesy that wrote a demo (this build's crate version).
pub const NESY_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The eight bytes every PNG file starts with.
pub const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];

/// The three benchmark cameras, in the order prompts show them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CameraName {
    /// Looking down on the table.
    Top,
    /// Facing the robot from beyond the table.
    Front,
    /// From behind the robot.
    Back,
}

impl CameraName {
    /// All three, in prompt order.
    pub const ALL: [CameraName; 3] = [CameraName::Top, CameraName::Front, CameraName::Back];

    /// `top`, `front` or `back` (the renderer's camera names).
    pub fn as_str(self) -> &'static str {
        match self {
            CameraName::Top => "top",
            CameraName::Front => "front",
            CameraName::Back => "back",
        }
    }

    /// The camera of a renderer name.
    pub fn from_name(name: &str) -> Option<CameraName> {
        CameraName::ALL.into_iter().find(|c| c.as_str() == name)
    }
}

/// One camera's images of a keyframe, PNG- or JPEG-encoded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CameraImages {
    /// The plain rendering (or photograph).
    pub raw: Vec<u8>,
    /// The same with object labels (set-of-marks); absent for real-world demos that were
    /// not labelled.
    pub marked: Option<Vec<u8>>,
}

impl CameraImages {
    /// The labelled image if there is one, else the plain one (what a VLM prompt shows).
    pub fn marked_or_raw(&self) -> &[u8] {
        self.marked.as_deref().unwrap_or(&self.raw)
    }
}

/// One named camera view of a keyframe.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NamedView {
    /// The view's name: `top`, `front` or `back` for the simulator; a real demo's own
    /// (`wrist`, `realsense`, ...).
    pub name: String,
    /// Its images.
    pub images: CameraImages,
}

/// The camera views of a keyframe, in the order prompts show them: the simulator's top,
/// front and back, or any number of named views of a real demonstration.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct KeyframeViews {
    views: Vec<NamedView>,
}

impl KeyframeViews {
    /// Views from a list, in prompt order (the readers check that names are unique and the
    /// same at every keyframe).
    pub fn new(views: Vec<NamedView>) -> KeyframeViews {
        KeyframeViews { views }
    }

    /// The images of the view named `name`.
    pub fn get(&self, name: &str) -> Option<&CameraImages> {
        self.views.iter().find(|v| v.name == name).map(|v| &v.images)
    }

    /// The images of the view named `name`, to change them.
    pub fn get_mut(&mut self, name: &str) -> Option<&mut CameraImages> {
        self.views
            .iter_mut()
            .find(|v| v.name == name)
            .map(|v| &mut v.images)
    }

    /// The views, in prompt order.
    pub fn iter(&self) -> std::slice::Iter<'_, NamedView> {
        self.views.iter()
    }

    /// The view names, in prompt order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.views.iter().map(|v| v.name.as_str())
    }

    /// How many views there are.
    pub fn len(&self) -> usize {
        self.views.len()
    }

    /// True when there is no view.
    pub fn is_empty(&self) -> bool {
        self.views.is_empty()
    }

    /// The simulator's three views, built from a function of the camera.
    pub fn from_fn<E>(mut f: impl FnMut(CameraName) -> Result<CameraImages, E>) -> Result<KeyframeViews, E> {
        let mut views = Vec::with_capacity(CameraName::ALL.len());
        for camera in CameraName::ALL {
            views.push(NamedView {
                name: camera.as_str().to_owned(),
                images: f(camera)?,
            });
        }
        Ok(KeyframeViews { views })
    }
}

/// Who gave the demonstration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Demonstrator {
    /// A robot (the simulator's scripted expert, or a teleoperated arm).
    Robot,
    /// A person. Their hand is read as a finger gripper: what the hand grasps, the states
    /// say the gripper holds, so the target robot's procedure follows the same steps.
    Human,
}

/// One keyframe of a demo.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    /// Position in the demo, from 0 (the initial state).
    pub index: usize,
    /// Simulated time in seconds when the keyframe was taken (for real-world demos: as
    /// given in the manifest, else the index).
    pub time: f64,
    /// The camera views (at least one).
    pub views: KeyframeViews,
    /// The ground-truth symbolic state, when known (always for simulated demos).
    pub state: Option<State>,
    /// The completed API call that led to this keyframe, with its result (none for
    /// keyframe 0, and none when a real-world demo does not record it).
    pub action: Option<TraceEntry>,
}

/// What a demo is about.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoMetadata {
    /// The natural-language instruction.
    pub instruction: String,
    /// The scene's object names, in scene order (as `get_obj_names` lists them).
    pub objects: Vec<String>,
    /// The end effector the demonstration's states describe: the demonstrating robot's, or
    /// `finger` for a person's hand.
    pub embodiment: Embodiment,
    /// A robot or a person.
    pub demonstrator: Demonstrator,
    /// Where the demo was imported from, when `nesy demo import` wrote it (free-form JSON:
    /// the source's kind, path and the keyframe choice).
    pub imported_from: Option<serde_json::Value>,
    /// The benchmark scenario the demo was recorded from (e.g. `obst_low_03_s0`).
    pub scenario_id: Option<String>,
    /// Which side of the scenario the demo shows (`source` or `target`).
    pub side: Option<String>,
    /// Version of nesy that recorded it (absent for hand-made real-world folders).
    pub nesy_version: Option<String>,
    /// The scene the demo is to be adapted to, when the recorder knew it.
    pub target_scene: Option<SceneSpec>,
}

/// A demonstration: metadata and keyframes.
#[derive(Clone, Debug, PartialEq)]
pub struct Demo {
    /// What the demo is about.
    pub metadata: DemoMetadata,
    /// Keyframes in time order; `keyframes[k].index == k`.
    pub keyframes: Vec<Keyframe>,
}

impl Demo {
    /// The ground-truth states of all keyframes, or `None` if any keyframe lacks one.
    pub fn states(&self) -> Option<Vec<State>> {
        self.keyframes.iter().map(|k| k.state.clone()).collect()
    }

    /// The API calls between keyframes (`calls[t]` leads from keyframe `t` to `t + 1`), or
    /// `None` if any transition lacks one.
    pub fn calls(&self) -> Option<Vec<TraceEntry>> {
        self.keyframes.iter().skip(1).map(|k| k.action.clone()).collect()
    }
}

/// Why a demo could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The path is neither a `demo.mcap` nor a folder with `manifest.json`.
    #[error(
        "{path}: not a demo: expected a .mcap file, a folder containing demo.mcap, or a folder containing manifest.json"
    )]
    NotADemo {
        /// What was given.
        path: PathBuf,
    },
    /// The MCAP container is damaged: truncated, bad magic, bad record, bad CRC, bad chunk.
    #[error("{path}: corrupt or truncated MCAP file: {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// What the MCAP reader found.
        source: mcap::McapError,
    },
    /// A topic the demo format requires has no channel in the file.
    #[error("{path}: missing topic {topic}: expected a channel for it (a nesy demo has {expected})")]
    MissingTopic {
        /// The file.
        path: PathBuf,
        /// The missing topic.
        topic: String,
        /// The list of required topics.
        expected: String,
    },
    /// The metadata record is absent.
    #[error(
        "{path}: missing metadata record {name:?}: expected one with instruction, objects and embodiment"
    )]
    MissingMetadata {
        /// The file.
        path: PathBuf,
        /// Its expected name.
        name: String,
    },
    /// A JSON document (message, metadata value or manifest) does not parse or does not
    /// have the expected shape.
    #[error("{path}: {location}: at {field}: {message}")]
    Json {
        /// The file.
        path: PathBuf,
        /// Where in the file: a topic and keyframe, a metadata key, or the manifest line.
        location: String,
        /// The JSON path of the offending value (`.` for the whole document).
        field: String,
        /// What serde expected.
        message: String,
    },
    /// A value parsed but is not acceptable.
    #[error("{path}: {location}: expected {expected}, found {found}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Where in the file: a topic and keyframe, a metadata key, a frame file.
        location: String,
        /// What would have been acceptable.
        expected: String,
        /// What was there.
        found: String,
    },
}

impl DemoError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> DemoError {
        DemoError::Io {
            path: path.to_owned(),
            source,
        }
    }

    pub(crate) fn invalid(
        path: &Path,
        location: impl Into<String>,
        expected: impl Into<String>,
        found: impl Into<String>,
    ) -> DemoError {
        DemoError::Invalid {
            path: path.to_owned(),
            location: location.into(),
            expected: expected.into(),
            found: found.into(),
        }
    }

    /// Parses JSON into `T`, reporting the JSON path of a mismatch.
    pub(crate) fn parse_json<T: serde::de::DeserializeOwned>(
        path: &Path,
        location: &str,
        text: &[u8],
    ) -> Result<T, DemoError> {
        let de = &mut serde_json::Deserializer::from_slice(text);
        serde_path_to_error::deserialize(de).map_err(|e| {
            let field = e.path().to_string();
            DemoError::Json {
                path: path.to_owned(),
                location: location.to_owned(),
                field,
                message: e.into_inner().to_string(),
            }
        })
    }
}

/// The eight bytes every PNG file starts with are [`PNG_SIGNATURE`]; a JPEG file starts
/// with these three.
pub const JPEG_SIGNATURE: [u8; 3] = [0xFF, 0xD8, 0xFF];

/// The encoding of a demo image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// PNG.
    Png,
    /// JPEG.
    Jpeg,
}

impl ImageFormat {
    /// The format of `bytes`, from their signature.
    pub fn of(bytes: &[u8]) -> Option<ImageFormat> {
        if bytes.starts_with(&PNG_SIGNATURE) {
            Some(ImageFormat::Png)
        } else if bytes.starts_with(&JPEG_SIGNATURE) {
            Some(ImageFormat::Jpeg)
        } else {
            None
        }
    }

    /// The file extension the folder layout writes: `png` or `jpg`.
    pub fn extension(self) -> &'static str {
        match self {
            ImageFormat::Png => "png",
            ImageFormat::Jpeg => "jpg",
        }
    }

    /// The media type: `image/png` or `image/jpeg`.
    pub fn mime(self) -> &'static str {
        match self {
            ImageFormat::Png => "image/png",
            ImageFormat::Jpeg => "image/jpeg",
        }
    }
}

/// Width and height of a PNG (from its header) or a JPEG (from its frame header), without
/// decoding the pixels; `None` when the header is missing or damaged.
///
/// ```
/// use nesy_sim::demo::image_size;
///
/// let image = nesy_sim::perception::render::Image { width: 5, height: 3, rgb: vec![0; 45] };
/// let png = image.to_png();
/// assert_eq!(image_size(&png), Some((5, 3)));
/// assert_eq!(image_size(b"not an image"), None);
/// ```
pub fn image_size(bytes: &[u8]) -> Option<(u32, u32)> {
    match ImageFormat::of(bytes)? {
        ImageFormat::Png => {
            // The IHDR chunk comes first: length, "IHDR", width, height (big-endian).
            let header = bytes.get(12..24)?;
            if &header[..4] != b"IHDR" {
                return None;
            }
            let width = u32::from_be_bytes(header[4..8].try_into().ok()?);
            let height = u32::from_be_bytes(header[8..12].try_into().ok()?);
            (width > 0 && height > 0).then_some((width, height))
        }
        ImageFormat::Jpeg => {
            // Walk the marker segments to the first start-of-frame (SOF0..SOF15 except the
            // DHT, JPG and DAC markers), whose payload gives precision, height and width.
            let mut at = 2;
            loop {
                while bytes.get(at) == Some(&0xFF) && bytes.get(at + 1) == Some(&0xFF) {
                    at += 1;
                }
                if bytes.get(at) != Some(&0xFF) {
                    return None;
                }
                let marker = *bytes.get(at + 1)?;
                let length = u16::from_be_bytes([*bytes.get(at + 2)?, *bytes.get(at + 3)?]) as usize;
                let is_frame = (0xC0..=0xCF).contains(&marker) && !matches!(marker, 0xC4 | 0xC8 | 0xCC);
                if is_frame {
                    let height = u16::from_be_bytes([*bytes.get(at + 5)?, *bytes.get(at + 6)?]) as u32;
                    let width = u16::from_be_bytes([*bytes.get(at + 7)?, *bytes.get(at + 8)?]) as u32;
                    return (width > 0 && height > 0).then_some((width, height));
                }
                if marker == 0xD9 || marker == 0xDA || length < 2 {
                    return None;
                }
                at += 2 + length;
            }
        }
    }
}

/// Checks that `bytes` are a PNG or JPEG image with a readable size, and returns its format
/// and size.
pub(crate) fn check_image(
    path: &Path,
    location: &str,
    bytes: &[u8],
) -> Result<(ImageFormat, (u32, u32)), DemoError> {
    let head = || {
        let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
        if head.is_empty() {
            "no data".to_owned()
        } else {
            format!("bytes {}", head.join(" "))
        }
    };
    let Some(format) = ImageFormat::of(bytes) else {
        return Err(DemoError::invalid(
            path,
            location,
            "PNG data (starting 89 50 4e 47 0d 0a 1a 0a) or JPEG data (starting ff d8 ff)",
            head(),
        ));
    };
    let size = image_size(bytes).ok_or_else(|| {
        DemoError::invalid(
            path,
            location,
            format!(
                "a {} image with a readable header",
                format.extension().to_uppercase()
            ),
            "a truncated or damaged header",
        )
    })?;
    Ok((format, size))
}

/// Checks that `bytes` are a PNG image (the MCAP layout stores PNG only).
pub(crate) fn check_png(path: &Path, location: &str, bytes: &[u8]) -> Result<(), DemoError> {
    match ImageFormat::of(bytes) {
        Some(ImageFormat::Png) => Ok(()),
        _ => {
            let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
            Err(DemoError::invalid(
                path,
                location,
                "PNG data (starting 89 50 4e 47 0d 0a 1a 0a)",
                if head.is_empty() {
                    "no data".to_owned()
                } else {
                    format!("bytes {}", head.join(" "))
                },
            ))
        }
    }
}

/// Reads a demo from `path`: a `.mcap` file, a folder holding `demo.mcap`, or a folder
/// holding `manifest.json` and `frames/` (or that `manifest.json` itself).
pub fn read(path: impl AsRef<Path>) -> Result<Demo, DemoError> {
    let path = path.as_ref();
    let meta = std::fs::metadata(path).map_err(|e| DemoError::io(path, e))?;
    if meta.is_dir() {
        let mcap = path.join("demo.mcap");
        if mcap.is_file() {
            return read_mcap(&mcap);
        }
        if path.join(folder::MANIFEST_FILE).is_file() {
            return read_folder(path);
        }
        return Err(DemoError::NotADemo {
            path: path.to_owned(),
        });
    }
    if path.file_name().is_some_and(|n| n == folder::MANIFEST_FILE) {
        return read_folder(path.parent().unwrap_or(Path::new(".")));
    }
    if path.extension().is_some_and(|e| e == "mcap") {
        return read_mcap(path);
    }
    Err(DemoError::NotADemo {
        path: path.to_owned(),
    })
}
