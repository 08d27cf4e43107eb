//! `nesy demo`: bring a real-world demonstration into nesy.
//!
//! - `import SOURCE --out DIR` writes the demo folder `nesy adapt --demo` reads, from a video
//!   (MP4 with H.264), a folder of frames (one view, or one subfolder per view) or the
//!   authors' demo format (`data.json` and `frames/<view>/frame_<i>.jpg`), choosing keyframes
//!   and writing a contact sheet of the choice.
//! - `frames RECORDING --out SHEET.png` writes a contact sheet of a recording's keyframes.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use std::process::ExitCode;

use nesy_import::{AutoSettings, DEFAULT_VIEW, ImportOptions, KeyframeMode, MIN_MOTION, MIN_REST_S};
use nesy_sim::demo::DemoEmbodiment;

/// Arguments of `nesy demo`.
#[derive(Debug, clap::Args)]
pub(crate) struct DemoArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: DemoAction,
}

/// Who demonstrated, as the command line writes it.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub(crate) enum DemonstratorArg {
    /// A person (the hand is read as a finger gripper).
    Human,
    /// A robot with a two-finger gripper.
    Finger,
    /// A robot with a vacuum suction tool.
    Vacuum,
}

/// Arguments of `nesy demo import`.
#[derive(Debug, clap::Args)]
pub(crate) struct ImportArgs {
    /// A video (`.mp4`, `.m4v` or `.mov` with H.264), a folder of frames (`*.jpg`/`*.png`,
    /// or one subfolder per view), or a folder with the authors' `data.json` and `frames/`.
    source: PathBuf,
    /// The demo folder to write (new, or empty).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Keyframes: `auto` (where the scene, having changed, comes to rest; the default for
    /// a video), `every:SECONDS`, `at:T1,T2,...` (seconds), or `all` (every frame; the
    /// default for a folder, and the only choice for the authors' format).
    #[arg(long, value_name = "MODE", value_parser = parse_mode)]
    keyframes: Option<KeyframeMode>,
    /// `auto`: the least luma difference (0-255, over the 4-pixel block of a 128-pixel
    /// thumbnail where it is largest) that counts as motion; a noisy camera raises it by
    /// itself to three times its quiet level.
    #[arg(long, value_name = "LUMA", default_value_t = MIN_MOTION)]
    min_motion: f32,
    /// `auto`: seconds the pictures must stay still for the scene to be at rest.
    #[arg(long, value_name = "SECONDS", default_value_t = MIN_REST_S)]
    min_rest: f64,
    /// Frames per second of a frames folder (needed by auto, every: and at:; a video
    /// carries its own times).
    #[arg(long, value_name = "FPS")]
    fps: Option<f64>,
    /// The view name of a video, or of a folder holding its frames directly.
    #[arg(long, value_name = "NAME", default_value = DEFAULT_VIEW)]
    view: String,
    /// The task's instruction (required for a video or a frames folder).
    #[arg(long, value_name = "TEXT")]
    instruction: Option<String>,
    /// The objects in the scene, comma-separated (required for a video or a frames folder).
    #[arg(long, value_name = "A,B,...", value_delimiter = ',')]
    objects: Option<Vec<String>>,
    /// Who demonstrated (default: human for a video or frames, finger for the authors'
    /// format).
    #[arg(long, value_enum)]
    demonstrator: Option<DemonstratorArg>,
    /// The ground truth of a simulated demonstration video (`demo.video.json` from
    /// `nesy record --video`): keyframes get the recording's states at their frames (and
    /// the recorded calls of the true keyframes they match), the task and robot come from
    /// it, and the chosen keyframes are scored against the true ones.
    #[arg(long, value_name = "FILE")]
    truth: Option<PathBuf>,
    /// Print the import report as JSON.
    #[arg(long)]
    json: bool,
}

/// The `nesy demo` actions.
#[derive(Debug, clap::Subcommand)]
pub(crate) enum DemoAction {
    /// Write a demo folder from a video, a frames folder or the authors' demo format.
    Import(ImportArgs),
    /// Write a contact sheet of a recording's keyframes (a demo, or the `execution.mcap` of
    /// `nesy adapt --execute --render-every N`), each captioned with the call that led to it:
    /// a run's key steps at a glance.
    Frames {
        /// The recording (`demo.mcap` or `execution.mcap`).
        recording: PathBuf,
        /// The sheet to write (PNG).
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
        /// The camera view (`top`, `front`, `back`, or a real demo's own).
        #[arg(long, value_name = "NAME", default_value = "front")]
        view: String,
        /// Only the keyframes after these robot-API calls, comma-separated
        /// (`move_parallel,open_gripper`), with the first and the last keyframe.
        #[arg(long, value_name = "CALL,...", value_delimiter = ',')]
        after: Option<Vec<String>>,
    },
}

