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
//! Optional keys: `scenario_id`, `side`, `nesy_version`, `target_scene` (an inline
//! `scene.json` document) and `keyframes`. Without `keyframes`, the keyframes are the
//! frame numbers found in `frames/` (0000, 0001, ... with no gaps). With it, there must be
//! exactly one entry per frame number; each entry may give `time` (seconds), `state` (the
//! true atoms, e.g. `"(OnTopOf red_cube floor)"`) and `action` (a nesy-sim trace entry).
//! Frame numbers have four digits; the plain top, front and back views are required for
//! every keyframe, the `_marked` ones are optional.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::{CameraImages, CameraName, Demo, DemoError, DemoMetadata, Keyframe, KeyframeViews, check_png};
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
    /// The demonstrating robot's end effector: `finger` or `vacuum`.
    pub embodiment: Embodiment,
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
    /// One entry per keyframe; when absent, the keyframes are the frames in `frames/`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub keyframes: Option<Vec<ManifestKeyframe>>,
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

/// The file name of one frame: `NNNN_<camera>[_marked].png`.
pub fn frame_file_name(index: usize, camera: CameraName, marked: bool) -> String {
    let suffix = if marked { "_marked" } else { "" };
    format!("{index:04}_{}{suffix}.png", camera.as_str())
}

/// Parses a frame file name into (index, camera, marked).
fn parse_frame_name(name: &str) -> Option<(usize, CameraName, bool)> {
    let stem = name.strip_suffix(".png")?;
    let (digits, rest) = stem.split_once('_')?;
    if digits.len() != 4 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let (camera, marked) = match rest.strip_suffix("_marked") {
        Some(c) => (c, true),
        None => (rest, false),
    };
    Some((digits.parse().ok()?, CameraName::from_name(camera)?, marked))
}

fn read_file(path: &Path) -> Result<Vec<u8>, DemoError> {
    nesy_input::read_bytes(path, nesy_input::MAX_IMAGE_BYTES).map_err(|e| DemoError::io(path, e))
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

    // Frame files by index.
    let frames_dir = dir.join(FRAMES_DIR);
    let mut found: BTreeMap<usize, BTreeMap<(CameraName, bool), PathBuf>> = BTreeMap::new();
    let entries = std::fs::read_dir(&frames_dir).map_err(|e| DemoError::io(&frames_dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| DemoError::io(&frames_dir, e))?;
        let name = entry.file_name();
        if let Some((index, camera, marked)) = name.to_str().and_then(parse_frame_name) {
            found
                .entry(index)
                .or_default()
                .insert((camera, marked), entry.path());
        }
    }
    let count = match &manifest.keyframes {
        Some(list) => list.len(),
        None => found.keys().next_back().map_or(0, |last| last + 1),
    };
    if count == 0 {
        return Err(DemoError::invalid(
            &frames_dir,
            "frames",
            "at least one keyframe (files 0000_top.png, 0000_front.png, 0000_back.png)",
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

    let mut keyframes = Vec::with_capacity(count);
    for k in 0..count {
        let files = found.get(&k);
        let views = KeyframeViews::from_fn(|camera| {
            let raw_path = files.and_then(|f| f.get(&(camera, false))).ok_or_else(|| {
                let expected = frames_dir.join(frame_file_name(k, camera, false));
                DemoError::invalid(
                    &expected,
                    "frame",
                    "a PNG file (every keyframe has top, front and back)",
                    "no such file",
                )
            })?;
            let raw = read_file(raw_path)?;
            check_png(raw_path, "frame", &raw)?;
            let marked = match files.and_then(|f| f.get(&(camera, true))) {
                Some(p) => {
                    let bytes = read_file(p)?;
                    check_png(p, "frame", &bytes)?;
                    Some(bytes)
                }
                None => None,
            };
            Ok(CameraImages { raw, marked })
        })?;
        let entry = manifest
            .keyframes
            .as_ref()
            .and_then(|list| list.get(k).cloned())
            .unwrap_or_default();
        keyframes.push(Keyframe {
            index: k,
            time: entry.time.unwrap_or(k as f64),
            views,
            state: entry.state,
            action: entry.action,
        });
    }
    let metadata = DemoMetadata {
        instruction: manifest.instruction,
        objects: manifest.objects,
        embodiment: manifest.embodiment,
        scenario_id: manifest.scenario_id,
        side: manifest.side,
        nesy_version: manifest.nesy_version,
        target_scene: manifest.target_scene,
    };
    Ok(Demo { metadata, keyframes })
}

/// Writes `demo` in the folder layout (all keyframe fields included in the manifest).
pub fn write_folder(demo: &Demo, dir: &Path) -> Result<(), DemoError> {
    let frames_dir = dir.join(FRAMES_DIR);
    std::fs::create_dir_all(&frames_dir).map_err(|e| DemoError::io(&frames_dir, e))?;
    for keyframe in &demo.keyframes {
        for camera in CameraName::ALL {
            let images = keyframe.views.get(camera);
            let mut files = vec![(false, &images.raw)];
            if let Some(marked) = &images.marked {
                files.push((true, marked));
            }
            for (marked, bytes) in files {
                let path = frames_dir.join(frame_file_name(keyframe.index, camera, marked));
                std::fs::write(&path, bytes).map_err(|e| DemoError::io(&path, e))?;
            }
        }
    }
    let m = &demo.metadata;
    let manifest = Manifest {
        format_version: MANIFEST_VERSION,
        instruction: m.instruction.clone(),
        objects: m.objects.clone(),
        embodiment: m.embodiment,
        scenario_id: m.scenario_id.clone(),
        side: m.side.clone(),
        nesy_version: m.nesy_version.clone(),
        target_scene: m.target_scene.clone(),
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
        assert_eq!(
            parse_frame_name("0003_top.png"),
            Some((3, CameraName::Top, false))
        );
        assert_eq!(
            parse_frame_name("0012_back_marked.png"),
            Some((12, CameraName::Back, true))
        );
        assert_eq!(parse_frame_name("12_back.png"), None);
        assert_eq!(parse_frame_name("0001_side.png"), None);
        assert_eq!(parse_frame_name("0001_top.jpg"), None);
        for camera in CameraName::ALL {
            let name = frame_file_name(7, camera, true);
            assert_eq!(parse_frame_name(&name), Some((7, camera, true)));
        }
    }
}
