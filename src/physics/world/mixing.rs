//! Stage 6: entrainment and detrainment with the environment (eqs
//! 11–15) and exchange between touching parcels (§5.3), as rates.
//!
//! Second order (Heun, the trapezoidal rule with a forward-Euler predictor,
//! kept in step with the kick–drift–kick): the scalars these processes
//! change (dry mass, q_v, q_l, θ, θ_l) are advanced like the velocity. At
//! the start of a sub-step they take the whole step with the rates G_n of
//! the last evaluation (the predictor, in `integrate`); after the drift the
//! rates G_{n+1} are evaluated at the new positions, the predicted scalars
//! and the predicted velocity, and the scalars are corrected by
//! dt/2 (G_{n+1} − G_n): in all, s_{n+1} = s_n + dt/2 (G_n + G_{n+1}).
//! Like the leapfrog's force, G_{n+1} is kept for the next sub-step, so one
//! evaluation per sub-step suffices. Volume (eq 6), condensation and the
//! exposed area are functions of the state, evaluated after the scalars
//! they depend on, so they add no splitting error.

use std::f64::consts::PI;

use rayon::prelude::*;

use super::PAR_MIN;

use super::{ClampCounts, MAX_MIX_FRACTION, MIN_DRY_MASS_KG, ParcelWorld, wind_at};
use crate::physics::parcel::Parcel;

/// Rates of the mixing processes of one parcel: d/dt of dry mass (kg s⁻¹),
/// q_v and q_l (s⁻¹), θ and θ_l (K s⁻¹).
pub(crate) type MixRate = [f64; 5];

/// What the exchange reads of each parcel (56 bytes instead of the whole
/// record, so a neighbour costs one cache line).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct MixState {
    /// Radius. units: m
    radius_m: f64,
    /// Mean density m/V. units: kg m⁻³
    rho_kg_m3: f64,
    /// Dry-air mass. units: kg
    dry_mass_kg: f64,
    /// The exchanged scalars q_v, q_l, θ, θ_l. units: kg/kg, kg/kg, K, K
    scalars: [f64; 4],
}

/// Advances a parcel's mixed scalars by `rate × dt` (predictor and corrector).
///
/// The rates carry water between the parcel and its surroundings; how it
/// splits into vapour and liquid is the condensation's business (adjusted at
/// the end of the same sub-step). So where a liquid rate from an earlier
/// state would take more liquid than the parcel now holds (it evaporated
/// meanwhile), the rest comes from its vapour: the total water is exactly
/// what the rates say, and nothing is created by setting q_l to zero.
pub(super) fn advance_scalars(p: &mut Parcel, rate: &MixRate, dt: f64) {
    p.dry_mass_kg += rate[0] * dt;
    p.qv_kg_per_kg += rate[1] * dt;
    p.ql_kg_per_kg += rate[2] * dt;
    p.theta_k += rate[3] * dt;
    p.theta_l_k += rate[4] * dt;
    if p.ql_kg_per_kg < 0.0 {
        p.qv_kg_per_kg += p.ql_kg_per_kg;
        p.ql_kg_per_kg = 0.0;
    }
}

impl ParcelWorld {
    /// Rates of entrainment (eqs 11–14) and detrainment (eq 15), and the
    /// exchange between touching parcels, at the current state; with
    /// `dt > 0` the scalars are corrected by dt/2 (G_new − G_old) and G_new
    /// kept. `dt` also bounds the rates (the counted clamps below are
    /// per-sub-step limits); a force refresh (`dt = 0`) bounds them for max_dt_s.
    pub(super) fn mix(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let c = &self.cfg.physics;
        let cap_dt = if dt > 0.0 { dt } else { c.max_dt_s };
        let mut rates = std::mem::take(&mut self.scratch.rates);
        rates.clear();
        rates.resize(self.parcels.len(), ([0.0; 5], 0.0));
        if c.mixing {
            self.environment_rates(cap_dt, &mut rates, clamps);
        }
        if c.exchange {
            self.exchange_rates(cap_dt, &mut rates, clamps);
        }
        let counted = self
            .parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(&rates)
            .map(|(p, (g, e))| {
                let mut n = 0;
                if dt > 0.0 {
                    let diff: MixRate = std::array::from_fn(|k| g[k] - p.mix_rate[k]);
                    advance_scalars(p, &diff, 0.5 * dt);
                    if p.dry_mass_kg < MIN_DRY_MASS_KG {
                        p.dry_mass_kg = MIN_DRY_MASS_KG;
                        n = 1;
                    }
                }
                p.mix_rate = *g;
                p.entrain_rate_kg_s = *e;
                n
            })
            .sum::<u64>();
        clamps.mass += counted;
        self.scratch.rates = rates;
    }

