//! Error against run time. Render: one fixed frame at a sweep of settings,
//! each compared (mean FLIP and RMSE) with a reference frame that converges
//! (finer view step, more octaves, several rays per pixel; see
//! [`reference_config`] and [`REFERENCE_DIFFERENCES`]); the resolution-scale
//! points are upscaled to the reference size first.
//! The physics sweep lives in `physics_error.rs` and is re-exported here.

use crate::config::{Camera, RenderConfig};
use crate::error::Result;
use crate::physics::CloudParcel;
use crate::render::GpuContext;
use crate::render::headless::Headless;
use crate::sky::Sun;

use super::measure::{Repeats, Source, measure};
pub use super::physics_error::{PhysicsError, PhysicsErrorRow, physics_sweep, physics_sweep_with};
use super::stats::{mean_flip, pareto_front, resize_rgba, rgb, rmse};

/// Step of the reference as a fraction of the default step (at most 1/16).
pub const REFERENCE_STEP_FRACTION: f32 = 1.0 / 16.0;
/// Octaves of the reference: the most the noise texture supports (the fBm
/// truncated as late as it can be).
pub const REFERENCE_OCTAVES: u32 = 6;
/// Rays per pixel of the reference along each image axis: it is rendered
/// at this multiple of the frame size, then box-filtered down in linear
/// light, so the finest octave averages out instead of aliasing.
pub const REFERENCE_SUPERSAMPLE: u32 = 2;

/// Growth of the light-march steps: `LIGHT_GROWTH` of
/// shaders/raymarch/lighting.wgsl (a test reads it from there).
pub const LIGHT_GROWTH: f32 = 1.6;

/// Shortest first light step the configuration accepts (`render.light_step_m`). units: m
const MIN_LIGHT_STEP_M: f32 = 1.0;

/// Every way the reference differs from the setting it is compared with.
pub const REFERENCE_DIFFERENCES: &[&str] = &[
    "view-ray step 1/16 of the default (the march covers the same length with 16× the steps, at most 4096)",
    "6 noise octaves instead of the setting's (the fBm truncated as late as the texture allows)",
    "2×2 rays per pixel (rendered at twice the size, box-filtered in linear light)",
    "no early exit",
    "grid culling or brute force as the report states (the grid takes exactly the brute-force samples)",
    "the same light march as the default setting (4 samples growing ×1.6 over 833 m): its \
     discretisation is part of the lighting model (only its first sample sees the noise, the \
     growth is a shader constant), so it is not refined toward a limit",
];

/// Length a light march of `steps` samples from a first step of `first_m`
/// covers (steps grow ×[`LIGHT_GROWTH`]). units: m
pub fn light_march_length_m(steps: u32, first_m: f32) -> f32 {
    first_m * (LIGHT_GROWTH.powi(steps as i32) - 1.0) / (LIGHT_GROWTH - 1.0)
}

/// Length of the default light march (kept when the sample count changes,
/// so only the sampling changes, not the reach of the shadow). units: m
fn light_march_m() -> f32 {
    let d = RenderConfig::default();
    light_march_length_m(d.light_steps, d.light_step_m)
}

/// Length the default view march covers at its nominal step; kept when the
/// step changes (max_steps follows). units: m
fn view_march_m() -> f32 {
    let d = RenderConfig::default();
    d.max_steps as f32 * d.step_m
}

/// `cfg` with view-ray step `step_m` and as many steps as cover the default
/// march length (at most 4096).
pub fn with_step(cfg: &RenderConfig, step_m: f32) -> RenderConfig {
    RenderConfig {
        step_m,
        max_steps: ((view_march_m() / step_m).ceil() as u32).clamp(1, 4096),
        ..cfg.clone()
    }
}

/// `cfg` with `n` light-march samples over the default light-march length:
/// the first step is chosen so the geometric series of steps sums to it.
/// Where that step would be shorter than the 1 m the configuration allows
/// (n ≥ 15 with the defaults), it is 1 m and the march reaches further
/// ([`light_march_length_m`] says how far; the report shows it).
pub fn with_light_steps(cfg: &RenderConfig, n: u32) -> RenderConfig {
    RenderConfig {
        light_steps: n,
        // Zero steps march nothing, and the setting's own count keeps its own
        // step exactly (solving it back from the length would round).
        light_step_m: if n == 0 || n == cfg.light_steps {
            cfg.light_step_m
        } else {
            (light_march_m() / light_march_length_m(n, 1.0)).max(MIN_LIGHT_STEP_M)
        },
        ..cfg.clone()
    }
}

