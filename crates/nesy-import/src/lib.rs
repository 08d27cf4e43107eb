//! # nesy-import
//!
//! Real-world demonstrations into nesy's demo folder layout (`nesy_sim::demo`), which
//! `nesy adapt --demo` reads:
//!
//! - a **video**: MP4 (`.mp4`, `.m4v`, `.mov`) with an H.264 track, read with the `mp4`
//!   demuxer and Cisco's OpenH264 decoder (built from source into the binary);
//! - a **frames folder**: one view (`DIR/*.jpg`) or several (`DIR/<view>/*.png`, with
//!   `<view>_marked/` for labelled frames), in time order;
//! - the **authors' demo format**: `data.json` (instruction, objects and each keyframe's
//!   symbolic state) and `frames/<view>/frame_<i>.jpg`.
//!
//! A simulated demonstration video (`nesy record --video`, written with [`VideoWriter`])
//! comes with its ground truth (`demo.video.json`); given as [`ImportOptions::truth`], it
//! puts the recording's states into the imported keyframes and scores the keyframe choice
//! against the true keyframes ([`match_keyframes`]).
//!
//! Keyframes are chosen by [`KeyframeMode`]: `auto` finds the frames at which the scene,
//! having changed, has come to rest; `every:SECONDS` and `at:T1,T2,...` are the manual
//! modes; `all` keeps every frame. Each import writes `contact_sheet.png` (the keyframes
//! with their numbers and times) beside the demo's `manifest.json`, and records in the
//! manifest what it read (`imported_from`).
//!
//! ```no_run
//! use nesy_import::{ImportOptions, KeyframeMode, import};
//!
//! let options = ImportOptions {
//!     keyframes: KeyframeMode::Auto,
//!     fps: Some(30.0),
//!     instruction: Some("Gather the screws on the tray.".into()),
//!     objects: Some(vec!["black_screws".into(), "tray".into()]),
//!     ..ImportOptions::default()
//! };
//! let report = import("frames/".as_ref(), "demos/screws".as_ref(), &options).unwrap();
//! println!("{} keyframes", report.keyframes.len());
//! ```

mod authors;
mod decode;
mod error;
mod frames;
mod keyframes;
mod sheet;
mod video;

use std::path::{Path, PathBuf};

use nesy_sim::demo::{
    CameraImages, Demo, DemoEmbodiment, DemoMetadata, Keyframe, KeyframeViews, NESY_VERSION, NamedView,
    ViewResolution,
};
use nesy_sim::perception::render::Image;
use serde::Serialize;

pub use authors::{AuthorsDemo, DATA_FILE, ViewFrames, read_authors_demo};
pub use decode::{BLOCK, THUMBNAIL_WIDTH, Thumbnail, decode};
pub use error::ImportError;
pub use frames::{FrameFolder, ViewFiles, read_frame_folder};
pub use keyframes::{
    AutoSettings, KeyframeMatch, KeyframeMode, MATCH_TOLERANCE_S, MIN_MOTION, MIN_REST_S, MotionTrace,
    detect, match_keyframes, select,
};
pub use sheet::{CELL_WIDTH, COLUMNS, contact_sheet};
pub use video::{VIDEO_EXTENSIONS, VideoInfo, VideoWriter, is_video, read_mp4, write_mp4};

/// The contact sheet's file name in the demo folder.
pub const CONTACT_SHEET_FILE: &str = "contact_sheet.png";

/// The view name of a frames folder that holds its frames directly.
pub const DEFAULT_VIEW: &str = "camera";

