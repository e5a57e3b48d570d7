//! The landscape scene (profiles/landscape.toml) and the terrain-following
//! ground: parcels leave the terrain at its height, sink back into it, the
//! heat/humidity maps follow the relief, and the physics' ground is the one
//! the renderer draws (one height function, src/landscape/mod.rs).

use std::path::Path;

use cumulus::physics::ground::GroundMap;
use cumulus::physics::{GroundConfig, ParcelSpec, ParcelWorld, WorldConfig};
use cumulus::scene::SceneProfile;
use glam::DVec3;

use crate::common::cli;

fn landscape() -> (SceneProfile, WorldConfig, cumulus::atmosphere::Environment) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/landscape.toml");
    let scene = SceneProfile::load(&path).unwrap();
    let dir = path.parent().unwrap();
    let cfg = scene.world_config(dir).unwrap();
    let env = scene.atmosphere.build(dir).unwrap();
    (scene, cfg, env)
}

/// (x, y) on an `n`×`n` grid over the domain (cell centres). units: m
fn grid(size_m: [f64; 2], n: usize) -> impl Iterator<Item = (f64, f64)> {
    (0..n * n).map(move |k| {
        let (i, j) = ((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
        (
            size_m[0] * (i / n as f64 - 0.5),
            size_m[1] * (j / n as f64 - 0.5),
        )
    })
}

#[test]
fn the_landscape_is_large_with_real_relief() {
    let (scene, cfg, _) = landscape();
    assert!(scene.ground.size_m[0] >= 40_000.0 && scene.ground.size_m[1] >= 40_000.0);
    assert!(cfg.ground.follow_terrain && !cfg.ground.terrain.is_flat());
    // The slopes are heated by the scene's own sun at solar noon: 47.4° N on
    // 10 July (declination 22.2°) puts it due south, 64.8° high.
    let [sx, sy, sz] = cfg.ground.midday_sun;
    assert!(sx.abs() < 0.01 && sy < 0.0, "{:?}", cfg.ground.midday_sun);
    assert!((sz.asin().to_degrees() - 64.8).abs() < 0.5, "{sz}");
    let w = ParcelWorld::new(landscape().2, cfg.clone(), 1).unwrap();
    let heights: Vec<f64> = grid(cfg.ground.size_m, 64)
        .map(|(x, y)| w.ground().height_m(x, y))
        .collect();
    let lo = heights.iter().cloned().fold(f64::MAX, f64::min);
    let hi = heights.iter().cloned().fold(f64::MIN, f64::max);
    // Hills and valleys: several hundred metres between the valley floors
    // and the hill tops inside the domain (the terrain's scale is 700 m).
    assert!(hi - lo > 300.0, "relief {lo:.0}–{hi:.0} m");
}

#[test]
fn parcels_leave_the_terrain_at_its_height() {
    let (_, cfg, env) = landscape();
    let mut w = ParcelWorld::new(env, cfg, 1).unwrap();
    let mut checked = 0;
    let mut highest = 0.0f64;
    for _ in 0..40 {
        w.step(0.5);
        for p in w.parcels() {
            // Emitted at the start of this 0.5-s frame: it has moved less
            // than a metre since (buoyancy of a 2-K excess is ~0.07 m/s²).
            if p.age_s <= 0.5 + 1e-9 {
                let ground = w.ground().height_m(p.position_m.x, p.position_m.y);
                assert!(
                    (p.position_m.z - ground).abs() < 1.0,
                    "parcel at {:?}, ground {ground:.1} m",
                    p.position_m
                );
                highest = highest.max(ground);
                checked += 1;
            }
        }
    }
    assert!(checked >= 20, "only {checked} new parcels");
    assert!(
        highest > 100.0,
        "all parcels left low ground ({highest:.0} m)"
    );
}

#[test]
fn grounded_means_below_the_terrain() {
    let (_, mut cfg, env) = landscape();
    cfg.emission.enabled = false;
    // A hill top inside the domain.
    let w0 = ParcelWorld::new(env.clone(), cfg.clone(), 1).unwrap();
    let (x, y) = grid(cfg.ground.size_m, 64)
        .max_by(|a, b| {
            w0.ground()
                .height_m(a.0, a.1)
                .total_cmp(&w0.ground().height_m(b.0, b.1))
        })
        .unwrap();
    let ground = w0.ground().height_m(x, y);
    assert!(ground > 300.0, "{ground}");
    let sinking_into_the_hill = |cfg: WorldConfig| {
        let mut w = ParcelWorld::new(env.clone(), cfg, 1).unwrap();
        let mut spec =
            ParcelSpec::from_environment(&env, DVec3::new(x, y, ground - 50.0), 0.0, 0.0, 150.0);
        spec.velocity_m_s = DVec3::new(0.0, 0.0, -1.0);
        w.spawn_parcel(spec).unwrap();
        w.step(0.5).fates.grounded
    };
    assert_eq!(sinking_into_the_hill(cfg.clone()), 1);
    // The same parcel over flat ground (z = 0) is still in the air.
    cfg.ground.follow_terrain = false;
    cfg.ground.terrain = Default::default();
    assert_eq!(sinking_into_the_hill(cfg), 0);
}

#[test]
fn heat_and_humidity_follow_the_relief() {
    let (_, cfg, env) = landscape();
    let w = ParcelWorld::new(env, cfg.clone(), 1).unwrap();
    let g = w.ground();
    // The same warm fields on flat ground: what the relief changes.
    let flat = GroundMap::new(&GroundConfig {
        follow_terrain: false,
        terrain: Default::default(),
        ..cfg.ground.clone()
    });
    let t = &cfg.ground.terrain;
    let scale = t.height_scale_m() as f64;
    let (mut sunny, mut shaded) = ((0.0, 0), (0.0, 0));
    let (mut low, mut high) = ((0.0, 0), (0.0, 0));
    let add = |s: &mut (f64, i32), v: f64| {
        s.0 += v;
        s.1 += 1;
    };
    for (x, y) in grid(cfg.ground.size_m, 400) {
        let (heat, humidity) = g.sample(x, y);
        let (field_heat, _) = flat.sample(x, y);
        let rel = g.height_m(x, y) / scale;
        let n = t.normal(x as f32, y as f32, 100.0);
        // Inside a warm field, on slopes of the same height band, facing
        // the midday sun (south, −y) or away from it.
        if field_heat > 0.2 && (0.3..0.5).contains(&rel) {
            if n.y < -0.08 {
                add(&mut sunny, heat / field_heat);
            } else if n.y > 0.08 {
                add(&mut shaded, heat / field_heat);
            }
        }
        if rel < 0.15 {
            add(&mut low, humidity);
        } else if rel > 0.4 {
            add(&mut high, humidity);
        }
    }
    let mean = |s: (f64, i32)| {
        assert!(s.1 > 100, "too few samples: {}", s.1);
        s.0 / s.1 as f64
    };
    // Cosine law: a slope β turned toward or away from a sun at elevation e
    // gets cos β ± sin β cot e of the flat ground's sunshine; at the cut's
    // gentlest slope (|n.y| = 0.08, β = 4.6°) under this scene's 64.8° noon
    // sun that is 1.035 against 0.959, a contrast of 1.079. Steeper slopes
    // only add to it, so the sunny fields must be ≥ 7% warmer.
    assert!(mean(sunny) > 1.07 * mean(shaded), "{sunny:?} vs {shaded:?}");
    // Valley floors are moist, hill tops are not (twice as humid at least).
    assert!(mean(low) > 2.0 * mean(high), "{low:?} vs {high:?}");
}

#[test]
fn the_physics_ground_is_the_drawn_terrain() {
    let (scene, cfg, env) = landscape();
    let w = ParcelWorld::new(env, cfg, 1).unwrap();
    let mut terrain = scene.render.terrain.clone();
    terrain.resolution = 33;
    let mesh = cumulus::landscape::terrain::build_mesh(&terrain).unwrap();
    let water = terrain.water_level_m;
    let mut ground_vertices = 0;
    for v in mesh.vertices {
        let [x, y, z] = v.position;
        if v.normal == cumulus::landscape::terrain::WATER_NORMAL {
            // The lake's plane (drawn only; the physics has no water).
            assert_eq!(Some(z as f64), water.map(f64::from));
            continue;
        }
        ground_vertices += 1;
        // The same f32 function: equal up to the f64 → f32 round trip.
        assert!((w.ground().height_m(x as f64, y as f64) - z as f64).abs() < 1e-3);
    }
    assert!(ground_vertices >= 33 * 33, "{ground_vertices}");
}

#[test]
fn two_simulated_hours_of_the_landscape_reach_two_thousand_cloud_parcels() {
    // The issue's own command, as a user types it (no --out: the summary
    // only). About 21 s on 2 cores in release.
    let err =
        cli::run(["simulate", "profiles/landscape.toml", "--duration", "7200"]).expect_success();
    // "... peak N condensed parcels at t = T s ..."
    let peak = err
        .split("peak ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|n| n.parse::<usize>().ok())
        .unwrap_or_else(|| panic!("no peak in the summary: {err}"));
    // The scene's promise (issue 10): a field of at least 2000 condensed
    // parcels at its peak within two simulated hours.
    assert!(peak >= 2000, "peak {peak} condensed parcels: {err}");
    assert!(err.contains("no CSV written"), "{err}");
}
