//! Execution recordings: a policy's recorded API calls replayed on a fresh copy of its scene
//! (`nesy_sim::demo::replay_execution`) and written as `execution.mcap` (a keyframe after
//! every action, in the demo format: the three views, the observer's state, the call) and
//! `rollout.mp4` (one camera filmed at a fixed rate, each frame captioned with the call under
//! way). The replay runs in this process, not in the policy's sandbox, which writes nothing.

use std::path::{Path, PathBuf};
use std::sync::mpsc::SyncSender;

use anyhow::Context;
use nesy_core::Embodiment;
use nesy_sim::api::TraceEntry;
use nesy_sim::demo::mcap_format::{Film, FilmFrame};
use nesy_sim::demo::{ExecutionRecording, RecordOptions, VideoFrame, VideoOptions, replay_execution};
use nesy_sim::scene::SceneSpec;

use nesy_pipeline::output::{EXECUTION_RECORDING_FILE, ROLLOUT_VIDEO_FILE};

/// Side of the rollout's square frames (pixels).
const ROLLOUT_SIZE: u32 = 384;

/// What [`record_rollout`] wrote.
pub(crate) struct Rollout {
    /// `execution.mcap`.
    pub mcap: PathBuf,
    /// `rollout.mp4`.
    pub video: PathBuf,
    /// The replay: its keyframes, goal verdict and any divergence from the recorded run.
    pub recording: ExecutionRecording,
    /// The rollout's frame rate.
    pub fps: u32,
}

/// JPEG quality of the frames an execution recording keeps on its film topic.
const FILM_JPEG_QUALITY: u8 = 85;

/// Runs `produce` while a second thread encodes the frames it sends into an MP4 at `path`;
/// returns what `produce` returned, the number of frames written, and, when `keep_film`, each
/// frame as JPEG with its time (for an execution recording's film topic).
pub(crate) fn with_video_encoder<T>(
    path: &Path,
    fps: u32,
    keep_film: bool,
    produce: impl FnOnce(SyncSender<VideoFrame>) -> T,
) -> anyhow::Result<(T, usize, Vec<FilmFrame>)> {
    // A few frames of slack keep the renderer and the encoder both busy.
    let (frames, received) = std::sync::mpsc::sync_channel::<VideoFrame>(4);
    let mut writer = nesy_import::VideoWriter::create(path, f64::from(fps))?;
    let encoder = std::thread::spawn(
        move || -> Result<(usize, Vec<FilmFrame>), nesy_import::ImportError> {
            let mut film = Vec::new();
            for frame in received {
                writer.push(&frame.image)?;
                if keep_film {
                    film.push(FilmFrame {
                        time: frame.time,
                        jpeg: frame.image.to_jpeg(FILM_JPEG_QUALITY),
                    });
                }
            }
            Ok((writer.finish()?, film))
        },
    );
    let produced = produce(frames);
    let (written, film) = encoder
        .join()
        .map_err(|_| anyhow::anyhow!("the video encoder thread stopped unexpectedly"))??;
    Ok((produced, written, film))
}

/// The rollout's frame rate for `--render-every N`: one frame every `N` control steps, a
/// whole number of frames per second.
pub(crate) fn rollout_fps(render_every: u32) -> anyhow::Result<u32> {
    let rate = nesy_sim::demo::control_rate();
    if render_every == 0 || !rate.is_multiple_of(render_every) {
        anyhow::bail!(
            "--render-every must divide the simulator's {rate} control steps per second (1, 2, 4, 5, 10, 20, 25, 50 or 100), got {render_every}"
        );
    }
    Ok(rate / render_every)
}

/// Replays `trace` on the scene at `scene_path` (with the end effector the run used) and
/// writes `execution.mcap` and `rollout.mp4` (a frame every `render_every` control steps)
/// into `out_dir`.
pub(crate) fn record_rollout(
    scene_path: &Path,
    embodiment: Option<Embodiment>,
    trace: &[TraceEntry],
    out_dir: &Path,
    render_every: u32,
) -> anyhow::Result<Rollout> {
    let fps = rollout_fps(render_every)?;
    let mut scene =
        SceneSpec::from_file(scene_path).with_context(|| format!("reading {}", scene_path.display()))?;
    if let Some(embodiment) = embodiment {
        scene.embodiment = embodiment;
    }
    let video = VideoOptions {
        fps,
        // Large enough for the caption to name the call and its arguments.
        size: ROLLOUT_SIZE,
        hold_seconds: 0.0,
        ..VideoOptions::default()
    };
    video.check().map_err(anyhow::Error::msg)?;
    std::fs::create_dir_all(out_dir).with_context(|| format!("creating {}", out_dir.display()))?;
    let options = RecordOptions {
        side: Some("execution".to_owned()),
        ..RecordOptions::default()
    };
    let video_path = out_dir.join(ROLLOUT_VIDEO_FILE);
    let (recording, written, frames) = with_video_encoder(&video_path, fps, true, |frames| {
        replay_execution(&scene, trace, &options, Some((&video, frames)))
    })
    .with_context(|| format!("writing {}", video_path.display()))?;
    let recording =
        recording.with_context(|| format!("replaying the execution on {}", scene_path.display()))?;
    anyhow::ensure!(
        written == recording.frames,
        "{}: {written} frame(s) written of {} rendered",
        video_path.display(),
        recording.frames
    );
    let mcap = out_dir.join(EXECUTION_RECORDING_FILE);
    let film = Film {
        camera: video.camera.name.to_owned(),
        frames,
    };
    recording
        .write_mcap_file(&mcap, Some(&film))
        .with_context(|| format!("writing {}", mcap.display()))?;
    Ok(Rollout {
        mcap,
        video: video_path,
        recording,
        fps,
    })
}

/// Prints [`describe`]'s line after `prefix`: on stdout, or on stderr when stdout carries a
/// `--json` document alone.
pub(crate) fn announce(rollout: &Rollout, prefix: &str, json: bool) -> std::io::Result<()> {
    let line = format!("{prefix}{}", describe(rollout));
    if json {
        eprintln!("{line}");
        Ok(())
    } else {
        outln!("{line}")
    }
}

/// One line on the rollout for a run's summary.
pub(crate) fn describe(rollout: &Rollout) -> String {
    let mut line = format!(
        "{} ({} keyframes), {} ({} frames at {} fps)",
        rollout.mcap.display(),
        rollout.recording.demo.keyframes.len(),
        rollout.video.display(),
        rollout.recording.frames,
        rollout.fps
    );
    if let Some(d) = &rollout.recording.divergence {
        line.push_str(&format!(
            "; the replay diverged at call {} ({}): recorded {}, replayed {}",
            d.index + 1,
            d.call,
            d.recorded,
            d.replayed
        ));
    }
    line
}
