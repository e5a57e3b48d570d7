//! `cumulus export`: simulate a scene to a time, then write its cloud density
//! (paper eq. 18, noise included) as a Mitsuba 3 `gridvolume` `.vol` or an
//! OpenVDB `.vdb` plus a JSON sidecar (camera, sun, sky, medium) beside it. Both files are written
//! atomically: a failed export leaves neither a partial grid nor a sidecar.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use cumulus::config::Camera;
use cumulus::export::sidecar::Sidecar;
use cumulus::export::vdb::Meta;
use cumulus::export::{self, DEFAULT_MAX_MEMORY_MIB, GridFormat, GridSpec};
use cumulus::methods::raymarch::field::CloudField;
use cumulus::methods::slices::gpu::field::AuthoredField;
use cumulus::methods::slices::gpu::slices_frame;

use super::render::{CloudArgs, Clouds};

/// Grids with more cells than this get a progress bar.
const PROGRESS_CELLS: u64 = 4_000_000;

/// Arguments of `cumulus export`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Writes OUT and OUT with the extension .json (the sidecar). Values = density rho in [0, 1]; \
sigma_t = medium.extinction_scale_per_m x rho. \
OUT.vol: float32 VOL v3, x fastest; in Mitsuba 3 a heterogeneous medium whose gridvolume loads OUT with \
to_world = translate(bounds_min_m) x scale(bounds_max_m - bounds_min_m), scale = extinction_scale_per_m. \
OUT.vdb: OpenVDB, a sparse float grid named density in metres (z up); in Blender: File > Import > OpenVDB, \
then in the volume's material (Principled Volume) set Density to extinction_scale_per_m (docs/rendering.md, Exporting the density). \
A scene with [[ellipsoids]] (authored, Schpok 2003) exports what the slices method draws: \
the implicit field of the ellipsoids (animated to the frame's time) and the parcels as spheres, \
times the tier's media filter of the noise octaves, zero at or under Sharpness and scaled by each cloud's \
opacity per metre (its plane opacity over its plane spacing), so that extinction_scale_per_m x value is the \
extinction the slices composite (values may exceed 1 where primitives overlap). \
With --frames N > 1 the frames go to OUT-0000.vol, OUT-0001.vol, … (each with its .json), one \
every --every seconds from --time (OUT-0000.vdb, … likewise): an animation's keyframes as a numbered series. \
Any number of parcels (the density is evaluated on the CPU). When the default voxel's grid would \
pass --max-memory-mib, the finest voxel that fits is used and stderr says so; --voxel forces a size."
)]
pub struct Args {
    /// Scene profile (TOML); the embedded fair-weather scene when omitted.
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub overrides: super::SetArgs,
    /// Output grid: FILE.vol (Mitsuba 3 gridvolume) or FILE.vdb (OpenVDB,
    /// for Blender, Houdini, …); the sidecar goes beside it as FILE.json.
    #[arg(long)]
    pub out: PathBuf,
    /// Simulated time of the (first) exported frame, counted from the start
    /// of the simulation; default: the scene's [simulation] start_s. units: s
    #[arg(long, allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// Number of frames (a numbered series when more than one).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100000))]
    pub frames: u32,
    /// Simulated time between frames. units: s
    #[arg(long, default_value_t = 60.0, allow_negative_numbers = true)]
    pub every: f64,
    /// Voxel side; default from the render step, the noise's finest octave,
    /// the base's shell and the smallest parcel (see `cumulus::export`),
    /// coarsened to fit --max-memory-mib. units: m
    #[arg(long, allow_negative_numbers = true)]
    pub voxel: Option<f32>,
    /// Most memory the grid may take (the values; the file is as large):
    /// a larger default grid gets coarser voxels, a larger --voxel grid is an
    /// error. units: MiB
    #[arg(long, default_value_t = DEFAULT_MAX_MEMORY_MIB)]
    pub max_memory_mib: u64,
    #[command(flatten)]
    pub clouds: CloudArgs,
}

/// `clouds.vol` → `clouds.json`.
pub fn sidecar_path(out: &Path) -> PathBuf {
    out.with_extension("json")
}

/// A frame time `export` accepts. units: s
fn check_time(time: f64) -> anyhow::Result<()> {
    anyhow::ensure!(
        time.is_finite() && time >= 0.0,
        "invalid --time {time}: a finite number of seconds ≥ 0"
    );
    Ok(())
}

