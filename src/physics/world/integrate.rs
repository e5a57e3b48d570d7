//! Stages 1 and 10: the kick–drift–kick sub-step, its stable length and
//! the order of the stages between drift and kick.

use std::time::Instant;

use rayon::prelude::*;

use super::PAR_MIN;

use super::{ClampCounts, ParcelWorld};
use crate::atmosphere::thermo;

impl ParcelWorld {
    /// Largest stable sub-step for a frame of `frame_dt_s`: CFL λh/v_max,
    /// 0.25·√(h/a_max), max_dt_s, and the SPH sound-speed limit λh/√K
    /// whenever two parcels interact or can come within h during the
    /// frame (so the first contact at a high K never takes a full step).
    pub(super) fn dt_limit(&self, frame_dt_s: f64) -> f64 {
        let c = &self.cfg.physics;
        let h = c.support_radius_m;
        // Maxima do not depend on the order: exact in parallel.
        let (vmax, amax) = self
            .parcels
            .par_iter()
            .with_min_len(PAR_MIN)
            .map(|p| (p.velocity_m_s.length(), p.accel_m_s2.length()))
            .reduce(|| (0.0_f64, 0.0_f64), |a, b| (a.0.max(b.0), a.1.max(b.1)));
        let mut dt = c.max_dt_s;
        if vmax > 0.0 {
            dt = dt.min(c.cfl * h / vmax);
        }
        if amax > 0.0 {
            dt = dt.min(0.25 * (h / amax).sqrt());
        }
        if c.sph && self.contact_possible(frame_dt_s, vmax, amax) {
            dt = dt.min(c.cfl * h / c.stiffness.sqrt());
        }
        dt
    }

    pub(super) fn substep(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let t0 = Instant::now();
        self.parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .for_each(|p| {
                p.velocity_m_s += p.accel_m_s2 * (0.5 * dt);
                p.position_m += p.velocity_m_s * dt;
            });
        self.counters.integrate += t0.elapsed();

        self.update(dt, clamps);

        let t0 = Instant::now();
        let vmax = self.cfg.physics.max_speed_m_s;
        clamps.speed += self
            .parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .map(|p| {
                p.velocity_m_s += p.accel_m_s2 * (0.5 * dt);
                p.age_s += dt;
                let s = p.velocity_m_s.length();
                if s > vmax {
                    p.velocity_m_s *= vmax / s;
                    1u64
                } else {
                    0
                }
            })
            .sum::<u64>();
        // Guard: a parcel with any non-finite state is removed and counted,
        // never left to poison its neighbours.
        let before = self.parcels.len();
        self.parcels.retain(|p| {
            p.position_m.is_finite()
                && p.velocity_m_s.is_finite()
                && p.accel_m_s2.is_finite()
                && p.theta_k.is_finite()
                && p.theta_l_k.is_finite()
                && p.qv_kg_per_kg.is_finite()
                && p.ql_kg_per_kg.is_finite()
                && p.dry_mass_kg.is_finite()
                && p.volume_m3.is_finite()
        });
        clamps.non_finite += (before - self.parcels.len()) as u64;
        self.counters.integrate += t0.elapsed();
    }

    /// Everything between the drift and the second kick; with `dt = 0` it
    /// only refreshes forces (new parcels, new environment).
    pub(super) fn update(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let t0 = Instant::now();
        let env = &self.env;
        self.parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .for_each(|p| {
                let z = p.position_m.z;
                let pr = env.pressure_pa(z);
                // T = θ Π (thermo::temperature_from_theta_k), Π kept for condensation.
                let ex = thermo::exner(pr);
                let t = env.theta_k(z) * ex;
                // Same expression as Environment::density_kg_m3, one pressure lookup fewer.
                p.env_at_centre = (pr, thermo::air_density_kg_m3(pr, t, env.qv(z)), ex);
            });
        self.build_neighbours();
        let t1 = Instant::now();
        self.counters.neighbours += t1 - t0;

        if self.cfg.physics.sph || self.cfg.physics.viscosity {
            self.sph_density();
        }
        let t2 = Instant::now();
        self.counters.sph += t2 - t1;

        if self.cfg.physics.needs_exposed_area() {
            self.exposed_area(clamps);
        }
        let t3 = Instant::now();
        self.counters.exposed_area += t3 - t2;

        if dt > 0.0 {
            if self.cfg.physics.mixing {
                self.mix_with_environment(dt, clamps);
            }
            if self.cfg.physics.exchange {
                self.exchange(dt, clamps);
            }
        }
        let t4 = Instant::now();
        self.counters.mixing += t4 - t3;

        self.update_volume(clamps);
        if self.cfg.physics.condensation {
            self.condense(clamps);
        }
        let t5 = Instant::now();
        self.counters.thermo += t5 - t4;

        self.forces(dt, clamps);
        self.counters.integrate += t5.elapsed();
    }
}
