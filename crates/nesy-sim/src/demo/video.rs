//! Filming a recorded demonstration: one camera at a fixed frame rate for the whole episode,
//! and the ground truth that comes with it ([`VideoTruth`], written beside the video as
//! `demo.video.json`): the frame rate, the true keyframes (the frames at which the recorder
//! took its keyframes, with the calls that led to them) and the observer's symbolic state at
//! every frame.
//!
//! The frames themselves leave the simulator through a channel as they are rendered
//! ([`VideoFrame`]); encoding them is the caller's business (`nesy record --video` writes
//! MP4 with nesy-import), so the simulator links no video codec.

use std::path::Path;

use nesy_core::State;
use serde::{Deserialize, Serialize};

use super::DemoError;
use crate::api::{Embodiment, TraceEntry};
use crate::perception::render::{CORNER_CAMERA, Camera, Image};
use crate::world::CONTROL_DT;

/// The file name of a demonstration video's ground truth, beside the video.
pub const VIDEO_TRUTH_FILE: &str = "demo.video.json";

/// The [`VideoTruth`] format this build reads and writes.
pub const VIDEO_TRUTH_VERSION: u32 = 1;

/// How to film a demonstration while recording it.
#[derive(Clone, Debug, PartialEq)]
pub struct VideoOptions {
    /// The camera filmed (see [`filming_camera`](crate::perception::render::filming_camera)).
    pub camera: Camera,
    /// Side of the square frames in pixels (even, as H.264 needs).
    pub size: u32,
    /// Frames per second; a whole number of control steps apart, so it divides
    /// [`control_rate`].
    pub fps: u32,
    /// Seconds the robot holds still after each action (a person's pause between steps).
    pub hold_seconds: f64,
}

impl Default for VideoOptions {
    fn default() -> Self {
        VideoOptions {
            camera: CORNER_CAMERA,
            size: 256,
            fps: 10,
            hold_seconds: 0.5,
        }
    }
}

/// Control steps per simulated second (100): a video's frame rate must divide it.
pub fn control_rate() -> u32 {
    (1.0 / CONTROL_DT).round() as u32
}

impl VideoOptions {
    /// Checks the options, saying what is wrong.
    pub fn check(&self) -> Result<(), String> {
        let rate = control_rate();
        if self.fps == 0 || !rate.is_multiple_of(self.fps) {
            return Err(format!(
                "the video frame rate must divide the simulator's {rate} control steps per second (e.g. 5, 10, 20, 25, 50), got {}",
                self.fps
            ));
        }
        if !(16..=4096).contains(&self.size) || !self.size.is_multiple_of(2) {
            return Err(format!(
                "the video frame size must be an even number of pixels from 16 to 4096, got {}",
                self.size
            ));
        }
        if !(self.hold_seconds.is_finite() && (0.0..=10.0).contains(&self.hold_seconds)) {
            return Err(format!(
                "the hold after each action must be 0 to 10 seconds, got {}",
                self.hold_seconds
            ));
        }
        Ok(())
    }

    /// Control steps between two frames.
    pub(crate) fn step_interval(&self) -> u64 {
        u64::from(control_rate() / self.fps.max(1))
    }

    /// Control steps of the hold after each action.
    pub(crate) fn hold_steps(&self) -> u32 {
        (self.hold_seconds / CONTROL_DT).round() as u32
    }
}

/// One rendered frame of a demonstration video.
#[derive(Clone, Debug)]
pub struct VideoFrame {
    /// Its position in the video, from 0.
    pub index: usize,
    /// Its time in seconds (`index / fps`).
    pub time: f64,
    /// The picture.
    pub image: Image,
}

/// A keyframe of the recording, placed in the video.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrueKeyframe {
    /// The keyframe's index in the demo.
    pub index: usize,
    /// Its simulated time in seconds.
    pub time: f64,
    /// The video frame nearest that time.
    pub frame: usize,
    /// The call that led to it (none for the initial keyframe).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub action: Option<TraceEntry>,
}

/// The symbolic state from one frame until the next span's first frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateSpan {
    /// The first frame showing this state.
    pub first_frame: usize,
    /// The observer's state.
    pub state: State,
}

/// The ground truth of a demonstration video (`demo.video.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VideoTruth {
    /// [`VIDEO_TRUTH_VERSION`].
    pub format_version: u32,
    /// The instruction demonstrated.
    pub instruction: String,
    /// The scene's object names.
    pub objects: Vec<String>,
    /// The robot's end effector.
    pub embodiment: Embodiment,
    /// The benchmark scenario, when the scene is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scenario_id: Option<String>,
    /// `source` or `target`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<String>,
    /// The camera filmed, by name.
    pub camera: String,
    /// Frame width and height in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Frames per second.
    pub fps: u32,
    /// Seconds the robot held still after each action.
    pub hold_seconds: f64,
    /// Frames in the video.
    pub frames: usize,
    /// The recording's keyframes, in order.
    pub keyframes: Vec<TrueKeyframe>,
    /// The observer's state at every frame, as spans in frame order (the first starts at 0).
    pub states: Vec<StateSpan>,
}

impl VideoTruth {
    /// The observer's state at `frame` (the last frame's for a frame past the end).
    pub fn state_at(&self, frame: usize) -> Option<&State> {
        let after = self.states.partition_point(|s| s.first_frame <= frame);
        after.checked_sub(1).map(|i| &self.states[i].state)
    }

