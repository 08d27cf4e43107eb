//! `nesy robot-server`: the simulator served over the robot protocol, so that the bridge is
//! tested end to end against a separate process and a lab can try its client set-up without
//! hardware.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use nesy_core::Embodiment;
use nesy_policy::{EpisodeFactory, EpisodeSpec, SimEpisodes};
use nesy_robot::{EventLog, RobotAddress, ServerOptions, SessionEnd, serve_session};
use serde_json::json;

/// Arguments of `nesy robot-server`.
#[derive(Debug, clap::Args)]
pub(crate) struct RobotServerArgs {
    /// The scene each session starts from (a fresh copy per connection).
    #[arg(long)]
    pub scene: PathBuf,
    /// Override the scene's end effector.
    #[arg(long, value_parser = super::run::parse_embodiment)]
    pub embodiment: Option<Embodiment>,
    /// Where to listen: `HOST:PORT` (port 0 takes a free one) or `unix:PATH`.
    #[arg(long, value_name = "ADDRESS", default_value = "127.0.0.1:0")]
    pub listen: RobotAddress,
    /// Stop the robot after this many seconds without a message from the client.
    #[arg(long, value_name = "SECS", default_value_t = 1.5)]
    pub heartbeat_timeout: f64,
    /// Serve one session, then exit.
    #[arg(long)]
    pub once: bool,
    /// Write the server's events (requests, answers, stops) here as JSON lines, instead of
    /// to standard error.
    #[arg(long, value_name = "FILE")]
    pub log: Option<PathBuf>,
}

/// Runs `nesy robot-server`: prints `listening on ADDRESS` once bound, then serves sessions
/// one after another (one with `--once`).
pub(crate) fn run(args: RobotServerArgs) -> anyhow::Result<ExitCode> {
    let scene = std::path::absolute(&args.scene).unwrap_or(args.scene.clone());
    let spec = EpisodeSpec::Scene {
        path: scene.clone(),
        embodiment: args.embodiment,
    };
    // The first session's episode is built up front, so that a bad scene is reported before
    // anyone connects.
    let mut ready = Some(SimEpisodes.build(&spec).map_err(anyhow::Error::from)?);
    let options = ServerOptions {
        robot_name: format!("nesy simulator: {}", args.scene.display()),
        heartbeat_timeout: Duration::from_millis(super::seconds_to_ms(
            "--heartbeat-timeout",
            args.heartbeat_timeout,
        )?),
    };
    let sink: Box<dyn Write + Send> = match &args.log {
        Some(path) => Box::new(
            std::fs::File::create(path).with_context(|| format!("creating the log {}", path.display()))?,
        ),
        None => Box::new(std::io::stderr()),
    };
    let log = EventLog::new(sink);
    let listener = args
        .listen
        .listen()
        .with_context(|| format!("listening on {}", args.listen))?;
    let address = listener.address()?;
    outln!("listening on {address}")?;
    log.event(
        "listening",
        json!({"address": address.to_string(), "scene": scene}),
    );
    loop {
        let episode = match ready.take() {
            Some(episode) => episode,
            None => SimEpisodes.build(&spec).map_err(anyhow::Error::from)?,
        };
        let end = serve_session(&listener, episode, &options, &log).context("serving a session")?;
        log.event("session_ended", json!({"end": format!("{end:?}")}));
        if args.once {
            return Ok(if end == SessionEnd::Stopped {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            });
        }
    }
}
