//! Stage 8: accelerations (eq 17 per unit mass): SPH pressure and
//! viscosity, atmospheric pressure, buoyancy, drag, entrained momentum.
//! Gathered per parcel from the state after the thermodynamics.

use std::f64::consts::PI;

use glam::DVec3;
use rayon::prelude::*;

use super::PAR_MIN;

use super::{ClampCounts, ParcelWorld, wind_at};
use crate::atmosphere::thermo;
use crate::physics::parcel::Parcel;
use crate::physics::sph;

impl ParcelWorld {
    /// Accelerations at the new positions (eq 17 per unit mass).
    pub(super) fn forces(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let c = &self.cfg.physics;
        let h = c.support_radius_m;
        let (parcels, grid, env, cfg) = (&self.parcels, &self.grid, &self.env, &self.cfg);
        // What the neighbour loops read of each neighbour, as dense arrays:
        // the total mass (after this sub-step's mixing) and the SPH density
        // and pressure of the density stage.
        let mut mass = std::mem::take(&mut self.scratch.mass);
        parcels
            .par_iter()
            .with_min_len(PAR_MIN)
            .map(|p| p.total_mass_kg())
            .collect_into_vec(&mut mass);
        let sph_state = &self.scratch.density;
        // The predicted end-of-step velocities (computed after the drift).
        let vpred = std::mem::take(&mut self.scratch.vpred);
        // Guard: explicit viscosity relaxes v_i towards its neighbours at the
        // rate s_i = Σ_j μ m_j/(ρ_i ρ_j) ∇²W, and a pair's relative velocity
        // at up to s_i + s_j; past 1/dt a step overshoots and the velocities
        // blow up (viscosity_mu = 1e6 on a 100-parcel cluster reached the
        // speed cap 2452 times). Each pair's coefficient is scaled by
        // min(1, 1/(2 dt max(s_i, s_j))), symmetric so momentum is kept, and
        // the parcels that needed it are counted. A force refresh (dt = 0)
        // is scaled for max_dt_s.
        let visc_dt = if dt > 0.0 { dt } else { c.max_dt_s };
        let mut visc_rate = std::mem::take(&mut self.scratch.visc_rate);
        let viscous = c.viscosity && c.viscosity_mu > 0.0;
        (0..parcels.len())
            .into_par_iter()
            .with_min_len(PAR_MIN)
            .map(|i| {
                if !viscous {
                    return 0.0;
                }
                let rhoi = sph_state[i].0;
                grid.of(i)
                    .iter()
                    .map(|nb| {
                        c.viscosity_mu * mass[nb.j] / (rhoi * sph_state[nb.j].0)
                            * sph::viscosity_laplacian(nb.dist, h)
                    })
                    .sum()
            })
            .collect_into_vec(&mut visc_rate);
        if dt > 0.0 {
            clamps.viscosity += visc_rate
                .iter()
                .filter(|&&s| 2.0 * s * visc_dt > 1.0)
                .count() as u64;
        }
        let (vp, vr, pos) = (&vpred, &visc_rate, &self.hot_pos);
        // Of its neighbours a parcel reads only the dense arrays, so the
        // acceleration goes straight into its record (one pass).
        let accel = |i: usize, p: &Parcel| {
            let mi = mass[i];
            let mut a = DVec3::ZERO;
            if c.sph || c.viscosity {
                let (rhoi, pi) = sph_state[i];
                let mut fp = DVec3::ZERO;
                let mut fv = DVec3::ZERO;
                for nb in grid.of(i) {
                    if nb.dist >= h {
                        // A contact beyond the SPH support: no kernel force.
                        continue;
                    }
                    let (mj, (rhoj, pj)) = (mass[nb.j], sph_state[nb.j]);
                    if c.sph {
                        // eq 9 (mass-weighted, antisymmetric: momentum is conserved).
                        let s = pi / (rhoi * rhoi) + pj / (rhoj * rhoj);
                        let r = pos[i] - pos[nb.j];
                        fp -= sph::spiky_gradient(r, h) * (mi * mj * s);
                    }
                    if c.viscosity {
                        // eq 10 is a force density; divided by ρ_i below.
                        let rate = 2.0 * vr[i].max(vr[nb.j]) * visc_dt;
                        let scale = if rate > 1.0 { 1.0 / rate } else { 1.0 };
                        fv += (vp[nb.j] - vp[i])
                            * (scale * c.viscosity_mu * mj / rhoj
                                * sph::viscosity_laplacian(nb.dist, h));
                    }
                }
                a += fp / mi;
                if c.viscosity {
                    a += fv / rhoi;
                }
            }
            if c.atmospheric_pressure {
                a += p.atm_force_n / mi;
            }
            let z = p.position_m.z;
            if c.buoyancy {
                // eq 5 with θ_v of eq 4 (optionally with condensate loading).
                let ql = if c.condensate_loading {
                    p.ql_kg_per_kg
                } else {
                    0.0
                };
                let tv = thermo::virtual_potential_temperature_k(p.theta_k, p.qv_kg_per_kg, ql);
                let tv_env = env.theta_v_k(z);
                a.z += thermo::GRAVITY * (tv - tv_env) / tv_env;
            }
            let rel = vp[i] - wind_at(cfg, env, z);
            if c.drag {
                let area = PI * p.radius_m * p.radius_m;
                a -=
                    rel * (0.5 * c.drag_coefficient * p.env_at_centre.1 * rel.length() * area / mi);
            }
            if c.mixing {
                // Entrained air arrives with the wind's velocity.
                a -= rel * (p.entrain_rate_kg_s / mi);
            }
            a
        };
        self.parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .enumerate()
            .for_each(|(i, p)| p.accel_m_s2 = accel(i, p));
        self.scratch.vpred = vpred;
        self.scratch.visc_rate = visc_rate;
        self.scratch.mass = mass;
    }
}
