//! `cumulus render`: simulate a scene, then render frame(s) headless with the
//! same renderer the window uses, as PNG or linear HDR OpenEXR.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use cumulus::config::{Camera, TemporalMode};
use cumulus::physics::{CloudParcel, ParcelWorld};
use cumulus::render::headless::Headless;
use cumulus::render::{FrameInput, GpuContext};

/// On or off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Switch {
    On,
    Off,
}

/// Arguments of `cumulus render`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "With --frames N > 1 the frames are written as FILE-0000.png, FILE-0001.png, … \
(the number before the extension of --out), one every --every seconds of simulated time \
starting at --time. Every file is written atomically."
)]
pub struct Args {
    /// Scene profile (TOML); the embedded fair-weather scene when omitted.
    pub scene: Option<PathBuf>,
    /// Output image: FILE.png (tone-mapped sRGB, as the window shows it) or
    /// FILE.exr (the linear HDR scene before the tone map, 32-bit float RGB).
    #[arg(long)]
    pub out: PathBuf,
    /// Image width in pixels (1 to 16384; the device may allow less).
    #[arg(long, default_value_t = 960, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: u32,
    /// Image height in pixels (1 to 16384; the device may allow less).
    #[arg(long, default_value_t = 540, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: u32,
    /// Simulated time of the (first) frame, counted from the start of the
    /// simulation; default: the scene's [simulation] start_s. units: s
    #[arg(long, allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// Local clock time of the (first) frame (0 to 24, e.g. 18.5): moves the
    /// scene's [sun] clock, so the sun and the ground's heating follow. units: h
    #[arg(long, allow_negative_numbers = true)]
    pub hour: Option<f64>,
    /// Local date of the (first) frame, YYYY-MM-DD (moves the [sun] clock).
    #[arg(long)]
    pub date: Option<String>,
    /// Cloud render method (overrides the scene's [render] method): baked
    /// (default), exact, sprites (Wang 2003) or slices (Schpok 2003: the
    /// scene's authored [[ellipsoids]] and the parcels, by light-aligned
    /// slicing planes).
    #[arg(long, value_parser = super::watch::parse_method)]
    pub method: Option<cumulus::config::RenderMethod>,
    #[command(flatten)]
    pub overrides: super::SetArgs,
    /// Finite-difference normals (overrides the scene's [render] normals).
    #[arg(long, value_enum)]
    pub normals: Option<Switch>,
    /// Temporal upscaling ([render] temporal): draw N frames of each
    /// output frame on the temporal path (one pixel in 16, or in 4 under
    /// `--set render.temporal=2x2`, marched per frame, the others
    /// reprojected and accumulated) and write the last. 16 frames (4 at
    /// 2x2) march every pixel once; more average more ray-start jitters.
    /// Without it every pixel is marched once (no temporal path).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub accumulate: Option<u32>,
    /// Number of frames.
    #[arg(long, default_value_t = 1)]
    pub frames: u32,
    /// Simulated time between frames. units: s
    #[arg(long, default_value_t = 60.0, allow_negative_numbers = true)]
    pub every: f64,
    /// Do not write the names of the scene's named sprite clouds into the
    /// image (written above each cloud by default, e.g. cloud_types.toml).
    #[arg(long)]
    pub no_labels: bool,
    #[command(flatten)]
    pub clouds: CloudArgs,
    /// Also write the drawn cloud parcels (of the first frame) to this CSV
    /// file, which `--parcels` reads back.
    #[arg(long, value_name = "FILE.csv")]
    pub save_parcels: Option<PathBuf>,
    /// Part of the GPU adapter's name to use (e.g. llvmpipe).
    #[arg(long)]
    pub adapter: Option<String>,
}

/// Whether `path` names an OpenEXR file (extension `exr`, any case).
fn is_exr(path: &Path) -> bool {
    super::has_extension(path, "exr")
}

/// `FILE.png` → `FILE-0007.png`.
pub fn numbered(out: &Path, i: u32) -> PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_else(|| "png".into());
    out.with_file_name(format!("{stem}-{i:04}.{ext}"))
}

