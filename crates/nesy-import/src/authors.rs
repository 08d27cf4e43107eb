//! The authors' demo format: `data.json` (instruction, objects, and the symbolic state of
//! every keyframe) and `frames/<view>/frame_<i>.jpg`, with `<view>_marked` for the labelled
//! views.
//!
//! ```text
//! <dir>/data.json
//! <dir>/frames/top/frame_0.jpg  frame_1.jpg ...
//! <dir>/frames/top_marked/frame_0.jpg ...
//! <dir>/frames/front/...  front_marked/  back/  back_marked/
//! ```
//!
//! `data.json` holds `instruction` (text), `objects` (names), `object_states` (one entry per
//! keyframe: a list of atoms such as `"(OnTopOf red_cube floor)"`, or one text with an
//! atom per line) and `additional_context` (`"None"` in the authors' demos; kept in the
//! import record otherwise). The format stores no times: keyframe `i` is given time `i`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nesy_core::{Atom, State};
use serde_json::Value;

use crate::error::ImportError;
use nesy_sim::demo::{is_view_name, view_order_key};

/// The data file's name.
pub const DATA_FILE: &str = "data.json";

/// One view's frames, one per keyframe: the plain frame and its labelled version.
pub type ViewFrames = Vec<(PathBuf, Option<PathBuf>)>;

/// What the authors' folder holds, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct AuthorsDemo {
    /// The instruction.
    pub instruction: String,
    /// The object names.
    pub objects: Vec<String>,
    /// The symbolic state of each keyframe.
    pub states: Vec<State>,
    /// `additional_context`, unless absent or `"None"`.
    pub context: Option<String>,
    /// Per view (prompt order): its name, and each keyframe's plain and labelled frame.
    pub views: Vec<(String, ViewFrames)>,
}

/// Reads an authors' demo folder; errors name the file and the field or frame.
pub fn read_authors_demo(dir: &Path) -> Result<AuthorsDemo, ImportError> {
    let data_path = dir.join(DATA_FILE);
    let text = nesy_input::read_text(&data_path, nesy_input::MAX_JSON_BYTES)
        .map_err(|e| ImportError::io(&data_path, e))?;
    let data: Value = serde_json::from_str(&text).map_err(|e| {
        ImportError::invalid(
            &data_path,
            format!("line {}, column {}: {e}", e.line(), e.column()),
        )
    })?;
    let field = |name: &str| {
        data.get(name)
            .ok_or_else(|| ImportError::invalid(&data_path, format!("missing field `{name}`")))
    };
    let bad = |name: String, expected: &str| {
        ImportError::invalid(&data_path, format!("field `{name}`: expected {expected}"))
    };
    let instruction = field("instruction")?
        .as_str()
        .ok_or_else(|| bad("instruction".into(), "text"))?
        .to_owned();
    let objects: Vec<String> = field("objects")?
        .as_array()
        .ok_or_else(|| bad("objects".into(), "a list of object names"))?
        .iter()
        .enumerate()
        .map(|(i, o)| {
            o.as_str()
                .map(str::to_owned)
                .ok_or_else(|| bad(format!("objects[{i}]"), "an object name"))
        })
        .collect::<Result<_, _>>()?;
    let entries = field("object_states")?
        .as_array()
        .ok_or_else(|| bad("object_states".into(), "one state per keyframe"))?;
    let mut states = Vec::with_capacity(entries.len());
    for (k, entry) in entries.iter().enumerate() {
        let lines: Vec<String> = match entry {
            Value::Array(atoms) => atoms
                .iter()
                .enumerate()
                .map(|(j, a)| {
                    a.as_str().map(str::to_owned).ok_or_else(|| {
                        bad(
                            format!("object_states[{k}][{j}]"),
                            "an atom such as \"(OnTopOf a b)\"",
                        )
                    })
                })
                .collect::<Result<_, _>>()?,
            Value::String(text) => text
                .lines()
                .map(|l| l.trim().trim_start_matches("- ").trim().to_owned())
                .filter(|l| !l.is_empty())
                .collect(),
            _ => {
                return Err(bad(
                    format!("object_states[{k}]"),
                    "a list of atoms or a text of atom lines",
                ));
            }
        };
        let mut atoms = Vec::with_capacity(lines.len());
        for (j, line) in lines.iter().enumerate() {
            let atom: Atom = line.parse().map_err(|e| {
                bad(
                    format!("object_states[{k}][{j}]"),
                    &format!("an atom such as \"(OnTopOf a b)\" ({e}), found {line:?}"),
                )
            })?;
            atoms.push(atom);
        }
        states.push(State::from_atoms(atoms));
    }
    if states.len() < 2 {
        return Err(bad(
            "object_states".into(),
            "at least two keyframes (the initial state and one action)",
        ));
    }
    let context = data
        .get("additional_context")
        .and_then(Value::as_str)
        .filter(|c| !c.trim().is_empty() && c.trim() != "None")
        .map(str::to_owned);
    let views = read_frames(&dir.join("frames"), states.len())?;
    Ok(AuthorsDemo {
        instruction,
        objects,
        states,
        context,
        views,
    })
}

