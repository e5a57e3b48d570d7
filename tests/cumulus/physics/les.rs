//! profiles/bomex.toml against the BOMEX case it stands for (Siebesma et
//! al. 2003; the case definition at knmi.nl/~siebesma/gcss/bomexcomp.init.html):
//! the environment cumulus builds from the scene's temperatures and
//! dewpoints has the published θ_l and q_t (as a mixing ratio) at every
//! height, and the emission carries the published surface fluxes.

use std::path::Path;

/// The published profiles at height `z_m`: (θ_l K, q_t kg/kg, specific).
fn bomex(z_m: f64) -> (f64, f64) {
    let lin = |z0: f64, z1: f64, a: f64, b: f64| a + (b - a) * (z_m - z0) / (z1 - z0);
    let (theta, q_gkg) = if z_m <= 520.0 {
        (298.7, lin(0.0, 520.0, 17.0, 16.3))
    } else if z_m <= 1480.0 {
        (
            lin(520.0, 1480.0, 298.7, 302.4),
            lin(520.0, 1480.0, 16.3, 10.7),
        )
    } else if z_m <= 2000.0 {
        (
            lin(1480.0, 2000.0, 302.4, 308.2),
            lin(1480.0, 2000.0, 10.7, 4.2),
        )
    } else {
        (
            308.2 + 3.65e-3 * (z_m - 2000.0),
            4.2 - 1.2e-3 * (z_m - 2000.0),
        )
    };
    (theta, q_gkg * 1e-3)
}

#[test]
fn the_bomex_scene_has_the_published_profiles_and_fluxes() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bomex.toml");
    let (scene, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
    let env = scene.atmosphere.build(&source.base_dir()).unwrap();
    for z in (0..=3000).step_by(40) {
        let z = z as f64;
        let (theta, q) = bomex(z);
        let r = q / (1.0 - q);
        // 0.02 K and 0.5 %: the points are written to 4 decimals of a
        // degree, and the dewpoint's rounding moves q by ~0.03 %; a wrong
        // corner or gradient is off by tenths of a kelvin or more.
        assert!(
            (env.theta_k(z) - theta).abs() < 0.02,
            "θ at {z} m: {} vs {theta}",
            env.theta_k(z)
        );
        assert!(
            (env.qv(z) / r - 1.0).abs() < 5e-3,
            "q_v at {z} m: {} vs {r}",
            env.qv(z)
        );
    }
    // The surface fluxes as emission: rate × V × excess (docs/les.md).
    let cfg = scene.world_config(&source.base_dir()).unwrap();
    let v = 4.0 / 3.0 * std::f64::consts::PI * cfg.emission.radius_m.powi(3);
    let rate_per_m2_s = cfg.emission.rate_per_km2_per_h / 1e6 / 3600.0;
    let heat = rate_per_m2_s * v * cfg.ground.heat_excess_k;
    let moisture = rate_per_m2_s * v * cfg.ground.moisture_excess_kg_per_kg;
    // 1 %: the rate is written to three figures.
    assert!((heat / 8e-3 - 1.0).abs() < 0.01, "w'θ' {heat} K m/s");
    assert!(
        (moisture / 5.2e-5 - 1.0).abs() < 0.01,
        "w'q' {moisture} m/s"
    );
}

/// One simulated hour of the BOMEX scene (the LES's spin-up; the model is
/// in its steady state by then, docs/les.md) with the given entrainment
/// model: the mean over frames of (cloud base, cloud top, cloud cover) in
/// the second half hour. units: m, m, 1
fn bomex_hour(model: cumulus::physics::EntrainmentModel) -> (f64, f64, f64) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bomex.toml");
    let (scene, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
    let env = scene.atmosphere.build(&source.base_dir()).unwrap();
    let mut cfg = scene.world_config(&source.base_dir()).unwrap();
    cfg.physics.entrainment_model = model;
    let mut w = cumulus::physics::ParcelWorld::new(env, cfg, 1).unwrap();
    let (mut sum, mut n) = ((0.0, 0.0, 0.0), 0.0);
    for f in 0..720 {
        w.step(5.0);
        let d = w.diagnostics();
        if f >= 360
            && let (Some(b), Some(t)) = (d.cloud_base_m, d.cloud_top_m)
        {
            sum = (sum.0 + b, sum.1 + t, sum.2 + w.cloud_cover());
            n += 1.0;
        }
    }
    assert!(n > 300.0, "clouds in most frames of the second half hour");
    (sum.0 / n, sum.1 / n, sum.2 / n)
}

