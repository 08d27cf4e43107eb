//! The folder layout of a demo: the path for real-world demonstrations, which have camera
//! images but usually no ground-truth states or recorded API calls.
//!
//! ```text
//! <dir>/manifest.json
//! <dir>/frames/0000_top.png   0000_front.png   0000_back.png
//! <dir>/frames/0000_top_marked.png ...          (optional labelled views)
//! <dir>/frames/0001_top.png ...
//! ```
//!
//! Frames are `NNNN_<view>.png`, `.jpg` or `.jpeg`: a four-digit keyframe number, then the
//! view's name (lower-case letters, digits, `_` and `-`; the simulator's are `top`, `front`
//! and `back`, a real demo's may be one camera of any name). Every keyframe has every view,
//! each view keeps one resolution throughout, and a `_marked` labelled version of a view is
//! optional.
//!
//! `manifest.json` ([`Manifest`], schema `assets/schema/demo-manifest.schema.json`):
//!
//! ```json
//! {
//!   "format_version": 1,
//!   "instruction": "Place the cube blocks in to the box.",
//!   "objects": ["red_cube", "blue_cube", "toy_box"],
//!   "embodiment": "finger",
//!   "keyframes": [ {"time": 0.0}, {"time": 4.2, "state": ["(GripperClosed)"]} ]
//! }
//! ```
//!
//! `embodiment` is `finger`, `vacuum` or `human` (a person's hand, read as a finger
//! gripper). Optional keys: `views` (the view names in prompt order; by default the
//! simulator's top, front and back first, then the others by name), `scenario_id`, `side`,
//! `nesy_version`, `target_scene` (an inline `scene.json` document), `imported_from` (what
//! `nesy demo import` read) and `keyframes`. Without `keyframes`, the keyframes are the frame
//! numbers found in `frames/` (0000, 0001, ... with no gaps). With it, there must be exactly
//! one entry per frame number; each entry may give `time` (seconds), `state` (the true
//! atoms, e.g. `"(OnTopOf red_cube floor)"`) and `action` (a nesy-sim trace entry).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{
    CameraImages, CameraName, Demo, DemoError, DemoMetadata, Demonstrator, ImageFormat, Keyframe,
    KeyframeViews, NamedView, check_image,
};
use crate::api::{Embodiment, TraceEntry};
use crate::scene::SceneSpec;

/// File name of the manifest.
pub(super) const MANIFEST_FILE: &str = "manifest.json";
/// Folder of the frames.
pub(super) const FRAMES_DIR: &str = "frames";
/// The manifest format version this build reads and writes.
pub(super) const MANIFEST_VERSION: u32 = 1;

/// `manifest.json` of a demo folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(rename = "DemoManifest")]
pub struct Manifest {
    /// Format version; must be 1.
    pub format_version: u32,
    /// The natural-language instruction.
    pub instruction: String,
    /// Object names in the scene.
    pub objects: Vec<String>,
    /// The demonstrator: a robot's end effector (`finger` or `vacuum`) or `human`.
    pub embodiment: DemoEmbodiment,
    /// The view names in prompt order (by default: top, front and back first, then the
    /// others by name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub views: Option<Vec<String>>,
    /// Benchmark scenario id, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scenario_id: Option<String>,
    /// `source` or `target`, if from a scenario.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<String>,
    /// Version of nesy that wrote the folder, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nesy_version: Option<String>,
    /// The scene the demo is to be adapted to, inline.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_scene: Option<SceneSpec>,
    /// What `nesy demo import` read to write this folder (its kind, path and keyframe
    /// choice).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(with = "Option<serde_json::Map<String, serde_json::Value>>")]
    pub imported_from: Option<serde_json::Value>,
    /// One entry per keyframe; when absent, the keyframes are the frames in `frames/`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub keyframes: Option<Vec<ManifestKeyframe>>,
}

/// Who demonstrated, as a manifest writes it: a robot's end effector, or a person.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DemoEmbodiment {
    /// A robot with a two-finger gripper.
    Finger,
    /// A robot with a vacuum suction tool.
    Vacuum,
    /// A person; the hand is read as a finger gripper.
    Human,
}

impl DemoEmbodiment {
    /// The end effector the states describe, and who demonstrated.
    pub fn split(self) -> (Embodiment, Demonstrator) {
        match self {
            DemoEmbodiment::Finger => (Embodiment::Finger, Demonstrator::Robot),
            DemoEmbodiment::Vacuum => (Embodiment::Vacuum, Demonstrator::Robot),
            DemoEmbodiment::Human => (Embodiment::Finger, Demonstrator::Human),
        }
    }

