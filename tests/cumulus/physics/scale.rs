//! Scale: the parallel physics gives bit-identical states at any thread
//! count, and the neighbour grid finds every pair a brute-force search finds.

use cumulus::physics::{ParcelSpec, PhysicsConfig};
use glam::DVec3;

use crate::common;
use crate::common::fair_weather;
use crate::common::physics::{state_bits, world};

/// The fair-weather scene with emission, plus a dense overlapping cluster
/// (so that every gather stage has real work), stepped `frames` frames on a
/// pool of `threads` threads.
fn run_on(threads: usize, frames: usize) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = world(fair_weather(), PhysicsConfig::default(), true, 11);
        // 600 parcels: more than two blocks of the neighbour lists (256 each).
        for i in 0..600 {
            let (a, b, c) = (i % 10, (i / 10) % 10, i / 100);
            let pos = DVec3::new(
                a as f64 * 170.0 - 800.0,
                b as f64 * 170.0 - 800.0,
                300.0 + c as f64 * 170.0,
            );
            let spec = ParcelSpec::from_environment(
                w.environment(),
                pos,
                0.2 * (i % 7) as f64,
                1e-4 * (i % 5) as f64,
                100.0,
            );
            w.spawn_parcel(spec).unwrap();
        }
        for _ in 0..frames {
            w.step(2.0);
        }
        assert!(w.parcels().len() > 500);
        state_bits(&w)
    })
}

#[test]
fn one_and_two_threads_give_bit_identical_states() {
    let one = run_on(1, 20);
    let two = run_on(2, 20);
    let four = run_on(4, 20);
    assert_eq!(one.len(), two.len());
    assert!(one == two, "1 and 2 threads differ");
    assert!(one == four, "1 and 4 threads differ");
}

#[test]
fn contacts_beyond_the_support_radius_are_seen() {
    // Two spheres of r = 200 m, 350 m apart: farther than h = 300 m, yet
    // they overlap by 50 m. Each must hide part of the other's surface and
    // exchange vapour; the SPH kernels (zero beyond h) must add nothing.
    // Mixing on so that the exposed area is computed (the environment is
    // dry, so only the exchange can moisten the dry parcel).
    let physics = PhysicsConfig {
        atmospheric_pressure: false,
        condensation: false,
        ..PhysicsConfig::default()
    };
    let env = common::physics::neutral();
    let mut w = world(env, physics, false, 1);
    for (x, dq) in [(-175.0, 2e-3), (175.0, 0.0)] {
        let mut spec = ParcelSpec::from_environment(
            w.environment(),
            DVec3::new(x, 0.0, 2000.0),
            0.0,
            dq,
            200.0,
        );
        spec.velocity_m_s = DVec3::ZERO;
        w.spawn_parcel(spec).unwrap();
    }
    let q0 = w.parcels()[0].qv_kg_per_kg;
    w.step(1.0);
    let p = w.parcels();
    let full = 4.0 * std::f64::consts::PI * p[0].radius_m * p[0].radius_m;
    // The hidden cap of a 50 m lens on a 200 m sphere is 2π r (r − x) with
    // x = 175 m: 1/16 of the sphere; the 18 × 9 quads see at least a few %.
    assert!(
        p[0].exposed_area_m2 < 0.99 * full,
        "{} of {full}",
        p[0].exposed_area_m2
    );
    assert!(p[0].qv_kg_per_kg < q0, "the moist parcel must give vapour");
    assert!(
        p[1].qv_kg_per_kg > 0.0,
        "the dry parcel must receive vapour"
    );
    // No SPH force beyond h: a neutral, dry pair at rest stays at rest.
    assert_eq!(p[0].velocity_m_s.x, 0.0);
}

#[test]
fn the_bench_physics_speed_table_measures_one_sub_step() {
    use cumulus::bench::physics_speed::{physics_speed, physics_speed_csv, physics_speed_md};
    let rows = physics_speed(&[256], 2, |_| {}).unwrap();
    assert_eq!(rows.len(), 1);
    let r = &rows[0];
    assert_eq!(r.parcels, 256);
    assert!(r.threads >= 1 && r.substep_ms > 0.0 && r.substep_ms.is_finite());
    assert_eq!(r.goal_ms, None, "goals are set at 10 000 and 100 000 only");
    let md = physics_speed_md(&rows);
    assert!(md.contains("| 256 |"), "{md}");
    let csv = String::from_utf8(physics_speed_csv(&rows)).unwrap();
    assert_eq!(csv.lines().count(), 2);
    assert!(
        csv.starts_with("parcels,threads,substep_ms,goal_ms\n"),
        "{csv}"
    );
}