    /// The time of `frame` in seconds.
    pub fn frame_time(&self, frame: usize) -> f64 {
        frame as f64 / f64::from(self.fps.max(1))
    }

    /// Writes the truth as pretty JSON.
    pub fn write(&self, path: &Path) -> Result<(), DemoError> {
        let mut text = serde_json::to_string_pretty(self)
            .map_err(|e| DemoError::invalid(path, "video truth", "a serialisable document", e.to_string()))?;
        text.push('\n');
        std::fs::write(path, text).map_err(|e| DemoError::io(path, e))
    }

    /// Reads and checks a `demo.video.json`: its version, spans in frame order starting at
    /// frame 0, keyframes and spans within the video.
    pub fn read(path: &Path) -> Result<VideoTruth, DemoError> {
        let bytes =
            nesy_input::read_bytes(path, nesy_input::MAX_JSON_BYTES).map_err(|e| DemoError::io(path, e))?;
        Self::parse(path, &bytes)
    }

    /// [`VideoTruth::read`] on bytes already read; `path` names them in errors.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<VideoTruth, DemoError> {
        let truth: VideoTruth = DemoError::parse_json(path, "video truth", bytes)?;
        let bad = |field: &str, expected: &str, found: String| {
            Err(DemoError::invalid(
                path,
                format!("field `{field}`"),
                expected,
                found,
            ))
        };
        if truth.format_version != VIDEO_TRUTH_VERSION {
            return bad(
                "format_version",
                &VIDEO_TRUTH_VERSION.to_string(),
                truth.format_version.to_string(),
            );
        }
        if truth.fps == 0 {
            return bad("fps", "a positive frame rate", "0".into());
        }
        if truth.states.first().is_none_or(|s| s.first_frame != 0) {
            return bad(
                "states",
                "spans starting at frame 0",
                format!("{} span(s)", truth.states.len()),
            );
        }
        if let Some(w) = truth
            .states
            .windows(2)
            .find(|w| w[1].first_frame <= w[0].first_frame)
        {
            return bad(
                "states",
                "spans in increasing frame order",
                format!("frame {} after frame {}", w[1].first_frame, w[0].first_frame),
            );
        }
        if let Some(s) = truth.states.iter().find(|s| s.first_frame >= truth.frames) {
            return bad(
                "states",
                &format!("spans within the video's {} frames", truth.frames),
                format!("a span at frame {}", s.first_frame),
            );
        }
        if let Some(k) = truth.keyframes.iter().find(|k| k.frame >= truth.frames) {
            return bad(
                "keyframes",
                &format!("frames within the video's {} frames", truth.frames),
                format!("keyframe {} at frame {}", k.index, k.frame),
            );
        }
        Ok(truth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth() -> VideoTruth {
        let state = |pred: &str, arg: &str| State::from_atoms([nesy_core::Atom::new(pred, &[arg])]);
        VideoTruth {
            format_version: VIDEO_TRUTH_VERSION,
            instruction: "i".into(),
            objects: vec!["apple".into()],
            embodiment: Embodiment::Finger,
            scenario_id: None,
            side: None,
            camera: "front".into(),
            width: 16,
            height: 16,
            fps: 10,
            hold_seconds: 0.5,
            frames: 30,
            keyframes: vec![TrueKeyframe {
                index: 0,
                time: 0.0,
                frame: 0,
                action: None,
            }],
            states: vec![
                StateSpan {
                    first_frame: 0,
                    state: state("OnTopOf", "apple"),
                },
                StateSpan {
                    first_frame: 12,
                    state: state("GripperHolding", "apple"),
                },
            ],
        }
    }

    #[test]
    fn the_state_at_a_frame_is_its_spans() {
        let t = truth();
        assert_eq!(t.state_at(0), Some(&t.states[0].state));
        assert_eq!(t.state_at(11), Some(&t.states[0].state));
        assert_eq!(t.state_at(12), Some(&t.states[1].state));
        assert_eq!(t.state_at(400), Some(&t.states[1].state));
    }

    #[test]
    fn reading_refuses_spans_out_of_order_by_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(VIDEO_TRUTH_FILE);
        let mut t = truth();
        t.write(&path).unwrap();
        assert_eq!(VideoTruth::read(&path).unwrap(), t);
        t.states[1].first_frame = 0;
        t.write(&path).unwrap();
        let error = VideoTruth::read(&path).unwrap_err().to_string();
        assert!(
            error.contains("field `states`") && error.contains("increasing"),
            "{error}"
        );
    }

    #[test]
    fn every_truncation_is_refused_with_the_file_named() {
        let text = serde_json::to_string_pretty(&truth()).unwrap();
        let path = Path::new("demo.video.json");
        assert_eq!(VideoTruth::parse(path, text.as_bytes()).unwrap(), truth());
        for cut in 0..text.len() - 1 {
            let error = VideoTruth::parse(path, &text.as_bytes()[..cut]).unwrap_err();
            assert!(error.to_string().starts_with("demo.video.json"), "{error}");
        }
    }

    #[test]
    fn frame_rates_must_divide_the_control_rate() {
        let bad = VideoOptions {
            fps: 30,
            ..VideoOptions::default()
        };
        assert!(bad.check().unwrap_err().contains("divide"));
        assert!(VideoOptions::default().check().is_ok());
        assert_eq!(VideoOptions::default().step_interval(), 10);
        assert_eq!(VideoOptions::default().hold_steps(), 50);
    }
}
