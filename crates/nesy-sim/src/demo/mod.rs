//! Demonstrations: what a recorded (or real-world) demo holds, and how it is stored.
//!
//! A [`Demo`] is its metadata (instruction, objects, embodiment, scenario, version, and
//! optionally the target scene it is meant to be adapted to) plus its keyframes. A keyframe
//! is the initial state or the state after one completed action call (the authors'
//! definition, `docs/benchmark.md` §7); it carries the three camera views (plain and labelled PNG), the
//! ground-truth symbolic state when one is known, and the API call that led to it.
//!
//! Two storage layouts are read by [`read`]:
//! - `demo.mcap` (written by [`write_mcap`] / `nesy record`): the topics are listed in
//!   [`mcap_format`] and in the crate README;
//! - a folder with `manifest.json` and `frames/NNNN_{top,front,back}.png` ([`read_folder`], [`write_folder`]), the
//!   path for real-world demos, which have images but no ground-truth states.

mod folder;
pub mod mcap_format;
mod record;

use std::path::{Path, PathBuf};

use nesy_core::State;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::api::{Embodiment, TraceEntry};
use crate::scene::SceneSpec;

pub use folder::{Manifest, ManifestKeyframe, frame_file_name, manifest_schema, read_folder, write_folder};
pub use mcap_format::{read_mcap, read_mcap_bytes, write_mcap, write_mcap_file};
pub use record::{ExpertRun, RecordError, RecordOptions, Recording, record_scene, run_expert};

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

/// One camera's images of a keyframe, PNG-encoded.
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

/// The three views of a keyframe.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyframeViews {
    /// Top camera.
    pub top: CameraImages,
    /// Front camera.
    pub front: CameraImages,
    /// Back camera.
    pub back: CameraImages,
}

impl KeyframeViews {
    /// The images of one camera.
    pub fn get(&self, camera: CameraName) -> &CameraImages {
        match camera {
            CameraName::Top => &self.top,
            CameraName::Front => &self.front,
            CameraName::Back => &self.back,
        }
    }

    /// Builds the views from a function of the camera.
    pub fn from_fn<E>(mut f: impl FnMut(CameraName) -> Result<CameraImages, E>) -> Result<KeyframeViews, E> {
        Ok(KeyframeViews {
            top: f(CameraName::Top)?,
            front: f(CameraName::Front)?,
            back: f(CameraName::Back)?,
        })
    }
}

/// One keyframe of a demo.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    /// Position in the demo, from 0 (the initial state).
    pub index: usize,
    /// Simulated time in seconds when the keyframe was taken (for real-world demos: as
    /// given in the manifest, else the index).
    pub time: f64,
    /// The camera views.
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
    /// The demonstrating robot's end effector.
    pub embodiment: Embodiment,
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

/// Checks that `bytes` are a PNG image.
pub(crate) fn check_png(path: &Path, location: &str, bytes: &[u8]) -> Result<(), DemoError> {
    if bytes.starts_with(&PNG_SIGNATURE) {
        Ok(())
    } else {
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
