//! Headless benchmark (`cumulus bench`): performance tables (paper Table 1:
//! parcel count × normals × shadows, physics and per-pass shares), error
//! against run time for render settings and physics time steps with their
//! Pareto fronts (and against the path tracer when its results are in the
//! output folder, [`pathtraced`]), frame time against parcel count for each
//! render method (baked, exact with grid culling, brute force), the
//! savings of leaving passes out, the physics sub-step time at scale
//! ([`physics_speed`]), the render methods side by side ([`methods`]), the
//! landscape with temporal upscaling off, 2x2 and 4x4 ([`landscape`]), the
//! slices' vertex field on the CPU against the compute pass
//! ([`slices_field`]), and the project's speed targets checked as ratios
//! within one run. Everything is written atomically into one directory as
//! Markdown, CSV and PNG.
//!
//! Layers: [`scenes`] builds worlds with exact condensed-parcel counts;
//! [`measure`] times frames (warm-up + median); [`perf`], [`accuracy`] and
//! the modules above run the sweeps; [`stats`] holds the medians, image
//! metrics and Pareto fronts; [`report`] and [`plots`] write the files.

pub mod accuracy;
mod charts;
pub mod clipmap;
pub mod gpu_check;
pub mod landscape;
pub mod measure;
pub mod methods;
pub mod pathtraced;
pub mod perf;
mod physics_error;
pub mod physics_speed;
pub mod plots;
pub mod report;
pub mod scenes;
pub mod slices_field;
pub mod stats;

use std::path::PathBuf;

use crate::config::RenderConfig;
use crate::error::Result;
use crate::render::GpuContext;

use accuracy::{PhysicsError, RenderError, RenderSweep};
use measure::Repeats;
use perf::{PerfRow, PruningRow, ScalingRow};

/// Parcel counts of the scaling table in quick mode.
/// (1000 and 10 000: the bake's target, bake(10 000)/bake(1000).)
pub const QUICK_SCALING_COUNTS: [usize; 6] = [8, 85, 1000, 1024, 4096, 10_000];
/// Parcel counts of the scaling table in full mode.
pub const FULL_SCALING_COUNTS: [usize; 9] = [8, 85, 256, 1000, 1024, 4096, 8192, 10_000, 16_384];
/// Parcel counts of the performance table (paper Table 1, and beyond).
pub const TABLE_COUNTS: [usize; 6] = [8, 14, 34, 85, 256, 1024];

/// Most parcels measured by brute force on a CPU adapter. Mesa llvmpipe
/// cuts brute-force marches short once the parcel loop has run ~65 000
/// times in a ray (34 parcels: exact up to ~1300 steps, towers lost from
/// ~2000 — see [`accuracy::brute_force_reference`]); 256 parcels × the
/// default 160 steps stays below that, 1024 would not.
pub const CPU_BRUTE_MAX: usize = 256;

/// How much to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Every sweep point, many repeats: for real GPUs.
    Full,
    /// Fewer repeats and sweep points, small frames: minutes on a CPU adapter.
    Quick,
    /// Seconds on a CPU adapter: two parcel counts, one point per sweep (tests).
    Tiny,
}

impl Mode {
    /// Frame size when none is given. units: px
    pub fn default_size(self) -> (u32, u32) {
        match self {
            Mode::Full => (960, 540),
            Mode::Quick => (160, 120),
            Mode::Tiny => (64, 48),
        }
    }
}

/// Options of a bench run.
#[derive(Debug, Clone)]
pub struct Options {
    pub mode: Mode,
    /// Output directory (created if missing).
    pub out: PathBuf,
    /// Frame size; None = the mode's default. units: px
    pub size: Option<(u32, u32)>,
    /// Part of the adapter name to use (e.g. "llvmpipe").
    pub adapter: Option<String>,
    /// Show progress bars on stderr.
    pub progress: bool,
    /// Render method of the performance and pruning tables and the error
    /// sweep's base (the scaling table measures every method).
    pub method: crate::config::RenderMethod,
    /// `--set TABLE.KEY=VALUE` overrides applied to every scene file the
    /// bench loads (the profiles of the methods table, see
    /// [`methods::cases`]), validated exactly like the file.
    pub overrides: Vec<String>,
}

