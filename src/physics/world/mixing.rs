//! Stage 5–6: entrainment and detrainment with the environment (eqs
//! 11–15) and exchange between touching parcels (§5.3).

use std::f64::consts::PI;

use rayon::prelude::*;

use super::PAR_MIN;

use super::{ClampCounts, MAX_DETRAIN_FRACTION, MIN_DRY_MASS_KG, ParcelWorld, wind_at};

impl ParcelWorld {
    /// Entrainment (eqs 11–14) and detrainment (eq 15) over one sub-step.
    pub(super) fn mix_with_environment(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let (c, env, cfg) = (&self.cfg.physics, &self.env, &self.cfg);
        let env_cl = self.env_condensation_level_m;
        let counted = self.parcels.par_iter_mut().with_min_len(PAR_MIN).map(|p| {
            let mut clamps = ClampCounts::default();
            // The air met during the sub-step, at its midpoint: the drift
            // went from z − v dt to z at the mid-step velocity v, so the
            // midpoint rule makes the entrained mass second order in dt.
            let z = p.position_m.z - 0.5 * dt * p.velocity_m_s.z;
            let rel = p.velocity_m_s - wind_at(cfg, env, z);
            // |v + δv_t| with δv_t of random direction: the magnitudes add in quadrature.
            let speed = (rel.length_squared() + c.turbulence_m_s * c.turbulence_m_s).sqrt();
            let r = p.radius_m;
            let area = p.exposed_area_m2;
            let m = p.total_mass_kg();
            // eq 11: ε' = ε r; swept environment air through the exposed area.
            let dma_e = c.entrainment_surface_factor
                * (c.entrainment_rate_per_m * r)
                * area
                * env.density_kg_m3(z)
                * speed
                * dt;
            // eq 11's ρ_atm is moist air; its dry part is what the mixing ratios count.
            let env_qv = env.qv(z);
            let dry_in = dma_e / (1.0 + env_qv);
            // eq 12 prints ω_s; we read it as a typo for the environment's own
            // mixing ratio: entrained air carries the vapour it has, and
            // entraining saturated vapour would moisten a parcel from dry air.
            let vap_in = env_qv * dry_in;
            let dme = dry_in + vap_in; // eq 13
            // eq 14: mass-weighted θ of the mixture.
            let env_theta = env.theta_k(z);
            p.theta_k = (m * p.theta_k + dme * env_theta) / (m + dme);
            // Environment air holds no liquid, so θ_l mixes exactly like θ.
            p.theta_l_k = (m * p.theta_l_k + dme * env_theta) / (m + dme);
            let mut vap = p.dry_mass_kg * p.qv_kg_per_kg + vap_in;
            let mut liq = p.dry_mass_kg * p.ql_kg_per_kg;
            let mut dry = p.dry_mass_kg + dry_in;
            p.entrain_rate_kg_s = dme / dt;

            // eq 15: detrainment from the condensation level up (paper §7.1:
            // "detrainment begins at condensation level while entrainment
            // occurs throughout"), at the parcel's own density, removing air
            // and water in proportion. The level is the lower of the parcel's
            // own plane and the scene's (surface environment air), so a
            // parcel that has dried out above the cloud base keeps leaking.
            if z >= p.cond_plane_z_m.min(env_cl) && c.detrainment_rate_per_m > 0.0 {
                let rho_p = m / p.volume_m3;
                let dm_d = c.detrainment_surface_factor
                    * (c.detrainment_rate_per_m * r)
                    * area
                    * rho_p
                    * speed
                    * dt;
                let mut frac = dm_d / (m + dme);
                if frac > MAX_DETRAIN_FRACTION {
                    frac = MAX_DETRAIN_FRACTION;
                    clamps.detrainment += 1;
                }
                dry *= 1.0 - frac;
                vap *= 1.0 - frac;
                liq *= 1.0 - frac;
            }
            if dry < MIN_DRY_MASS_KG {
                dry = MIN_DRY_MASS_KG;
                clamps.mass += 1;
            }
            p.dry_mass_kg = dry;
            p.qv_kg_per_kg = vap / dry;
            p.ql_kg_per_kg = liq / dry;
            clamps
        });
        clamps.add(&counted.reduce(ClampCounts::default, ClampCounts::sum));
    }
    /// Exchange between touching parcels (§5.3, eq 16 is a mass exchange):
    /// through the contact disk of area A, an air mass F = k_ex A ρ̄ dt
    /// crosses each way, carrying its vapour, liquid water and heat, so
    /// each of q_v, q_l, θ and θ_l relaxes by F (x_j − x_i)/m_i. Each pair's
    /// F is symmetric and computed from the state before the exchange, so
    /// Σ m x is conserved pair by pair for every quantity and the result
    /// does not depend on the pair order. F is bounded by half of
    /// min(m_i/n_i, m_j/n_j), n the parcel's number of contacts, so each
    /// parcel's new values are a convex mixture with at least half its own
    /// weight: nothing overshoots or goes negative (the bound is counted).
    pub(super) fn exchange(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let k = self.cfg.physics.exchange_velocity_m_s;
        let (parcels, grid) = (&self.parcels, &self.grid);
        let touching = |i: usize, n: &super::neighbours::Neighbour| {
            n.dist < parcels[i].radius_m + parcels[n.j].radius_m
        };
        let mut contacts = std::mem::take(&mut self.scratch.contacts);
        (0..parcels.len())
            .into_par_iter()
            .with_min_len(PAR_MIN)
            .map(|i| grid.of(i).iter().filter(|n| touching(i, n)).count() as u32)
            .collect_into_vec(&mut contacts);
        // Air mass exchanged by the pair (a, b), a < b, and whether it was bounded.
        let pair = |a: usize, b: usize, d: f64| -> (f64, bool) {
            let (pa, pb) = (&parcels[a], &parcels[b]);
            let area = contact_area_m2(pa.radius_m, pb.radius_m, d);
            let rho = 0.5 * (pa.total_mass_kg() / pa.volume_m3 + pb.total_mass_kg() / pb.volume_m3);
            let f = k * area * rho * dt;
            let cap = 0.5
                * (pa.dry_mass_kg / contacts[a] as f64).min(pb.dry_mass_kg / contacts[b] as f64);
            if f > cap { (cap, true) } else { (f, false) }
        };
        let mut out = std::mem::take(&mut self.scratch.exchange);
        (0..parcels.len())
            .into_par_iter()
            .with_min_len(PAR_MIN)
            .map(|i| {
                let pi = &parcels[i];
                let mut d = [0.0; 4];
                let mut capped = 0u64;
                for n in grid.of(i).iter().filter(|n| touching(i, n)) {
                    let (f, hit) = pair(i.min(n.j), i.max(n.j), n.dist);
                    capped += (hit && i < n.j) as u64;
                    let pj = &parcels[n.j];
                    let w = f / pi.dry_mass_kg;
                    d[0] += w * (pj.qv_kg_per_kg - pi.qv_kg_per_kg);
                    d[1] += w * (pj.ql_kg_per_kg - pi.ql_kg_per_kg);
                    d[2] += w * (pj.theta_k - pi.theta_k);
                    d[3] += w * (pj.theta_l_k - pi.theta_l_k);
                }
                (d, capped)
            })
            .collect_into_vec(&mut out);
        clamps.exchange += out.iter().map(|(_, c)| c).sum::<u64>();
        self.parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(&out)
            .for_each(|(p, (d, _))| {
                p.qv_kg_per_kg += d[0];
                p.ql_kg_per_kg += d[1];
                p.theta_k += d[2];
                p.theta_l_k += d[3];
            });
        self.scratch.contacts = contacts;
        self.scratch.exchange = out;
    }
}

/// Area of the contact disk of spheres of radii `ri`, `rj` whose centres
/// are `d` apart (they overlap: d < ri + rj); when one holds the other, the
/// smaller sphere's great disk. units: m → m²
pub(super) fn contact_area_m2(ri: f64, rj: f64, d: f64) -> f64 {
    let x = (d * d + ri * ri - rj * rj) / (2.0 * d.max(1e-9));
    let a2 = ri * ri - x * x;
    if a2 > 0.0 {
        PI * a2
    } else {
        PI * ri.min(rj).powi(2)
    }
}
