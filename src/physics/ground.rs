//! The ground's heat and humidity maps and the parcel generator (paper §7.3:
//! "parcels with a frequency proportional to the heat and humidity content
//! of the region").
//!
//! The maps are procedural: `patches` Gaussian bumps placed by the map seed,
//! each with its own heat and humidity strength in [0.3, 1], over a weak
//! background. Emission is a Poisson process per map cell: in a frame of
//! length dt, a cell emits with probability λ A dt where
//! λ = rate · heat · (0.5 + 0.5 humidity) · sun(t).
//!
//! With `follow_terrain` the maps follow the relief (the paper's "heat and
//! humidity content of the region"): a patch heats by the midday sunshine on
//! its slope (the scene's sun at solar noon: sunny slopes hot, shaded ones
//! cool) and more the higher and drier the ground; low ground is moist.

use super::config::{EmissionConfig, GroundConfig};
use super::rng::SplitMix64;

/// Emission cells per side of the domain.
const CELLS: usize = 32;

#[derive(Debug, Clone, PartialEq)]
struct Patch {
    x_m: f64,
    y_m: f64,
    sigma_m: f64,
    heat: f64,
    humidity: f64,
}

/// Heat and humidity maps of the ground, both in [0, 1].
#[derive(Debug, Clone, PartialEq)]
pub struct GroundMap {
    cfg: GroundConfig,
    patches: Vec<Patch>,
    /// λ weight heat · (0.5 + 0.5 humidity) at each cell centre, row-major.
    cell_weight: Vec<f64>,
}

impl GroundMap {
    /// Places the patches from `cfg.map_seed`.
    pub fn new(cfg: &GroundConfig) -> Self {
        let mut rng = SplitMix64::new(cfg.map_seed);
        let (hx, hy) = (0.5 * cfg.size_m[0], 0.5 * cfg.size_m[1]);
        let patches: Vec<Patch> = (0..cfg.patches)
            .map(|_| Patch {
                // Keep patch centres off the edges so their parcels stay in the domain.
                x_m: rng.range(-0.7 * hx, 0.7 * hx),
                y_m: rng.range(-0.7 * hy, 0.7 * hy),
                sigma_m: cfg.patch_radius_m * rng.range(0.6, 1.4),
                heat: rng.range(0.3, 1.0),
                humidity: rng.range(0.3, 1.0),
            })
            .collect();
        let mut map = GroundMap {
            cfg: cfg.clone(),
            patches,
            cell_weight: Vec::new(),
        };
        let mut w = Vec::with_capacity(CELLS * CELLS);
        for j in 0..CELLS {
            for i in 0..CELLS {
                let (x, y) = map.cell_centre(i, j);
                let (h, q) = map.sample(x, y);
                w.push(h * (0.5 + 0.5 * q));
            }
        }
        map.cell_weight = w;
        map
    }

    fn cell_size(&self) -> (f64, f64) {
        (
            self.cfg.size_m[0] / CELLS as f64,
            self.cfg.size_m[1] / CELLS as f64,
        )
    }

    fn cell_centre(&self, i: usize, j: usize) -> (f64, f64) {
        let (dx, dy) = self.cell_size();
        (
            -0.5 * self.cfg.size_m[0] + (i as f64 + 0.5) * dx,
            -0.5 * self.cfg.size_m[1] + (j as f64 + 0.5) * dy,
        )
    }

