//! The `cumulus` command: dispatches to one module per subcommand.

mod cli;

use clap::{Parser, Subcommand};

/// Grow cumulus clouds from atmospheric parcel physics and render them on the GPU.
///
/// With no command, opens the live window on the embedded default scene.
#[derive(Debug, Parser)]
#[command(name = "cumulus", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Open the live window: watch clouds form and edit the profile.
    Watch(cli::watch::Args),
    /// Simulate a scene and render frame(s) headless: PNG, or linear HDR .exr.
    Render(cli::render::Args),
    /// Run a scene headless: a summary, and per-frame diagnostics as CSV with --out.
    Simulate(cli::simulate::Args),
    /// Lift parcels through a sounding: LCL, LFC, EL, CAPE, CIN, Skew-T diagram.
    Parcel(cli::parcel::Args),
    /// Record performance tables and error against run time.
    Bench(cli::bench::Args),
    /// Run the matrix of stiff and extreme cases.
    Stability(cli::stability::Args),
    /// Write a frame's cloud density as a Mitsuba 3 .vol or OpenVDB .vdb grid, plus a JSON sidecar.
    Export(cli::export::Args),
    /// Write the sprite method's 16-tile texture atlas as a PNG.
    Atlas(cli::atlas::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => cli::watch::run(cli::watch::Args::default()),
        Some(Command::Watch(a)) => cli::watch::run(a),
        Some(Command::Render(a)) => cli::render::run(a),
        Some(Command::Simulate(a)) => cli::simulate::run(a),
        Some(Command::Parcel(a)) => cli::parcel::run(a),
        Some(Command::Bench(a)) => cli::bench::run(a),
        Some(Command::Stability(a)) => cli::stability::run(a),
        Some(Command::Export(a)) => cli::export::run(a),
        Some(Command::Atlas(a)) => cli::atlas::run(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            // 2: this machine's adapter cannot run it (no adapter, or a
            // method it lacks a capability for); the message says the fix.
            let unsupported = matches!(
                e.downcast_ref::<cumulus::Error>(),
                Some(cumulus::Error::Unsupported(_) | cumulus::Error::NoAdapter(_))
            );
            std::process::ExitCode::from(if unsupported { 2 } else { 1 })
        }
    }
}
