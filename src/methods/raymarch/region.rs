//! Where the `baked` method's field sits and how fine it is: the region of
//! the condensed parcels, its voxel size and its coarse cells (the voxel
//! size and memory rules are in the docs of [`super::baked`]).

use glam::Vec3;

use crate::methods::raymarch::baked::{BAKE_BLOCK, MAX_BAKE_VOXELS, PLANE_SHELL};
use crate::methods::raymarch::pack::GpuParcel;

/// Layout of the bake: where the region sits and how it is divided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Region {
    /// Lowest corner of the region (of voxel 0's cube). units: m
    pub min: Vec3,
    /// Voxel side. units: m
    pub voxel_m: f32,
    /// Coarse cells per axis (voxels = cells × BAKE_BLOCK).
    pub cells: [u32; 3],
    /// Voxel side the radii asked for, before the memory cap. units: m
    pub wanted_voxel_m: f32,
    /// How many times the voxel was enlarged to fit the memory cap.
    pub coarsened: u32,
}

impl Region {
    /// Voxels per axis.
    pub fn voxel_dims(&self) -> [u32; 3] {
        self.cells.map(|c| c * BAKE_BLOCK)
    }

    /// Voxels in all.
    pub fn voxels(&self) -> u64 {
        self.voxel_dims().iter().map(|&d| d as u64).product()
    }
}

/// Region and voxel size for `live` parcels (not empty), see the module docs.
pub(crate) fn region(live: &[GpuParcel], shell_m: f32) -> Region {
    let mut radii: Vec<f32> = live.iter().map(|p| p.radius_m).collect();
    radii.sort_by(f32::total_cmp);
    let median = radii[radii.len() / 2];
    let raw = (0.25 * median).min(PLANE_SHELL * shell_m).max(1.0);
    let wanted = 2f32.powf((raw.log2() * 4.0).round() / 4.0);
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for p in live {
        let c = Vec3::from(p.center_m);
        let reach = p.radius_m + shell_m;
        let mut a = c - Vec3::splat(reach);
        let b = c + Vec3::splat(reach);
        a.z = a.z.max(p.plane_z_m - PLANE_SHELL * shell_m).min(b.z);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    let mut voxel_m = wanted;
    let mut coarsened = 0;
    loop {
        // One empty voxel of padding all round: outside the region the
        // clamped texture then reads v = −1, as far from every parcel.
        let min = lo - Vec3::splat(voxel_m);
        let ext = hi - lo + Vec3::splat(2.0 * voxel_m);
        let cell = voxel_m * BAKE_BLOCK as f32;
        let cells = [0, 1, 2].map(|a| ((ext[a] / cell).ceil() as u32).max(1));
        let r = Region {
            min,
            voxel_m,
            cells,
            wanted_voxel_m: wanted,
            coarsened,
        };
        if r.voxels() <= MAX_BAKE_VOXELS {
            return r;
        }
        voxel_m *= (r.voxels() as f64 / MAX_BAKE_VOXELS as f64)
            .cbrt()
            .max(1.01) as f32;
        coarsened += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parcel(x: f32, r: f32) -> GpuParcel {
        GpuParcel {
            center_m: [x, 0.0, 2000.0],
            radius_m: r,
            fill: 1.0,
            plane_z_m: 1800.0,
            _pad: [0.0; 2],
        }
    }

    #[test]
    fn voxel_follows_radii_and_plane_shell() {
        // Small parcels: a quarter radius (rounded to 2^¼ steps).
        let r = region(&[parcel(0.0, 100.0)], 280.0);
        assert!((r.voxel_m - 25.0).abs() / 25.0 < 0.1, "{}", r.voxel_m);
        // Large parcels: one plane shell (0.3 × 280 m = 84 m).
        let r = region(&[parcel(0.0, 2000.0)], 280.0);
        assert!((r.voxel_m - 84.0).abs() / 84.0 < 0.1, "{}", r.voxel_m);
        assert_eq!(r.coarsened, 0);
    }

    #[test]
    fn a_landscape_fits_the_voxel_budget_with_coarser_voxels() {
        // 40 km × 40 km of parcels 1–12 km high.
        let mut live = Vec::new();
        for i in 0..41 {
            for j in 0..41 {
                live.push(GpuParcel {
                    center_m: [
                        i as f32 * 1000.0 - 20_000.0,
                        j as f32 * 1000.0 - 20_000.0,
                        1000.0 + (i * j % 12) as f32 * 1000.0,
                    ],
                    radius_m: 400.0,
                    fill: 1.0,
                    plane_z_m: 900.0,
                    _pad: [0.0; 2],
                });
            }
        }
        let r = region(&live, 280.0);
        assert!(r.voxels() <= MAX_BAKE_VOXELS);
        assert!(r.coarsened > 0 && r.voxel_m > r.wanted_voxel_m);
        let v = r.voxel_dims();
        let size = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) * r.voxel_m;
        assert!(size.x >= 40_000.0 && size.z >= 11_000.0, "{size}");
    }
}