    /// (heat, humidity) in [0, 1] at (x, y). units: m → 1
    pub fn sample(&self, x_m: f64, y_m: f64) -> (f64, f64) {
        let (mut h, mut q) = (self.cfg.background, self.cfg.background);
        for p in &self.patches {
            let d2 = (x_m - p.x_m).powi(2) + (y_m - p.y_m).powi(2);
            let g = (-0.5 * d2 / (p.sigma_m * p.sigma_m)).exp();
            h = h.max(p.heat * g);
            q = q.max(p.humidity * g);
        }
        let t = &self.cfg.terrain;
        if t.is_flat() || t.height_scale_m() <= 0.0 {
            return (h, q);
        }
        // Insolation of the slope under the midday sun over that of flat
        // ground, 0 in its shade.
        let sun = glam::DVec3::from(self.cfg.midday_sun);
        let n = t.normal(x_m as f32, y_m as f32, 100.0).as_dvec3();
        let insolation = n.dot(sun).max(0.0) / sun.z;
        let rel = (self.height_m(x_m, y_m) / t.height_scale_m() as f64).clamp(0.0, 1.0);
        (
            (h * insolation * (0.6 + 0.8 * rel)).clamp(0.0, 1.0),
            q.max(0.8 * (1.0 - rel).powi(2)),
        )
    }

    /// Height of the ground at (x, y) (0 unless `follow_terrain`). units: m → m
    pub fn height_m(&self, x_m: f64, y_m: f64) -> f64 {
        self.cfg.terrain.height_m(x_m as f32, y_m as f32) as f64
    }

    /// θ and q_v excess of air leaving the ground at (x, y). units: m → (K, kg/kg)
    pub fn excess(&self, x_m: f64, y_m: f64) -> (f64, f64) {
        let (h, q) = self.sample(x_m, y_m);
        (
            self.cfg.heat_excess_k * h,
            self.cfg.moisture_excess_kg_per_kg * q,
        )
    }

    /// Sun factor at simulation time `t_s`: sin(π (hour − 6)/12), zero at night.
    pub fn sun(emission: &EmissionConfig, t_s: f64) -> f64 {
        if !emission.diurnal {
            return 1.0;
        }
        let hour = (emission.start_hour + t_s / 3600.0).rem_euclid(24.0);
        (std::f64::consts::PI * (hour - 6.0) / 12.0).sin().max(0.0)
    }

    /// Draws the emissions of one frame of length `dt_s` starting at `t_s`:
    /// (x, y) positions in cell order, so the result depends only on the RNG state.
    ///
    /// Each cell emits a Poisson number of parcels with mean λ = rate ×
    /// weight × area × dt (inverse transform of one uniform draw), so a
    /// cell can emit several per frame, nothing is capped, and the count
    /// over a time span does not depend on how it is cut into frames.
    pub fn draw(
        &self,
        emission: &EmissionConfig,
        t_s: f64,
        dt_s: f64,
        rng: &mut SplitMix64,
    ) -> Vec<(f64, f64)> {
        let (dx, dy) = self.cell_size();
        let cell_km2 = dx * dy * 1e-6;
        let base = emission.rate_per_km2_per_h * Self::sun(emission, t_s) * dt_s / 3600.0;
        let mut out = Vec::new();
        for j in 0..CELLS {
            for i in 0..CELLS {
                let lambda = base * self.cell_weight[j * CELLS + i] * cell_km2;
                // Two draws per cell per frame keep the stream length fixed
                // whatever the rates, so changing a rate never shifts other
                // draws; the positions come from a generator seeded by the second.
                let u = rng.next_f64();
                let seed = rng.next_u64();
                let k = poisson_inverse(lambda, u);
                let (cx, cy) = self.cell_centre(i, j);
                let mut pos = SplitMix64::new(seed);
                for _ in 0..k {
                    let (ux, uy) = (pos.next_f64(), pos.next_f64());
                    out.push((cx + (ux - 0.5) * dx, cy + (uy - 0.5) * dy));
                }
            }
        }
        out
    }
}

