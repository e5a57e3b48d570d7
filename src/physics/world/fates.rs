//! Births and deaths: emission from the ground at the start of a frame,
//! condensation planes, fill, deaths and escapes at its end.

use glam::DVec3;
use rayon::prelude::*;

use super::PAR_MIN;

use super::moisture::{condensation_plane_m, fill_ratio};
use super::{Fates, ParcelWorld};
use crate::physics::parcel::ParcelSpec;

impl ParcelWorld {
    /// The ground's emission for the frame of `frame_dt_s` that starts now,
    /// done ahead of [`step`](ParcelWorld::step) (which then does not emit
    /// again for that frame): lets a caller look at the world between the
    /// births and the dynamics (the stability harness measures the SPH
    /// energy the births bring). Returns the frame's births and suppressions.
    pub fn emit_now(&mut self, frame_dt_s: f64) -> Fates {
        let mut fates = Fates::default();
        if frame_dt_s.is_finite() && frame_dt_s > 0.0 && !self.emitted_ahead {
            self.emit(frame_dt_s, &mut fates);
            self.emitted_ahead = true;
            self.fates_ahead = fates;
        }
        fates
    }

    pub(super) fn emit(&mut self, dt_s: f64, fates: &mut Fates) {
        let e = &self.cfg.emission;
        if std::mem::take(&mut self.emitted_ahead) {
            // Done by emit_now for this frame: report its counts with the frame.
            fates.add(&std::mem::take(&mut self.fates_ahead));
            return;
        }
        if !e.enabled {
            return;
        }
        let draws = self.ground.draw(e, self.time_s, dt_s, &mut self.rng);
        for (x, y) in draws {
            if self.parcels.len() >= self.cfg.emission.max_parcels as usize {
                fates.suppressed += 1;
                continue;
            }
            let (dth, dq) = self.ground.excess(x, y);
            let spec = ParcelSpec::from_environment(
                &self.env,
                DVec3::new(x, y, self.ground.height_m(x, y)),
                dth,
                dq,
                self.cfg.emission.radius_m,
            );
            // The ranges are validated config values, so this cannot fail
            // short of a profile at its limits; count it as suppressed then.
            if self.spawn_parcel(spec).is_ok() {
                fates.emitted += 1;
            } else {
                fates.suppressed += 1;
            }
        }
    }

    /// End of frame: condensation planes, fill, deaths and escapes; returns
    /// how many parcels show a saturated fill (f = 1 with more liquid than
    /// the opaque content: a display count, not a clamp).
    pub(super) fn finish_frame(&mut self, fates: &mut Fates) -> u64 {
        let half = [
            0.5 * self.cfg.ground.size_m[0],
            0.5 * self.cfg.ground.size_m[1],
        ];
        let top = self.cfg.physics.domain_top_m.min(self.env.top_m());
        let z_max = self.env.top_m().max(self.cfg.physics.domain_top_m);
        let max_age = self.cfg.physics.max_age_s;
        let death_depth = self.cfg.physics.death_depth_m;
        let opaque = self.cfg.physics.opaque_lwc_kg_m3;
        let (env, deaths, ground) = (&self.env, self.deaths, &self.ground);
        let (counted, opaque_count) = self
            .parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .map(|p| {
                let mut f = Fates::default();
                let plane = condensation_plane_m(env, z_max, p);
                let (fill, saturated) = fill_ratio(p, opaque);
                p.cond_plane_z_m = plane;
                p.fill = fill;
                p.was_cloudy |= p.ql_kg_per_kg > 0.0;
                let x = p.position_m;
                let sinking = p.velocity_m_s.z < 0.0;
                if x.x.abs() > half[0] || x.y.abs() > half[1] {
                    f.escaped_sides += 1;
                } else if x.z > top {
                    f.escaped_top += 1;
                } else if !deaths {
                } else if x.z < ground.height_m(x.x, x.y) && sinking {
                    f.grounded += 1;
                } else if p.was_cloudy
                    && p.ql_kg_per_kg <= 0.0
                    && sinking
                    && x.z < plane - death_depth
                {
                    f.evaporated += 1;
                } else if p.age_s > max_age {
                    f.aged += 1;
                }
                p.alive = f == Fates::default();
                (f, saturated as u64)
            })
            .reduce(
                || (Fates::default(), 0),
                |(a, n), (b, m)| (Fates::sum(a, b), n + m),
            );
        fates.add(&counted);
        let before = self.parcels.len();
        self.parcels.retain(|p| p.alive);
        if self.parcels.len() != before {
            self.forces_stale = true;
        }
        opaque_count
    }
}
