//! A deterministic stand-in cloud field: a few cumulus towers, each a small
//! cluster of parcels sharing a condensation plane, for renders, tests and
//! the bench when no physics run is wanted. Radii are physical parcel radii
//! (the renderer enlarges them by `render.radius_scale`).

use glam::Vec3;

use crate::physics::CloudParcel;

fn rand(i: u32, salt: u32) -> f32 {
    let mut h = i.wrapping_mul(0x9e37_79b9) ^ salt.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h & 0xff_ffff) as f32 / 0xff_ffff as f32
}

/// `towers` cumulus towers scattered over a `domain_m`-wide domain with
/// their bases on a condensation plane at `base_m`; `growth` ∈ [0, 1] scales
/// how tall they have grown. Same arguments, same parcels.
pub fn cumulus_field(
    towers: u32,
    domain_m: f32,
    base_m: f32,
    growth: f32,
    seed: u32,
) -> Vec<CloudParcel> {
    let g = growth.clamp(0.0, 1.0);
    let mut out = Vec::new();
    for t in 0..towers {
        let s = seed.wrapping_mul(1000).wrapping_add(t);
        let cx = (rand(s, 1) - 0.5) * domain_m * 0.8;
        let cy = (rand(s, 2) - 0.5) * domain_m * 0.8;
        let size = 0.6 + 0.8 * rand(s, 3);
        let r0 = 150.0 * size;
        // Bottom ring of parcels just above the base, then a rising column.
        let layers = 1 + (3.0 * g * size) as u32;
        for l in 0..=layers {
            let count = if l == 0 { 3 } else { 2 };
            for k in 0..count {
                let i = l * 10 + k;
                let a = rand(s, 10 + i) * std::f32::consts::TAU;
                let spread = 2.5 * r0 * (0.9 - 0.15 * l as f32).max(0.3);
                let r = r0 * (1.0 - 0.12 * l as f32).max(0.45);
                let z = base_m + 2.5 * (r * 0.55 + l as f32 * r0 * 0.85);
                out.push(CloudParcel {
                    id: out.len() as u64,
                    center_m: Vec3::new(cx + a.cos() * spread, cy + a.sin() * spread, z),
                    radius_m: r,
                    fill: (0.75 + 0.25 * rand(s, 40 + i)) * (0.6 + 0.4 * g),
                    cond_plane_z_m: base_m,
                });
            }
        }
    }
    out
}

/// The default stand-in: seven towers over a 10 km domain, base at 1.2 km,
/// grown for `time_s` seconds (full height after 20 minutes).
pub fn default_field(time_s: f32) -> Vec<CloudParcel> {
    cumulus_field(7, 10_000.0, 1200.0, 0.35 + time_s / 1200.0, 42)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_is_deterministic_and_above_the_base() {
        let a = default_field(600.0);
        assert_eq!(a, default_field(600.0));
        assert!(a.len() >= 7 * 3);
        for p in &a {
            assert!(p.center_m.z > p.cond_plane_z_m);
            assert!(p.fill > 0.0 && p.fill <= 1.0);
            assert!(p.center_m.x.abs() < 5000.0 && p.center_m.y.abs() < 5000.0);
        }
    }
}
