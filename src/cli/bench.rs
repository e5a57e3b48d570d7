//! `cumulus bench`: headless performance tables and error against run time
//! (see `cumulus::bench`).

use std::path::PathBuf;

use cumulus::bench::{Mode, Options};

/// Arguments of `cumulus bench`.
#[derive(Debug, clap::Args)]
#[command(after_help = "Writes performance.md/.csv, error_vs_runtime.csv/.png, \
physics_error_vs_runtime.csv/.png, scaling.csv/.png, pruning.csv, reference.png and report.md \
(all sections and the speed targets) into --out, each file atomically. The full run is meant \
for real GPUs; --quick finishes in minutes on a CPU adapter (llvmpipe).")]
pub struct Args {
    /// Fewer repeats and sweep points, 160×120 unless --width/--height say otherwise.
    #[arg(long)]
    pub quick: bool,
    /// Seconds-long run for tests (two parcel counts, one point per sweep).
    #[arg(long, hide = true, conflicts_with = "quick")]
    pub tiny: bool,
    /// Only the headline speed goals, at 1920×1080 unless --width/--height
    /// say otherwise: writes gpu-check.md (adapter, driver, resolution,
    /// commit, pass/fail per goal) and gpu-check.csv into --out. Needs only
    /// the binary and profiles/; a few minutes on a discrete GPU.
    #[arg(long, conflicts_with_all = ["quick", "tiny", "method"])]
    pub gpu_check: bool,
    /// Output directory.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// Frame width in pixels (default 960, or 160 with --quick).
    #[arg(long, requires = "height")]
    pub width: Option<u32>,
    /// Frame height in pixels (default 540, or 120 with --quick).
    #[arg(long, requires = "width")]
    pub height: Option<u32>,
    /// Part of the GPU adapter's name to use (e.g. llvmpipe).
    #[arg(long)]
    pub adapter: Option<String>,
    /// Render method of the performance and pruning tables (the scaling
    /// table measures every method): baked (default), exact, sprites or slices.
    #[arg(long, value_parser = super::watch::parse_method)]
    pub method: Option<cumulus::config::RenderMethod>,
    /// Overrides for every scene file the bench loads (the methods table's
    /// profiles): `--set render.slices.quality=32`.
    #[command(flatten)]
    pub overrides: super::SetArgs,
}

/// Runs `cumulus bench`.
pub fn run(args: Args) -> anyhow::Result<()> {
    let mode = if args.tiny {
        Mode::Tiny
    } else if args.quick {
        Mode::Quick
    } else {
        Mode::Full
    };
    let size = args.width.zip(args.height);
    if let Some((w, h)) = size {
        anyhow::ensure!(
            (16..=8192).contains(&w) && (16..=8192).contains(&h),
            "--width and --height must be 16 to 8192 pixels (got {w}×{h})"
        );
    }
    // Before minutes of measuring.
    super::writable_folder("--out", &args.out)?;
    if args.gpu_check {
        let start = std::time::Instant::now();
        let (md, rows) = cumulus::bench::run_gpu_check(
            args.adapter.as_deref(),
            size,
            &args.out,
            &args.overrides.set,
            true,
        )?;
        print!("{md}");
        eprintln!(
            "wrote {} ({} cases) in {:.0} s",
            args.out.join("gpu-check.md").display(),
            rows.len(),
            start.elapsed().as_secs_f64()
        );
        return Ok(());
    }
    let opts = Options {
        mode,
        out: args.out,
        size,
        adapter: args.adapter,
        progress: true,
        method: args.method.unwrap_or_default(),
        overrides: args.overrides.set,
    };
    let start = std::time::Instant::now();
    let results = cumulus::bench::run(&opts)?;
    eprintln!(
        "adapter: {} ({}); wrote {} in {:.0} s",
        results.info.adapter,
        results.info.backend,
        opts.out.join("report.md").display(),
        start.elapsed().as_secs_f64()
    );
    for t in cumulus::bench::report::targets(&results) {
        eprintln!(
            "target {}: {} (goal {}): {}",
            t.name,
            t.measured,
            t.goal,
            match t.pass {
                Some(true) => "pass",
                Some(false) => "FAIL",
                None => "not measured",
            }
        );
    }
    Ok(())
}
