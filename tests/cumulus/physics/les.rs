//! profiles/bomex.toml against the BOMEX case it stands for (Siebesma et
//! al. 2003; the case definition at knmi.nl/~siebesma/gcss/bomexcomp.init.html):
//! the environment cumulus builds from the scene's temperatures and
//! dewpoints has the published θ_l and q_t (as a mixing ratio) at every
//! height, and the emission carries the published surface fluxes; hour by
//! hour, the model against the published LES results (docs/les.md).

use std::path::Path;

use crate::common;

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
    common::physics::assert_published_profile(&env, 3000, 40, |z| {
        let (theta, q) = bomex(z);
        (theta, q / (1.0 - q))
    });
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

/// Hourly means over the frames with cloud of one BOMEX run with the
/// given entrainment model: (cloud base, cloud top, highest centre of a
/// cloudy parcel, cloud cover, liquid water path) for hours 0–1, 1–2, …;
/// the greatest value of each hour's mean cloud-fraction profile and its
/// height; also the time of the first cloud. units: m, m, m, 1, kg m⁻²;
/// (1, m); s
struct BomexHours {
    hours: Vec<(f64, f64, f64, f64, f64)>,
    profile_max: Vec<(f64, f64)>,
    first_cloud_s: f64,
}

/// Levels of the cloud-fraction profile: every 20 m to 4 km. units: m
const PROFILE_DZ_M: f64 = 20.0;
const PROFILE_LEVELS: usize = 200;

/// Adds to `profile` the cloud fraction at each level: the area of the
/// horizontal sections of the cloudy parcels' spheres above their
/// condensation planes (what `cloud_cover` projects), over the ground's
/// area. Parcels overlapping at a level count twice, so this bounds the
/// LES's fraction of cloudy grid points from above.
fn add_cloud_fraction(w: &cumulus::physics::ParcelWorld, area_m2: f64, profile: &mut [f64]) {
    for p in w.parcels().iter().filter(|p| p.is_condensed()) {
        for (k, f) in profile.iter_mut().enumerate() {
            let z = (k as f64 + 0.5) * PROFILE_DZ_M;
            let dz = z - p.position_m.z;
            if z >= p.cond_plane_z_m && dz.abs() < p.radius_m {
                *f += std::f64::consts::PI * (p.radius_m * p.radius_m - dz * dz) / area_m2;
            }
        }
    }
}

