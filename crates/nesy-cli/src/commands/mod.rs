//! One module per subcommand: its clap arguments and its `run` function.

pub mod adapt;
pub mod bench;
pub mod cassette;
pub mod record;
pub mod render;
pub mod run;
pub mod scenarios;
pub mod verify;
pub mod worker;