/// What each section measures, by mode.
#[derive(Debug, Clone)]
pub struct Plan {
    pub counts: Vec<usize>,
    pub reps: Repeats,
    /// Parcels in the render error frame.
    pub error_parcels: usize,
    pub sweep: RenderSweep,
    /// Measured frames of the (slow) reference.
    pub reference_repeats: usize,
    pub physics_parcels: usize,
    pub physics_duration_s: f64,
    pub physics_dts: Vec<f64>,
    pub physics_reference_dt_s: f64,
    /// Parcel counts of the physics speed table.
    pub physics_speed_counts: Vec<usize>,
    pub scaling_counts: Vec<usize>,
    /// Largest count measured by brute force.
    pub brute_max: usize,
    pub pruning_parcels: usize,
}

impl Plan {
    /// The plan of `mode`.
    pub fn for_mode(mode: Mode) -> Self {
        match mode {
            Mode::Full => Plan {
                counts: TABLE_COUNTS.to_vec(),
                reps: Repeats {
                    warmup: 3,
                    measured: 11,
                    budget_ms: 20_000.0,
                },
                error_parcels: 34,
                sweep: RenderSweep {
                    step_factors: vec![4.0, 2.0, 0.5, 0.25, 0.125],
                    octaves: vec![1, 2, 3, 5, 6],
                    light_steps: vec![0, 1, 2, 8, 16],
                    no_grid_culling: true,
                    early_exit: vec![0.0, 0.005, 0.05, 0.1, 0.2],
                    resolution_scales: vec![0.25, 0.5, 0.75],
                    slices_quality: vec![16, 32, 64, 256],
                },
                reference_repeats: 3,
                physics_parcels: 8,
                physics_duration_s: 600.0,
                physics_dts: vec![8.0, 4.0, 2.0, 1.0, 0.5, 0.25],
                physics_reference_dt_s: 1.0 / 64.0,
                scaling_counts: FULL_SCALING_COUNTS.to_vec(),
                physics_speed_counts: vec![1000, 10_000, 100_000],
                brute_max: 1024,
                pruning_parcels: 85,
            },
            Mode::Quick => Plan {
                counts: TABLE_COUNTS.to_vec(),
                reps: Repeats {
                    warmup: 1,
                    measured: 3,
                    budget_ms: 2_500.0,
                },
                error_parcels: 34,
                sweep: RenderSweep {
                    step_factors: vec![4.0, 2.0, 0.5, 0.25],
                    octaves: vec![1, 2, 6],
                    light_steps: vec![0, 1, 16],
                    no_grid_culling: true,
                    early_exit: vec![0.0, 0.1],
                    resolution_scales: vec![0.5],
                    slices_quality: vec![32],
                },
                reference_repeats: 1,
                physics_parcels: 8,
                physics_duration_s: 240.0,
                physics_dts: vec![4.0, 2.0, 1.0, 0.5],
                physics_reference_dt_s: 1.0 / 16.0,
                scaling_counts: QUICK_SCALING_COUNTS.to_vec(),
                physics_speed_counts: vec![1000, 10_000],
                brute_max: 85,
                pruning_parcels: 85,
            },
            Mode::Tiny => Plan {
                counts: vec![8, 85],
                // One warm-up even here: the CPU adapter compiles a pipeline
                // on its first draw, which would otherwise be timed.
                reps: Repeats {
                    warmup: 1,
                    measured: 1,
                    budget_ms: 1_000.0,
                },
                error_parcels: 14,
                sweep: RenderSweep {
                    step_factors: vec![2.0],
                    octaves: vec![],
                    light_steps: vec![],
                    no_grid_culling: false,
                    early_exit: vec![],
                    resolution_scales: vec![0.5],
                    slices_quality: vec![],
                },
                reference_repeats: 1,
                physics_parcels: 4,
                physics_duration_s: 20.0,
                physics_dts: vec![2.0, 1.0],
                physics_reference_dt_s: 0.25,
                physics_speed_counts: vec![256],
                scaling_counts: vec![8, 85],
                brute_max: 85,
                pruning_parcels: 8,
            },
        }
    }

