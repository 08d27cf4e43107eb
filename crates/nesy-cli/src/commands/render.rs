//! `nesy render`: render a scene's top, front and back views (plain and labelled) as PNG.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use nesy_sim::perception::render::{
    MAX_RENDER_THREADS, VIEW_SIZE, default_threads, render_views, write_views,
};
use nesy_sim::world::{Sim, SimConfig};

/// Arguments of `nesy render`.
#[derive(Debug, clap::Args)]
pub(crate) struct RenderArgs {
    /// Scene file (`scene.json`).
    #[arg(long)]
    pub scene: PathBuf,
    /// Output directory; receives `{top,front,back}.png` and `*_marked.png`.
    #[arg(long)]
    pub out: PathBuf,
    /// Image side in pixels.
    #[arg(long, default_value_t = VIEW_SIZE)]
    pub size: u32,
    /// Render threads (default: available cores, at most 4; at most 64).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=MAX_RENDER_THREADS as u64))]
    pub threads: Option<u64>,
    /// Control steps to let objects settle before rendering (0.01 s each; at most
    /// 100 000, 1000 s simulated).
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(0..=MAX_SETTLE_STEPS as i64))]
    pub settle_steps: u32,
}

/// Most settle steps `nesy render` takes: 1000 s simulated, far past any scene at rest.
pub(crate) const MAX_SETTLE_STEPS: u32 = 100_000;

/// Runs `nesy render`.
pub(crate) fn run(args: RenderArgs) -> anyhow::Result<ExitCode> {
    if !(16..=4096).contains(&args.size) {
        anyhow::bail!("--size must be between 16 and 4096 pixels, got {}", args.size);
    }
    let spec = nesy_sim::scene::SceneSpec::from_file(&args.scene)?;
    let config = SimConfig {
        settle_steps: args.settle_steps,
        ..SimConfig::default()
    };
    let sim =
        Sim::with_config(&spec, config).map_err(|e| e.with_origin(&args.scene.display().to_string()))?;
    let threads = args.threads.map_or_else(default_threads, |n| n as usize).max(1);
    let started = Instant::now();
    let views = render_views(&sim, args.size, threads);
    let elapsed = started.elapsed();
    let written = write_views(&views, &args.out)
        .with_context(|| format!("writing images to {}", args.out.display()))?;
    for path in &written {
        outln!("{}", path.display())?;
    }
    eprintln!(
        "rendered 3 views at {}x{} in {:.1} ms on {threads} thread(s)",
        args.size,
        args.size,
        elapsed.as_secs_f64() * 1000.0
    );
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture(name: &str) -> PathBuf {
        nesy_testkit::workspace_root().join("fixtures/scenes").join(name)
    }

    #[test]
    fn writes_six_pngs() {
        let out = tempfile::tempdir().unwrap();
        let args = RenderArgs {
            scene: fixture("hinge_finger.json"),
            out: out.path().to_path_buf(),
            size: 64,
            threads: Some(2),
            settle_steps: 5,
        };
        assert_eq!(run(args).unwrap(), ExitCode::SUCCESS);
        for view in [
            "top",
            "front",
            "back",
            "top_marked",
            "front_marked",
            "back_marked",
        ] {
            let bytes = std::fs::read(out.path().join(format!("{view}.png"))).unwrap();
            assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
            // IHDR width and height.
            assert_eq!(&bytes[16..24], &[0, 0, 0, 64, 0, 0, 0, 64]);
        }
    }

    #[test]
    fn a_bad_scene_names_the_file_and_field() {
        let dir = tempfile::tempdir().unwrap();
        let scene = dir.path().join("bad.json");
        std::fs::write(
            &scene,
            r#"{"schema_version": 1, "embodiment": "suction", "objects": []}"#,
        )
        .unwrap();
        let args = RenderArgs {
            scene: scene.clone(),
            out: dir.path().join("out"),
            size: 64,
            threads: None,
            settle_steps: 0,
        };
        let message = format!("{:#}", run(args).unwrap_err());
        assert!(
            message.contains("bad.json") && message.contains("embodiment"),
            "{message}"
        );
    }
}