    /// Entrainment (eqs 11–14) and detrainment (eq 15) rates, added to `out`
    /// (with the entrained mass rate for the momentum dilution).
    fn environment_rates(&self, cap_dt: f64, out: &mut [(MixRate, f64)], clamps: &mut ClampCounts) {
        let (c, env, cfg) = (&self.cfg.physics, &self.env, &self.cfg);
        let env_cl = self.env_condensation_level_m;
        let vpred = &self.scratch.vpred;
        let counted = out
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .enumerate()
            .map(|(i, (g, e))| {
                let p = &self.parcels[i];
                let z = p.position_m.z;
                // The predicted velocity at the parcel's time level (the
                // same as drag sees): with the trapezoidal rule the
                // environment is taken at the end of the sub-step, where
                // its density is already known (env_at_centre).
                let rel = vpred[i] - wind_at(cfg, env, z);
                // |v + δv_t| with δv_t of random direction: the magnitudes add in quadrature.
                let speed = (rel.length_squared() + c.turbulence_m_s * c.turbulence_m_s).sqrt();
                let (r, area, m, md) = (
                    p.radius_m,
                    p.exposed_area_m2,
                    p.total_mass_kg(),
                    p.dry_mass_kg,
                );
                // eq 11: ε' (= ε r in the paper; `EntrainmentModel`); swept
                // environment air through the exposed area.
                let mut ent = c.entrainment_surface_factor
                    * c.entrainment_coefficient(r)
                    * area
                    * p.env_at_centre.1
                    * speed;
                // At most half the parcel's mass in one sub-step (counted):
                // the explicit step then mixes parcel and environment
                // convexly, never overshooting the environment's θ or q.
                let mut capped_ent = 0;
                if ent / m * cap_dt > MAX_MIX_FRACTION {
                    ent = MAX_MIX_FRACTION * m / cap_dt;
                    capped_ent = 1;
                }
                // eq 11's ρ_atm is moist air; its dry part is what the mixing ratios count.
                let env_qv = env.qv(z);
                let dry_in = ent / (1.0 + env_qv);
                // eq 12 prints ω_s; we read it as a typo for the environment's own
                // mixing ratio: entrained air carries the vapour it has, and
                // entraining saturated vapour would moisten a parcel from dry air.
                // eq 13: the entrained mass is dry_in (1 + q_env) = ent.
                // eq 14: θ mixes by mass: dθ/dt = ṁ_e (θ_env − θ)/m;
                // environment air holds no liquid, so θ_l mixes like θ.
                let env_theta = env.theta_k(z);
                g[3] += ent / m * (env_theta - p.theta_k);
                g[4] += ent / m * (env_theta - p.theta_l_k);
                // Vapour: d(m_d q_v)/dt = q_env ṁ_d,in, so dq_v/dt = ṁ_d,in (q_env − q_v)/m_d.
                g[1] += dry_in * (env_qv - p.qv_kg_per_kg) / md;
                g[2] -= dry_in * p.ql_kg_per_kg / md;
                g[0] += dry_in;
                *e = ent;

                // eq 15: detrainment from the condensation level up (paper §7.1:
                // "detrainment begins at condensation level while entrainment
                // occurs throughout"), at the parcel's own density, removing air
                // and water in proportion (so the mixing ratios stay). The level
                // is the lower of the parcel's own plane and the scene's
                // (surface environment air), so a parcel that has dried out
                // above the cloud base keeps leaking.
                let mut capped = 0;
                if z >= p.cond_plane_z_m.min(env_cl) && c.detrainment_rate_per_m > 0.0 {
                    let rho_p = m / p.volume_m3;
                    let det = c.detrainment_surface_factor
                        * (c.detrainment_rate_per_m * r)
                        * area
                        * rho_p
                        * speed;
                    let mut frac = det / m;
                    if frac * cap_dt > MAX_MIX_FRACTION {
                        frac = MAX_MIX_FRACTION / cap_dt;
                        capped = 1;
                    }
                    g[0] -= frac * md;
                }
                (capped_ent, capped)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        clamps.entrainment += counted.0;
        clamps.detrainment += counted.1;
    }

    /// Exchange between touching parcels (§5.3, eq 16 is a mass exchange):
    /// through the contact disk of area A, an air mass flux F = k_ex A ρ̄
    /// crosses each way, carrying its vapour, liquid water and heat, so
    /// each of q_v, q_l, θ and θ_l relaxes at the rate F (x_j − x_i)/m_i.
    /// Each pair's F is symmetric and computed from the state before the
    /// exchange, so Σ m x is conserved pair by pair for every quantity and
    /// the result does not depend on the pair order. F dt is bounded by
    /// half of min(m_i/n_i, m_j/n_j), n the parcel's number of contacts, so
    /// each rate × dt is a convex mixture with at least half the parcel's
    /// own weight: nothing overshoots or goes negative (the bound is counted).
    fn exchange_rates(
        &mut self,
        cap_dt: f64,
        out: &mut [(MixRate, f64)],
        clamps: &mut ClampCounts,
    ) {
        let k = self.cfg.physics.exchange_velocity_m_s;
        let grid = &self.grid;
        let mut state = std::mem::take(&mut self.scratch.mix_state);
        self.parcels
            .par_iter()
            .with_min_len(PAR_MIN)
            .map(|p| MixState {
                radius_m: p.radius_m,
                rho_kg_m3: p.total_mass_kg() / p.volume_m3,
                dry_mass_kg: p.dry_mass_kg,
                scalars: [p.qv_kg_per_kg, p.ql_kg_per_kg, p.theta_k, p.theta_l_k],
            })
            .collect_into_vec(&mut state);
        let parcels = &state;
        let touching = |i: usize, n: &super::neighbours::Neighbour| {
            n.dist < parcels[i].radius_m + parcels[n.j].radius_m
        };
        let mut contacts = std::mem::take(&mut self.scratch.contacts);
        (0..parcels.len())
            .into_par_iter()
            .with_min_len(PAR_MIN)
            .map(|i| grid.of(i).iter().filter(|n| touching(i, n)).count() as u32)
            .collect_into_vec(&mut contacts);
        // Air mass flux exchanged by the pair (a, b), a < b, and whether it was bounded.
        let pair = |a: usize, b: usize, d: f64| -> (f64, bool) {
            let (pa, pb) = (&parcels[a], &parcels[b]);
            let area = contact_area_m2(pa.radius_m, pb.radius_m, d);
            let rho = 0.5 * (pa.rho_kg_m3 + pb.rho_kg_m3);
            let f = k * area * rho;
            let cap = 0.5
                * (pa.dry_mass_kg / contacts[a] as f64).min(pb.dry_mass_kg / contacts[b] as f64)
                / cap_dt;
            if f > cap { (cap, true) } else { (f, false) }
        };
        let counted = out
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .enumerate()
            .map(|(i, (g, _))| {
                let pi = &parcels[i];
                let mut capped = 0u64;
                for n in grid.of(i).iter().filter(|n| touching(i, n)) {
                    let (f, hit) = pair(i.min(n.j), i.max(n.j), n.dist);
                    capped += (hit && i < n.j) as u64;
                    let pj = &parcels[n.j];
                    let w = f / pi.dry_mass_kg;
                    for s in 0..4 {
                        g[s + 1] += w * (pj.scalars[s] - pi.scalars[s]);
                    }
                }
                capped
            })
            .sum::<u64>();
        clamps.exchange += counted;
        self.scratch.contacts = contacts;
        self.scratch.mix_state = state;
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