/// The reference: step ≤ 1/16 of the default, every parcel at every sample
/// (no grid culling; see [`brute_force_reference`]), no early exit, the most
/// octaves, the default light march (see [`REFERENCE_DIFFERENCES`]); it is
/// rendered with [`REFERENCE_SUPERSAMPLE`]² rays per pixel by [`reference_frame`].
pub fn reference_config(base: &RenderConfig, brute_force: bool) -> RenderConfig {
    let mut r = with_step(base, base.step_m * REFERENCE_STEP_FRACTION);
    r.light_steps = base.light_steps;
    r.light_step_m = base.light_step_m;
    r.noise_octaves = REFERENCE_OCTAVES;
    r.grid_culling = !brute_force;
    r.early_exit_transmittance = 0.0;
    // The paper's per-sample union: what the baked field approximates.
    r.method = crate::config::RenderMethod::Exact;
    r
}

/// Whether the reference is rendered by brute force on this adapter.
///
/// On a CPU adapter (Mesa llvmpipe) brute force at the reference's step
/// comes out with whole towers missing: measured on the 34-parcel bench
/// frame, brute force and grid culling are bit-identical up to ~1300 march
/// steps and differ (far towers lost by brute force) from ~2000 on, which
/// points at the driver's shader loop limiter, not at the renderer. The grid
/// path takes exactly the brute-force samples (bit-identical wherever brute
/// force completes; the report measures this at the default settings), so
/// there the reference is rendered with grid culling and labelled so.
pub fn brute_force_reference(ctx: &GpuContext) -> bool {
    !ctx.is_cpu()
}

