//! Helpers of the physics tests: environments, worlds, lattices and the
//! bit pattern of a world's state.

use cumulus::atmosphere::{Environment, PressureModel};
use cumulus::physics::{
    EmissionConfig, Parcel, ParcelSpec, ParcelWorld, PhysicsConfig, WorldConfig,
};
use glam::DVec3;

use super::level;

/// Dry, isentropic: every dry parcel of θ = 300 K is neutral at every height.
pub fn neutral() -> Environment {
    Environment::new(
        vec![level(0.0, 300.0, 0.0), level(10_000.0, 300.0, 0.0)],
        100_000.0,
        PressureModel::Hydrostatic,
    )
    .unwrap()
}

pub fn world(env: Environment, physics: PhysicsConfig, emission: bool, seed: u64) -> ParcelWorld {
    let cfg = WorldConfig {
        physics,
        emission: EmissionConfig {
            enabled: emission,
            ..EmissionConfig::default()
        },
        ..WorldConfig::default()
    };
    ParcelWorld::new(env, cfg, seed).unwrap()
}

/// A cubic lattice of n³ neutral dry parcels of radius `r` at `spacing`, centred at 2 km.
pub fn lattice(w: &mut ParcelWorld, n: usize, r: f64, spacing: f64) {
    let off = 0.5 * (n as f64 - 1.0) * spacing;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let pos = DVec3::new(
                    i as f64 * spacing - off,
                    j as f64 * spacing - off,
                    2000.0 + k as f64 * spacing - off,
                );
                let spec = ParcelSpec::from_environment(w.environment(), pos, 0.0, 0.0, r);
                w.spawn_parcel(spec).unwrap();
            }
        }
    }
}

pub fn centre_of_mass(ps: &[Parcel]) -> DVec3 {
    let m: f64 = ps.iter().map(|p| p.total_mass_kg()).sum();
    ps.iter()
        .map(|p| p.position_m * p.total_mass_kg())
        .sum::<DVec3>()
        / m
}

pub fn max_speed(ps: &[Parcel]) -> f64 {
    ps.iter()
        .map(|p| p.velocity_m_s.length())
        .fold(0.0, f64::max)
}

/// Every state bit of every parcel.
pub fn state_bits(w: &ParcelWorld) -> Vec<u64> {
    let mut out = Vec::new();
    for p in w.parcels() {
        for v in [p.position_m, p.velocity_m_s, p.accel_m_s2] {
            out.extend([v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]);
        }
        for v in [
            p.dry_mass_kg,
            p.qv_kg_per_kg,
            p.ql_kg_per_kg,
            p.theta_k,
            p.theta_l_k,
            p.volume_m3,
            p.radius_m,
            p.cond_plane_z_m,
            p.fill,
        ] {
            out.push(v.to_bits());
        }
    }
    out
}

/// The shipped profile `profiles/<name>` simulated to its start time as
/// `cumulus render` does (2 s frames, seed 1): the scene, its folder (for
/// `RenderConfig::resolve_paths`) and the cloud parcels at the start.
pub fn scene_at_start(
    name: &str,
) -> (
    cumulus::scene::SceneProfile,
    std::path::PathBuf,
    Vec<cumulus::physics::CloudParcel>,
) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("profiles")
        .join(name);
    let (scene, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
    let base = source.base_dir();
    let env = scene.atmosphere.build(&base).unwrap();
    let mut world = ParcelWorld::new(env, scene.world_config(&base).unwrap(), 1).unwrap();
    let start = scene.simulation.start_s;
    while world.time_s() < start - 1e-9 {
        world.step(2f64.min(start - world.time_s()));
    }
    let mut parcels = Vec::new();
    world.cloud_parcels(&mut parcels);
    (scene, base, parcels)
}

/// Holds `env` to a published initial profile every `step_m` from the
/// ground to `top_m`: `published(z)` gives θ (K) and the vapour mixing
/// ratio (kg/kg). Tolerances 0.02 K and 0.5 %: the scenes' points are
/// written to 4 decimals of a degree and the dewpoint's rounding moves
/// the mixing ratio by ~0.03 %, while a wrong level, corner or gradient
/// is off by tenths of a kelvin or more (benches/les/*_points.py).
pub fn assert_published_profile(
    env: &Environment,
    top_m: usize,
    step_m: usize,
    published: impl Fn(f64) -> (f64, f64),
) {
    for z in (0..=top_m).step_by(step_m) {
        let z = z as f64;
        let (theta, r) = published(z);
        assert!(
            (env.theta_k(z) - theta).abs() < 0.02,
            "θ at {z} m: {} vs {theta}",
            env.theta_k(z)
        );
        assert!(
            (env.qv(z) / r - 1.0).abs() < 5e-3,
            "mixing ratio at {z} m: {} vs {r}",
            env.qv(z)
        );
    }
}
