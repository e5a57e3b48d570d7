//! SPH kernels of Müller, Charypar & Gross, "Particle-based fluid simulation
//! for interactive applications" (SCA 2003), which the paper cites for its
//! kernels (\[16\]): poly6 for density (eq 7), the gradient of "spiky" for
//! pressure (eq 9, poly6's gradient vanishes at the centre and lets particles
//! clump), and the Laplacian of the "viscosity" kernel for eq 10 (positive
//! everywhere, so viscosity only ever damps relative motion).

use std::f64::consts::PI;

use glam::DVec3;

/// Poly6 kernel W(r, h) = 315/(64π h⁹) (h² − r²)³ for r < h. units: m⁻³
pub fn poly6(r2: f64, h: f64) -> f64 {
    let h2 = h * h;
    if r2 >= h2 {
        return 0.0;
    }
    let d = h2 - r2;
    315.0 / (64.0 * PI * h.powi(9)) * d * d * d
}

/// Gradient of the spiky kernel with respect to x_i, for r = x_i − x_j:
/// −45/(π h⁶) (h − |r|)² r/|r|. Zero at r = 0: exactly coincident parcels
/// have no direction to push each other in, so they get no SPH force from
/// each other (any other force that separates them brings it back; the
/// exposed-area and exchange stages skip d = 0 too). units: m⁻⁴
pub fn spiky_gradient(r: DVec3, h: f64) -> DVec3 {
    let len = r.length();
    if len >= h || len <= 0.0 {
        return DVec3::ZERO;
    }
    let d = h - len;
    r * (-45.0 / (PI * h.powi(6)) * d * d / len)
}

/// Laplacian of the viscosity kernel, 45/(π h⁶)(h − r). units: m⁻⁵
pub fn viscosity_laplacian(r: f64, h: f64) -> f64 {
    if r >= h {
        return 0.0;
    }
    45.0 / (PI * h.powi(6)) * (h - r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn poly6_integrates_to_one() {
        // Midpoint rule over radial shells; 1e-4 is the quadrature error at 20k shells.
        let h = 2.0;
        let n = 20_000;
        let dr = h / n as f64;
        let s: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * dr;
                4.0 * PI * r * r * poly6(r * r, h) * dr
            })
            .sum();
        assert!((s - 1.0).abs() < 1e-4, "{s}");
    }

    #[test]
    fn spiky_gradient_points_towards_the_other_particle() {
        // W decreases away from x_j, so ∇_i W points from x_i back to x_j (−r).
        let g = spiky_gradient(DVec3::new(1.0, 0.0, 0.0), 2.0);
        assert!(g.x < 0.0 && g.y == 0.0 && g.z == 0.0);
    }
}
