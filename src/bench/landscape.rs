//! The landscape case (`landscape.csv`, a section of `report.md`):
//! `profiles/landscape.toml` (40 km × 40 km of cumulus over hills) at
//! 1920×1080 (smaller in quick and tiny runs), its ray-march at full
//! resolution and with temporal upscaling at 1 pixel in 4 and in 16
//! (`[render] temporal`, all in one run): the median frame, the cloud
//! passes' time and its ratio to the full march's, and the mean FLIP of
//! the upscaled frame against the full-resolution march after the same
//! number of frames of the still scene ([`ACCUMULATED_FRAMES`]).

use std::fmt::Write as _;
use std::path::Path;

use crate::config::{MarchPath, RenderConfig, TemporalMode};
use crate::error::Result;
use crate::render::headless::Headless;
use crate::render::{FrameInput, GpuContext};

use super::Mode;
use super::measure::{Repeats, Source, measure};
use super::stats::{mean_flip, rgb};

/// Frames drawn before the upscaled and the full frame are compared: two
/// rounds of the 4×4 pattern (every pixel marched twice; eight rounds of
/// the 2×2 one).
pub const ACCUMULATED_FRAMES: u32 = 32;

/// The cloud time the 4×4 path aims at, over the full march's (issue 34).
pub const GOAL_RATIO_4X4: f64 = 1.0 / 8.0;

/// Frame size and simulated time of the landscape case in `mode`: full
/// 1080p at the scene's start time (967 condensed parcels); quick a
/// quarter of that; tiny a thumbnail at 300 s (the first few clouds), so
/// the tiny run's test stays seconds long.
pub fn plan(mode: Mode) -> ((u32, u32), Option<f64>) {
    match mode {
        Mode::Full => ((1920, 1080), None),
        Mode::Quick => ((480, 270), None),
        Mode::Tiny => ((64, 36), Some(300.0)),
    }
}

/// One row of `landscape.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct LandscapeRow {
    pub temporal: TemporalMode,
    pub width: u32,
    pub height: u32,
    /// Condensed parcels drawn.
    pub parcels: usize,
    /// Median frame (upload + GPU). units: ms
    pub frame_ms: f64,
    /// Median of the cloud passes (march, temporal resolve, composite). units: ms
    pub cloud_ms: f64,
    /// Mean FLIP of this path's frame after [`ACCUMULATED_FRAMES`] frames
    /// against the full-resolution march's (0 for the full march itself).
    pub mean_flip_vs_full: f64,
    /// Mean march iterations per pixel of the full march (samples and
    /// empty-space jumps; `[render] debug_march_steps`); None for the
    /// temporal row.
    pub steps_per_pixel: Option<f64>,
}

/// Mean and largest march iterations per pixel of `cfg`'s full march of
/// `input` at `w`×`h` (the debug output, read from the HDR scene).
pub fn march_steps(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    input: &FrameInput<'_>,
    (w, h): (u32, u32),
) -> Result<(f64, f64)> {
    let cfg = RenderConfig {
        debug_march_steps: true,
        temporal: Some(TemporalMode::Off),
        ..cfg.clone()
    };
    let mut hl = Headless::new(ctx, &cfg, w, h)?;
    hl.renderer.set_scene_whole(true);
    hl.render(ctx, input)?;
    let hdr = hl.read_hdr(ctx)?;
    let steps: Vec<f64> = hdr.chunks_exact(3).map(|p| p[0] as f64).collect();
    let max = steps.iter().copied().fold(0.0, f64::max);
    Ok((steps.iter().sum::<f64>() / steps.len().max(1) as f64, max))
}

/// Measures the landscape with temporal upscaling off, then at 2×2 and
/// 4×4.
/// The bench's landscape scene under `profiles/`.
pub const SCENE: &str = "landscape.toml";

