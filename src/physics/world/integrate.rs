//! Stages 1 and 9: the kick–drift–kick sub-step, its stable length and
//! the order of the stages between drift and kick.

use std::time::Instant;

use rayon::prelude::*;

use super::PAR_MIN;

use glam::DVec3;

use super::mixing::advance_scalars;
use super::moisture::{condense, update_volume};
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
                // The mixed scalars' predictor: the whole step at the last
                // rates (corrected after the drift, in `mix`).
                let g = p.mix_rate;
                advance_scalars(p, &g, dt);
            });
        self.counters.integrate += t0.elapsed();

        self.update(dt, clamps);

        let t0 = Instant::now();
        let vmax = if self.speed_cap {
            self.cfg.physics.max_speed_m_s
        } else {
            f64::INFINITY
        };
        // The second kick, the speed guard, and whether any state became
        // non-finite (one pass; the removal below only runs when needed).
        let (speed, bad) = self
            .parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .map(|p| {
                p.velocity_m_s += p.accel_m_s2 * (0.5 * dt);
                p.age_s += dt;
                let s = p.velocity_m_s.length();
                let capped = if s > vmax {
                    p.velocity_m_s *= vmax / s;
                    1u64
                } else {
                    0
                };
                (capped, !finite(p) as u64)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        clamps.speed += speed;
        // Guard: a parcel with any non-finite state is removed and counted,
        // never left to poison its neighbours.
        if bad > 0 {
            self.parcels.retain(finite);
            clamps.non_finite += bad;
        }
        self.counters.integrate += t0.elapsed();
    }

    /// Everything between the drift and the second kick; with `dt = 0` it
    /// only refreshes forces and rates (new parcels, new environment).
    pub(super) fn update(&mut self, dt: f64, clamps: &mut ClampCounts) {
        let t0 = Instant::now();
        let (env, c) = (&self.env, &self.cfg.physics);
        // One pass over the parcels (each pass streams every parcel's record
        // through memory): the environment at the new centre; the predicted
        // end-of-step velocity v + a_old dt/2 that the velocity-dependent
        // terms (drag, viscosity, entrainment) see; volume and radius at the
        // new pressure and predicted mass (eq 6), so that the contacts and
        // the exposed area belong to this time level.
        let mut vpred = std::mem::take(&mut self.scratch.vpred);
        vpred.resize(self.parcels.len(), DVec3::ZERO);
        let counted = self
            .parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(vpred.par_iter_mut())
            .map(|(p, vp)| {
                let z = p.position_m.z;
                // T = θ Π (thermo::temperature_from_theta_k), Π kept for condensation.
                let (pr, ex) = env.pressure_exner(z);
                let t = env.theta_k(z) * ex;
                // Same expression as Environment::density_kg_m3, one pressure lookup fewer.
                p.env_at_centre = (pr, thermo::air_density_kg_m3(pr, t, env.qv(z)), ex);
                *vp = p.velocity_m_s + p.accel_m_s2 * (0.5 * dt);
                update_volume(p, c)
            })
            .reduce(ClampCounts::default, ClampCounts::sum);
        clamps.add(&counted);
        self.scratch.vpred = vpred;
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

        if self.cfg.physics.mixing || self.cfg.physics.exchange {
            self.mix(dt, clamps);
        }
        let t4 = Instant::now();
        self.counters.mixing += t4 - t3;

        // The corrector changed the masses (not the pressure): eq 6 again,
        // then condensation, in one pass.
        let (c, alpha) = (&self.cfg.physics, self.cfg.physics.latent_heat_alpha);
        let counted = self
            .parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .map(|p| {
                let mut n = update_volume(p, c);
                if c.condensation {
                    n.add(&condense(p, alpha));
                }
                n
            })
            .reduce(ClampCounts::default, ClampCounts::sum);
        clamps.add(&counted);
        let t5 = Instant::now();
        self.counters.thermo += t5 - t4;

        self.forces(dt, clamps);
        self.counters.integrate += t5.elapsed();
    }
}

/// Whether every state value the physics integrates is a finite number.
fn finite(p: &crate::physics::Parcel) -> bool {
    p.position_m.is_finite()
        && p.velocity_m_s.is_finite()
        && p.accel_m_s2.is_finite()
        && p.theta_k.is_finite()
        && p.theta_l_k.is_finite()
        && p.qv_kg_per_kg.is_finite()
        && p.ql_kg_per_kg.is_finite()
        && p.dry_mass_kg.is_finite()
        && p.volume_m3.is_finite()
}