    /// The manifest's word for a demo's metadata.
    pub fn of(embodiment: Embodiment, demonstrator: Demonstrator) -> DemoEmbodiment {
        match (demonstrator, embodiment) {
            (Demonstrator::Human, _) => DemoEmbodiment::Human,
            (Demonstrator::Robot, Embodiment::Finger) => DemoEmbodiment::Finger,
            (Demonstrator::Robot, Embodiment::Vacuum) => DemoEmbodiment::Vacuum,
        }
    }
}

/// What the manifest may say about one keyframe.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ManifestKeyframe {
    /// Time in seconds from the start of the demo.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<f64>,
    /// Ground-truth atoms, e.g. `(InsideOf apple hinge_body)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(with = "Option<Vec<String>>")]
    pub state: Option<nesy_core::State>,
    /// The API call that led to this keyframe (a nesy-sim trace entry).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(with = "Option<serde_json::Map<String, serde_json::Value>>")]
    pub action: Option<TraceEntry>,
}

/// JSON Schema of `manifest.json`.
pub fn manifest_schema() -> String {
    let mut text = serde_json::to_string_pretty(&schemars::schema_for!(Manifest)).unwrap_or_default();
    text.push('\n');
    text
}

/// The file name of one frame: `NNNN_<view>[_marked].<png|jpg>`.
pub fn frame_file_name(index: usize, view: &str, marked: bool, format: ImageFormat) -> String {
    let suffix = if marked { "_marked" } else { "" };
    format!("{index:04}_{view}{suffix}.{}", format.extension())
}

/// A view name: lower-case ASCII letters, digits, `_` and `-`, starting with a letter or a
/// digit, and not itself ending in `_marked` (that suffix names a view's labelled frames).
pub fn is_view_name(name: &str) -> bool {
    name.bytes()
        .next()
        .is_some_and(|b| b.is_ascii_lowercase() || b.is_ascii_digit())
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
        && !name.ends_with("_marked")
}

/// Parses a frame file name into (index, view, marked).
fn parse_frame_name(name: &str) -> Option<(usize, &str, bool)> {
    let stem = [".png", ".jpg", ".jpeg"]
        .iter()
        .find_map(|ext| name.strip_suffix(ext))?;
    let (digits, rest) = stem.split_once('_')?;
    if digits.len() != 4 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let (view, marked) = match rest.strip_suffix("_marked") {
        Some(v) => (v, true),
        None => (rest, false),
    };
    is_view_name(view).then_some((digits.parse().ok()?, view, marked))
}

fn read_file(path: &Path) -> Result<Vec<u8>, DemoError> {
    nesy_input::read_bytes(path, nesy_input::MAX_IMAGE_BYTES).map_err(|e| DemoError::io(path, e))
}

/// The key that sorts views into their default prompt order: the simulator's cameras first
/// (top, front, back), then the others by name.
pub fn view_order_key(name: &str) -> (usize, String) {
    let rank = CameraName::from_name(name).map_or(CameraName::ALL.len(), |c| c as usize);
    (rank, name.to_owned())
}

/// The default prompt order of views ([`view_order_key`]), each name once.
fn default_view_order(names: impl IntoIterator<Item = String>) -> Vec<String> {
    let mut names: Vec<String> = names.into_iter().collect();
    names.sort_by_key(|n| view_order_key(n));
    names.dedup();
    names
}

/// The resolution one view keeps: set by its first frame, checked for every later one.
#[derive(Debug, Clone, Default)]
pub struct ViewResolution {
    /// The first frame's size and file.
    first: Option<((u32, u32), PathBuf)>,
}

impl ViewResolution {
    /// Reads a frame file of the view: PNG or JPEG, with a readable header, of the size of
    /// the view's first frame (the first call sets it). The error names the file, and the
    /// first frame when the sizes differ.
    pub fn read_frame(&mut self, path: &Path) -> Result<Vec<u8>, DemoError> {
        let bytes = read_file(path)?;
        let (_, found) = check_image(path, "frame", &bytes)?;
        match &self.first {
            Some((expected, first)) if *expected != found => Err(DemoError::invalid(
                path,
                "frame",
                format!(
                    "{}x{} pixels, the resolution of this view's other frames ({})",
                    expected.0,
                    expected.1,
                    first.display()
                ),
                format!("{}x{}", found.0, found.1),
            )),
            Some(_) => Ok(bytes),
            None => {
                self.first = Some((found, path.to_owned()));
                Ok(bytes)
            }
        }
    }
}