/// What an import is told besides its source.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportOptions {
    /// How keyframes are chosen (the authors' format holds keyframes only: `all`).
    pub keyframes: KeyframeMode,
    /// What `auto` counts as motion and as rest.
    pub auto: AutoSettings,
    /// Frames per second of a frames folder (times are frame numbers without it, and only
    /// `all` can be used).
    pub fps: Option<f64>,
    /// The view name of a video, or of a folder that holds its frames directly.
    pub view: String,
    /// The instruction (required for a video or a frames folder; replaces the authors' one).
    pub instruction: Option<String>,
    /// The object names (required for a video or a frames folder; replace the authors'
    /// list).
    pub objects: Option<Vec<String>>,
    /// Who demonstrated (default: `human` for a video or a frames folder, `finger` for the
    /// authors' robot demos).
    pub embodiment: Option<DemoEmbodiment>,
    /// The ground truth of a simulated demonstration video (`demo.video.json`, written by
    /// `nesy record --video`): each keyframe gets the recording's state at its frame (and,
    /// when it lies within [`MATCH_TOLERANCE_S`] of a true keyframe, the call that led to
    /// that one), the task and the robot come from it unless given, and the report compares
    /// the chosen keyframes with the true ones.
    pub truth: Option<PathBuf>,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            keyframes: KeyframeMode::All,
            auto: AutoSettings::default(),
            fps: None,
            view: DEFAULT_VIEW.into(),
            instruction: None,
            objects: None,
            embodiment: None,
            truth: None,
        }
    }
}

/// What an import read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceKind {
    /// A folder of frames.
    Frames,
    /// The authors' demo format.
    Authors,
    /// A video file (MP4, H.264).
    Video,
}

/// One chosen keyframe: its frame in the source and its time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChosenKeyframe {
    /// The frame's position in the source sequence, from 0.
    pub frame: usize,
    /// Its time in seconds (the frame number when the source has no frame rate).
    pub time: f64,
}

/// What an import did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImportReport {
    /// The source's kind.
    pub kind: SourceKind,
    /// The demo folder written.
    pub out: PathBuf,
    /// The view names, in prompt order.
    pub views: Vec<String>,
    /// Frames in the source.
    pub frames: usize,
    /// The keyframes, in order.
    pub keyframes: Vec<ChosenKeyframe>,
    /// The contact sheet written.
    pub contact_sheet: PathBuf,
    /// The chosen keyframes against the true ones, for a video with its ground truth.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub truth_match: Option<KeyframeMatch>,
    /// What `auto` measured, when it ran (for a look at why a change was or was not taken).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionTrace>,
}

/// One frame's files: per view, the plain frame and its labelled version.
type FrameFiles = Vec<(PathBuf, Option<PathBuf>)>;

/// Imports `source` (a video, a frames folder, or a folder with the authors' `data.json`)
/// into a new demo folder `out`, which must not exist or be empty.
pub fn import(source: &Path, out: &Path, options: &ImportOptions) -> Result<ImportReport, ImportError> {
    let is_video = is_video(source);
    if !source.is_dir() && !is_video {
        return Err(ImportError::invalid(
            source,
            "expected a video (.mp4, .m4v or .mov with H.264), a folder of frames (one view, or one subfolder per view) or an authors' demo folder (data.json and frames/)",
        ));
    }
    if std::fs::read_dir(out).is_ok_and(|mut entries| entries.next().is_some()) {
        return Err(ImportError::invalid(
            out,
            "the output folder exists and is not empty; choose a new one",
        ));
    }
    if let (Some(truth), false) = (&options.truth, is_video) {
        return Err(ImportError::invalid(
            truth,
            "a recording's ground truth goes with its video; the source is not a video",
        ));
    }
    if is_video {
        import_video(source, out, options)
    } else if source.join(DATA_FILE).is_file() {
        import_authors(source, out, options)
    } else {
        import_frames(source, out, options)
    }
}