fn bomex_hours(model: cumulus::physics::EntrainmentModel, hours: usize) -> BomexHours {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bomex.toml");
    let (scene, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
    let env = scene.atmosphere.build(&source.base_dir()).unwrap();
    let mut cfg = scene.world_config(&source.base_dir()).unwrap();
    cfg.physics.entrainment_model = model;
    let area_m2 = cfg.ground.size_m[0] * cfg.ground.size_m[1];
    let mut w = cumulus::physics::ParcelWorld::new(env, cfg, 1).unwrap();
    let mut first_cloud_s = f64::NAN;
    let mut out = Vec::new();
    let mut profile_max = Vec::new();
    for _ in 0..hours {
        let (mut sum, mut n, mut lwp) = ((0.0, 0.0, 0.0, 0.0), 0.0, 0.0);
        let mut profile = vec![0.0; PROFILE_LEVELS];
        // 720 frames of 5 s: the frame of benches/les/bomex_compare.py.
        for _ in 0..720 {
            w.step(5.0);
            add_cloud_fraction(&w, area_m2, &mut profile);
            let d = w.diagnostics();
            if let (Some(b), Some(t)) = (d.cloud_base_m, d.cloud_top_m) {
                if first_cloud_s.is_nan() {
                    first_cloud_s = d.time_s;
                }
                let centre = w
                    .parcels()
                    .iter()
                    .filter(|p| p.is_condensed())
                    .map(|p| p.position_m.z)
                    .fold(f64::MIN, f64::max);
                sum = (
                    sum.0 + b,
                    sum.1 + t,
                    sum.2 + centre,
                    sum.3 + w.cloud_cover(),
                );
                lwp += w.liquid_water_path();
                n += 1.0;
            }
        }
        assert!(n > 300.0, "clouds in most frames of every hour");
        out.push((sum.0 / n, sum.1 / n, sum.2 / n, sum.3 / n, lwp / n));
        let (k, f) = profile
            .iter()
            .enumerate()
            .fold((0, 0.0), |m, (k, &f)| if f > m.1 { (k, f) } else { m });
        profile_max.push((f / 720.0, (k as f64 + 0.5) * PROFILE_DZ_M));
    }
    BomexHours {
        hours: out,
        profile_max,
        first_cloud_s,
    }
}

/// The model over time against the published BOMEX LES (Siebesma et al.
/// 2003; docs/les.md, "The LES results"): first clouds after about half an
/// hour, quasi-steady after the spin-up; over the last 3 h a total cloud
/// cover of 13 % (8 % UCLA to 17 % NCAR), a cloud base of ~500 m, a
/// cloud-fraction profile greatest (≈ 0.06) near cloud base and gone by
/// ~2000 m, and an ensemble-mean LWP that never exceeds ~11 g m⁻² (Fig. 2b,
/// read by eye). The test runs 3 hours: ours is steady from the first
/// (asserted below), so hour 2–3 stands for the LES's hours 3–6.
#[test]
fn bomex_over_time_base_and_cover_reproduced_tops_only_with_stronger_entrainment() {
    use cumulus::physics::EntrainmentModel;
    // Cloud fraction vanishes at ~2000 m in Fig. 6 (read by eye, ±50 m),
    // where the case's inversion ends (θ_l 308.2 K, q_t 4.2 g/kg).
    const LES_CLOUD_TOP_M: f64 = 2000.0;
    // Bottom of the inversion: the top of the LES cloud layer.
    const INVERSION_BASE_M: f64 = 1480.0;
    let runs: Vec<_> = [
        EntrainmentModel::Paper,
        EntrainmentModel::Plume,
        EntrainmentModel::Observed,
    ]
    .into_iter()
    .map(|m| (m, bomex_hours(m, 3)))
    .collect();
    for (m, r) in &runs {
        for (h, (base, top, centre, cover, lwp)) in r.hours.iter().enumerate() {
            let (f, z) = r.profile_max[h];
            eprintln!(
                "{m:?} hour {h}–{}: base {base:.0} m, top {top:.0} m, \
                 highest cloudy centre {centre:.0} m, cover {cover:.3}, \
                 LWP {:.1} g/m², cloud-fraction profile max {f:.3} at {z:.0} m",
                h + 1,
                1e3 * lwp
            );
        }
        eprintln!("{m:?}: first cloud {:.1} min", r.first_cloud_s / 60.0);
        // Not reproduced: the spin-up. The LES's first clouds come "after
        // half an hour" (section 2a; ~25 min in Fig. 2a), when resolved
        // turbulence has made saturated grid boxes; our thermals leave the
        // sea with their excess and condense within minutes (measured
        // 4.6–5.9 min). 15 min: half the LES's time.
        assert!(
            r.first_cloud_s < 900.0,
            "{m:?}: first cloud {} s",
            r.first_cloud_s
        );
        // Quasi-steady after the first hour, as the case is designed
        // (constant fluxes, forcing holding the profiles): hour 2–3 against
        // hour 1–2. 2 % of base and top (measured ≤ 0.3 %), 10 % of cover
        // (its hourly mean moves by ≤ 5 % with the 50–80 cloudy parcels).
        let (a, b) = (r.hours[1], r.hours[2]);
        assert!((b.0 / a.0 - 1.0).abs() < 0.02, "{m:?} base {a:?} → {b:?}");
        assert!((b.1 / a.1 - 1.0).abs() < 0.02, "{m:?} top {a:?} → {b:?}");
        assert!((b.3 / a.3 - 1.0).abs() < 0.10, "{m:?} cover {a:?} → {b:?}");
        // Reproduced: the cloud base lies within 100 m of the LES's ~500 m
        // (Siebesma et al. section 2b(1); Fig. 6's cloud fraction starts
        // there; ours is the lowest condensation plane of all thermals,
        // below a mean base).
        for &(base, ..) in &r.hours[1..] {
            assert!((base - 500.0).abs() < 100.0, "{m:?} cloud base {base} m");
        }
        // Not reproduced: the shape of the cloud-fraction profile. The LES's
        // is greatest just above cloud base (~600 m) and falls off upward,
        // since all clouds share a base but not a top; ours is greatest at
        // the top of the cloud layer (measured 1.53–2.41 km), where the
        // parcels stop and stay. 1400 m: well above the LES's maximum and
        // the middle of the cloud layer.
        let (_, z_max) = r.profile_max[2];
        assert!(z_max > 1400.0, "{m:?} profile max at {z_max} m");
        // Not reproduced: the liquid water. The LES ensemble-mean LWP stays
        // under ~11 g m⁻² at every time (Fig. 2b, by eye, ±1 g m⁻²); ours
        // is more than three times that (measured 37, 42, 53 g m⁻²): the
        // cloudy parcels are few, big and little diluted, and entrained air
        // adds mass and so liquid (eq 6).
        let lwp = r.hours[2].4;
        assert!(lwp > 3.0 * 0.011, "{m:?} LWP {lwp} kg/m²");
    }
    let steady = |i: usize| runs[i].1.hours[2];
    let (paper, plume, observed) = (steady(0), steady(1), steady(2));
    // Not reproduced with the paper's entrainment: its cloudy parcels rise
    // through the whole inversion (measured: highest centre 2.5 km, top
    // 2.63 km), where the LES's cloud fraction is gone by ~2000 m.
    assert!(paper.2 > LES_CLOUD_TOP_M, "paper centre {} m", paper.2);
    assert!(paper.1 > LES_CLOUD_TOP_M + 500.0, "paper top {} m", paper.1);
    // Reproduced with plume or observed entrainment: the cloudy parcels
    // stop inside the inversion (highest centres measured 1.64 km observed,
    // 1.81 km plume: ≥ 150 m from either edge) and their sphere tops
    // (measured 2.04 and 1.92 km) lie within 150 m of where the LES's
    // cloud fraction vanishes: the reading (±50 m) and the spheres'
    // 150 m radius.
    for (name, r) in [("plume", plume), ("observed", observed)] {
        assert!(
            (INVERSION_BASE_M..LES_CLOUD_TOP_M).contains(&r.2),
            "{name} highest cloudy centre {} m",
            r.2
        );
        assert!(
            (r.1 - LES_CLOUD_TOP_M).abs() < 150.0,
            "{name} top {} m",
            r.1
        );
    }
    // Cover against the LES's means over the last 3 h (section 2a): 13 %
    // ensemble mean, 8 % (UCLA) to 17 % (NCAR); none of the participants'
    // sensitivity runs went "beyond about 25%".
    // Reproduced with the paper's entrainment: inside the models' range
    // at every hour (measured 10.2–11.5 %).
    for &(.., cover, _) in &runs[0].1.hours {
        assert!((0.08..0.17).contains(&cover), "paper cover {cover}");
    }
    // Plume: above the ensemble mean, at the top of the range (measured
    // 17.8 % at hour 2–3 against NCAR's 17 %) and under the 25 % ceiling.
    assert!((0.13..0.25).contains(&plume.3), "plume cover {}", plume.3);
    // Not reproduced with the observed rate: above every model and the
    // sensitivity runs' ceiling (measured 25.5 %), since entrained air
    // adds mass and so volume (eq 6) and the parcels swell.
    assert!(observed.3 > 0.25, "observed cover {}", observed.3);
}

/// A world with every physics term and the emission off, holding parcels
/// of 150 m at `centres` with `ql` kg/kg of liquid, stepped once; and the
/// ground's area (m²).
fn cloudy_parcels(centres: &[glam::DVec3], ql: f64) -> (cumulus::physics::ParcelWorld, f64) {
    use cumulus::physics::{ParcelSpec, ParcelWorld, WorldConfig};
    let mut cfg = WorldConfig {
        physics: super::fidelity::nothing(),
        ..WorldConfig::default()
    };
    cfg.emission.enabled = false;
    let area = cfg.ground.size_m[0] * cfg.ground.size_m[1];
    let env = cumulus::atmosphere::AtmosphereSpec::default()
        .build(Path::new("."))
        .unwrap();
    let mut w = ParcelWorld::new(env, cfg, 1).unwrap();
    for &c in centres {
        let mut s = ParcelSpec::from_environment(w.environment(), c, 0.0, 0.0, 150.0);
        s.ql_kg_per_kg = ql;
        w.spawn_parcel(s).unwrap();
    }
    w.step(1.0);
    (w, area)
}

/// `ParcelWorld::cloud_cover`, the LES's "columns with cloud" for parcels:
/// a cloudy parcel wholly above its condensation plane covers its disk
/// πr², and a second one straight above it (a taller cloud, not a wider
/// one) adds nothing; one beside it adds its own disk.
#[test]
fn cloud_cover_is_the_area_of_the_union_of_cloudy_disks() {
    use glam::DVec3;
    let cover_of = |centres: &[DVec3]| {
        // Far past saturation: the parcel's own condensation level lies
        // kilometres below it, so all of its sphere is cloud.
        let (w, _) = cloudy_parcels(centres, 5e-3);
        assert!(
            w.parcels()
                .iter()
                .all(|p| p.cond_plane_z_m < p.position_m.z - p.radius_m)
        );
        w.cloud_cover()
    };
    let area = cloudy_parcels(&[], 0.0).1;
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

/// `ParcelWorld::liquid_water_path`, the LES's domain-mean LWP: all the
/// parcels' liquid over the ground's area, so that, unlike the cover, a
/// second cloudy parcel straight above the first doubles it.
#[test]
fn liquid_water_path_is_the_liquid_of_all_parcels_over_the_ground() {
    use glam::DVec3;
    let area = cloudy_parcels(&[], 0.0).1;
    let world_of = |centres: &[DVec3], ql: f64| cloudy_parcels(centres, ql).0;
    let one = world_of(&[DVec3::new(0.0, 0.0, 3000.0)], 5e-3);
    let p = &one.parcels()[0];
    let expected = p.dry_mass_kg * p.ql_kg_per_kg / area;
    // A parcel of 150 m holds ~10⁴ kg of liquid at 5 g/kg: ~0.3 g m⁻² on
    // the default ground; 1e-9 relative is rounding.
    assert!(expected > 1e-4, "{expected}");
    assert!((one.liquid_water_path() / expected - 1.0).abs() < 1e-9);
    let stacked = world_of(
        &[DVec3::new(0.0, 0.0, 3000.0), DVec3::new(0.0, 0.0, 3400.0)],
        5e-3,
    );
    let sum: f64 = stacked
        .parcels()
        .iter()
        .map(|p| p.dry_mass_kg * p.ql_kg_per_kg)
        .sum();
    // Both count: about twice the one parcel (the upper one is thinner air).
    assert!((stacked.liquid_water_path() / (sum / area) - 1.0).abs() < 1e-9);
    assert!(stacked.liquid_water_path() > 1.5 * one.liquid_water_path());
    let dry = world_of(&[DVec3::new(0.0, 0.0, 3000.0)], 0.0);
    assert_eq!(dry.liquid_water_path(), 0.0, "no liquid, no path");
}
