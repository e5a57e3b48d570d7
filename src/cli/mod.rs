//! Command-line front end: one module per subcommand, each with its clap
//! `Args` and a `run` function. `main.rs` only dispatches.

pub mod bench;
pub mod export;
pub mod parcel;
pub mod render;
pub mod simulate;
pub mod stability;
pub mod sun_args;
pub mod watch;
