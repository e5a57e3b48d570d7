//! Bench scenes: parcel worlds built to hold an exact number of condensed
//! parcels in a deterministic cumulus-field layout (towers of stacked
//! parcels on a jittered lattice over the domain), and a dry cluster for the
//! physics time-step sweep.

use glam::DVec3;

use crate::atmosphere::{AtmosphereSpec, Environment, thermo};
use crate::error::{Error, Result};
use crate::physics::rng::SplitMix64;
use crate::physics::{CloudParcel, EmissionConfig, ParcelSpec, ParcelWorld, WorldConfig};

/// Parcels per tower (the last tower takes the remainder).
const PARCELS_PER_TOWER: usize = 10;
/// Physical parcel radius in the cloud field: that of emitted parcels
/// (the renderer draws spheres `render.radius_scale` times larger). units: m
const FIELD_RADIUS_M: f64 = 150.0;
/// Side of the square the towers stand in (inside the 10 km domain). units: m
const FIELD_SIDE_M: f64 = 8000.0;

/// The default (fair-weather) environment.
pub fn default_environment() -> Result<Environment> {
    AtmosphereSpec::default().build(std::path::Path::new("."))
}

/// World configuration of bench scenes: the defaults without ground
/// emission (emission draws would change the parcel count between frames).
pub fn world_config() -> WorldConfig {
    WorldConfig {
        emission: EmissionConfig {
            enabled: false,
            ..EmissionConfig::default()
        },
        ..WorldConfig::default()
    }
}

/// A world holding exactly `n` condensed parcels: ⌈n/10⌉ towers on a
/// jittered lattice, each a column of rings of up to three saturated,
/// cloudy parcels above the environment's condensation level. Fails if the
/// world does not report exactly `n` cloud parcels.
pub fn cloud_field(n: usize) -> Result<ParcelWorld> {
    let env = default_environment()?;
    let mut world = ParcelWorld::new(env, world_config(), 1)?;
    let base_m = world.environment_condensation_level_m() + 0.6 * FIELD_RADIUS_M;
    let towers = n.div_ceil(PARCELS_PER_TOWER).max(1);
    let side = (towers as f64).sqrt().ceil() as usize;
    let pitch = FIELD_SIDE_M / side as f64;
    let mut rng = SplitMix64::new(0xC0FFEE);
    let mut left = n;
    for t in 0..towers {
        let in_tower = left.div_ceil(towers - t);
        left -= in_tower;
        let cx =
            ((t % side) as f64 + 0.5) * pitch - 0.5 * FIELD_SIDE_M + rng.range(-0.25, 0.25) * pitch;
        let cy =
            ((t / side) as f64 + 0.5) * pitch - 0.5 * FIELD_SIDE_M + rng.range(-0.25, 0.25) * pitch;
        for k in 0..in_tower {
            let layer = k / 3;
            let a = rng.range(0.0, std::f64::consts::TAU);
            let spread = if k == 0 { 0.0 } else { 0.8 * FIELD_RADIUS_M };
            let pos = DVec3::new(
                cx + a.cos() * spread,
                cy + a.sin() * spread,
                base_m + layer as f64 * 1.2 * FIELD_RADIUS_M,
            );
            let radius = FIELD_RADIUS_M * rng.range(0.8, 1.1);
            let mut spec = ParcelSpec::from_environment(world.environment(), pos, 0.5, 0.0, radius);
            // Saturated air carrying liquid water: condensed at once, and it
            // stays condensed through a frame (no evaporation at saturation).
            let p_pa = world.environment().pressure_pa(pos.z);
            let t_k = thermo::temperature_from_theta_k(spec.theta_k, p_pa);
            spec.qv_kg_per_kg = thermo::saturation_mixing_ratio(t_k, p_pa);
            spec.ql_kg_per_kg = rng.range(4.0e-4, 1.0e-3);
            world.spawn_parcel(spec)?;
        }
    }
    let got = cloud_parcels(&world).len();
    if got != n {
        return Err(Error::invalid(
            "bench cloud-field condensed parcel count",
            got,
            format!("exactly {n} (the scene asked for)"),
        ));
    }
    Ok(world)
}

/// The world's condensed parcels, as the renderer gets them.
pub fn cloud_parcels(world: &ParcelWorld) -> Vec<CloudParcel> {
    let mut out = Vec::new();
    world.cloud_parcels(&mut out);
    out
}

/// A dry cluster of `n` warm, moist parcels released at 500 m: they rise,
/// condense and mix. Deterministic; used for the physics time-step sweep.
pub fn rising_cluster(n: usize, cfg: WorldConfig) -> Result<ParcelWorld> {
    let env = default_environment()?;
    let mut world = ParcelWorld::new(env, cfg, 1)?;
    // Follow every parcel to the end so that runs at different steps compare
    // the same parcels; escapes from the domain still apply.
    world.set_deaths(false);
    let mut rng = SplitMix64::new(7);
    for k in 0..n {
        let a = k as f64 / n as f64 * std::f64::consts::TAU;
        let ring = if k == 0 { 0.0 } else { 180.0 };
        let pos = DVec3::new(
            a.cos() * ring + rng.range(-20.0, 20.0),
            a.sin() * ring + rng.range(-20.0, 20.0),
            500.0 + 120.0 * (k % 3) as f64,
        );
        let spec = ParcelSpec::from_environment(world.environment(), pos, 1.5, 0.002, 150.0);
        world.spawn_parcel(spec)?;
    }
    Ok(world)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cloud_field_has_exact_counts_and_survives_a_frame() {
        for n in [8, 14, 34, 85] {
            let mut w = cloud_field(n).unwrap();
            assert_eq!(cloud_parcels(&w).len(), n);
            w.step(1.0);
            assert_eq!(cloud_parcels(&w).len(), n, "{n} parcels after a frame");
        }
    }
}
