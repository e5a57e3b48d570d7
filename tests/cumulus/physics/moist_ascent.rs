//! The dynamic parcel against parcel theory (issue 12, item 4): one parcel of
//! the sounding's surface air, released into the full `ParcelWorld` with
//! mixing off, follows the moist adiabat of the kinematic lifting
//! (atmosphere::lifting, itself within 0.35 K of MetPy 1.7.1 in
//! atmosphere::metpy) from the ground to its equilibrium level on
//! both shipped soundings.
//!
//! Both soundings are capped (LFC ≈ 2 km), so surface air at rest never
//! rises: the parcel starts with an upward kick and without drag. Drag only
//! decelerates the parcel (it touches neither θ nor water), but at the
//! default C_d = 0.5 and r = 150 m it stops a 20 m/s kick at 0.9–1.2 km,
//! short of either LFC, and the moist ascent would never be reached. (With
//! drag, a 60 m/s kick carries the 1999 parcel to the top of its sounding and
//! it matches the lifting within 0.003 K: drag is not a source of error.)

use std::path::Path;

use cumulus::atmosphere::lifting::{LiftOptions, lift_at};
use cumulus::atmosphere::{Environment, Sounding, thermo};
use cumulus::physics::{EmissionConfig, ParcelSpec, ParcelWorld, PhysicsConfig, WorldConfig};
use glam::DVec3;

/// Upward start velocity: enough kinetic energy (200 J/kg) to cross the
/// convective inhibition under either cap. units: m s⁻¹
const KICK_M_S: f64 = 20.0;

fn sounding(file: &str) -> Environment {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("profiles/soundings")
        .join(file);
    Sounding::load(&path).unwrap().to_environment().unwrap()
}

/// (height m, parcel T K) of the dynamic parcel from the ground to its first
/// apex (or the top of the sounding), one point per frame of `dt_s`.
fn dynamic_ascent(env: &Environment, dt_s: f64) -> Vec<(f64, f64)> {
    let mut cfg = WorldConfig {
        physics: PhysicsConfig {
            mixing: false,
            drag: false,
            max_dt_s: dt_s,
            domain_top_m: env.top_m() + 1000.0,
            ..PhysicsConfig::default()
        },
        emission: EmissionConfig {
            enabled: false,
            ..EmissionConfig::default()
        },
        ..WorldConfig::default()
    };
    cfg.ground.size_m = [1.0e6, 1.0e6];
    let mut world = ParcelWorld::new(env.clone(), cfg, 0).unwrap();
    world.set_deaths(false);
    let p0 = env.pressure_pa(0.0);
    world
        .spawn_parcel(ParcelSpec {
            position_m: DVec3::ZERO,
            velocity_m_s: DVec3::new(0.0, 0.0, KICK_M_S),
            theta_k: thermo::potential_temperature_k(env.temperature_k(0.0), p0),
            qv_kg_per_kg: env.qv(0.0),
            ql_kg_per_kg: 0.0,
            radius_m: 150.0,
        })
        .unwrap();
    let mut path = Vec::new();
    for _ in 0..20_000 {
        // A parcel still buoyant at the sounding's top leaves the domain there.
        let Some(p) = world.parcels().first() else {
            break;
        };
        let z = p.position_m.z;
        path.push((
            z,
            thermo::temperature_from_theta_k(p.theta_k, env.pressure_pa(z)),
        ));
        if (path.len() > 1 && p.velocity_m_s.z <= 0.0) || z >= env.top_m() {
            break;
        }
        world.step(dt_s);
    }
    path
}

fn check(file: &str, dt_s: f64) {
    let env = sounding(file);
    let opts = LiftOptions::default();
    // Up to the EL; the 1999 parcel is buoyant to the sounding's top.
    let theory = lift_at(&env, &opts, &[]).unwrap();
    let el_m = theory.el.map_or(env.top_m(), |el| el.z_m);
    let lcl_m = theory.lcl.expect("the surface parcel saturates").z_m;
    let path = dynamic_ascent(&env, dt_s);
    let apex_m = path.iter().map(|p| p.0).fold(f64::MIN, f64::max);
    // Within one frame of the EL (without drag the parcel reaches 73–80 m/s
    // here, so 100 m/s bounds a frame's climb; one still buoyant at the
    // sounding's top leaves it between two frames):
    // the comparison covers the whole moist ascent.
    assert!(
        apex_m >= el_m - 100.0 * dt_s,
        "{file}: the parcel stops at {apex_m:.0} m, below its EL {el_m:.0} m"
    );
    let mut below: Vec<(f64, f64)> = path.into_iter().filter(|p| p.0 <= el_m).collect();
    below.sort_by(|a, b| a.0.total_cmp(&b.0));
    let heights: Vec<f64> = below.iter().map(|p| p.0.max(0.0)).collect();
    let lifted = lift_at(&env, &opts, &heights).unwrap();
    assert_eq!(
        lifted.levels.len(),
        below.len(),
        "{file}: one level per point"
    );
    let (mut worst, mut at, mut latent) = (0.0_f64, 0.0, 0.0_f64);
    for (&(z, t), l) in below.iter().zip(&lifted.levels) {
        let d = t - l.t_k;
        if d.abs() > worst.abs() {
            (worst, at) = (d, z);
        }
        // The moist parcel's warming over the dry adiabat (θ conserved):
        // shows the comparison reaches well into the condensing ascent.
        let dry_t = thermo::temperature_from_theta_k(
            below[0].1 / thermo::exner(env.pressure_pa(below[0].0)),
            l.p_pa,
        );
        latent = latent.max(t - dry_t);
    }
    eprintln!(
        "{file} dt {dt_s} s: apex {apex_m:.0} m, LCL {lcl_m:.0} m, EL {el_m:.0} m, \
         worst ΔT {worst:+.4} K at {at:.0} m, latent warming {latent:.1} K"
    );
    // Latent heat must show: tens of K above the dry adiabat at the EL.
    assert!(
        latent > 20.0,
        "{file}: only {latent:.2} K of latent warming"
    );
    // Issue 12 asks for 0.5 K. Without mixing the only difference is where
    // condensation is booked: both apply the constant-pressure saturation
    // adjustment (ΔT = L/c_p Δq) at the end of each step, so θ gains the
    // latent heat of a whole step at the step's top Exner value. That bias
    // grows with the height climbed per step: the lifting's 10 m steps give
    // ≈ 0.003 K (atmosphere::lifting::MAX_STEP_M); the world's 1 s frames
    // (up to 80 m per frame) 0.015 K, its 5 s frames 0.047 K.
    // 0.1 K covers 5 s frames with a 2× margin and still fails on any lost
    // latent heat or water, or an Exner mismatch.
    assert!(
        worst.abs() < 0.1,
        "{file} dt {dt_s} s: dynamic parcel {worst:+.3} K off the moist adiabat at {at:.0} m"
    );
}

#[test]
fn dynamic_parcel_follows_the_moist_adiabat_on_oun_2011_05_22() {
    // 1 s frames and 5 s frames: the match must not hinge on the time step.
    check("oun-2011-05-22-12z.txt", 1.0);
    check("oun-2011-05-22-12z.txt", 5.0);
}

#[test]
fn dynamic_parcel_follows_the_moist_adiabat_on_oun_1999_05_04() {
    check("oun-1999-05-04-00z.txt", 1.0);
    check("oun-1999-05-04-00z.txt", 5.0);
}