    /// Progress ticks the run will make.
    fn ticks(&self) -> u64 {
        let settings = self.sweep.settings(&RenderConfig::default()).len();
        let limited = |max: usize| self.scaling_counts.iter().filter(|&&n| n <= max).count();
        let brute = limited(
            self.brute_max
                .min(crate::methods::raymarch::pack::MAX_PARCELS),
        ) + limited(crate::methods::raymarch::pack::MAX_PARCELS);
        (self.counts.len() * 4
            + 1
            + settings
            + 1
            + self.physics_dts.len()
            + self.physics_speed_counts.len()
            + self.scaling_counts.len()
            + brute
            + methods::cases().len()
            + slices_field::ROWS
            + 5) as u64
    }
}

/// Where and how the run was measured.
#[derive(Debug, Clone)]
pub struct RunInfo {
    pub adapter: String,
    pub driver: String,
    pub backend: String,
    pub cpu_adapter: bool,
    pub gpu_timestamps: bool,
    pub width: u32,
    pub height: u32,
    /// "debug" or "release" (`cfg!(debug_assertions)`).
    pub profile: &'static str,
    /// `git rev-parse --short HEAD` at run time, or "unknown".
    pub commit: String,
    pub mode: Mode,
    pub reps: Repeats,
}

impl RunInfo {
    /// A run on `ctx` at `size`.
    pub fn of(ctx: &GpuContext, size: (u32, u32), mode: Mode, reps: Repeats) -> Self {
        RunInfo {
            adapter: ctx.adapter_name(),
            driver: ctx.driver(),
            backend: ctx.backend(),
            cpu_adapter: ctx.is_cpu(),
            gpu_timestamps: ctx.timestamps,
            width: size.0,
            height: size.1,
            profile: if cfg!(debug_assertions) {
                "debug"
            } else {
                "release"
            },
            commit: commit(),
            mode,
            reps,
        }
    }
}

/// Today's date (UTC), YYYY-MM-DD.
pub fn today() -> String {
    let days = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() / 86_400) as i64;
    // civil_from_days counts from 2000-01-01, 10 957 days after 1970-01-01.
    let (y, m, d) = crate::sun::civil_from_days(days - 10_957);
    format!("{y:04}-{m:02}-{d:02}")
}

/// `cumulus bench --gpu-check`: opens the GPU, measures the goals'
/// cases at `size` (default [`gpu_check::SIZE`]) and writes
/// `gpu-check.md` and `.csv` into `out`. Returns the page and the rows.
pub fn run_gpu_check(
    adapter: Option<&str>,
    size: Option<(u32, u32)>,
    out: &std::path::Path,
    overrides: &[String],
    progress: bool,
) -> Result<(String, Vec<gpu_check::CheckRow>)> {
    methods::check_overrides(overrides)?;
    let ctx = GpuContext::new_headless(adapter)?;
    crate::render::renderer::check_method(&ctx, crate::config::RenderMethod::default())?;
    let size = size.unwrap_or(gpu_check::SIZE);
    let bar = if progress {
        indicatif::ProgressBar::new_spinner()
    } else {
        indicatif::ProgressBar::hidden()
    };
    let rows = gpu_check::gpu_check(&ctx, size, overrides, |m| {
        bar.set_message(m.to_string());
        bar.tick();
    })?;
    bar.finish_and_clear();
    let info = RunInfo::of(&ctx, size, Mode::Full, gpu_check::REPEATS);
    let md = gpu_check::check_md(&info, &today(), &rows);
    gpu_check::write(out, &md, &rows)?;
    Ok((md, rows))
}

/// Everything a run measured.
#[derive(Debug, Clone)]
pub struct BenchResults {
    pub info: RunInfo,
    pub performance: Vec<PerfRow>,
    pub render_error: RenderError,
    pub physics_error: PhysicsError,
    pub physics_speed: Vec<physics_speed::PhysicsSpeedRow>,
    pub scaling: Vec<ScalingRow>,
    pub pruning: Vec<PruningRow>,
    /// Rows of error_vs_pathtraced.csv found in the output folder, if any.
    pub pathtraced: Option<Vec<pathtraced::PathTracedRow>>,
    /// The render methods side by side (methods.csv).
    pub methods: Vec<methods::MethodRow>,
    /// The landscape scene with temporal upscaling off, 2x2 and 4x4
    /// (landscape.csv).
    pub landscape: Vec<landscape::LandscapeRow>,
    /// The 100 km landscape's clipmap (not in the tiny mode).
    pub clipmap: Option<clipmap::ClipmapRow>,
}

