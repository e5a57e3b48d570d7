//! Command-line front end: one module per subcommand, each with its clap
//! `Args` and a `run` function. `main.rs` only dispatches.

pub mod atlas;
pub mod bench;
pub mod export;
pub mod parcel;
mod parcel_report;
pub mod render;
pub mod simulate;
pub mod stability;
pub mod sun_args;
pub mod watch;

/// `--set TABLE.KEY=VALUE`: scene overrides for every command that loads a
/// scene, applied to the TOML and validated exactly like the file
/// (`cumulus::scene::set`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SetArgs {
    /// Override a scene value, validated like the file (repeatable), e.g.
    /// `--set physics.mixing=false --set render.method=exact`.
    #[arg(long = "set", value_name = "TABLE.KEY=VALUE")]
    pub set: Vec<String>,
}
