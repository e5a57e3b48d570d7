//! `cumulus watch [SCENE]`: the live window. Plain `cumulus` runs it on the
//! embedded default scene.

use std::path::PathBuf;

use anyhow::Context as _;

/// Arguments of `cumulus watch`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene profile (TOML); the embedded fair-weather scene when omitted.
    pub scene: Option<PathBuf>,
    /// Run `--frames` frames, capture the whole window (3D view and panel)
    /// to this PNG, and exit.
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<PathBuf>,
    /// Frames to run, then exit (after writing the screenshot if asked; 10
    /// by default with --screenshot, else run until the window is closed).
    /// Counted frames advance the simulation by a fixed 1/30 s times the
    /// time speed, so a capture does not depend on the machine's speed.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: Option<u32>,
    /// Simulated time of the first frame, pre-simulated (with a progress
    /// display) so clouds have formed when the window opens; Reset returns
    /// to it. Default: the scene's [simulation] start_s.
    #[arg(long, value_name = "S")]
    pub warmup: Option<f64>,
    /// Window width in logical pixels.
    #[arg(long, default_value_t = 1280, value_parser = clap::value_parser!(u32).range(200..=8192))]
    pub width: u32,
    /// Window height in logical pixels.
    #[arg(long, default_value_t = 760, value_parser = clap::value_parser!(u32).range(200..=8192))]
    pub height: u32,
    /// Cloud render method (overrides the scene's [render] method): baked
    /// (default), exact, sprites (Wang 2003) or slices (Schpok 2003; its
    /// panel edits the qualitative controls and the authored ellipsoids).
    #[arg(long, value_parser = parse_method)]
    pub method: Option<cumulus::config::RenderMethod>,
    #[command(flatten)]
    pub overrides: super::SetArgs,
    /// Destroy the GPU device after frame N, to exercise the recovery from
    /// a lost device (a message in the panel and a new device).
    #[arg(long, value_name = "N", hide = true)]
    pub lose_device_after: Option<u32>,
}

/// Parses `--method` (the error names the allowed values).
pub fn parse_method(s: &str) -> Result<cumulus::config::RenderMethod, String> {
    s.parse().map_err(|e: cumulus::error::Error| e.to_string())
}

impl Default for Args {
    fn default() -> Self {
        let d = cumulus::app::WatchOptions::default();
        Self {
            scene: d.scene,
            screenshot: d.screenshot,
            frames: d.frames,
            warmup: d.warmup_s,
            width: d.size.0,
            height: d.size.1,
            method: d.method,
            overrides: super::SetArgs { set: d.set },
            lose_device_after: d.lose_device_after,
        }
    }
}

/// Runs `cumulus watch`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if let Some(path) = &args.screenshot {
        super::output_extension("--screenshot", path, &[("png", "")])?;
        super::writable_output("--screenshot", path)?;
    }
    if let Some(w) = args.warmup
        && !(w.is_finite() && (0.0..=cumulus::scene::MAX_START_S).contains(&w))
    {
        anyhow::bail!(
            "invalid --warmup {w}: a number of seconds from 0 to {}",
            cumulus::scene::MAX_START_S
        );
    }
    let opts = cumulus::app::WatchOptions {
        scene: args.scene,
        screenshot: args.screenshot,
        frames: args.frames,
        warmup_s: args.warmup,
        size: (args.width, args.height),
        method: args.method,
        set: args.overrides.set,
        lose_device_after: args.lose_device_after,
    };
    cumulus::app::run(opts).context("cumulus watch")
}