/// The views under `frames/`, each with one `frame_<i>.jpg` per keyframe.
#[allow(clippy::type_complexity)]
fn read_frames(
    frames: &Path,
    count: usize,
) -> Result<Vec<(String, Vec<(PathBuf, Option<PathBuf>)>)>, ImportError> {
    let mut folders: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
    let entries = std::fs::read_dir(frames).map_err(|e| ImportError::io(frames, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| ImportError::io(frames, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') || !entry.path().is_dir() {
            continue;
        }
        if !is_view_name(name.strip_suffix("_marked").unwrap_or(&name)) {
            return Err(ImportError::invalid(
                entry.path(),
                "expected a view folder named with lower-case letters, digits, `_` and `-`",
            ));
        }
        folders.insert(name, numbered_frames(&entry.path(), count)?);
    }
    let mut views = Vec::new();
    for (name, frames_of_view) in &folders {
        if let Some(base) = name.strip_suffix("_marked") {
            if !folders.contains_key(base) {
                return Err(ImportError::invalid(
                    frames.join(name),
                    format!("labelled frames of a view `{base}` that has no folder of its own"),
                ));
            }
            continue;
        }
        let marked = folders.get(&format!("{name}_marked"));
        let pairs = frames_of_view
            .iter()
            .enumerate()
            .map(|(i, raw)| (raw.clone(), marked.map(|m| m[i].clone())))
            .collect();
        views.push((name.clone(), pairs));
    }
    if views.is_empty() {
        return Err(ImportError::invalid(
            frames,
            "expected one folder of frames per view (top, front, back, ...)",
        ));
    }
    views.sort_by_key(|(n, _)| view_order_key(n));
    Ok(views)
}

/// `frame_0.jpg` … `frame_<count-1>.jpg` of one view folder (PNG accepted too).
fn numbered_frames(folder: &Path, count: usize) -> Result<Vec<PathBuf>, ImportError> {
    let mut found: BTreeMap<usize, PathBuf> = BTreeMap::new();
    let entries = std::fs::read_dir(folder).map_err(|e| ImportError::io(folder, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| ImportError::io(folder, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let index = ["jpg", "jpeg", "png"]
            .iter()
            .find_map(|ext| name.strip_suffix(&format!(".{ext}")))
            .and_then(|stem| stem.strip_prefix("frame_"))
            .and_then(|digits| digits.parse::<usize>().ok());
        if let Some(index) = index {
            if index >= count {
                return Err(ImportError::invalid(
                    entry.path(),
                    format!("a frame number below {count} (data.json has {count} object_states)"),
                ));
            }
            found.insert(index, entry.path());
        }
    }
    (0..count)
        .map(|i| {
            found.remove(&i).ok_or_else(|| {
                ImportError::invalid(
                    folder.join(format!("frame_{i}.jpg")),
                    "no such file (one frame per entry of object_states)",
                )
            })
        })
        .collect()
}
