//! Temporary stand-ins for the parcel world and the GPU renderer, with the
//! method names of the real ones, so the window compiles and runs while those
//! land on main. Delete this file once `physics::ParcelWorld` and
//! `render::Renderer` are wired in.

use crate::atmosphere::Environment;
use crate::physics::CloudParcel;

/// Stand-in for `physics::ParcelWorld`: a fixed field of cloud parcels whose
/// bases sit at the environment's LCL and whose tops grow towards its EL.
pub struct World {
    env: Environment,
    time_s: f64,
    seeds: Vec<(f32, f32, f32)>,
}

/// What the panel shows of the world.
#[derive(Debug, Clone, Copy, Default)]
pub struct Diagnostics {
    pub time_s: f64,
    pub parcels: usize,
    pub condensed_parcels: usize,
}

impl World {
    pub fn new(env: Environment, seed: u64) -> crate::Result<Self> {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f32 / (1u64 << 53) as f32
        };
        let seeds = (0..14)
            .map(|_| (next() * 8000.0 - 4000.0, next() * 8000.0 - 4000.0, next()))
            .collect();
        Ok(Self {
            env,
            time_s: 0.0,
            seeds,
        })
    }

    pub fn step(&mut self, dt_s: f64) {
        self.time_s += dt_s;
    }

    pub fn set_environment(&mut self, env: Environment) {
        self.env = env;
    }

    pub fn environment(&self) -> &Environment {
        &self.env
    }

    pub fn cloud_parcels(&self, out: &mut Vec<CloudParcel>) {
        out.clear();
        let curve = super::profile_edit::parcel_curve(&self.env);
        let Some(base) = curve.lcl_m else { return };
        let top = curve.el_m.unwrap_or(base + 500.0).max(base + 100.0);
        let grow = (self.time_s / 300.0).min(1.0) as f32;
        for &(x, y, r) in &self.seeds {
            let depth = (top - base) as f32 * (0.3 + 0.7 * r) * grow;
            if depth < 20.0 {
                continue;
            }
            let radius = (depth * 0.5).clamp(100.0, 700.0);
            out.push(CloudParcel {
                center_m: glam::Vec3::new(x, y, base as f32 + depth * 0.5),
                radius_m: radius,
                fill: 0.8,
                cond_plane_z_m: base as f32,
            });
        }
    }

    pub fn diagnostics(&self) -> Diagnostics {
        let mut v = Vec::new();
        self.cloud_parcels(&mut v);
        Diagnostics {
            time_s: self.time_s,
            parcels: self.seeds.len(),
            condensed_parcels: v.len(),
        }
    }
}