/// What the paper's model reproduces of the BOMEX LES and what it does
/// not (docs/les.md): the cloud base lies near the LES's 500–600 m (we
/// report the lowest condensation plane, which sits below the mean base by
/// the spread of the thermals' lifting condensation levels: 400–650 m
/// allowed), the cover is of the LES's order (4–10 %; 2–20 % allowed: our
/// 150 m parcels are coarse), but the paper's radius-independent
/// entrainment lets the tops overshoot the 2 km inversion that holds the
/// LES clouds under 1.9 km; plume entrainment (c/R) brings the tops down.
#[test]
fn bomex_cloud_base_and_cover_are_the_les_order_and_plume_entrainment_lowers_the_tops() {
    use cumulus::physics::EntrainmentModel;
    let (base, top, cover) = bomex_hour(EntrainmentModel::Paper);
    eprintln!("paper: base {base:.0} m, top {top:.0} m, cover {cover:.3}");
    assert!((400.0..650.0).contains(&base), "cloud base {base} m");
    assert!((0.02..0.2).contains(&cover), "cloud cover {cover}");
    // The paper's tops pass the inversion (2 km): what it does not reproduce.
    assert!(top > 2000.0, "cloud top {top} m");
    let (_, plume_top, _) = bomex_hour(EntrainmentModel::Plume);
    eprintln!("plume: top {plume_top:.0} m");
    // Lower by more than 300 m (measured: 2.6 km → 2.0 km over hours 3–6).
    assert!(
        plume_top < top - 300.0,
        "plume {plume_top} m vs paper {top} m"
    );
}

/// `ParcelWorld::cloud_cover`, the LES's "columns with cloud" for parcels:
/// a cloudy parcel wholly above its condensation plane covers its disk
/// πr², and a second one straight above it (a taller cloud, not a wider
/// one) adds nothing; one beside it adds its own disk.
#[test]
fn cloud_cover_is_the_area_of_the_union_of_cloudy_disks() {
    use cumulus::physics::{ParcelSpec, ParcelWorld, WorldConfig};
    use glam::DVec3;
    let physics = super::fidelity::nothing();
    let mut cfg = WorldConfig {
        physics,
        ..WorldConfig::default()
    };
    cfg.emission.enabled = false;
    let area = cfg.ground.size_m[0] * cfg.ground.size_m[1];
    let env = cumulus::atmosphere::AtmosphereSpec::default()
        .build(Path::new("."))
        .unwrap();
    let cover_of = |centres: &[DVec3]| {
        let mut w = ParcelWorld::new(env.clone(), cfg.clone(), 1).unwrap();
        for &c in centres {
            let mut s = ParcelSpec::from_environment(w.environment(), c, 0.0, 0.0, 150.0);
            // Far past saturation: the parcel's own condensation level lies
            // kilometres below it, so all of its sphere is cloud.
            s.ql_kg_per_kg = 5e-3;
            w.spawn_parcel(s).unwrap();
        }
        w.step(1.0);
        assert!(
            w.parcels()
                .iter()
                .all(|p| p.cond_plane_z_m < p.position_m.z - p.radius_m)
        );
        w.cloud_cover()
    };
    let r = 150.0_f64;
    let disk = std::f64::consts::PI * r * r / area;
    let one = cover_of(&[DVec3::new(0.0, 0.0, 3000.0)]);
    // 3 %: 25 m cells counted by their centres miss or add at most half a
    // cell along the rim (2πr × 12.5 m is 17 % of πr² at worst), but the
    // misses and additions cancel to a few per cent for a disk.
    assert!((one / disk - 1.0).abs() < 0.03, "{one} vs {disk}");
    let stacked = cover_of(&[DVec3::new(0.0, 0.0, 3000.0), DVec3::new(0.0, 0.0, 3400.0)]);
    assert_eq!(
        stacked, one,
        "a parcel straight above another covers nothing new"
    );
    let beside = cover_of(&[
        DVec3::new(0.0, 0.0, 3000.0),
        DVec3::new(1000.0, 0.0, 3000.0),
    ]);
    assert!((beside / (2.0 * disk) - 1.0).abs() < 0.03, "{beside}");
}
