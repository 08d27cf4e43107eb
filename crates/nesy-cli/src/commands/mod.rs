//! One module per subcommand: its clap arguments and its `run` function.

pub(crate) mod adapt;
pub(crate) mod bench;
pub(crate) mod cassette;
pub(crate) mod demo;
pub(crate) mod prompts;
pub(crate) mod record;
pub(crate) mod render;
pub(crate) mod robot;
pub(crate) mod robot_server;
pub(crate) mod rollout;
pub(crate) mod run;
pub(crate) mod scenarios;
pub(crate) mod serve;
pub(crate) mod task;
pub(crate) mod verify;
pub(crate) mod worker;

/// A `--flag SECONDS` value as whole milliseconds: finite and positive, or an error naming
/// the flag.
pub(crate) fn seconds_to_ms(flag: &str, seconds: f64) -> anyhow::Result<u64> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 1e9) {
        anyhow::bail!("{flag} must be a positive number of seconds (at most 1e9), got {seconds}");
    }
    Ok((seconds * 1000.0).ceil() as u64)
}

/// A setting that is either on or off on the command line (`--flag on|off`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum OnOff {
    /// On.
    On,
    /// Off.
    Off,
}

impl OnOff {
    /// True for `on`.
    pub(crate) fn is_on(self) -> bool {
        self == OnOff::On
    }
}