/// Where a frame's clouds come from, for the commands that simulate a scene
/// up to a frame (`render`, `export`).
#[derive(Debug, Clone, clap::Args)]
pub struct CloudArgs {
    /// Physics frame step (sub-stepped as needed). units: s
    #[arg(long, default_value_t = 2.0)]
    pub dt: f64,
    /// Seed of the emission draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Use the deterministic stand-in cloud field instead of simulating.
    #[arg(long, conflicts_with = "parcels")]
    pub stand_in: bool,
    /// Draw the cloud parcels of this file instead of simulating (CSV with
    /// the header `id,x_m,y_m,z_m,radius_m,fill,cond_plane_z_m`, as
    /// `render --save-parcels` writes it); the field does not change with time.
    #[arg(long, value_name = "FILE.csv")]
    pub parcels: Option<PathBuf>,
}

impl CloudArgs {
    /// Checks the values before any work (the error names the flag).
    pub fn validate(&self) -> anyhow::Result<()> {
        check_frame_dt(self.dt)
    }
}

/// Longest physics frame `--dt` of the commands that simulate a scene
/// (each frame is sub-stepped as the physics needs). units: s
const MAX_FRAME_DT_S: f64 = 600.0;

/// Checks a scene simulation's `--dt` (`render`, `export`, `simulate`).
pub(crate) fn check_frame_dt(dt: f64) -> anyhow::Result<()> {
    anyhow::ensure!(
        dt.is_finite() && dt > 0.0 && dt <= MAX_FRAME_DT_S,
        "invalid --dt {dt}: a positive number of seconds up to {MAX_FRAME_DT_S}"
    );
    Ok(())
}

/// Where the clouds come from: the parcel physics, the stand-in field or a
/// cloud-field file.
pub(crate) enum Clouds {
    World { world: Box<ParcelWorld>, dt: f64 },
    StandIn,
    File(Vec<CloudParcel>),
}

impl Clouds {
    /// The stand-in field, the parcels of `--parcels`, or `scene`'s world at
    /// t = 0 with `args`' seed (`source` says where the scene came from).
    pub(crate) fn new(
        args: &CloudArgs,
        scene: &cumulus::scene::SceneProfile,
        source: &cumulus::scene::SceneSource,
    ) -> anyhow::Result<Self> {
        if args.stand_in {
            return Ok(Clouds::StandIn);
        }
        if let Some(path) = &args.parcels {
            return Ok(Clouds::File(cumulus::physics::cloud_file::read(path)?));
        }
        let env = scene
            .build_atmosphere(source)
            .context("building the atmosphere")?;
        let world = ParcelWorld::new(env, scene.world_config(&source.base_dir())?, args.seed)?;
        Ok(Clouds::World {
            world: Box::new(world),
            dt: args.dt,
        })
    }

    /// The condensed parcels at simulated time `time_s` (≥ the last call's);
    /// `bar` shows the simulated seconds.
    pub(crate) fn at(
        &mut self,
        time_s: f64,
        out: &mut Vec<CloudParcel>,
        bar: Option<&indicatif::ProgressBar>,
    ) -> anyhow::Result<()> {
        match self {
            Clouds::StandIn => *out = cumulus::methods::standin::default_field(time_s as f32),
            Clouds::File(parcels) => out.clone_from(parcels),
            Clouds::World { world, dt } => {
                // Frames of `dt`, the last one shortened to land on `time_s`.
                while world.time_s() < time_s - 1e-9 {
                    let step = dt.min(time_s - world.time_s());
                    let report = world.step(step);
                    if let Some(b) = bar {
                        b.set_position(world.time_s() as u64);
                    }
                    anyhow::ensure!(
                        report.clamps.non_finite == 0,
                        "the physics produced a NaN/infinite state at t = {:.1} s; try a smaller --dt",
                        world.time_s()
                    );
                }
                world.cloud_parcels(out);
            }
        }
        Ok(())
    }

    /// What the simulation held back so far (clamps by kind, emissions
    /// suppressed, the opaque display count); None without a simulation.
    pub(crate) fn held_back(&self) -> Option<String> {
        match self {
            Clouds::World { world, .. } => {
                Some(crate::cli::simulate::held_back(&world.diagnostics()))
            }
            _ => None,
        }
    }
}

