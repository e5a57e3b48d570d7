//! The coarse 18 × 9 tessellation of a parcel's sphere (paper §5.1 and
//! §7): 18 slices in longitude, 9 bands in polar angle. A quad is hidden
//! when its centre lies inside a neighbour's sphere; the rest is the exposed
//! area through which the parcel mixes and feels the atmosphere.

use std::f64::consts::PI;

use glam::DVec3;

/// Slices in longitude.
pub const SLICES: usize = 18;
/// Bands in polar angle.
pub const BANDS: usize = 9;
/// Quads per sphere.
pub const QUADS: usize = SLICES * BANDS;

/// Quad centre directions and areas on the unit sphere.
#[derive(Debug, Clone)]
pub struct UnitSphere {
    /// Unit outward normal at each quad centre.
    pub normal: Vec<DVec3>,
    /// Area of each quad on the unit sphere (they sum to 4π). units: 1 (m² per m² of r²)
    pub area: Vec<f64>,
}

impl UnitSphere {
    /// Builds the 18 × 9 tessellation. Band areas are exact spherical zones,
    /// 2π (cos θ_a − cos θ_b)/18, so the areas sum to 4π up to rounding.
    pub fn new() -> Self {
        let mut normal = Vec::with_capacity(QUADS);
        let mut area = Vec::with_capacity(QUADS);
        let dphi = 2.0 * PI / SLICES as f64;
        for b in 0..BANDS {
            let ta = PI * b as f64 / BANDS as f64;
            let tb = PI * (b + 1) as f64 / BANDS as f64;
            let tm = 0.5 * (ta + tb);
            let zone = dphi * (ta.cos() - tb.cos());
            for s in 0..SLICES {
                let phi = dphi * (s as f64 + 0.5);
                normal.push(DVec3::new(
                    tm.sin() * phi.cos(),
                    tm.sin() * phi.sin(),
                    tm.cos(),
                ));
                area.push(zone);
            }
        }
        UnitSphere { normal, area }
    }
}

impl Default for UnitSphere {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn areas_sum_to_the_sphere_and_normals_balance() {
        let s = UnitSphere::new();
        let a: f64 = s.area.iter().sum();
        // Exact zones: only rounding error remains.
        assert!((a - 4.0 * PI).abs() < 1e-12);
        // A closed sphere feels no net uniform pressure: Σ n dA = 0 by symmetry.
        let f: DVec3 = s.normal.iter().zip(&s.area).map(|(n, a)| *n * *a).sum();
        assert!(f.length() < 1e-12, "{f}");
    }
}