fn parse_mode(text: &str) -> Result<KeyframeMode, String> {
    text.parse()
}

/// Runs `nesy demo`.
pub(crate) fn run(args: DemoArgs) -> anyhow::Result<ExitCode> {
    match args.action {
        DemoAction::Import(import_args) => import(import_args),
        DemoAction::Frames {
            recording,
            out,
            view,
            after,
        } => frames(&recording, &out, &view, after.as_deref()),
    }
}

/// `nesy demo import`: a demo folder from a video, a frames folder or the authors' format.
fn import(args: ImportArgs) -> anyhow::Result<ExitCode> {
    let ImportArgs {
        source,
        out,
        keyframes,
        min_motion,
        min_rest,
        fps,
        view,
        instruction,
        objects,
        demonstrator,
        truth,
        json,
    } = args;
    let keyframes = keyframes.unwrap_or(if nesy_import::is_video(&source) {
        KeyframeMode::Auto
    } else {
        KeyframeMode::All
    });
    let options = ImportOptions {
        keyframes,
        auto: AutoSettings {
            min_motion,
            min_rest_s: min_rest,
        },
        fps,
        view,
        instruction,
        objects: objects.map(|list| {
            list.into_iter()
                .map(|o| o.trim().to_owned())
                .filter(|o| !o.is_empty())
                .collect()
        }),
        embodiment: demonstrator.map(|d| match d {
            DemonstratorArg::Human => DemoEmbodiment::Human,
            DemonstratorArg::Finger => DemoEmbodiment::Finger,
            DemonstratorArg::Vacuum => DemoEmbodiment::Vacuum,
        }),
        truth,
    };
    let report = nesy_import::import(&source, &out, &options)?;
    if json {
        outln!("{}", serde_json::to_string_pretty(&report)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    let times: Vec<String> = report
        .keyframes
        .iter()
        .map(|k| format!("{:.2}", k.time))
        .collect();
    outln!(
        "imported {} keyframe(s) of {} frame(s), views {}: {}\n  times (s)      {}\n  contact sheet  {}\n  adapt it with  nesy adapt --demo {} ...",
        report.keyframes.len(),
        report.frames,
        report.views.join(", "),
        report.out.display(),
        times.join(" "),
        report.contact_sheet.display(),
        report.out.display()
    )?;
    if let Some(m) = &report.truth_match {
        let seconds = |times: &[f64]| {
            times
                .iter()
                .map(|t| format!("{t:.2}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        outln!(
            "  against the recording's {} true keyframes (within {} s): recall {:.1}% ({} found), precision {:.1}% ({} extra)\n  missed (s)     {}\n  extra (s)      {}",
            m.truth,
            m.tolerance_s,
            100.0 * m.recall(),
            m.matched,
            100.0 * m.precision(),
            m.extra.len(),
            seconds(&m.missed),
            seconds(&m.extra)
        )?;
    }
    Ok(ExitCode::SUCCESS)
}

/// `nesy demo frames`: the chosen keyframes of a recording, captioned, on one sheet.
fn frames(recording: &Path, out: &Path, view: &str, after: Option<&[String]>) -> anyhow::Result<ExitCode> {
    let demo = nesy_sim::demo::read_mcap(recording)?;
    let last = demo.keyframes.len().saturating_sub(1);
    let chosen: Vec<&nesy_sim::demo::Keyframe> = demo
        .keyframes
        .iter()
        .filter(|k| match after {
            None => true,
            Some(calls) => {
                k.index == 0
                    || k.index == last
                    || k.action
                        .as_ref()
                        .is_some_and(|a| calls.iter().any(|c| c.trim() == a.call.name()))
            }
        })
        .collect();
    let mut cells = Vec::with_capacity(chosen.len());
    for keyframe in chosen {
        let images = keyframe.views.get(view).with_context(|| {
            format!(
                "{}: keyframe {} has no view {view:?}",
                recording.display(),
                keyframe.index
            )
        })?;
        let picture = nesy_import::decode(&images.raw)
            .map_err(|e| anyhow::anyhow!("{}: keyframe {}: {e}", recording.display(), keyframe.index))?;
        let caption = match &keyframe.action {
            Some(entry) => format!("{} {}", keyframe.index, entry.call.label()),
            None => format!("{} start", keyframe.index),
        };
        cells.push((picture, caption));
    }
    let sheet = nesy_import::contact_sheet(&cells);
    std::fs::write(out, sheet.to_png()).with_context(|| format!("writing {}", out.display()))?;
    outln!(
        "{} ({} keyframes of {})",
        out.display(),
        cells.len(),
        demo.keyframes.len()
    )?;
    Ok(ExitCode::SUCCESS)
}
