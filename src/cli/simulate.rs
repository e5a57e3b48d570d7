//! `cumulus simulate`: runs a scene headless with a progress bar on stderr,
//! prints a summary (first cloud, peak of the cloud field, wall time) and,
//! with `--out`, writes one CSV row of diagnostics per frame (atomically, at
//! the end). Exits non-zero if the physics produced a NaN.

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use cumulus::physics::{Diagnostics, ParcelWorld, StepReport};
use cumulus::scene::{load_scene_with, locate_key};

/// Arguments of `cumulus simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Scene profile (TOML); the embedded fair-weather scene when omitted.
    pub scene: Option<PathBuf>,
    /// Simulated time. units: s
    #[arg(long, allow_negative_numbers = true)]
    pub duration: f64,
    /// Output CSV file (one row per frame). Without it only the summary is
    /// printed.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Frame step (the physics sub-steps it as needed). units: s
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true)]
    pub dt: f64,
    /// Seed of the emission draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[command(flatten)]
    pub overrides: super::SetArgs,
}

/// Most frames one run may ask for: the CSV holds one row per frame in
/// memory (about 150 bytes each), so 10⁷ frames is ~1.5 GB.
const MAX_FRAMES: f64 = 1.0e7;

/// One CSV row: each column's name beside its value, so the header and
/// the rows cannot disagree. Clamps are cumulative, one `clamp_<kind>`
/// column per kind of `ClampCounts`; `suppressed` counts emissions refused
/// at `max_parcels`; `opaque_parcel_frames` is the display count of parcels
/// shown fully opaque (not a clamp); `cloud_cover` is
/// `ParcelWorld::cloud_cover` and `liquid_water_path_kg_m2`
/// `ParcelWorld::liquid_water_path`.
fn columns(d: &Diagnostics, r: &StepReport, cover: f64, lwp: f64) -> Vec<(String, String)> {
    let fixed = [
        ("time_s", format!("{:.3}", d.time_s)),
        ("parcels", d.parcels.to_string()),
        ("condensed_parcels", d.condensed_parcels.to_string()),
        ("cloud_base_m", opt(d.cloud_base_m)),
        ("cloud_top_m", opt(d.cloud_top_m)),
        ("total_water_kg", format!("{:.6e}", d.total_water_kg)),
        ("kinetic_energy_j", format!("{:.6e}", d.kinetic_energy_j)),
        ("substeps", r.substeps.to_string()),
        ("dt_s", format!("{:.6}", r.dt_s)),
        ("budget_hit", (r.budget_hit as u8).to_string()),
        ("emitted", d.fates.emitted.to_string()),
        ("escaped", d.escaped.to_string()),
        ("evaporated", d.fates.evaporated.to_string()),
        ("grounded", d.fates.grounded.to_string()),
        ("aged", d.fates.aged.to_string()),
        ("suppressed", d.fates.suppressed.to_string()),
        ("opaque_parcel_frames", d.opaque_parcel_frames.to_string()),
        ("cloud_cover", format!("{cover:.5}")),
        ("liquid_water_path_kg_m2", format!("{lwp:.6e}")),
    ];
    let clamps = d
        .clamps
        .kinds()
        .into_iter()
        .map(|(k, n)| (format!("clamp_{k}"), n.to_string()));
    fixed
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .chain(clamps)
        .collect()
}

/// The summary's lines on what was held back: the clamps by kind, then
/// the emissions refused at `max_parcels` and the opaque display count
/// (shared by `simulate` and `render`).
pub(crate) fn held_back(d: &Diagnostics) -> String {
    format!(
        "clamps: {}\nsuppressed: {} emissions refused at max_parcels; opaque (display, not a clamp): {} parcel-frames",
        d.clamps, d.fates.suppressed, d.opaque_parcel_frames
    )
}

fn opt(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.3}")).unwrap_or_default()
}

/// The header and the row of one step.
fn header_and_row(d: &Diagnostics, r: &StepReport, cover: f64, lwp: f64) -> (String, String) {
    let c = columns(d, r, cover, lwp);
    let join =
        |f: &dyn Fn(&(String, String)) -> String| c.iter().map(f).collect::<Vec<_>>().join(",");
    (join(&|(n, _)| n.to_string()), join(&|(_, v)| v.clone()))
}