/// The smallest k with P(K ≤ k) > u for K ~ Poisson(λ): 0 when u < e^−λ.
/// Capped at λ + 10√λ + 10 (a tail below 1e-20) so a rounding of the
/// cumulative sum can never loop on.
fn poisson_inverse(lambda: f64, u: f64) -> u64 {
    if !(lambda > 0.0) {
        return 0;
    }
    let cap = (lambda + 10.0 * lambda.sqrt() + 10.0) as u64;
    let mut term = (-lambda).exp();
    let mut cdf = term;
    let mut k = 0;
    while u >= cdf && k < cap {
        k += 1;
        term *= lambda / k as f64;
        cdf += term;
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_are_hotter_than_background() {
        let g = GroundMap::new(&GroundConfig::default());
        let p = &g.patches[0];
        let (h, _) = g.sample(p.x_m, p.y_m);
        assert!(h >= 0.3 && h > GroundConfig::default().background);
    }

    #[test]
    fn emission_count_follows_the_rate_and_the_map() {
        // Poisson process: over many frames the count must match
        // rate · Σ(weight · cell area) · time within 5 σ = 5 √E.
        let g = GroundMap::new(&GroundConfig::default());
        let e = EmissionConfig {
            diurnal: false,
            ..EmissionConfig::default()
        };
        let (dx, dy) = g.cell_size();
        let weight_km2: f64 = g.cell_weight.iter().sum::<f64>() * dx * dy * 1e-6;
        let (frames, dt) = (3000, 10.0);
        let expect = e.rate_per_km2_per_h * weight_km2 * frames as f64 * dt / 3600.0;
        let mut rng = SplitMix64::new(3);
        let mut n = 0usize;
        let mut hot = 0usize;
        for _ in 0..frames {
            for (x, y) in g.draw(&e, 0.0, dt, &mut rng) {
                n += 1;
                if g.sample(x, y).0 > 0.25 {
                    hot += 1;
                }
            }
        }
        assert!(
            (n as f64 - expect).abs() < 5.0 * expect.sqrt(),
            "{n} vs {expect}"
        );
        // Most parcels come from the patches although they cover a small
        // part of the ground (the background map value is 0.05).
        let hot_cells = (0..CELLS * CELLS)
            .filter(|k| {
                let (x, y) = g.cell_centre(k % CELLS, k / CELLS);
                g.sample(x, y).0 > 0.25
            })
            .count();
        let hot_area = hot_cells as f64 / (CELLS * CELLS) as f64;
        assert!(hot_area < 0.2, "{hot_area}");
        assert!(hot as f64 > 0.5 * n as f64, "{hot} of {n}");
    }

    #[test]
    fn long_frames_emit_as_many_parcels_as_short_ones() {
        // Poisson counts per cell: ten 600 s frames and 3000 frames of 2 s
        // must both match rate · Σ(weight · area) · time within 5 σ, even
        // where a hot cell expects more than one parcel per long frame (a
        // probability capped at 1 would emit too few there).
        let g = GroundMap::new(&GroundConfig::default());
        let e = EmissionConfig {
            diurnal: false,
            rate_per_km2_per_h: 3000.0,
            ..EmissionConfig::default()
        };
        let (dx, dy) = g.cell_size();
        let peak = g.cell_weight.iter().fold(0.0_f64, |a, &b| a.max(b));
        assert!(e.rate_per_km2_per_h / 3600.0 * 600.0 * peak * dx * dy * 1e-6 > 1.0);
        let weight_km2: f64 = g.cell_weight.iter().sum::<f64>() * dx * dy * 1e-6;
        let expect = e.rate_per_km2_per_h * weight_km2 * 6000.0 / 3600.0;
        for (frames, dt) in [(10, 600.0), (3000, 2.0)] {
            let mut rng = SplitMix64::new(5);
            let n: usize = (0..frames)
                .map(|_| g.draw(&e, 0.0, dt, &mut rng).len())
                .sum();
            assert!(
                (n as f64 - expect).abs() < 5.0 * expect.sqrt(),
                "{frames} frames of {dt} s: {n} vs {expect}"
            );
        }
    }

    #[test]
    fn no_sun_no_emission() {
        let e = EmissionConfig {
            start_hour: 0.0,
            ..EmissionConfig::default()
        };
        assert_eq!(GroundMap::sun(&e, 0.0), 0.0);
        assert!((GroundMap::sun(&e, 12.0 * 3600.0) - 1.0).abs() < 1e-12);
    }
}