/// sRGB8 → linear light.
fn srgb_to_linear(v: u8) -> f32 {
    let c = v as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light → sRGB8.
fn linear_to_srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// Box-filters an RGBA8 sRGB image of (`ss`·w)×(`ss`·h) down to w×h in
/// linear light (the mean of the rays of each pixel).
pub fn downsample_linear(rgba: &[u8], w: u32, h: u32, ss: u32) -> Vec<u8> {
    let big_w = (w * ss) as usize;
    let mut out = Vec::with_capacity((4 * w * h) as usize);
    let n = (ss * ss) as f32;
    for y in 0..h as usize {
        for x in 0..w as usize {
            let mut acc = [0.0f32; 4];
            for sy in 0..ss as usize {
                for sx in 0..ss as usize {
                    let i = 4 * ((y * ss as usize + sy) * big_w + x * ss as usize + sx);
                    for (c, a) in acc.iter_mut().take(3).enumerate() {
                        *a += srgb_to_linear(rgba[i + c]);
                    }
                    acc[3] += rgba[i + 3] as f32;
                }
            }
            for a in &acc[..3] {
                out.push(linear_to_srgb(a / n));
            }
            out.push((acc[3] / n).round() as u8);
        }
    }
    out
}

/// Renders `cfg` at `supersample`² rays per pixel and box-filters it to
/// `width`×`height`: (RGBA8 sRGB, median render time in ms).
#[allow(clippy::too_many_arguments)]
pub fn reference_frame(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    camera: Camera,
    sun: Sun,
    parcels: &[CloudParcel],
    (width, height): (u32, u32),
    supersample: u32,
    reps: Repeats,
) -> Result<(Vec<u8>, f64)> {
    let ss = supersample.max(1);
    let mut hl = Headless::new(ctx, cfg, width * ss, height * ss)?;
    let m = measure(ctx, &mut hl, camera, sun, Source::Parcels(parcels), reps)?;
    Ok((downsample_linear(&m.rgba, width, height, ss), m.render_ms))
}

/// One render setting of the sweep.
#[derive(Debug, Clone)]
pub struct RenderSetting {
    /// Which parameter differs from the default ("default" for none).
    pub parameter: String,
    /// Its value, as written in the table.
    pub value: String,
    pub cfg: RenderConfig,
    /// Resolution scale (1 = reference size).
    pub scale: f32,
}

/// What the sweep varies, each list one parameter (others at default).
#[derive(Debug, Clone)]
pub struct RenderSweep {
    /// Multiples of the default step.
    pub step_factors: Vec<f32>,
    pub octaves: Vec<u32>,
    pub light_steps: Vec<u32>,
    /// Also measure brute force (no grid culling).
    pub no_grid_culling: bool,
    pub early_exit: Vec<f32>,
    pub resolution_scales: Vec<f32>,
    /// Quality (slicing planes) of the `slices` method (Schpok 2003): its
    /// error-against-run-time axis, rows `slices_quality` (the default
    /// quality is the `method = slices` row).
    pub slices_quality: Vec<u32>,
}

impl RenderSweep {
    /// The default setting first, then one parameter at a time.
    pub fn settings(&self, base: &RenderConfig) -> Vec<RenderSetting> {
        let s = |parameter: &str, value: String, cfg: RenderConfig, scale: f32| RenderSetting {
            parameter: parameter.into(),
            value,
            cfg,
            scale,
        };
        let mut out = vec![s("default", "-".into(), base.clone(), 1.0)];
        for &f in &self.step_factors {
            let c = with_step(base, base.step_m * f);
            out.push(s("step_m", format!("{}", c.step_m), c, 1.0));
        }
        for &o in &self.octaves {
            let c = RenderConfig {
                noise_octaves: o,
                ..base.clone()
            };
            out.push(s("noise_octaves", o.to_string(), c, 1.0));
        }
        for &n in &self.light_steps {
            let c = with_light_steps(base, n);
            // The march's reach beside the count: it differs where the first
            // step hits its 1 m minimum.
            let value = format!("{n} ({:.0} m)", light_march_length_m(n, c.light_step_m));
            out.push(s("light_steps", value, c, 1.0));
        }
        // Each method against the reference (kept even where one equals
        // the default row).
        for m in crate::config::RenderMethod::ALL {
            let c = RenderConfig {
                method: m,
                ..base.clone()
            };
            out.push(s("method", m.name().into(), c, 1.0));
        }
        for m in [
            crate::config::MarchPath::Fragment,
            crate::config::MarchPath::Compute,
        ] {
            let c = RenderConfig {
                march: m,
                ..base.clone()
            };
            out.push(s("march", m.name().into(), c, 1.0));
        }
        if self.no_grid_culling {
            let c = RenderConfig {
                method: crate::config::RenderMethod::Exact,
                grid_culling: false,
                ..base.clone()
            };
            out.push(s("grid_culling", "off".into(), c, 1.0));
        }
        for &e in &self.early_exit {
            let c = RenderConfig {
                early_exit_transmittance: e,
                ..base.clone()
            };
            out.push(s("early_exit_transmittance", format!("{e}"), c, 1.0));
        }
        for &r in &self.resolution_scales {
            out.push(s("resolution_scale", format!("{r}"), base.clone(), r));
        }
        for &q in &self.slices_quality {
            let mut c = RenderConfig {
                method: crate::config::RenderMethod::Slices,
                ..base.clone()
            };
            c.slices.quality = q;
            out.push(s("slices_quality", q.to_string(), c, 1.0));
        }
        // A swept value equal to the default is the default row again.
        let mut seen: Vec<(RenderConfig, u32)> = Vec::new();
        out.retain(|st| {
            let key = (st.cfg.clone(), st.scale.to_bits());
            if st.parameter == "method" || st.parameter == "march" {
                true
            } else if seen.contains(&key) {
                false
            } else {
                seen.push(key);
                true
            }
        });
        out
    }
}

/// One row of the render error table.
#[derive(Debug, Clone)]
pub struct RenderErrorRow {
    pub parameter: String,
    pub value: String,
    /// Rendered size. units: px
    pub width: u32,
    pub height: u32,
    /// Median frame time (upload + passes). units: ms
    pub time_ms: f64,
    /// Mean FLIP against the reference (0 = identical).
    pub mean_flip: f64,
    /// RMSE of sRGB values on 0..1 against the reference.
    pub rmse: f64,
    /// On the Pareto front of (time, mean FLIP).
    pub pareto: bool,
}

/// The render sweep's result.
#[derive(Debug, Clone)]
pub struct RenderError {
    pub parcels: usize,
    /// (mean FLIP, RMSE) of grid culling against brute force at the default
    /// settings (0 = the culling is exact), when the sweep has brute force.
    pub culling_vs_brute: Option<(f64, f64)>,
    pub reference: RenderConfig,
    pub reference_ms: f64,
    pub rows: Vec<RenderErrorRow>,
    /// Reference frame (RGBA8), for the report.
    pub reference_rgba: Vec<u8>,
    pub width: u32,
    pub height: u32,
}

impl RenderError {
    /// The default setting's row.
    pub fn default_row(&self) -> &RenderErrorRow {
        &self.rows[0]
    }
}

/// Runs the render sweep on `parcels` at `width`×`height`.
#[allow(clippy::too_many_arguments)]
pub fn render_sweep(
    ctx: &GpuContext,
    parcels: &[CloudParcel],
    camera: Camera,
    sun: Sun,
    base: &RenderConfig,
    sweep: &RenderSweep,
    (width, height): (u32, u32),
    reps: Repeats,
    reference_reps: Repeats,
    mut tick: impl FnMut(&str),
) -> Result<RenderError> {
    let reference = reference_config(base, brute_force_reference(ctx));
    tick("render reference");
    let (reference_rgba, reference_ms) = reference_frame(
        ctx,
        &reference,
        camera,
        sun,
        parcels,
        (width, height),
        REFERENCE_SUPERSAMPLE,
        reference_reps,
    )?;
    let ref_rgb = rgb(&reference_rgba);
    let mut hl = Headless::new(ctx, base, width, height)?;
    let mut rows = Vec::new();
    // Full-size images of the default and of brute force at default settings.
    let mut default_rgb = None;
    let mut brute_rgb = None;
    for st in sweep.settings(base) {
        tick(&format!("render {} = {}", st.parameter, st.value));
        let (w, h) = if st.scale == 1.0 {
            (width, height)
        } else {
            (
                ((width as f32 * st.scale).round() as u32).max(1),
                ((height as f32 * st.scale).round() as u32).max(1),
            )
        };
        let m = if (w, h) == (width, height) {
            hl.renderer.set_config(ctx, &st.cfg)?;
            measure(ctx, &mut hl, camera, sun, Source::Parcels(parcels), reps)?
        } else {
            let mut small = Headless::new(ctx, &st.cfg, w, h)?;
            measure(ctx, &mut small, camera, sun, Source::Parcels(parcels), reps)?
        };
        let img = rgb(&resize_rgba(&m.rgba, w, h, width, height));
        match st.parameter.as_str() {
            // Grid culling is the exact method's: compare it with brute force.
            "method" if st.cfg.method == crate::config::RenderMethod::Exact => {
                default_rgb = Some(img.clone())
            }
            "grid_culling" => brute_rgb = Some(img.clone()),
            _ => {}
        }
        rows.push(RenderErrorRow {
            parameter: st.parameter,
            value: st.value,
            width: w,
            height: h,
            time_ms: m.render_ms,
            mean_flip: mean_flip(&ref_rgb, &img, width, height),
            rmse: rmse(&ref_rgb, &img),
            pareto: false,
        });
    }
    let pts: Vec<(f64, f64)> = rows.iter().map(|r| (r.time_ms, r.mean_flip)).collect();
    for (row, p) in rows.iter_mut().zip(pareto_front(&pts)) {
        row.pareto = p;
    }
    let culling_vs_brute = default_rgb
        .zip(brute_rgb)
        .map(|(a, b)| (mean_flip(&b, &a, width, height), rmse(&b, &a)));
    Ok(RenderError {
        parcels: parcels.len(),
        culling_vs_brute,
        reference,
        reference_ms,
        rows,
        reference_rgba,
        width,
        height,
    })
}

#[cfg(test)]
mod tests {

    #[test]
    fn the_light_growth_matches_the_cloud_shader() {
        use crate::render::twins::{module, wgsl_const};
        let clouds = module(
            &crate::methods::raymarch::passes::CLOUDS,
            &crate::methods::raymarch::passes::BAKED,
        );
        assert_eq!(
            wgsl_const(&clouds, "LIGHT_GROWTH"),
            super::LIGHT_GROWTH as f64
        );
    }

    use super::*;

    #[test]
    fn reference_is_at_most_a_sixteenth_of_the_default_step_and_brute_force() {
        let d = RenderConfig::default();
        let r = reference_config(&d, true);
        r.validate().unwrap();
        assert!(r.step_m <= d.step_m / 16.0);
        // It covers at least the default march length.
        assert!(r.step_m * r.max_steps as f32 >= d.step_m * d.max_steps as f32);
        assert!(!r.grid_culling);
        assert_eq!(r.early_exit_transmittance, 0.0);
        // The light march is the tested setting's, not a different model.
        assert_eq!(
            (r.light_steps, r.light_step_m),
            (d.light_steps, d.light_step_m)
        );
    }

    #[test]
    fn light_growth_matches_the_shader() {
        let wgsl = crate::render::renderer::shader_files()
            .into_iter()
            .find(|(p, _)| *p == "raymarch/lighting.wgsl")
            .unwrap()
            .1;
        let line = wgsl
            .lines()
            .find(|l| l.trim_start().starts_with("const LIGHT_GROWTH"))
            .expect("lighting.wgsl defines LIGHT_GROWTH");
        let v: f32 = line
            .split('=')
            .nth(1)
            .and_then(|r| r.trim().trim_end_matches(';').parse().ok())
            .expect("a number");
        assert_eq!(v, LIGHT_GROWTH);
    }

    #[test]
    fn light_step_rows_keep_the_march_length() {
        let d = RenderConfig::default();
        let len = light_march_length_m(d.light_steps, d.light_step_m);
        // 833 m with the defaults (4 samples from 90 m, ×1.6 each).
        assert!((len - 833.3).abs() < 1.0, "{len}");
        for n in [1, 2, 8] {
            let c = with_light_steps(&d, n);
            c.validate().unwrap();
            let l = light_march_length_m(n, c.light_step_m);
            // Relative 1e-4: float rounding of the geometric sum only.
            assert!((l - len).abs() < len * 1e-4, "{n}: {l} vs {len}");
        }
        // Where the first step would be under 1 m it is 1 m (valid, longer).
        let c = with_light_steps(&d, 16);
        c.validate().unwrap();
        assert_eq!(c.light_step_m, 1.0);
    }

    #[test]
    fn downsampling_averages_in_linear_light() {
        // Black and white rays average to linear 0.5, i.e. sRGB 188, not 128.
        let px = [0u8, 0, 0, 255, 255, 255, 255, 255];
        let img: Vec<u8> = px.iter().chain(&px).copied().collect();
        let out = downsample_linear(&img, 1, 1, 2);
        assert_eq!(out, vec![188, 188, 188, 255]);
    }

    #[test]
    fn sweep_starts_with_the_default_and_has_no_duplicates() {
        let d = RenderConfig::default();
        let sweep = RenderSweep {
            step_factors: vec![2.0, 1.0],
            octaves: vec![4, 2],
            light_steps: vec![4, 8],
            no_grid_culling: true,
            early_exit: vec![0.02, 0.0],
            resolution_scales: vec![1.0, 0.5],
            slices_quality: vec![32],
        };
        let s = sweep.settings(&d);
        assert_eq!(s[0].parameter, "default");
        assert_eq!(s[0].cfg, d);
        // Default duplicates (step×1, 4 octaves, 4 light steps, 0.02, scale 1)
        // dropped; every method row, both march-path rows and the slices
        // quality row kept.
        let methods = crate::config::RenderMethod::ALL.len();
        assert_eq!(
            s.len(),
            1 + 1 + 1 + 1 + 1 + 1 + 1 + methods + 2 + 1,
            "{s:#?}"
        );
        let q = s
            .iter()
            .find(|st| st.parameter == "slices_quality")
            .unwrap();
        assert_eq!(q.cfg.method, crate::config::RenderMethod::Slices);
        assert_eq!(q.cfg.slices.quality, 32);
        for st in &s {
            st.cfg.validate().unwrap();
        }
    }
}