fn import_frames(source: &Path, out: &Path, options: &ImportOptions) -> Result<ImportReport, ImportError> {
    let folder = read_frame_folder(source, &options.view)?;
    let (instruction, objects) = task_of(source, options, "a frames folder")?;
    let times: Vec<f64> = match options.fps {
        Some(fps) if fps.is_finite() && fps > 0.0 => (0..folder.len()).map(|i| i as f64 / fps).collect(),
        Some(fps) => {
            return Err(ImportError::invalid(
                source,
                format!("--fps must be a positive number, got {fps}"),
            ));
        }
        None if options.keyframes == KeyframeMode::All => (0..folder.len()).map(|i| i as f64).collect(),
        None => {
            return Err(ImportError::Keyframes {
                path: source.to_owned(),
                message: format!(
                    "`{}` needs the frame rate (--fps); without it every frame is a keyframe (--keyframes all)",
                    options.keyframes.label()
                ),
            });
        }
    };
    let files: Vec<FrameFiles> = (0..folder.len())
        .map(|i| {
            folder
                .views
                .iter()
                .map(|v| (v.frames[i].clone(), v.marked.as_ref().map(|m| m[i].clone())))
                .collect()
        })
        .collect();
    // `auto` compares thumbnails; the frames themselves are not kept (the contact sheet
    // decodes the chosen ones again).
    let mut thumbnails = Vec::new();
    if options.keyframes == KeyframeMode::Auto {
        for frame in &files {
            let decoded = decode_frame(frame)?;
            thumbnails.push(decoded.iter().map(Thumbnail::of).collect());
        }
    }
    let (chosen, motion) = choose(source, options, &times, &thumbnails)?;
    let views: Vec<String> = folder.views.iter().map(|v| v.name.clone()).collect();
    let plan = Plan {
        kind: SourceKind::Frames,
        source,
        out,
        options,
        instruction,
        objects,
        embodiment: options.embodiment.unwrap_or(DemoEmbodiment::Human),
        views,
        times: &times,
        chosen: &chosen,
        frames: Frames::Files(&files),
        states: None,
        actions: None,
        context: None,
    };
    plan.write(motion)
}

fn import_video(source: &Path, out: &Path, options: &ImportOptions) -> Result<ImportReport, ImportError> {
    let truth = options
        .truth
        .as_deref()
        .map(|path| nesy_sim::demo::VideoTruth::read(path).map(|truth| (path, truth)))
        .transpose()?;
    let told = match &truth {
        Some((_, t)) => ImportOptions {
            instruction: options
                .instruction
                .clone()
                .or_else(|| Some(t.instruction.clone())),
            objects: options.objects.clone().or_else(|| Some(t.objects.clone())),
            view: if options.view == DEFAULT_VIEW {
                t.camera.clone()
            } else {
                options.view.clone()
            },
            embodiment: options.embodiment.or(Some(DemoEmbodiment::of(
                t.embodiment,
                nesy_sim::demo::Demonstrator::Robot,
            ))),
            ..options.clone()
        },
        None => options.clone(),
    };
    let options = &told;
    let (instruction, objects) = task_of(source, options, "a video")?;
    // Pass 1: the frame times, and the thumbnails `auto` compares.
    let auto = options.keyframes == KeyframeMode::Auto;
    let mut thumbnails = Vec::new();
    let info = read_mp4(source, |_, image| {
        if auto {
            thumbnails.push(vec![Thumbnail::of(&image)]);
        }
        Ok(())
    })?;
    let (chosen, motion) = choose(source, options, &info.times, &thumbnails)?;
    let (states, actions, truth_match) = match &truth {
        Some((path, truth)) => {
            if truth.frames != info.times.len() {
                return Err(ImportError::invalid(
                    path,
                    format!(
                        "the ground truth describes {} frames, the video {} has {}",
                        truth.frames,
                        source.display(),
                        info.times.len()
                    ),
                ));
            }
            let states = chosen
                .iter()
                .map(|&frame| truth.state_at(frame).cloned().unwrap_or_default())
                .collect();
            let true_times: Vec<f64> = truth
                .keyframes
                .iter()
                .map(|k| truth.frame_time(k.frame))
                .collect();
            let chosen_times: Vec<f64> = chosen.iter().map(|&frame| info.times[frame]).collect();
            let matched = match_keyframes(&true_times, &chosen_times, MATCH_TOLERANCE_S);
            // A chosen keyframe that found a true one carries the call that led to it.
            let mut actions = vec![None; chosen.len()];
            for &(t, c) in &matched.pairs {
                actions[c] = truth.keyframes[t].action.clone();
            }
            (Some(states), Some(actions), Some(matched))
        }
        None => (None, None, None),
    };
    // Pass 2: the chosen frames themselves (a video is not held in memory whole).
    let mut pictures = Vec::with_capacity(chosen.len());
    read_mp4(source, |i, image| {
        if chosen.binary_search(&i).is_ok() {
            pictures.push(image);
        }
        Ok(())
    })?;
    let plan = Plan {
        kind: SourceKind::Video,
        source,
        out,
        options,
        instruction,
        objects,
        embodiment: options.embodiment.unwrap_or(DemoEmbodiment::Human),
        views: vec![options.view.clone()],
        times: &info.times,
        chosen: &chosen,
        frames: Frames::Decoded(pictures),
        states,
        actions,
        context: None,
    };
    let mut report = plan.write(motion)?;
    report.truth_match = truth_match;
    Ok(report)
}