/// The commit being measured: `$CUMULUS_COMMIT` (for a release binary
/// run away from its source tree), else what git says here, else
/// "unknown".
fn commit() -> String {
    if let Ok(c) = std::env::var("CUMULUS_COMMIT")
        && !c.trim().is_empty()
    {
        return c.trim().to_string();
    }
    std::process::Command::new("git")
        .args(["rev-parse", "--short", "HEAD"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

/// Opens the GPU, runs every section and writes the files into
/// `opts.out`. Returns what was measured.
pub fn run(opts: &Options) -> Result<BenchResults> {
    // Bad overrides fail before the device opens and anything is measured.
    methods::check_overrides(&opts.overrides)?;
    let ctx = GpuContext::new_headless(opts.adapter.as_deref())?;
    run_with(&ctx, opts)
}

/// [`run`] on an open device.
pub fn run_with(ctx: &GpuContext, opts: &Options) -> Result<BenchResults> {
    let mut plan = Plan::for_mode(opts.mode);
    if ctx.is_cpu() {
        plan.brute_max = plan.brute_max.min(CPU_BRUTE_MAX);
    }
    let (width, height) = opts.size.unwrap_or(opts.mode.default_size());
    let size = (width, height);
    let info = RunInfo::of(ctx, size, opts.mode, plan.reps);

    let bar = if opts.progress {
        let b = indicatif::ProgressBar::new(plan.ticks());
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:32} {pos}/{len} {elapsed} (ETA {eta}) {wide_msg}",
            )
            .expect("valid template"),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    let tick = |msg: &str| {
        bar.set_message(msg.to_string());
        bar.inc(1);
    };

    let performance = perf::performance(ctx, size, &plan.counts, opts.method, plan.reps, tick)?;

    let base = RenderConfig {
        method: opts.method,
        ..RenderConfig::default()
    };
    let error_parcels = scenes::cloud_parcels(&scenes::cloud_field(plan.error_parcels)?);
    let render_error = accuracy::render_sweep(
        ctx,
        &error_parcels,
        perf::camera(),
        base.sun(),
        &base,
        &plan.sweep,
        size,
        plan.reps,
        Repeats {
            measured: plan.reference_repeats,
            ..plan.reps
        },
        tick,
    )?;

    let physics_error = accuracy::physics_sweep(
        plan.physics_parcels,
        plan.physics_duration_s,
        &plan.physics_dts,
        plan.physics_reference_dt_s,
        tick,
    )?;

    let physics_speed = physics_speed::physics_speed(&plan.physics_speed_counts, 5, tick)?;

    let scaling = perf::scaling(
        ctx,
        size,
        &plan.scaling_counts,
        plan.brute_max,
        plan.reps,
        tick,
    )?;
    let pruning = perf::pruning(
        ctx,
        size,
        plan.pruning_parcels,
        opts.method,
        plan.reps,
        tick,
    )?;
    let methods = methods::methods(ctx, size, plan.reps, &opts.overrides, tick)?;
    let slices = slices_field::slices_rows(ctx, size, plan.reps, &opts.overrides, tick)?;
    let landscape = landscape::landscape(ctx, opts.mode, plan.reps, &opts.overrides)?;
    tick("landscape");
    let clipmap = (opts.mode != Mode::Tiny)
        .then(|| clipmap::landscape_100km(&opts.overrides))
        .transpose()?;
    bar.finish_and_clear();

    let results = BenchResults {
        info,
        performance,
        render_error,
        physics_error,
        physics_speed,
        scaling,
        pruning,
        pathtraced: pathtraced::read(&opts.out)?,
        methods,
        landscape,
        clipmap,
    };
    report::write_all(&opts.out, &results)?;
    methods::write(&opts.out, &results.methods, width, height)?;
    landscape::write(&opts.out, &results.landscape)?;
    slices_field::write(&opts.out, &slices, width, height)?;
    Ok(results)
}
