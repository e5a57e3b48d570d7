//! Frame-time measurements: the performance table (parcel count × normals ×
//! shadows, paper Table 1), scaling with the parcel count for grid culling
//! against brute force, and what each optional pass costs (pruning).

use crate::error::Result;
use crate::physics::ParcelWorld;
use crate::render::headless::Headless;
use crate::render::{Camera, CameraConfig, GpuContext, RenderConfig, TerrainConfig};

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
pub fn variant_config(normals: bool, shadows: bool) -> RenderConfig {
    RenderConfig {
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
    reps: Repeats,
    mut tick: impl FnMut(&str),
) -> Result<Vec<PerfRow>> {
    let mut hl = Headless::new(ctx, &variant_config(false, false), size.0, size.1)?;
    let cam = camera();
    let worlds: Vec<ParcelWorld> = counts
        .iter()
        .map(|&n| scenes::cloud_field(n))
        .collect::<Result<_>>()?;
    let mut rows = Vec::new();
    for (normals, shadows) in VARIANTS {
        let cfg = variant_config(normals, shadows);
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

/// One row of the scaling table: render frame time (no physics) with and
/// without the culling grid.
#[derive(Debug, Clone)]
pub struct ScalingRow {
    pub parcels: usize,
    /// units: ms
    pub grid_ms: f64,
    /// None where brute force was skipped (too slow for this run). units: ms
    pub brute_ms: Option<f64>,
}

/// Frame time against parcel count, grid culling vs brute force (default
/// settings otherwise); brute force only up to `brute_max` parcels. The
/// grid-culling times are the render part (upload + passes) of the
/// performance rows with default settings where the table has the count
/// (the same frames: measuring them again would only add noise and time).
pub fn scaling(
    ctx: &GpuContext,
    size: (u32, u32),
    counts: &[usize],
    brute_max: usize,
    table: &[PerfRow],
    reps: Repeats,
    mut tick: impl FnMut(&str),
) -> Result<Vec<ScalingRow>> {
    let base = RenderConfig::default();
    let default_variant = (base.normals, base.shadows);
    let mut hl = Headless::new(ctx, &base, size.0, size.1)?;
    let cam = camera();
    let mut rows = Vec::new();
    for culling in [true, false] {
        let cfg = RenderConfig {
            grid_culling: culling,
            ..base.clone()
        };
        hl.renderer.set_config(ctx, &cfg)?;
        for &n in counts {
            if !culling && n > brute_max {
                continue;
            }
            tick(&format!(
                "scaling: {n} parcels, {}",
                if culling {
                    "grid culling"
                } else {
                    "brute force"
                }
            ));
            let known = table
                .iter()
                .find(|r| r.parcels == n && (r.normals, r.shadows) == default_variant);
            let ms = match known {
                Some(r) if culling => r.m.render_ms,
                _ => {
                    let parcels = scenes::cloud_parcels(&scenes::cloud_field(n)?);
                    measure(
                        ctx,
                        &mut hl,
                        cam,
                        cfg.sun(),
                        Source::Parcels(&parcels),
                        reps,
                    )?
                    .render_ms
                }
            };
            if culling {
                rows.push(ScalingRow {
                    parcels: n,
                    grid_ms: ms,
                    brute_ms: None,
                });
            } else if let Some(row) = rows.iter_mut().find(|r| r.parcels == n) {
                row.brute_ms = Some(ms);
            }
        }
    }
    Ok(rows)
}

/// One row of the pruning table.
#[derive(Debug, Clone)]
pub struct PruningRow {
    /// "all" or "no terrain" / "no shadows" / "no normals".
    pub variant: &'static str,
    /// Passes that ran, space-separated.
    pub passes: String,
    /// Frame time (upload + passes). units: ms
    pub frame_ms: f64,
    /// Frames measured.
    pub frames: usize,
}

/// A scene with terrain, shadows and normals against the same scene with
/// each left out (leaving out the terrain also leaves out its shadows).
pub fn pruning(
    ctx: &GpuContext,
    size: (u32, u32),
    parcels_n: usize,
    reps: Repeats,
    mut tick: impl FnMut(&str),
) -> Result<Vec<PruningRow>> {
    let all = variant_config(true, true);
    let variants: [(&'static str, RenderConfig); 4] = [
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
