//! A folder of frames as a time-ordered sequence: one view (`DIR/*.jpg`) or several
//! (`DIR/<view>/*.jpg`, with `DIR/<view>_marked/` for labelled versions).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nesy_sim::demo::{is_view_name, view_order_key};

use crate::error::ImportError;

/// File extensions read as frames.
const FRAME_EXTENSIONS: [&str; 3] = ["png", "jpg", "jpeg"];

/// The frame files of one view, in time order, and of its labelled version if there is one.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewFiles {
    /// The view's name.
    pub name: String,
    /// The folder holding its frames.
    pub folder: PathBuf,
    /// One file per frame.
    pub frames: Vec<PathBuf>,
    /// The labelled frames, one per frame, when the folder has them.
    pub marked: Option<Vec<PathBuf>>,
}

/// A folder's frames: every view has the same number of frames.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameFolder {
    /// The views, in prompt order.
    pub views: Vec<ViewFiles>,
}

impl FrameFolder {
    /// How many frames each view has.
    pub fn len(&self) -> usize {
        self.views.first().map_or(0, |v| v.frames.len())
    }

    /// True when there is no frame.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Reads a frames folder. Files directly in `dir` are one view named `single_view`;
/// otherwise each subfolder is a view (its name lower-case letters, digits, `_` and `-`),
/// and `<view>_marked` holds that view's labelled frames. Frames sort by name with numbers
/// compared as numbers (`frame_2` before `frame_10`).
pub fn read_frame_folder(dir: &Path, single_view: &str) -> Result<FrameFolder, ImportError> {
    let (files, folders) = list(dir)?;
    let mut views: Vec<ViewFiles> = Vec::new();
    if !files.is_empty() {
        views.push(ViewFiles {
            name: single_view.to_owned(),
            folder: dir.to_owned(),
            frames: files,
            marked: None,
        });
    } else {
        let mut by_name: BTreeMap<String, PathBuf> = BTreeMap::new();
        for folder in folders {
            let name = folder
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            if !is_view_name(name.strip_suffix("_marked").unwrap_or(&name)) {
                return Err(ImportError::invalid(
                    &folder,
                    "expected a view folder named with lower-case letters, digits, `_` and `-`",
                ));
            }
            by_name.insert(name, folder);
        }
        for (name, folder) in &by_name {
            if name.ends_with("_marked") {
                continue;
            }
            let (frames, _) = list(folder)?;
            let marked = match by_name.get(&format!("{name}_marked")) {
                Some(m) => Some(list(m)?.0),
                None => None,
            };
            views.push(ViewFiles {
                name: name.clone(),
                folder: folder.clone(),
                frames,
                marked,
            });
        }
        if let Some(orphan) = by_name
            .keys()
            .filter_map(|n| n.strip_suffix("_marked"))
            .find(|base| !by_name.contains_key(*base))
        {
            return Err(ImportError::invalid(
                &by_name[&format!("{orphan}_marked")],
                format!("labelled frames of a view `{orphan}` that has no folder of its own"),
            ));
        }
        views.sort_by_key(|v| view_order_key(&v.name));
    }
    let Some(first) = views.first() else {
        return Err(ImportError::invalid(
            dir,
            "expected frames (.png, .jpg or .jpeg files) or one folder of them per view",
        ));
    };
    let count = first.frames.len();
    for view in &views {
        let folder = &view.folder;
        if view.frames.is_empty() {
            return Err(ImportError::invalid(
                folder,
                "expected frames (.png, .jpg or .jpeg files), found none",
            ));
        }
        if view.frames.len() != count {
            return Err(ImportError::invalid(
                folder,
                format!(
                    "expected {count} frames, as view `{}` has; found {}",
                    first.name,
                    view.frames.len()
                ),
            ));
        }
        if let Some(marked) = &view.marked
            && marked.len() != count
        {
            return Err(ImportError::invalid(
                dir.join(format!("{}_marked", view.name)),
                format!(
                    "expected {count} labelled frames, one per frame of `{}`; found {}",
                    view.name,
                    marked.len()
                ),
            ));
        }
    }
    Ok(FrameFolder { views })
}

/// The frame files (naturally sorted) and the subfolders of `dir`; other files (and hidden
/// entries) are skipped.
fn list(dir: &Path) -> Result<(Vec<PathBuf>, Vec<PathBuf>), ImportError> {
    let entries = std::fs::read_dir(dir).map_err(|e| ImportError::io(dir, e))?;
    let (mut files, mut folders) = (Vec::new(), Vec::new());
    for entry in entries {
        let entry = entry.map_err(|e| ImportError::io(dir, e))?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        if path.is_dir() {
            folders.push(path);
        } else if path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| FRAME_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        {
            files.push(path);
        }
    }
    files.sort_by_key(|a| natural_key(a));
    folders.sort();
    Ok((files, folders))
}

/// A file name split into text and number runs, numbers compared by value.
fn natural_key(path: &Path) -> Vec<(String, u128)> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut key = Vec::new();
    let mut text = String::new();
    let mut digits = String::new();
    for c in name.chars() {
        if c.is_ascii_digit() {
            digits.push(c);
        } else {
            if !digits.is_empty() {
                key.push((std::mem::take(&mut text), digits.parse().unwrap_or(u128::MAX)));
                digits.clear();
            }
            text.push(c);
        }
    }
    key.push((text, digits.parse().unwrap_or(0)));
    key
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_sort_by_value() {
        let mut names: Vec<PathBuf> = ["frame_10.jpg", "frame_2.jpg", "frame_1.jpg", "frame_01b.jpg"]
            .iter()
            .map(PathBuf::from)
            .collect();
        names.sort_by_key(|a| natural_key(a));
        let names: Vec<String> = names.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(
            names,
            ["frame_1.jpg", "frame_01b.jpg", "frame_2.jpg", "frame_10.jpg"]
        );
    }
}