/// The instruction and the objects a source without them needs from the options.
fn task_of(source: &Path, options: &ImportOptions, what: &str) -> Result<(String, Vec<String>), ImportError> {
    let instruction = options.instruction.clone().ok_or_else(|| {
        ImportError::invalid(
            source,
            format!("{what} says nothing of the task: give its instruction (--instruction)"),
        )
    })?;
    let objects = options.objects.clone().ok_or_else(|| {
        ImportError::invalid(
            source,
            format!("{what} says nothing of the task: give its objects (--objects)"),
        )
    })?;
    Ok((instruction, objects))
}

/// The keyframes `mode` chooses among frames at `times`, and what `auto` measured.
fn choose(
    source: &Path,
    options: &ImportOptions,
    times: &[f64],
    thumbnails: &[Vec<Thumbnail>],
) -> Result<(Vec<usize>, Option<MotionTrace>), ImportError> {
    let refuse = |message| ImportError::Keyframes {
        path: source.to_owned(),
        message,
    };
    match &options.keyframes {
        KeyframeMode::Auto => {
            let (chosen, trace) = detect(times, thumbnails, &options.auto).map_err(refuse)?;
            Ok((chosen, Some(trace)))
        }
        mode => Ok((select(mode, times, &[], &options.auto).map_err(refuse)?, None)),
    }
}

fn import_authors(source: &Path, out: &Path, options: &ImportOptions) -> Result<ImportReport, ImportError> {
    if options.keyframes != KeyframeMode::All {
        return Err(ImportError::Keyframes {
            path: source.to_owned(),
            message: format!(
                "the authors' format holds keyframes only, so every frame is one (--keyframes all), not `{}`",
                options.keyframes.label()
            ),
        });
    }
    let demo = read_authors_demo(source)?;
    let count = demo.states.len();
    let times: Vec<f64> = (0..count).map(|i| i as f64).collect();
    let chosen: Vec<usize> = (0..count).collect();
    let files: Vec<FrameFiles> = (0..count)
        .map(|i| demo.views.iter().map(|(_, frames)| frames[i].clone()).collect())
        .collect();
    let plan = Plan {
        kind: SourceKind::Authors,
        source,
        out,
        options,
        instruction: options.instruction.clone().unwrap_or(demo.instruction),
        objects: options.objects.clone().unwrap_or(demo.objects),
        embodiment: options.embodiment.unwrap_or(DemoEmbodiment::Finger),
        views: demo.views.iter().map(|(n, _)| n.clone()).collect(),
        times: &times,
        chosen: &chosen,
        frames: Frames::Files(&files),
        states: Some(demo.states),
        actions: None,
        context: demo.context,
    };
    plan.write(None)
}

/// Everything needed to write the demo folder.
struct Plan<'a> {
    kind: SourceKind,
    source: &'a Path,
    out: &'a Path,
    options: &'a ImportOptions,
    instruction: String,
    objects: Vec<String>,
    embodiment: DemoEmbodiment,
    views: Vec<String>,
    times: &'a [f64],
    chosen: &'a [usize],
    frames: Frames<'a>,
    /// The ground-truth state of each chosen keyframe, in keyframe order.
    states: Option<Vec<nesy_core::State>>,
    /// The recorded call that led to each chosen keyframe, in keyframe order.
    actions: Option<Vec<Option<nesy_sim::api::TraceEntry>>>,
    context: Option<String>,
}

/// Where the chosen keyframes' pictures come from.
enum Frames<'a> {
    /// Files, per frame of the source: per view, the plain and the labelled frame.
    Files(&'a [FrameFiles]),
    /// A video's chosen frames, decoded (one view), in keyframe order.
    Decoded(Vec<Image>),
}

