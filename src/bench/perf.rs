//! Frame-time measurements: the performance table (parcel count × normals ×
//! shadows, paper Table 1), scaling with the parcel count for each render
//! method (baked, exact with grid culling, brute force), and what each
//! optional pass costs (pruning).

use crate::config::{Camera, CameraConfig, RenderConfig, RenderMethod, TerrainConfig};
use crate::error::Result;
use crate::methods::raymarch::pack;
use crate::physics::{CloudParcel, ParcelWorld};
use crate::render::GpuContext;
use crate::render::headless::Headless;

use super::measure::{Measured, Repeats, Source, measure};
use super::scenes;

/// The camera of every bench frame: south of the field, under the cloud
/// base, looking up across it so the towers fill much of the frame (the
/// default camera sees a wider landscape, where small frames would give the
/// clouds only a few pixels and the error metrics little to measure).
pub fn camera() -> Camera {
    Camera::from(&CameraConfig {
        position_m: [0.0, -7000.0, 700.0],
        target_m: [0.0, 0.0, 1500.0],
        vfov_deg: 60.0,
        ..CameraConfig::default()
    })
}

/// Render settings of a table variant: defaults with normals and shadows
/// as given (terrain on, so shadows have somewhere to fall).
pub fn variant_config(normals: bool, shadows: bool, method: RenderMethod) -> RenderConfig {
    RenderConfig {
        method,
        normals,
        shadows,
        ..RenderConfig::default()
    }
}

/// One row of the performance table.
#[derive(Debug, Clone)]
pub struct PerfRow {
    pub parcels: usize,
    pub normals: bool,
    pub shadows: bool,
    pub m: Measured,
}

/// The (normals, shadows) variants of the table, in table order.
pub const VARIANTS: [(bool, bool); 4] =
    [(false, false), (false, true), (true, false), (true, true)];

/// The performance table: every count × every variant, physics included.
/// Variants outside, counts inside, so each variant's pipelines are built
/// once; rows come back in table order (count, then variant).
pub fn performance(
    ctx: &GpuContext,
    size: (u32, u32),
    counts: &[usize],
    method: RenderMethod,
    reps: Repeats,
    mut tick: impl FnMut(&str),
) -> Result<Vec<PerfRow>> {
    let mut hl = Headless::new(ctx, &variant_config(false, false, method), size.0, size.1)?;
    let cam = camera();
    let worlds: Vec<ParcelWorld> = counts
        .iter()
        .map(|&n| scenes::cloud_field(n))
        .collect::<Result<_>>()?;
    let mut rows = Vec::new();
    for (normals, shadows) in VARIANTS {
        let cfg = variant_config(normals, shadows, method);
        hl.renderer.set_config(ctx, &cfg)?;
        for (&n, world) in counts.iter().zip(&worlds) {
            tick(&format!(
                "performance: {n} parcels, normals {}, shadows {}",
                on_off(normals),
                on_off(shadows)
            ));
            let m = measure(
                ctx,
                &mut hl,
                cam,
                cfg.sun(),
                Source::World { world, expected: n },
                reps,
            )?;
            rows.push(PerfRow {
                parcels: n,
                normals,
                shadows,
                m,
            });
        }
    }
    let order = |r: &PerfRow| {
        let v = VARIANTS
            .iter()
            .position(|&x| x == (r.normals, r.shadows))
            .unwrap_or(0);
        let c = counts.iter().position(|&c| c == r.parcels).unwrap_or(0);
        (c, v)
    };
    rows.sort_by_key(order);
    Ok(rows)
}