/// Reads a demo folder.
pub fn read_folder(dir: &Path) -> Result<Demo, DemoError> {
    let manifest_path = dir.join(MANIFEST_FILE);
    let text = read_file(&manifest_path)?;
    let manifest: Manifest = DemoError::parse_json(&manifest_path, "manifest", &text)?;
    if manifest.format_version != MANIFEST_VERSION {
        return Err(DemoError::invalid(
            &manifest_path,
            "field format_version",
            MANIFEST_VERSION.to_string(),
            manifest.format_version.to_string(),
        ));
    }

    // Frame files by index, then view and labelling.
    let frames_dir = dir.join(FRAMES_DIR);
    let mut found: BTreeMap<usize, BTreeMap<(String, bool), PathBuf>> = BTreeMap::new();
    let entries = std::fs::read_dir(&frames_dir).map_err(|e| DemoError::io(&frames_dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| DemoError::io(&frames_dir, e))?;
        let name = entry.file_name();
        let Some((index, view, marked)) = name.to_str().and_then(parse_frame_name) else {
            continue;
        };
        if let Some(twin) = found.get(&index).and_then(|f| f.get(&(view.to_owned(), marked))) {
            return Err(DemoError::invalid(
                &entry.path(),
                "frame",
                "one file per keyframe and view",
                format!("a second file beside {}", twin.display()),
            ));
        }
        found
            .entry(index)
            .or_default()
            .insert((view.to_owned(), marked), entry.path());
    }
    let count = match &manifest.keyframes {
        Some(list) => list.len(),
        None => found.keys().next_back().map_or(0, |last| last + 1),
    };
    if count == 0 {
        return Err(DemoError::invalid(
            &frames_dir,
            "frames",
            "at least one keyframe (files such as 0000_top.png or 0000_camera.jpg)",
            "no frame files",
        ));
    }
    if let Some((&extra, _)) = found.range(count..).next() {
        return Err(DemoError::invalid(
            &manifest_path,
            "field keyframes",
            format!("one entry per frame number in frames/ (frame {extra:04} exists)"),
            format!("{count} entries"),
        ));
    }

    // The views: as the manifest lists them, or the plain views of the first keyframe.
    let views: Vec<String> = match &manifest.views {
        Some(list) => {
            if list.is_empty() {
                return Err(DemoError::invalid(
                    &manifest_path,
                    "field views",
                    "at least one view name",
                    "[]",
                ));
            }
            for (i, name) in list.iter().enumerate() {
                if !is_view_name(name) || list[..i].contains(name) {
                    return Err(DemoError::invalid(
                        &manifest_path,
                        format!("field views[{i}]"),
                        "a unique view name of lower-case letters, digits, `_` and `-`",
                        format!("{name:?}"),
                    ));
                }
            }
            list.clone()
        }
        None => default_view_order(
            found
                .get(&0)
                .into_iter()
                .flat_map(|f| f.keys())
                .filter(|(_, marked)| !marked)
                .map(|(view, _)| view.clone()),
        ),
    };
    if views.is_empty() {
        return Err(DemoError::invalid(
            &frames_dir.join("0000_<view>.png"),
            "frame",
            "the first keyframe's views (a file such as 0000_top.png or 0000_camera.jpg)",
            "no such file",
        ));
    }

    let mut sizes: BTreeMap<(String, bool), ViewResolution> = BTreeMap::new();
    let mut keyframes = Vec::with_capacity(count);
    for k in 0..count {
        let files = found.get(&k);
        if let Some(((stray, _), path)) = files
            .into_iter()
            .flat_map(|f| f.iter())
            .find(|((view, _), _)| !views.contains(view))
        {
            return Err(DemoError::invalid(
                path,
                "frame",
                format!("a frame of one of the demo's views ({})", views.join(", ")),
                format!("a frame of view `{stray}`"),
            ));
        }
        let mut named = Vec::with_capacity(views.len());
        for view in &views {
            let raw_path = files.and_then(|f| f.get(&(view.clone(), false))).ok_or_else(|| {
                let expected = frames_dir.join(frame_file_name(k, view, false, ImageFormat::Png));
                DemoError::invalid(
                    &expected,
                    "frame",
                    format!(
                        "a PNG or JPEG file (every keyframe has every view: {})",
                        views.join(", ")
                    ),
                    "no such file",
                )
            })?;
            let raw = sizes
                .entry((view.clone(), false))
                .or_default()
                .read_frame(raw_path)?;
            let marked = match files.and_then(|f| f.get(&(view.clone(), true))) {
                Some(p) => Some(sizes.entry((view.clone(), true)).or_default().read_frame(p)?),
                None => None,
            };
            named.push(NamedView {
                name: view.clone(),
                images: CameraImages { raw, marked },
            });
        }
        let entry = manifest
            .keyframes
            .as_ref()
            .and_then(|list| list.get(k).cloned())
            .unwrap_or_default();
        keyframes.push(Keyframe {
            index: k,
            time: entry.time.unwrap_or(k as f64),
            views: KeyframeViews::new(named),
            state: entry.state,
            action: entry.action,
        });
    }
    let (embodiment, demonstrator) = manifest.embodiment.split();
    let metadata = DemoMetadata {
        instruction: manifest.instruction,
        objects: manifest.objects,
        embodiment,
        demonstrator,
        imported_from: manifest.imported_from,
        scenario_id: manifest.scenario_id,
        side: manifest.side,
        nesy_version: manifest.nesy_version,
        target_scene: manifest.target_scene,
    };
    Ok(Demo { metadata, keyframes })
}

