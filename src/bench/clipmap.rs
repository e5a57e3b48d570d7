//! The baked field's clipmap on `profiles/landscape_100km.toml` (100 km ×
//! 100 km of cumulus): its levels' voxels and the coarsest voxel the march
//! samples within 20 km of the camera, from the layout the bake itself
//! uses ([`crate::methods::raymarch::clipmap`]); no GPU, a few seconds of
//! physics.

use glam::Vec3;

use crate::error::Result;
use crate::methods::raymarch::clipmap::clipmap;
use crate::methods::raymarch::pack::gpu_parcels;

/// The bench's 100 km scene under `profiles/`.
pub const SCENE: &str = "landscape_100km.toml";
/// The reach: within NEAR_M of the camera, voxels ≤ FINE_VOXEL_M.
pub const NEAR_M: f32 = 20_000.0;
pub const FINE_VOXEL_M: f32 = 50.0;

/// The 100 km scene's clipmap at its start.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipmapRow {
    pub parcels: usize,
    /// Voxel side of each level, finest first. units: m
    pub level_voxel_m: Vec<f32>,
    /// The coarsest voxel sampled in the cloud layer within [`NEAR_M`] of
    /// the camera (every 500 m across, five heights). units: m
    pub near_voxel_m: f32,
}

/// Simulates the scene to its start (with the `--set` `overrides`) and
/// lays out its clipmap around its camera.
pub fn landscape_100km(overrides: &[String]) -> Result<ClipmapRow> {
    let l = super::methods::load_at(SCENE, None, overrides)?;
    let cfg = &l.profile.render;
    let live = gpu_parcels(&l.parcels, cfg.shell_m, cfg.radius_scale)?;
    let Some(z0) = l.parcels.iter().map(|p| p.cond_plane_z_m).reduce(f32::min) else {
        return Ok(ClipmapRow {
            parcels: 0,
            level_voxel_m: Vec::new(),
            near_voxel_m: 0.0,
        });
    };
    let z1 = l.parcels.iter().map(|p| p.center_m.z).fold(z0, f32::max);
    let map = clipmap(&live, cfg.shell_m, l.camera.position);
    let (lo, hi) = (map.top().min, map.top().max());
    let mut near = 0f32;
    let step = 500.0;
    let n = (NEAR_M / step) as i32;
    for i in -n..=n {
        for j in -n..=n {
            let d = Vec3::new(i as f32, j as f32, 0.0) * step;
            if d.length() > NEAR_M {
                continue;
            }
            for k in 0..5 {
                let z = z0 + (z1 - z0) * k as f32 / 4.0;
                let p = Vec3::new(l.camera.position.x + d.x, l.camera.position.y + d.y, z);
                if p.cmpge(lo).all() && p.cmple(hi).all() {
                    near = near.max(map.voxel_at(p).unwrap_or(f32::INFINITY));
                }
            }
        }
    }
    Ok(ClipmapRow {
        parcels: l.parcels.len(),
        level_voxel_m: map.levels.iter().map(|v| v.voxel_m).collect(),
        near_voxel_m: near,
    })
}

/// The report's line.
pub fn markdown(row: &ClipmapRow) -> String {
    let sides: Vec<String> = row
        .level_voxel_m
        .iter()
        .map(|v| format!("{v:.0}"))
        .collect();
    format!(
        "- 100 km landscape ({} cloud parcels): {} clipmap levels of {} m voxels; coarsest within {:.0} km of the camera {:.0} m (target ≤ {FINE_VOXEL_M:.0}: {})\n",
        row.parcels,
        row.level_voxel_m.len(),
        sides.join(", "),
        NEAR_M / 1000.0,
        row.near_voxel_m,
        if row.near_voxel_m <= FINE_VOXEL_M {
            "met"
        } else {
            "NOT met"
        }
    )
}