/// "on" / "off".
pub fn on_off(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

/// One row of the scaling table: the render frame (no physics) of one
/// method at one parcel count.
#[derive(Debug, Clone)]
pub struct ScalingRow {
    pub parcels: usize,
    /// "baked", "exact" (grid culling) or "brute" (exact, every parcel at
    /// every sample).
    pub method: &'static str,
    /// GPU time of the whole frame, first to last timestamp. units: ms
    pub frame_ms: f64,
    /// Cloud pass. units: ms
    pub clouds_ms: f64,
    /// Bake pass (baked only; re-baked every measured frame, the cost when
    /// every parcel moves, as at high time speed). units: ms
    pub bake_ms: f64,
    /// Exact path: mean parcel-list length over the non-empty grid cells.
    pub mean_list: Option<f64>,
    /// Exact path: longest parcel list.
    pub max_list: Option<u32>,
    /// Exact path: how often the grid was halved to fit its lists.
    pub coarsened: Option<u32>,
}

/// Mean and longest list, and the coarsening, of the exact path's grid for
/// `parcels` (None past what the uniforms hold).
fn list_stats(parcels: &[CloudParcel], cfg: &RenderConfig) -> Option<(f64, u32, u32)> {
    let packed = pack::pack(parcels, cfg.shell_m, cfg.radius_scale).ok()?;
    let d = packed.info.dims;
    let mut lens = Vec::new();
    for z in 0..d[2] {
        for y in 0..d[1] {
            for x in 0..d[0] {
                let n = packed.cell_list(x, y, z).len() as u32;
                if n > 0 {
                    lens.push(n);
                }
            }
        }
    }
    let mean = lens.iter().map(|&n| n as f64).sum::<f64>() / lens.len().max(1) as f64;
    Some((
        mean,
        lens.iter().copied().max().unwrap_or(0),
        packed.info.coarsened,
    ))
}

/// Rounds of the `baked` scaling rows. The targets are ratios of these
/// rows (frame(1024)/frame(85), frame(4096)/frame(85)), so their counts are
/// measured in turn, round after round, and each row keeps its median
/// round: a burst of load on a shared machine then lands in one round of
/// every count rather than in all the frames of one (docs/notes.md,
/// "Bench").
pub const BAKED_ROUNDS: usize = 3;

/// Frame time against parcel count for each method: baked at every count
/// (in [`BAKED_ROUNDS`] interleaved rounds), exact (grid culling) up to
/// [`pack::MAX_PARCELS`], brute force only up to `brute_max` (default
/// settings otherwise).
pub fn scaling(
    ctx: &GpuContext,
    size: (u32, u32),
    counts: &[usize],
    brute_max: usize,
    reps: Repeats,
    mut tick: impl FnMut(&str),
) -> Result<Vec<ScalingRow>> {
    let base = RenderConfig::default();
    let mut hl = Headless::new(ctx, &base, size.0, size.1)?;
    let cam = camera();
    let fields = counts
        .iter()
        .map(|&n| Ok(scenes::cloud_parcels(&scenes::cloud_field(n)?)))
        .collect::<Result<Vec<_>>>()?;
    let mut run =
        |n: usize, method: &'static str, parcels: &[CloudParcel], tick: &mut dyn FnMut(&str)| {
            let cfg = RenderConfig {
                method: if method == "baked" {
                    RenderMethod::Baked
                } else {
                    RenderMethod::Exact
                },
                grid_culling: method != "brute",
                ..base.clone()
            };
            tick(&format!("scaling: {n} parcels, {method}"));
            hl.renderer.set_config(ctx, &cfg)?;
            hl.renderer.set_always_bake(true);
            let m = measure(ctx, &mut hl, cam, cfg.sun(), Source::Parcels(parcels), reps)?;
            let stats = (method != "baked")
                .then(|| list_stats(parcels, &base))
                .flatten();
            Ok::<_, crate::error::Error>(ScalingRow {
                parcels: n,
                method,
                frame_ms: m.gpu_ms,
                clouds_ms: m.pass_ms("clouds").unwrap_or(0.0),
                bake_ms: m.pass_ms("bake").unwrap_or(0.0),
                mean_list: stats.map(|s| s.0),
                max_list: stats.map(|s| s.1),
                coarsened: stats.map(|s| s.2),
            })
        };
    let mut baked: Vec<Vec<ScalingRow>> = vec![Vec::new(); counts.len()];
    for _ in 0..BAKED_ROUNDS {
        for (i, (&n, parcels)) in counts.iter().zip(&fields).enumerate() {
            baked[i].push(run(n, "baked", parcels, &mut tick)?);
        }
    }
    let mut rows = Vec::new();
    for (i, (&n, parcels)) in counts.iter().zip(&fields).enumerate() {
        let mut rounds = std::mem::take(&mut baked[i]);
        rounds.sort_by(|a, b| a.frame_ms.total_cmp(&b.frame_ms));
        rows.push(rounds.swap_remove(rounds.len() / 2));
        if n <= pack::MAX_PARCELS {
            rows.push(run(n, "exact", parcels, &mut tick)?);
        }
        if n <= brute_max.min(pack::MAX_PARCELS) {
            rows.push(run(n, "brute", parcels, &mut tick)?);
        }
    }
    Ok(rows)
}

/// One row of the pruning table.
#[derive(Debug, Clone)]
pub struct PruningRow {
    /// "all" or "no terrain" / "no shadows" / "no normals" / "no aerial
    /// perspective".
    pub variant: &'static str,
    /// Passes that ran, space-separated.
    pub passes: String,
    /// Frame time (upload + passes). units: ms
    pub frame_ms: f64,
    /// Frames measured.
    pub frames: usize,
}

/// A scene with terrain, shadows, normals and the aerial perspective
/// against the same scene with each left out (leaving out the terrain also
/// leaves out its shadows).
pub fn pruning(
    ctx: &GpuContext,
    size: (u32, u32),
    parcels_n: usize,
    method: RenderMethod,
    reps: Repeats,
    mut tick: impl FnMut(&str),
) -> Result<Vec<PruningRow>> {
    let all = variant_config(true, true, method);
    let variants: [(&'static str, RenderConfig); 5] = [
        ("all", all.clone()),
        (
            "no terrain",
            RenderConfig {
                terrain: TerrainConfig {
                    enabled: false,
                    ..all.terrain.clone()
                },
                ..all.clone()
            },
        ),
        (
            "no shadows",
            RenderConfig {
                shadows: false,
                ..all.clone()
            },
        ),
        (
            "no normals",
            RenderConfig {
                normals: false,
                ..all.clone()
            },
        ),
        (
            "no aerial perspective",
            RenderConfig {
                aerial_perspective: false,
                ..all.clone()
            },
        ),
    ];
    let parcels = scenes::cloud_parcels(&scenes::cloud_field(parcels_n)?);
    let mut hl = Headless::new(ctx, &all, size.0, size.1)?;
    let cam = camera();
    let mut rows = Vec::new();
    for (variant, cfg) in variants {
        tick(&format!("pruning: {variant}"));
        hl.renderer.set_config(ctx, &cfg)?;
        let m = measure(
            ctx,
            &mut hl,
            cam,
            cfg.sun(),
            Source::Parcels(&parcels),
            reps,
        )?;
        rows.push(PruningRow {
            variant,
            frames: m.frames,
            passes: m
                .passes
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(" "),
            frame_ms: m.render_ms,
        });
    }
    Ok(rows)
}