/// Runs `cumulus export`.
pub fn run(args: Args) -> anyhow::Result<()> {
    // Before anything else: the format comes from the name.
    let format = match super::output_extension(
        "--out",
        &args.out,
        &[("vol", "Mitsuba 3 gridvolume"), ("vdb", "OpenVDB")],
    )? {
        "vdb" => GridFormat::Vdb,
        _ => GridFormat::Vol,
    };
    if let Some(t) = args.time {
        // Checked before loading the scene; the default is checked below.
        check_time(t)?;
    }
    args.clouds.validate()?;
    anyhow::ensure!(
        args.every.is_finite() && args.every > 0.0,
        "--every must be a positive number of seconds"
    );
    anyhow::ensure!(
        args.max_memory_mib >= 1,
        "--max-memory-mib must be at least 1"
    );
    if let Some(v) = args.voxel {
        // Checked before simulating: the same check GridSpec makes later.
        anyhow::ensure!(
            v.is_finite() && v >= export::MIN_VOXEL_M,
            "invalid --voxel = {v}: a voxel side of at least {} m",
            export::MIN_VOXEL_M
        );
    }
    let sidecar_out = sidecar_path(&args.out);
    // Before minutes of sampling: the first frame's grid and sidecar.
    let first = if args.frames > 1 {
        super::render::numbered(&args.out, 0)
    } else {
        args.out.clone()
    };
    super::writable_output("--out", &first)?;
    super::writable_output("--out", &sidecar_path(&first))?;

    let (scene, source) =
        cumulus::scene::load_scene_with(args.scene.as_deref(), &args.overrides.set)?;
    let scene_name = source.name();
    let cfg = scene.render.clone();
    cfg.validate()
        .with_context(|| format!("{scene_name}: checking [render]"))?;
    scene
        .camera
        .validate()
        .with_context(|| format!("{scene_name}: checking [camera]"))?;

    // As `render`: the scene opens at its start time unless told otherwise.
    let start = args.time.unwrap_or(scene.simulation.start_s);
    check_time(start)?;
    if !args.clouds.stand_in && args.clouds.parcels.is_none() {
        eprintln!("simulating {start:.0} s …");
    }
    let mut clouds = Clouds::new(&args.clouds, &scene, &source)?;
    let mut parcels = Vec::new();
    for i in 0..args.frames {
        let time = start + args.every * i as f64;
        let (out, sidecar_out) = if args.frames > 1 {
            let out = super::render::numbered(&args.out, i);
            let side = sidecar_path(&out);
            (out, side)
        } else {
            (args.out.clone(), sidecar_out.clone())
        };
        clouds.at(time, &mut parcels, None)?;
        export_frame(
            &args,
            format,
            &scene,
            &scene_name,
            &cfg,
            &parcels,
            time,
            &out,
            &sidecar_out,
        )?;
    }
    Ok(())
}

/// Samples and writes one frame at `time` (units: s) to `out` and its sidecar.
#[allow(clippy::too_many_arguments)]
fn export_frame(
    args: &Args,
    format: GridFormat,
    scene: &cumulus::scene::SceneProfile,
    scene_name: &str,
    cfg: &cumulus::config::RenderConfig,
    parcels: &[cumulus::physics::CloudParcel],
    time: f64,
    out: &Path,
    sidecar_out: &Path,
) -> anyhow::Result<()> {
    let field = Density::new(scene, cfg, parcels, time)?;
    let Some((lo, hi)) = field.bounds() else {
        let authored = scene.sprite_clouds.len() + scene.layers.len();
        if authored > 0 {
            anyhow::bail!(
                "no volumetric cloud at t = {time:.0} s in {scene_name}: its {authored} sprite \
                 cloud(s) and layer(s) are billboards of the sprites method (Wang 2003) with no \
                 density to export; export exports parcels and [[ellipsoids]]"
            );
        }
        anyhow::bail!(
            "no cloud at t = {time:.0} s in {scene_name}: nothing to export (try a later --time)"
        );
    };
    let spec = match args.voxel {
        Some(v) => GridSpec::covering(lo, hi, v, args.max_memory_mib)?,
        None => {
            let wanted = field.default_voxel_m(cfg);
            let spec = GridSpec::fitting(lo, hi, wanted, args.max_memory_mib)?;
            if let Some(note) = spec.coarsening_note(wanted, args.max_memory_mib) {
                eprintln!("note: {note}");
            }
            spec
        }
    };
    let voxel = spec.voxel_m;
    eprintln!(
        "t = {time:.0} s: {} → grid {}×{}×{} of {voxel:.1} m voxels over ({:.0}, {:.0}, {:.0})–({:.0}, {:.0}, {:.0}) m: {:.1} MiB",
        field.describe(),
        spec.dims[0],
        spec.dims[1],
        spec.dims[2],
        spec.min.x,
        spec.min.y,
        spec.min.z,
        spec.max().x,
        spec.max().y,
        spec.max().z,
        spec.bytes() as f64 / (1024.0 * 1024.0)
    );

    let bar = (spec.cells() > PROGRESS_CELLS).then(|| {
        let b = indicatif::ProgressBar::new(spec.cells());
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {percent}% of the cells, {elapsed} elapsed, ETA {eta}",
            )
            .expect("valid template"),
        );
        b
    });
    let scale_per_m = field.extinction_scale_per_m(cfg);
    let values = export::sample_grid(
        &spec,
        |p| field.value(p, scale_per_m),
        |done, _| {
            if let Some(b) = &bar {
                b.set_position(done);
            }
        },
    );
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let meta = [
        ("cumulus_scene", Meta::Str(scene_name.into())),
        ("cumulus_time_s", Meta::Float(time as f32)),
        ("cumulus_extinction_scale_per_m", Meta::Float(scale_per_m)),
    ];
    cumulus::output::write_atomic_with(out, |w| format.write(w, &spec, values, &meta))
        .with_context(|| "writing the grid")?;

    let vol_name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // The sun of the exported frame: the scene's [sun] clock, or the pinned one.
    let clock = scene.sun.as_ref().map(|s| s.clock()).transpose()?;
    let sun = super::sun_args::frame_sun(clock.as_ref(), cfg, time);
    let mut sidecar = Sidecar::new(
        scene_name,
        time,
        &vol_name,
        &spec,
        cfg,
        &Camera::from(&scene.camera),
        &sun,
    );
    sidecar.medium.extinction_scale_per_m = scale_per_m;
    let json = serde_json::to_vec_pretty(&sidecar).context("encoding the sidecar")?;
    if let Err(e) = cumulus::output::write_atomic(sidecar_out, &json) {
        // Whole or not at all: a grid without its sidecar is not an export.
        let _ = std::fs::remove_file(out);
        return Err(e).context("writing the sidecar");
    }
    eprintln!("wrote {} and {}", out.display(), sidecar_out.display());
    Ok(())
}

