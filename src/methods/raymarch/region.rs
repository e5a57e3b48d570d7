//! Where the `baked` method's field sits and how fine it is: the box of
//! the condensed parcels and the voxel size their radii ask for (the voxel
//! size rule is in the docs of [`super::baked`]; how the box is divided
//! into camera-centred levels is [`super::clipmap`]).

use glam::Vec3;

use crate::methods::raymarch::baked::PLANE_SHELL;
use crate::methods::raymarch::pack::GpuParcel;

/// The voxel side `live` parcels (not empty) ask for: the smaller of a
/// quarter of the median radius and one plane shell, at least 1 m, rounded
/// to a power of 2^¼. units: m
pub(crate) fn wanted_voxel_m(live: &[GpuParcel], shell_m: f32) -> f32 {
    let mut radii: Vec<f32> = live.iter().map(|p| p.radius_m).collect();
    radii.sort_by(f32::total_cmp);
    let median = radii[radii.len() / 2];
    let raw = (0.25 * median).min(PLANE_SHELL * shell_m).max(1.0);
    2f32.powf((raw.log2() * 4.0).round() / 4.0)
}

/// The box where some parcel's v > −1 (sphere plus shell, cut at the plane
/// shell under its condensation plane): (lowest, highest corner). units: m
pub(crate) fn parcel_box(live: &[GpuParcel], shell_m: f32) -> (Vec3, Vec3) {
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
    (lo, hi)
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
        // Small parcels: a quarter radius (rounded to 2^¼ steps, so within
        // 2^⅛ − 1 ≈ 9 % of 25 m).
        let v = wanted_voxel_m(&[parcel(0.0, 100.0)], 280.0);
        assert!((v - 25.0).abs() / 25.0 < 0.1, "{v}");
        // Large parcels: one plane shell (0.3 × 280 m = 84 m).
        let v = wanted_voxel_m(&[parcel(0.0, 2000.0)], 280.0);
        assert!((v - 84.0).abs() / 84.0 < 0.1, "{v}");
    }

    #[test]
    fn the_box_stops_a_plane_shell_under_the_base() {
        let (lo, hi) = parcel_box(&[parcel(0.0, 500.0)], 100.0);
        // 1800 m plane − 0.3 × 100 m shell.
        assert_eq!(lo.z, 1770.0);
        assert_eq!(hi, Vec3::new(600.0, 600.0, 2600.0));
    }
}