/// "N cloud parcels, radius a–b m, fill a–b, planes a–b m".
fn summary(parcels: &[CloudParcel]) -> String {
    if parcels.is_empty() {
        return "no cloud parcels".into();
    }
    let range = |f: &dyn Fn(&CloudParcel) -> f32| {
        let (lo, hi) = parcels
            .iter()
            .map(f)
            .fold((f32::MAX, f32::MIN), |(a, b), x| (a.min(x), b.max(x)));
        (lo, hi)
    };
    let (r0, r1) = range(&|p| p.radius_m);
    let (f0, f1) = range(&|p| p.fill);
    let (z0, z1) = range(&|p| p.cond_plane_z_m);
    let (c0, c1) = range(&|p| p.center_m.z);
    format!(
        "{} cloud parcels (radius {r0:.0}–{r1:.0} m, fill {f0:.2}–{f1:.2}, planes {z0:.0}–{z1:.0} m, centres {c0:.0}–{c1:.0} m)",
        parcels.len()
    )
}

/// Runs `cumulus render`.
pub fn run(args: Args) -> anyhow::Result<()> {
    super::output_extension(
        "--out",
        &args.out,
        &[
            ("png", "the tone-mapped frame"),
            ("exr", "the linear HDR scene"),
        ],
    )?;
    anyhow::ensure!(args.frames >= 1, "--frames must be at least 1");
    anyhow::ensure!(
        args.every.is_finite() && args.every > 0.0,
        "--every must be a positive number of seconds"
    );
    args.clouds.validate()?;
    // Before the simulation and the render: the first file written.
    let first = if args.frames > 1 {
        numbered(&args.out, 0)
    } else {
        args.out.clone()
    };
    super::writable_output("--out", &first)?;
    if let Some(path) = &args.save_parcels {
        super::writable_output("--save-parcels", path)?;
    }
    let (mut scene, source) =
        cumulus::scene::load_scene_with(args.scene.as_deref(), &args.overrides.set)?;
    let time = args.time.unwrap_or(scene.simulation.start_s);
    anyhow::ensure!(
        time.is_finite() && time >= 0.0,
        "invalid --time {time}: a finite number of seconds ≥ 0"
    );
    let clock = crate::cli::sun_args::apply(&mut scene, args.hour, args.date.as_deref(), time)?;
    let mut cfg = scene.render.clone();
    cfg.resolve_paths(&source.base_dir());
    if let Some(m) = args.method {
        cfg.method = m;
    }
    if let Some(n) = args.normals {
        cfg.normals = n == Switch::On;
    }
    // Headless, the temporal path runs only when asked to accumulate, with
    // the scene's (or --set's) block, "4x4" where that is off or unset.
    let scene_mode = cfg.temporal.filter(|m| m.block().is_some());
    cfg.temporal = Some(match args.accumulate {
        None => TemporalMode::Off,
        Some(_) => scene_mode.unwrap_or_default(),
    });
    // Validation errors name the field; say which file it is in.
    let scene_name = source.name();
    cfg.validate()
        .with_context(|| format!("{scene_name}: checking [render]"))?;
    scene
        .camera
        .validate()
        .with_context(|| format!("{scene_name}: checking [camera]"))?;
    let camera = Camera::from(&scene.camera);
    let mut clouds = Clouds::new(&args.clouds, &scene, &source)?;

    let ctx = GpuContext::new_headless(args.adapter.as_deref())?;
    eprintln!("adapter: {} ({})", ctx.describe(), ctx.choice());
    let (method, note) = cumulus::render::renderer::method_for(&ctx, &cfg, args.method.is_some());
    if let Some(note) = note {
        eprintln!("{note}");
        cfg.method = method;
    }
    let mut headless = Headless::new(&ctx, &cfg, args.width, args.height)?;
    // An .exr is the HDR scene target read back: keep the clouds in it.
    headless.renderer.set_scene_whole(is_exr(&args.out));
    let sprite_clouds = scene.build_sprite_clouds();
    if !sprite_clouds.is_empty() {
        eprintln!(
            "{scene_name}: {}",
            cumulus::methods::sprites::model::FillCounts::of(&sprite_clouds)
        );
    }
    headless.renderer.set_sprite_clouds(&ctx, sprite_clouds)?;
    headless
        .renderer
        .set_authored(&scene.ellipsoids, &scene.particles);

    let mut parcels = Vec::new();
    let warm = (!args.clouds.stand_in && args.clouds.parcels.is_none()).then(|| {
        let b = indicatif::ProgressBar::new(time.ceil() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "simulating to t = {len} s {bar:40} {pos} s  [{elapsed_precise} < {eta_precise}]",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    clouds.at(time, &mut parcels, warm.as_ref())?;
    if let Some(b) = warm {
        b.finish_and_clear();
        eprintln!(
            "simulated {time:.0} s in {:.1} s",
            b.elapsed().as_secs_f64()
        );
    }
    if let Some(path) = &args.save_parcels {
        let comment = format!("{scene_name}, {} parcels at t = {time} s", parcels.len());
        cumulus::physics::cloud_file::write(path, &parcels, &comment)
            .context("writing --save-parcels")?;
    }
    let bar = (args.frames > 1).then(|| {
        let b = indicatif::ProgressBar::new(args.frames as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} frames, {elapsed} elapsed, ETA {eta}",
            )
            .expect("valid template"),
        );
        b
    });
    for i in 0..args.frames {
        let t = time + args.every * i as f64;
        if i > 0 {
            clouds.at(t, &mut parcels, None)?;
        }
        let input = FrameInput {
            camera,
            parcels: &parcels,
            sun: crate::cli::sun_args::frame_sun(clock.as_ref(), &cfg, t),
            time_s: t as f32,
        };
        let warmup = args.accumulate.map_or(0, |n| n - 1);
        let (mut rgba, timings) = headless.render_after(&ctx, &input, warmup)?;
        let labels = if args.no_labels || !cfg.clouds {
            Vec::new()
        } else {
            cumulus::methods::sprites::gpu::cloud_labels(
                headless.renderer.sprite_clouds(),
                &camera,
                args.width,
                args.height,
            )
        };
        cumulus::plots::labels::draw_labels(&mut rgba, args.width, args.height, &labels)?;
        let path = if args.frames > 1 {
            numbered(&args.out, i)
        } else {
            args.out.clone()
        };
        if is_exr(&path) {
            let rgb = headless.read_hdr(&ctx)?;
            cumulus::output::write_exr_atomic(&path, args.width, args.height, &rgb)
        } else {
            cumulus::output::write_png_atomic(&path, args.width, args.height, &rgba)
        }
        .with_context(|| format!("writing frame {i}"))?;
        let passes: Vec<String> = timings
            .passes
            .iter()
            .map(|(n, ms)| format!("{n} {ms:.1} ms"))
            .collect();
        let bake = headless.renderer.bake_info();
        if cfg.method == cumulus::config::RenderMethod::Baked
            && let Some(note) = bake.coarsening_note()
        {
            eprintln!("note: {note}");
        }
        if cfg.method == cumulus::config::RenderMethod::Baked
            && let Some(note) = bake.levels_note()
        {
            eprintln!("{note}");
        }
        let st = headless.renderer.sprite_stats();
        let sprites = if st.sprites > 0 {
            format!(
                "; {} sprites ({} parcel clouds, {} scene clouds re-shaded, {:.1} ms to shade and sort)",
                st.sprites, st.parcel_clouds, st.reshaded, st.build_ms
            )
        } else {
            String::new()
        };
        let line = format!(
            "{}: t = {t:.0} s, {}{sprites}; {} method: {}, frame {:.1} ms ({}), upload {:.2} ms",
            path.display(),
            summary(&parcels),
            cfg.method,
            passes.join(", "),
            timings.frame_ms,
            if timings.gpu_timestamps {
                "GPU timestamps"
            } else {
                "CPU clock"
            },
            timings.upload_ms
        );
        // A bar drawn to no terminal (stderr into a file or a pipe) drops
        // what it is asked to print: the frame's line goes to stderr then.
        match &bar {
            Some(b) if !b.is_hidden() => {
                b.println(line);
                b.inc(1);
            }
            Some(b) => {
                eprintln!("{line}");
                b.inc(1);
            }
            None => eprintln!("{line}"),
        }
    }
    if let Some(b) = bar {
        b.finish();
    }
    if let Some(held) = clouds.held_back() {
        let end = time + args.every * (args.frames - 1) as f64;
        eprintln!("simulation to t = {end:.0} s: {held}");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbered_names() {
        assert_eq!(
            numbered(Path::new("a/b.png"), 7),
            PathBuf::from("a/b-0007.png")
        );
    }
}
