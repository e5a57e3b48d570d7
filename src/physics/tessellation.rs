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
/// The mask of a band whose every quad is in the cap.
pub const FULL_BAND: u32 = (1 << SLICES) - 1;
/// Quads per sphere.
pub const QUADS: usize = SLICES * BANDS;

/// Quad centre directions and areas on the unit sphere.
#[derive(Debug, Clone)]
pub struct UnitSphere {
    /// Unit outward normal at each quad centre.
    pub normal: Vec<DVec3>,
    /// Area of each quad on the unit sphere (they sum to 4π). units: 1 (m² per m² of r²)
    pub area: Vec<f64>,
    /// Sum of each band's 18 normals, in slice order (a band wholly inside
    /// a cap adds this once instead of quad by quad).
    pub band_normal_sum: [DVec3; BANDS],
    /// cos and sin of each band's centre polar angle.
    band_cos_sin: Vec<(f64, f64)>,
    /// The normals' components per band, slices in order (structure of
    /// arrays: the cap test of one band is a short loop over contiguous
    /// numbers that the compiler vectorises).
    band_x: [[f64; SLICES]; BANDS],
    band_y: [[f64; SLICES]; BANDS],
    band_z: [[f64; SLICES]; BANDS],
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
        let band_cos_sin = (0..BANDS)
            .map(|b| {
                let t = PI * (b as f64 + 0.5) / BANDS as f64;
                (t.cos(), t.sin())
            })
            .collect();
        let (mut band_x, mut band_y, mut band_z) = (
            [[0.0; SLICES]; BANDS],
            [[0.0; SLICES]; BANDS],
            [[0.0; SLICES]; BANDS],
        );
        for (q, n) in normal.iter().enumerate() {
            let (b, s) = (q / SLICES, q % SLICES);
            (band_x[b][s], band_y[b][s], band_z[b][s]) = (n.x, n.y, n.z);
        }
        let band_normal_sum =
            std::array::from_fn(|b| normal[b * SLICES..(b + 1) * SLICES].iter().sum());
        UnitSphere {
            band_normal_sum,
            normal,
            area,
            band_cos_sin,
            band_x,
            band_y,
            band_z,
        }
    }

    /// The quads of one cap {n : n·u > cos α} of unit axis `u`, as one
    /// bit mask of slices per band (bit s of band b is quad b·18 + s), and
    /// the number of quads tested. Only the bands whose polar angle is within
    /// α of u's are tested (the angle between a quad centre and u is at
    /// least their polar difference), without trigonometry: cos(θ_b − θ_u)
    /// < cos α is tested with the bands' stored cos and sin. Each quad of a
    /// tested band is decided by the exact test n·u > cos α, unless the
    /// whole band lies inside the cap: the angle between a quad centre and u
    /// is at most θ_b + θ_u (or 2π minus it), so cos(θ_b + θ_u) > cos α
    /// hides every quad of the band without a dot product.
    pub fn cap_masks(&self, u: DVec3, cos_alpha: f64) -> ([u32; BANDS], u32) {
        let (cu, su) = (u.z, (1.0 - u.z * u.z).max(0.0).sqrt());
        let mut masks = [0u32; BANDS];
        let mut tested = 0;
        for (b, (cb, sb)) in self.band_cos_sin.iter().enumerate() {
            // 1e-9: rounding margin, so a centre on the cap's edge is still tested.
            if cb * cu + sb * su < cos_alpha - 1e-9 {
                continue;
            }
            tested += SLICES as u32;
            // 1e-9 again: only a band inside by more than rounding is taken whole.
            if cb * cu - sb * su > cos_alpha + 1e-9 {
                masks[b] = FULL_BAND;
                continue;
            }
            let (x, y, z) = (&self.band_x[b], &self.band_y[b], &self.band_z[b]);
            let mut m = 0u32;
            for s in 0..SLICES {
                // The same sum, in the same order, as DVec3::dot.
                let d = x[s] * u.x + y[s] * u.y + z[s] * u.z;
                m |= ((d > cos_alpha) as u32) << s;
            }
            masks[b] = m;
        }
        (masks, tested)
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
    fn cap_masks_hold_exactly_the_quads_inside_the_cap() {
        // Against the brute-force test over all quads, for axes all over the
        // sphere (poles included) and caps from tiny to more than a hemisphere.
        let s = UnitSphere::new();
        let mut fewer = 0;
        for k in 0..400 {
            let (t, p) = (
                PI * (k % 20) as f64 / 19.0,
                0.37 + 2.0 * PI * (k / 20) as f64 / 20.0,
            );
            let u = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            for cos_a in [0.99, 0.9, 0.6, 0.2, -0.3] {
                let (masks, tested) = s.cap_masks(u, cos_a);
                for (q, n) in s.normal.iter().enumerate() {
                    let inside = masks[q / SLICES] & (1 << (q % SLICES)) != 0;
                    assert_eq!(inside, n.dot(u) > cos_a, "quad {q}, u {u}, cos {cos_a}");
                }
                fewer += (tested < QUADS as u32 / 2) as usize;
            }
        }
        // Small caps really are cheaper.
        assert!(fewer > 500, "{fewer}");
    }

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
