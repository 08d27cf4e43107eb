//! One module per subcommand: its clap arguments and its `run` function.

pub mod adapt;
pub mod cassette;
pub mod render;
pub mod run;
pub mod verify;
pub mod worker;