/// Writes `demo` in the folder layout (all keyframe fields included in the manifest; the
/// view order is recorded when it differs from the default).
pub fn write_folder(demo: &Demo, dir: &Path) -> Result<(), DemoError> {
    let frames_dir = dir.join(FRAMES_DIR);
    std::fs::create_dir_all(&frames_dir).map_err(|e| DemoError::io(&frames_dir, e))?;
    for keyframe in &demo.keyframes {
        for view in keyframe.views.iter() {
            let mut files = vec![(false, &view.images.raw)];
            if let Some(marked) = &view.images.marked {
                files.push((true, marked));
            }
            for (marked, bytes) in files {
                let format = ImageFormat::of(bytes).unwrap_or(ImageFormat::Png);
                let path = frames_dir.join(frame_file_name(keyframe.index, &view.name, marked, format));
                std::fs::write(&path, bytes).map_err(|e| DemoError::io(&path, e))?;
            }
        }
    }
    let m = &demo.metadata;
    let names: Vec<String> = demo
        .keyframes
        .first()
        .map(|k| k.views.names().map(str::to_owned).collect())
        .unwrap_or_default();
    let views = (names != default_view_order(names.clone())).then_some(names);
    let manifest = Manifest {
        format_version: MANIFEST_VERSION,
        instruction: m.instruction.clone(),
        objects: m.objects.clone(),
        embodiment: DemoEmbodiment::of(m.embodiment, m.demonstrator),
        views,
        scenario_id: m.scenario_id.clone(),
        side: m.side.clone(),
        nesy_version: m.nesy_version.clone(),
        target_scene: m.target_scene.clone(),
        imported_from: m.imported_from.clone(),
        keyframes: Some(
            demo.keyframes
                .iter()
                .map(|k| ManifestKeyframe {
                    time: Some(k.time),
                    state: k.state.clone(),
                    action: k.action.clone(),
                })
                .collect(),
        ),
    };
    let path = dir.join(MANIFEST_FILE);
    let mut text = serde_json::to_string_pretty(&manifest).unwrap_or_default();
    text.push('\n');
    std::fs::write(&path, text).map_err(|e| DemoError::io(&path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_names_parse() {
        assert_eq!(parse_frame_name("0003_top.png"), Some((3, "top", false)));
        assert_eq!(parse_frame_name("0012_back_marked.png"), Some((12, "back", true)));
        assert_eq!(
            parse_frame_name("0001_realsense.jpg"),
            Some((1, "realsense", false))
        );
        assert_eq!(
            parse_frame_name("0001_wrist-cam_marked.jpeg"),
            Some((1, "wrist-cam", true))
        );
        assert_eq!(parse_frame_name("12_back.png"), None);
        assert_eq!(parse_frame_name("0001_Top.png"), None);
        assert_eq!(parse_frame_name("0001_top.gif"), None);
        assert_eq!(parse_frame_name("0001_.png"), None);
        for view in ["top", "side_2"] {
            for format in [ImageFormat::Png, ImageFormat::Jpeg] {
                let name = frame_file_name(7, view, true, format);
                assert_eq!(parse_frame_name(&name), Some((7, view, true)));
            }
        }
    }

    #[test]
    fn the_simulator_views_come_first() {
        let order = default_view_order(["wrist", "back", "top", "aux", "front"].map(String::from));
        assert_eq!(order, ["top", "front", "back", "aux", "wrist"]);
    }
}