impl Plan<'_> {
    fn write(self, motion: Option<MotionTrace>) -> Result<ImportReport, ImportError> {
        if self.chosen.len() < 2 {
            return Err(ImportError::Keyframes {
                path: self.source.to_owned(),
                message: format!(
                    "`{}` chose {} keyframe(s); a demo needs the initial state and at least one action{}",
                    self.options.keyframes.label(),
                    self.chosen.len(),
                    if self.options.keyframes == KeyframeMode::Auto {
                        " (no change in the pictures came to rest; try every:SECONDS or at:T1,T2,...)"
                    } else {
                        ""
                    }
                ),
            });
        }
        let keyframes_chosen: Vec<ChosenKeyframe> = self
            .chosen
            .iter()
            .map(|&frame| ChosenKeyframe {
                frame,
                time: self.times[frame],
            })
            .collect();
        // Per view: the resolution of its plain frames and of its labelled ones.
        let mut sizes = vec![(ViewResolution::default(), ViewResolution::default()); self.views.len()];
        let mut keyframes = Vec::with_capacity(self.chosen.len());
        for (k, &frame) in self.chosen.iter().enumerate() {
            let mut named = Vec::with_capacity(self.views.len());
            match &self.frames {
                Frames::Files(files) => {
                    for (v, (raw_path, marked_path)) in files[frame].iter().enumerate() {
                        let raw = sizes[v].0.read_frame(raw_path)?;
                        let marked = match marked_path {
                            Some(p) => Some(sizes[v].1.read_frame(p)?),
                            None => None,
                        };
                        named.push(NamedView {
                            name: self.views[v].clone(),
                            images: CameraImages { raw, marked },
                        });
                    }
                }
                Frames::Decoded(pictures) => named.push(NamedView {
                    name: self.views[0].clone(),
                    images: CameraImages {
                        raw: pictures[k].to_png(),
                        marked: None,
                    },
                }),
            }
            keyframes.push(Keyframe {
                index: k,
                time: self.times[frame],
                views: KeyframeViews::new(named),
                state: self.states.as_ref().map(|s| s[k].clone()),
                action: self.actions.as_ref().and_then(|a| a[k].clone()),
            });
        }
        let (embodiment, demonstrator) = self.embodiment.split();
        let imported_from = serde_json::json!({
            "kind": self.kind,
            "path": self.source,
            "keyframes": self.options.keyframes.label(),
            "fps": self.options.fps,
            "frames": self.times.len(),
            "chosen": keyframes_chosen,
            "additional_context": self.context,
        });
        let demo = Demo {
            metadata: DemoMetadata {
                instruction: self.instruction,
                objects: self.objects,
                embodiment,
                demonstrator,
                imported_from: Some(imported_from),
                scenario_id: None,
                side: None,
                nesy_version: Some(NESY_VERSION.to_owned()),
                target_scene: None,
            },
            keyframes,
        };
        nesy_sim::demo::write_folder(&demo, self.out)?;
        // Read back as `nesy adapt` will, so that a folder it would refuse is refused now.
        nesy_sim::demo::read_folder(self.out)?;

        let mut cells = Vec::with_capacity(self.chosen.len());
        for (k, &frame) in self.chosen.iter().enumerate() {
            let first_view = match &self.frames {
                Frames::Files(files) => decode_file(&files[frame][0].0)?,
                Frames::Decoded(chosen) => chosen[k].clone(),
            };
            cells.push((first_view, format!("#{k} {:.2} s", self.times[frame])));
        }
        let sheet_path = self.out.join(CONTACT_SHEET_FILE);
        std::fs::write(&sheet_path, contact_sheet(&cells).to_png())
            .map_err(|e| ImportError::io(&sheet_path, e))?;
        Ok(ImportReport {
            kind: self.kind,
            out: self.out.to_owned(),
            views: self.views,
            frames: self.times.len(),
            keyframes: keyframes_chosen,
            contact_sheet: sheet_path,
            truth_match: None,
            motion,
        })
    }
}

fn decode_file(path: &Path) -> Result<Image, ImportError> {
    let bytes =
        nesy_input::read_bytes(path, nesy_input::MAX_IMAGE_BYTES).map_err(|e| ImportError::io(path, e))?;
    decode(&bytes).map_err(|e| ImportError::invalid(path, e))
}

/// Every view of one frame, decoded.
fn decode_frame(frame: &FrameFiles) -> Result<Vec<Image>, ImportError> {
    frame.iter().map(|(raw, _)| decode_file(raw)).collect()
}