pub fn landscape(
    ctx: &GpuContext,
    mode: Mode,
    reps: Repeats,
    overrides: &[String],
) -> Result<Vec<LandscapeRow>> {
    let ((w, h), time_s) = plan(mode);
    let l = super::methods::load_at(SCENE, time_s, overrides)?;
    let input = FrameInput {
        camera: l.camera,
        parcels: &l.parcels,
        sun: l.sun,
        time_s: 0.0,
    };
    let mut full_frame = Vec::new();
    let mut rows = Vec::new();
    for temporal in [
        TemporalMode::Off,
        TemporalMode::Block2,
        TemporalMode::Block4,
    ] {
        let on = temporal != TemporalMode::Off;
        let cfg = RenderConfig {
            temporal: Some(temporal),
            // The temporal path always marches in compute; so does the
            // full march here, so the two differ by the amortisation alone.
            march: MarchPath::Compute,
            ..l.profile.render.clone()
        };
        let mut hl = Headless::new(ctx, &cfg, w, h)?;
        let m = measure(
            ctx,
            &mut hl,
            l.camera,
            l.sun,
            Source::Parcels(&l.parcels),
            reps,
        )?;
        let cloud_ms = ["clouds", "temporal", "composite"]
            .iter()
            .filter_map(|p| m.pass_ms(p))
            .sum();
        let steps = (!on)
            .then(|| march_steps(ctx, &cfg, &input, (w, h)).map(|s| s.0))
            .transpose()?;
        let flip = if on {
            // A fresh history: exactly ACCUMULATED_FRAMES frames of the scene.
            let mut fresh = Headless::new(ctx, &cfg, w, h)?;
            let (img, _) = fresh.render_after(ctx, &input, ACCUMULATED_FRAMES - 1)?;
            mean_flip(&full_frame, &rgb(&img), w, h)
        } else {
            // The full march of a still scene is the same every frame.
            full_frame = rgb(&m.rgba);
            0.0
        };
        rows.push(LandscapeRow {
            temporal,
            width: w,
            height: h,
            parcels: l.parcels.len(),
            frame_ms: m.render_ms,
            cloud_ms,
            mean_flip_vs_full: flip,
            steps_per_pixel: steps,
        });
    }
    Ok(rows)
}

/// `landscape.csv`: temporal, width, height, parcels, frame_ms, cloud_ms,
/// mean_flip_vs_full, steps_per_pixel (the full march's only).
pub fn landscape_csv(rows: &[LandscapeRow]) -> Result<Vec<u8>> {
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.temporal.name().to_string(),
                r.width.to_string(),
                r.height.to_string(),
                r.parcels.to_string(),
                format!("{:.3}", r.frame_ms),
                format!("{:.3}", r.cloud_ms),
                format!("{:.4}", r.mean_flip_vs_full),
                r.steps_per_pixel
                    .map_or(String::new(), |v| format!("{v:.2}")),
            ]
        })
        .collect();
    super::report::csv_bytes(
        &[
            "temporal",
            "width",
            "height",
            "parcels",
            "frame_ms",
            "cloud_ms",
            "mean_flip_vs_full",
            "steps_per_pixel",
        ],
        &body,
    )
}

/// The landscape section of `report.md`.
pub fn landscape_md(rows: &[LandscapeRow]) -> String {
    let mut s = String::from("\n## Landscape\n\n");
    let Some(first) = rows.first() else {
        return s + "Not measured in this run.\n";
    };
    let _ = writeln!(
        s,
        "`profiles/landscape.toml` at {}×{}, {} condensed parcels, compute march. Temporal: \
         one pixel in 4 (2x2) or in 16 (4x4) marched per frame, the rest reprojected and \
         accumulated (`[render] temporal`). Clouds: the march, the temporal resolve and the \
         composite. FLIP: mean, the frame after {ACCUMULATED_FRAMES} frames of the still scene \
         against the full-resolution march's.\n\n\
         | temporal | frame (ms) | clouds (ms) | clouds / full march | mean FLIP vs full |\n\
         |---|---:|---:|---:|---:|",
        first.width, first.height, first.parcels
    );
    let full_ms = rows
        .iter()
        .find(|r| r.temporal == TemporalMode::Off)
        .map(|r| r.cloud_ms);
    for r in rows {
        let ratio = full_ms.map_or(String::from("–"), |f| format!("{:.3}", cloud_ratio(r, f)));
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2} | {ratio} | {:.4} |",
            r.temporal.name(),
            r.frame_ms,
            r.cloud_ms,
            r.mean_flip_vs_full
        );
    }
    if let (Some(f), Some(r4)) = (
        full_ms,
        rows.iter().find(|r| r.temporal == TemporalMode::Block4),
    ) {
        let ratio = cloud_ratio(r4, f);
        let _ = writeln!(
            s,
            "\n4x4: clouds {ratio:.3} of the full march's (goal ≤ {GOAL_RATIO_4X4:.3}: {}).",
            if ratio <= GOAL_RATIO_4X4 {
                "met"
            } else {
                "not met"
            }
        );
    }
    if let Some(steps) = first.steps_per_pixel {
        let _ = writeln!(
            s,
            "\nThe full march takes {steps:.1} iterations per pixel on average (samples and \
             empty-space jumps, `[render] debug_march_steps`)."
        );
    }
    s
}

/// Cloud time of `row` over the full march's `full_ms`.
pub fn cloud_ratio(row: &LandscapeRow, full_ms: f64) -> f64 {
    row.cloud_ms / full_ms.max(1e-9)
}

/// Writes `landscape.csv` into `dir`.
pub fn write(dir: &Path, rows: &[LandscapeRow]) -> Result<()> {
    crate::output::write_atomic(&dir.join("landscape.csv"), &landscape_csv(rows)?)
}
