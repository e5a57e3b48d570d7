//! Stage 5: exposed area of each sphere and the atmospheric pressure on
//! its hidden caps (paper §5.1).

use std::f64::consts::PI;

use glam::DVec3;
use rayon::prelude::*;

use super::PAR_MIN;

use super::{ClampCounts, ParcelWorld};
use crate::atmosphere::thermo;
use crate::physics::parcel::Parcel;
use crate::physics::tessellation::{BANDS, FULL_BAND, SLICES};

impl ParcelWorld {
    /// Exposed area of each sphere and the atmospheric pressure force on it
    /// (paper §5.1), from the 18 × 9 tessellation; every touching neighbour is tested.
    ///
    /// Archimedes' force is the pressure integrated over the whole sphere and
    /// is already in the θ_v buoyancy (eq 5). What the exposed-area term adds
    /// is the difference: the part of the sphere inside a neighbour feels no
    /// environment pressure; the neighbour presses instead on the contact
    /// disk with the pressure at the disk's centre P_ref. So each hidden quad
    /// contributes (P(z_q) − P_ref) n dA, summed over each neighbour's cap.
    /// By the divergence theorem a cap's sum is minus its own buoyancy,
    /// −ρ g V_cap ẑ: overlapping spheres are not buoyed twice for the shared
    /// volume. An isolated sphere gets exactly zero (no quad is evaluated).
    ///
    /// The weight is the paper's calibration. At 1 the whole Archimedes
    /// force of the overlap is removed, but the parcels' masses are not
    /// shared, so overlapping parcels would become heavier than their
    /// surroundings by g V_cap/V, far above thermal buoyancy (g Δθ/θ ≈
    /// 0.01 g): a small weight (default 0.01) keeps the term a gentle
    /// downward and inward pull on overlapping parcels.
    pub(super) fn exposed_area(&mut self, clamps: &mut ClampCounts) {
        let weight = if self.cfg.physics.atmospheric_pressure {
            self.cfg.physics.atm_pressure_weight
        } else {
            0.0
        };
        let (grid, env, sphere) = (&self.grid, &self.env, &self.sphere);
        // The radii of the neighbour build (unchanged since): a dense array
        // instead of one parcel record per neighbour. A parcel reads no
        // other's record, so its results go straight into it (one pass).
        let (pos, radius) = (&self.hot_pos, &self.hot_radius);
        let exposed_and_force = |i: usize, p: &Parcel| {
            let (ci, ri) = (p.position_m, p.radius_m);
            // P across the sphere by the quadratic through P(z_c − r), P(z_c),
            // P(z_c + r): three lookups instead of one per hidden quad; the
            // cubic remainder is (r/H)³ ≈ 1e-5 of the anomaly for r = 150 m.
            // Looked up only for a sphere that overlaps a neighbour; P(z_c)
            // is the sub-step's centre pressure, already known.
            let (mut d1, mut d2) = (0.0, 0.0);
            let pressure_anomaly = |d1: f64, d2: f64, dz: f64| d1 * dz + 0.5 * d2 * dz * dz;
            let r2 = ri * ri;
            // Per band: the pressure anomaly at its quads' height and
            // its quad area (every quad of a band has the same z and area).
            let mut band_p = [0.0; BANDS];
            let mut band_a = [0.0; BANDS];
            // Hidden quads, one mask of slices per band.
            let mut hidden = [0u32; BANDS];
            let mut force = DVec3::ZERO;
            let mut tested = 0u64;
            let mut evaluated = false;
            // Per overlapping neighbour: axis u towards it, cos of the
            // cap's half-angle, pressure at the contact disk's centre.
            // The part of sphere i inside sphere j is exactly the cap
            // {n : n·u > x/r_i}, x the distance of the intersection plane
            // from c_i, so the quad test is a dot product. Every
            // neighbour's cap is closed on its own contact disk, so a
            // quad inside two neighbours counts in both caps.
            for n in grid.of(i) {
                let rj = radius[n.j];
                if !(n.dist < ri + rj && n.dist > 0.0) {
                    continue;
                }
                let u = -(ci - pos[n.j]) / n.dist;
                let x = (n.dist * n.dist + ri * ri - rj * rj) / (2.0 * n.dist);
                // x ≥ r_i: sphere j lies inside sphere i and hides nothing of its surface.
                if x >= ri {
                    continue;
                }
                let x = x.max(-ri);
                if !evaluated {
                    evaluated = true;
                    let (pm, p0, pp) = (
                        env.pressure_pa(ci.z - ri),
                        p.env_at_centre.0,
                        env.pressure_pa(ci.z + ri),
                    );
                    (d1, d2) = ((pp - pm) / (2.0 * ri), (pp - 2.0 * p0 + pm) / (ri * ri));
                    for b in 0..BANDS {
                        let q = b * SLICES;
                        band_p[b] = pressure_anomaly(d1, d2, sphere.normal[q].z * ri);
                        band_a[b] = sphere.area[q];
                    }
                }
                let (cos, p_ref) = (x / ri, pressure_anomaly(d1, d2, x * u.z));
                let (masks, n_tested) = sphere.cap_masks(u, cos);
                tested += n_tested as u64;
                for (b, &m) in masks.iter().enumerate() {
                    hidden[b] |= m;
                    if weight == 0.0 || m == 0 {
                        continue;
                    }
                    // Quads in increasing order; a whole band at once.
                    let dp = (band_p[b] - p_ref) * band_a[b] * r2;
                    if m == FULL_BAND {
                        force += sphere.band_normal_sum[b] * dp;
                        continue;
                    }
                    let mut bits = m;
                    while bits != 0 {
                        let s = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        force += sphere.normal[b * SLICES + s] * dp;
                    }
                }
            }
            if !evaluated {
                return (4.0 * PI * r2, DVec3::ZERO, false, None);
            }
            // Exposed area: each band's visible quads times its quad area.
            let exposed: f64 = (0..BANDS)
                .map(|b| band_a[b] * r2 * (SLICES as u32 - hidden[b].count_ones()) as f64)
                .sum();
            // Bound: the caps cannot lose more than the sphere's whole
            // Archimedes force ρ g V.
            let force = force * weight;
            let bound = weight * p.env_at_centre.1 * thermo::GRAVITY * p.volume_m3;
            if force.length() > bound {
                (
                    exposed,
                    force * (bound / force.length()),
                    true,
                    Some(tested),
                )
            } else {
                (exposed, force, false, Some(tested))
            }
        };
        // Counts are integers: their parallel sum is exact.
        let (capped, evaluated, tested) = self
            .parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .enumerate()
            .map(|(i, p)| {
                let (exposed, force, capped, tested) = exposed_and_force(i, p);
                p.exposed_area_m2 = exposed;
                p.atm_force_n = force;
                (capped as u64, tested.is_some() as u64, tested.unwrap_or(0))
            })
            .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
        clamps.atm_force += capped;
        self.counters.exposed_area_evaluations += evaluated;
        self.counters.quads_tested += tested;
    }
}