/// The density a frame exports: the parcels' hypertexture (eq. 18), or,
/// for a scene with authored ellipsoids, what the slices method draws.
enum Density {
    Parcels(CloudField),
    /// Boxed: its octave table is ~2 KiB, the parcels' field ~150 B.
    Authored(Box<AuthoredField>),
}

impl Density {
    fn new(
        scene: &cumulus::scene::SceneProfile,
        cfg: &cumulus::config::RenderConfig,
        parcels: &[cumulus::physics::CloudParcel],
        time: f64,
    ) -> anyhow::Result<Self> {
        if scene.ellipsoids.is_empty() {
            return Ok(Density::Parcels(CloudField::new(
                parcels,
                cfg,
                time as f32,
            )?));
        }
        let camera = Camera::from(&scene.camera);
        let frame = slices_frame(
            &scene.ellipsoids,
            &scene.particles,
            parcels,
            cfg,
            time as f32,
            cfg.sun_direction(),
            camera.position,
            camera.target - camera.position,
            None, // the primitives only: no vertex values
        )?;
        Ok(Density::Authored(Box::new(AuthoredField::new(
            &frame,
            cfg.noise_texels,
        ))))
    }

    fn bounds(&self) -> Option<(glam::Vec3, glam::Vec3)> {
        match self {
            Density::Parcels(f) => (!f.parcels().is_empty()).then(|| f.bounds()),
            Density::Authored(f) => f.bounds(),
        }
    }

    /// The parcels' default voxel, or for authored clouds a 64th of the
    /// finest first-octave tile (the noise's coarse detail resolved by a
    /// few voxels; finer octaves need --voxel and the memory for it).
    fn default_voxel_m(&self, cfg: &cumulus::config::RenderConfig) -> f32 {
        match self {
            Density::Parcels(f) => export::default_voxel_m(cfg, f),
            Density::Authored(_) => {
                let finest = cfg
                    .slices
                    .tiers
                    .iter()
                    .map(|t| t.scale_m)
                    .fold(f32::MAX, f32::min);
                (finest / 64.0).max(export::MIN_VOXEL_M)
            }
        }
    }

    fn describe(&self) -> String {
        match self {
            Density::Parcels(f) => format!("{} parcels", f.parcels().len()),
            Density::Authored(_) => "authored ellipsoids (slices field)".into(),
        }
    }

    /// σ_t = this × the exported value: the ray-march's extinction per
    /// unit ρ, or for authored clouds the largest of the slices' clouds
    /// (each cloud's own is in its values). units: 1/m
    fn extinction_scale_per_m(&self, cfg: &cumulus::config::RenderConfig) -> f32 {
        match self {
            Density::Parcels(_) => cfg.extinction_per_m,
            Density::Authored(f) => f.max_extinction_per_m().unwrap_or(cfg.extinction_per_m),
        }
    }

    /// The exported value at `p`: ρ of the parcels' hypertexture, or the
    /// extinction the slices pass draws over [`Self::extinction_scale_per_m`]
    /// (its Sharpness cut-off and each cloud's opacity included, so an
    /// offline renderer draws the cloud the slices draw).
    fn value(&self, p: glam::Vec3, scale_per_m: f32) -> f32 {
        match self {
            Density::Parcels(f) => f.density(p),
            Density::Authored(f) => f.extinction_per_m(p) / scale_per_m,
        }
    }
}
