//! `cumulus export`: simulate a scene to a time, then write its cloud density
//! (paper eq. 18, noise included) as a Mitsuba 3 `gridvolume` `.vol` plus a
//! JSON sidecar (camera, sun, sky, medium) beside it. Both files are written
//! atomically: a failed export leaves neither a partial grid nor a sidecar.

use std::path::{Path, PathBuf};

use anyhow::Context as _;
use cumulus::export::sidecar::Sidecar;
use cumulus::export::{self, DEFAULT_MAX_MEMORY_MIB, GridSpec};
use cumulus::render::Camera;
use cumulus::render::field::CloudField;

use super::render::{CloudArgs, Clouds};

/// Grids with more cells than this get a progress bar.
const PROGRESS_CELLS: u64 = 4_000_000;

/// Arguments of `cumulus export`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Writes OUT (float32 VOL v3, x fastest, values = density rho in [0, 1]; \
sigma_t = medium.extinction_scale_per_m x rho) and OUT with the extension .json (the sidecar). \
In Mitsuba 3: a heterogeneous medium whose gridvolume loads OUT with to_world = translate(bounds_min_m) \
x scale(bounds_max_m - bounds_min_m), scale = extinction_scale_per_m."
)]
pub struct Args {
    /// Scene profile (TOML); the embedded fair-weather scene when omitted.
    pub scene: Option<PathBuf>,
    #[command(flatten)]
    pub overrides: super::SetArgs,
    /// Output grid (.vol); the sidecar goes beside it with the extension .json.
    #[arg(long)]
    pub out: PathBuf,
    /// Simulated time of the exported frame. units: s
    #[arg(long, default_value_t = 1800.0, allow_negative_numbers = true)]
    pub time: f64,
    /// Voxel side; default from the render step, the noise's finest octave,
    /// the base's shell and the smallest parcel (see `cumulus::export`). units: m
    #[arg(long, allow_negative_numbers = true)]
    pub voxel: Option<f32>,
    /// Most memory the grid may take (the values; the file is as large). units: MiB
    #[arg(long, default_value_t = DEFAULT_MAX_MEMORY_MIB)]
    pub max_memory_mib: u64,
    #[command(flatten)]
    pub clouds: CloudArgs,
}

/// `clouds.vol` → `clouds.json`.
pub fn sidecar_path(out: &Path) -> PathBuf {
    out.with_extension("json")
}

/// Fails early (before minutes of sampling) when `path`'s directory cannot
/// take a new file; nothing is left behind.
fn check_writable(path: &Path) -> anyhow::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)
        .and_then(|_| tempfile::NamedTempFile::new_in(dir).map(drop))
        .with_context(|| format!("{}: cannot write there", path.display()))
}

/// Runs `cumulus export`.
pub fn run(args: Args) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.time.is_finite() && args.time >= 0.0,
        "--time must be a finite number of seconds ≥ 0"
    );
    args.clouds.validate()?;
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
    anyhow::ensure!(
        sidecar_out != args.out,
        "--out {} would be overwritten by its own .json sidecar; give the grid a .vol name",
        args.out.display()
    );
    check_writable(&args.out)?;

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

    if !args.clouds.stand_in {
        eprintln!("simulating {:.0} s …", args.time);
    }
    let mut clouds = Clouds::new(&args.clouds, &scene, &source.base_dir())?;
    let mut parcels = Vec::new();
    clouds.at(args.time, &mut parcels, None)?;
    anyhow::ensure!(
        !parcels.is_empty(),
        "no cloud at t = {:.0} s in {scene_name}: nothing to export (try a later --time)",
        args.time
    );

    let field = CloudField::new(&parcels, &cfg, args.time as f32)?;
    let voxel = args
        .voxel
        .unwrap_or_else(|| export::default_voxel_m(&cfg, &field));
    let (lo, hi) = field.bounds();
    let spec = GridSpec::covering(lo, hi, voxel, args.max_memory_mib)?;
    eprintln!(
        "{} parcels → grid {}×{}×{} of {voxel:.1} m voxels over ({:.0}, {:.0}, {:.0})–({:.0}, {:.0}, {:.0}) m: {:.1} MiB",
        field.parcels().len(),
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
    let values = export::sample_grid(
        &spec,
        |p| field.density(p),
        |done, _| {
            if let Some(b) = &bar {
                b.set_position(done);
            }
        },
    );
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let grid = export::vol_grid(&spec, values);
    cumulus::output::write_atomic_with(&args.out, |w| export::write_vol(w, &grid))
        .with_context(|| "writing the grid")?;

    let vol_name = args
        .out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // The sun of the exported frame: the scene's [sun] clock, or the pinned one.
    let clock = scene.sun.as_ref().map(|s| s.clock()).transpose()?;
    let sun = super::sun_args::frame_sun(clock.as_ref(), &cfg, args.time);
    let sidecar = Sidecar::new(
        &scene_name,
        args.time,
        &vol_name,
        &spec,
        &cfg,
        &Camera::from(&scene.camera),
        &sun,
    );
    let json = serde_json::to_vec_pretty(&sidecar).context("encoding the sidecar")?;
    if let Err(e) = cumulus::output::write_atomic(&sidecar_out, &json) {
        // Whole or not at all: a grid without its sidecar is not an export.
        let _ = std::fs::remove_file(&args.out);
        return Err(e).context("writing the sidecar");
    }
    eprintln!("wrote {} and {}", args.out.display(), sidecar_out.display());
    Ok(())
}