/// Runs `cumulus simulate`.
pub fn run(args: Args) -> anyhow::Result<()> {
    if !(args.duration.is_finite() && args.duration > 0.0 && args.duration <= 1.0e7) {
        bail!(
            "invalid --duration {}: a positive number of seconds up to 1e7",
            args.duration
        );
    }
    super::render::check_frame_dt(args.dt)?;
    let frames = (args.duration / args.dt).ceil();
    if frames > MAX_FRAMES {
        bail!(
            "--duration {} s with --dt {} s makes {frames:.0} frames: at most {MAX_FRAMES:.0} frames are allowed (use a larger --dt)",
            args.duration,
            args.dt
        );
    }
    let frames = frames as u64;
    if let Some(out) = &args.out {
        super::writable_output("--out", out)?;
    }
    let (profile, source) = load_scene_with(args.scene.as_deref(), &args.overrides.set)?;
    // Validation errors name the field; say which file (and line) it is in.
    let scene_text = args
        .scene
        .as_ref()
        .and_then(|p| std::fs::read_to_string(p).ok());
    let place = |e: &cumulus::Error| -> String {
        let file = args.scene.as_ref().map_or_else(
            || cumulus::scene::EMBEDDED_SCENE_LABEL.to_string(),
            |p| p.display().to_string(),
        );
        match (e, &scene_text) {
            (cumulus::Error::InvalidParameter { name, .. }, Some(text)) => {
                match locate_key(text, name) {
                    Some((line, col)) => format!("{file}:{line}:{col}"),
                    None => file,
                }
            }
            _ => file,
        }
    };
    let env = profile
        .build_atmosphere(&source)
        .context("building the atmosphere")?;
    let world_cfg = profile.world_config(&source.base_dir()).map_err(|e| {
        anyhow::Error::new(e).context("reading the terrain ([ground] follow_terrain)")
    })?;
    let mut world = ParcelWorld::new(env, world_cfg, args.seed).map_err(|e| {
        let at = place(&e);
        anyhow::Error::new(e).context(format!(
            "{at}: checking [physics], [ground], [emission], [wind]"
        ))
    })?;

    let bar = indicatif::ProgressBar::new(frames);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} frames  {msg}  [{elapsed_precise} < {eta_precise}]",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    // Rows are kept only when they are written.
    let mut lines = Vec::with_capacity(if args.out.is_some() {
        frames as usize + 1
    } else {
        0
    });
    // When the first cloud forms and when the cloud field peaks: what a
    // scene's [simulation] start_s is chosen from.
    let mut first_cloud_s: Option<f64> = None;
    let mut peak = (0usize, 0.0f64);
    for _ in 0..frames {
        let report = world.step(args.dt);
        let d = world.diagnostics();
        if report.clamps.non_finite > 0
            || !d.total_water_kg.is_finite()
            || !d.kinetic_energy_j.is_finite()
        {
            bar.abandon();
            bail!(
                "the physics produced a NaN/infinite state at t = {:.1} s ({} parcels removed); \
                 try a smaller --dt or check the scene's [physics] constants",
                d.time_s,
                report.clamps.non_finite
            );
        }
        if args.out.is_some() {
            let (header, row) =
                header_and_row(&d, &report, world.cloud_cover(), world.liquid_water_path());
            if lines.is_empty() {
                lines.push(header);
            }
            lines.push(row);
        }
        if d.condensed_parcels > 0 && first_cloud_s.is_none() {
            first_cloud_s = Some(d.time_s);
        }
        if d.condensed_parcels > peak.0 {
            peak = (d.condensed_parcels, d.time_s);
        }
        bar.set_message(format!(
            "{} parcels, {} cloudy",
            d.parcels, d.condensed_parcels
        ));
        bar.inc(1);
    }
    bar.finish();
    let written = match &args.out {
        Some(out) => {
            let mut text = lines.join("\n");
            text.push('\n');
            cumulus::output::write_atomic(out, text.as_bytes())?;
            format!("wrote {} ({frames} frames)", out.display())
        }
        None => format!("{frames} frames (no --out: no CSV written)"),
    };
    let d = world.diagnostics();
    let c = world.counters();
    let cloud = match (d.cloud_base_m, d.cloud_top_m) {
        (Some(base), Some(top)) => format!("cloud base {base:.0} m, top {top:.0} m"),
        _ => "no cloud at the end".to_string(),
    };
    eprintln!(
        "{written}; {} parcels, {} condensed, {cloud}; {} sub-steps",
        d.parcels, d.condensed_parcels, c.substeps,
    );
    eprintln!("{}", held_back(&d));
    let history = match first_cloud_s {
        Some(t) => format!(
            "first condensed parcel at t = {t:.0} s; peak {} condensed parcels at t = {:.0} s",
            peak.0, peak.1
        ),
        None => format!(
            "no cloud formed: no parcel condensed in {} s",
            args.duration
        ),
    };
    eprintln!(
        "{history}; {:.1} s of wall time",
        bar.elapsed().as_secs_f64()
    );
    eprintln!(
        "CPU: neighbours {:?}, sph {:?}, exposed area {:?} ({} evaluations), mixing {:?}, thermo {:?}, integrate {:?}",
        c.neighbours,
        c.sph,
        c.exposed_area,
        c.exposed_area_evaluations,
        c.mixing,
        c.thermo,
        c.integrate
    );
    Ok(())
}
