//! tests/data/les/arm_sgp.toml against the ARM SGP shallow-cumulus case it stands
//! for (Brown et al. 2002, QJRMS 128, 1075): the environment has the
//! published initial θ and r_T, the emission the published daytime heat
//! flux; and the model, hour by hour from 11:30 UTC, against the eight LES
//! of the intercomparison (tests/data/les/arm_sgp_les_hourly.csv, derived
//! from the models' own output by benches/les/arm_sgp_les.py).

use std::path::Path;

use crate::common;

/// Table A.1 at height `z_m`: (θ K, r_T kg/kg), linear between levels.
fn arm(z_m: f64) -> (f64, f64) {
    const LEVELS: [(f64, f64, f64); 8] = [
        (0.0, 299.00, 15.20),
        (50.0, 301.50, 15.17),
        (350.0, 302.50, 14.98),
        (650.0, 303.53, 14.80),
        (700.0, 303.70, 14.70),
        (1300.0, 307.13, 13.50),
        (2500.0, 314.00, 3.00),
        (5500.0, 343.20, 3.00),
    ];
    let i = LEVELS.windows(2).position(|w| z_m <= w[1].0).unwrap();
    let ((z0, t0, r0), (z1, t1, r1)) = (LEVELS[i], LEVELS[i + 1]);
    let a = (z_m - z0) / (z1 - z0);
    (t0 + a * (t1 - t0), (r0 + a * (r1 - r0)) * 1e-3)
}

fn scene() -> (
    cumulus::atmosphere::Environment,
    cumulus::physics::WorldConfig,
) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/les/arm_sgp.toml");
    let (scene, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
    let env = scene.atmosphere.build(&source.base_dir()).unwrap();
    (env, scene.world_config(&source.base_dir()).unwrap())
}

#[test]
fn the_arm_scene_has_the_published_profiles_and_heat_flux() {
    let (env, cfg) = scene();
    common::physics::assert_published_profile(&env, 5500, 25, arm);
    // The sensible heat flux the emission carries, ρ c_p × rate × V × Δθ ×
    // the sun's factor, against Table A.2 where H > 0 (UTC h, W m⁻²).
    let v = 4.0 / 3.0 * std::f64::consts::PI * cfg.emission.radius_m.powi(3);
    let rho_cp = env.density_kg_m3(0.0) * 1005.7;
    for (utc_h, published) in [(15.5, 90.0), (18.0, 140.0), (19.0, 140.0), (21.5, 100.0)] {
        let t_s = (utc_h - 11.5) * 3600.0;
        let sun = cumulus::physics::ground::GroundMap::sun(&cfg.emission, t_s);
        let rate_per_m2_s = cfg.emission.rate_per_km2_per_h * sun / 1e6 / 3600.0;
        let h = rho_cp * rate_per_m2_s * v * cfg.ground.heat_excess_k;
        // 12 %: a sine for Table A.2's piecewise-linear cycle; measured
        // +10 % at 15:30 UTC (99 against 90 W m⁻²), within 1 % at the others.
        assert!(
            (h / published - 1.0).abs() < 0.12,
            "H at {utc_h} UTC: {h:.1} vs {published} W m⁻²"
        );
    }
}

/// One hour of a run: the mean cover over all frames, the mean cloud base
/// and top over the frames with cloud (None without any). units: 1, m, m
#[derive(Debug, Clone, Copy)]
struct Hour {
    cover: f64,
    base_m: Option<f64>,
    top_m: Option<f64>,
}

/// Hours 0–1, 1–2, … after 11:30 UTC of the scene with the given
/// entrainment, in 5-s frames (those of benches/les/arm_sgp_compare.py);
/// `heat_excess_k`, when given, replaces the scene's Δθ and scales the
/// rate so that the heat flux stays the same. units: K
fn arm_hours(
    model: cumulus::physics::EntrainmentModel,
    heat_excess_k: Option<f64>,
    hours: usize,
) -> Vec<Hour> {
    let (env, mut cfg) = scene();
    cfg.physics.entrainment_model = model;
    if let Some(dt) = heat_excess_k {
        cfg.emission.rate_per_km2_per_h *= cfg.ground.heat_excess_k / dt;
        cfg.ground.heat_excess_k = dt;
    }
    let mut w = cumulus::physics::ParcelWorld::new(env, cfg, 1).unwrap();
    (0..hours)
        .map(|_| {
            let (mut cover, mut base, mut top, mut cloudy) = (0.0, 0.0, 0.0, 0.0);
            for _ in 0..720 {
                w.step(5.0);
                let d = w.diagnostics();
                cover += w.cloud_cover();
                if let (Some(b), Some(t)) = (d.cloud_base_m, d.cloud_top_m) {
                    (base, top, cloudy) = (base + b, top + t, cloudy + 1.0);
                }
            }
            let some = |x: f64| (cloudy > 0.0).then(|| x / cloudy);
            Hour {
                cover: cover / 720.0,
                base_m: some(base),
                top_m: some(top),
            }
        })
        .collect()
}

/// The LES ensemble, hour by hour from 11:30 UTC: the mean, least and
/// greatest of the eight models' cover, base and top (None where no model
/// had cloud).
struct Les {
    cover: [f64; 3],
    base_m: Option<[f64; 3]>,
    top_m: Option<[f64; 3]>,
}

fn les() -> Vec<Les> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/les/arm_sgp_les_hourly.csv");
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines.next().unwrap();
    assert!(
        header.starts_with("hour_from,hour_to,cover_mean"),
        "{header}"
    );
    lines
        .enumerate()
        .map(|(h, l)| {
            let f: Vec<Option<f64>> = l.split(',').map(|x| x.parse().ok()).collect();
            assert_eq!(f[0], Some(h as f64), "rows are consecutive hours");
            let three = |i: usize| Some([f[i]?, f[i + 1]?, f[i + 2]?]);
            Les {
                cover: three(2).unwrap(),
                base_m: three(6),
                top_m: three(9),
            }
        })
        .collect()
}

/// The derived LES table says what Brown et al. 2002 say of their ensemble
/// (section 3a): first clouds "at around 1500 UTC", the largest cover
/// "just under 30%" about 17 UTC, about 15 % at 22 UTC, the base rising
/// from about 700 m at 15 UTC to 1200 m at 24 UTC, the tops greatest
/// (2500–3000 m) about 21 UTC. A wrongly read column or time base fails.
#[test]
fn the_arm_les_table_says_what_the_paper_says() {
    let les = les();
    assert_eq!(les.len(), 14, "11:30 to 01:30 UTC");
    // No cloud in any model before 14:30 UTC (hours 0–3), some in every
    // model from 14:30 to 15:30.
    assert!(
        les[..3]
            .iter()
            .all(|h| h.cover[2] == 0.0 && h.base_m.is_none())
    );
    assert!(les[3].cover[1] > 0.0);
    // Largest mean cover in 17:30–18:30 (hour 6), under 0.3 (measured 0.27).
    let peak = (0..14)
        .max_by(|&a, &b| les[a].cover[0].total_cmp(&les[b].cover[0]))
        .unwrap();
    assert_eq!(peak, 6, "peak hour");
    assert!(
        (0.25..0.30).contains(&les[6].cover[0]),
        "{}",
        les[6].cover[0]
    );
    // About 15 % at 22 UTC: 21:30–22:30 is hour 10 (measured 0.157);
    // "about" read as ±0.03.
    assert!(
        (les[10].cover[0] - 0.15).abs() < 0.03,
        "{}",
        les[10].cover[0]
    );
    // Base ~700 m at 15 UTC (hour 3, measured 702) and ~1200 m at 24 UTC
    // (hours 12, measured 1292): "around" read as ±100 m.
    let base = |h: usize| les[h].base_m.unwrap()[0];
    assert!((base(3) - 700.0).abs() < 100.0, "{}", base(3));
    assert!((base(12) - 1200.0).abs() < 100.0, "{}", base(12));
    // Greatest mean top between 2500 and 3000 m, in 20:30–22:30 (hours 9–10).
    let top = |h: usize| les[h].top_m.map_or(0.0, |t| t[0]);
    let highest = (0..14).max_by(|&a, &b| top(a).total_cmp(&top(b))).unwrap();
    assert!((9..=10).contains(&highest), "highest top in hour {highest}");
    assert!((2500.0..3000.0).contains(&top(highest)), "{}", top(highest));
}

/// The model over the day against the eight LES: with the environment held
/// at the 11:30 UTC sounding, the thermals carrying the LES mixed layer of
/// 15:30 UTC barely reach their condensation level, so the afternoon's
/// cumulus (LES: 15–27 % cover from 16:30 to 22:30 UTC, tops to 2.8 km)
/// are not reproduced with any entrainment; nor with a warmer excess; nor
/// is the cloud base's rise through the afternoon.
#[test]
fn arm_over_the_day_the_fixed_environment_makes_almost_no_cloud() {
    use cumulus::physics::EntrainmentModel;
    let les = les();
    // 11 hours: 11:30–22:30 UTC, the LES's first clouds to their decline.
    // The warmer excess: 5.5 K over the 11:30 surface air, 2.8 K over the
    // LES's mixed layer at 15:30 UTC (the scene's is 4.0 K).
    let (paper, observed, warmer) = std::thread::scope(|s| {
        let p = s.spawn(|| arm_hours(EntrainmentModel::Paper, None, 11));
        let o = s.spawn(|| arm_hours(EntrainmentModel::Observed, None, 11));
        let w = s.spawn(|| arm_hours(EntrainmentModel::Paper, Some(5.5), 11));
        (p.join().unwrap(), o.join().unwrap(), w.join().unwrap())
    });
    for (name, run) in [("paper", &paper), ("observed", &observed)] {
        for (h, ours) in run.iter().enumerate() {
            eprintln!("{name} {:05.2} UTC: {ours:?}", 11.5 + h as f64);
        }
        // Not reproduced: the cloud cover. From 16:30 to 22:30 UTC (hours
        // 5–10) every LES model has 13 % or more (measured 13.1–30.7 %);
        // ours stays under 1 % (measured 0.0 % with both: one cloudy
        // parcel all day with the paper's entrainment, none observed).
        for h in 5..=10 {
            assert!(les[h].cover[1] > 0.13, "LES hour {h}");
            assert!(run[h].cover < 0.01, "{name} hour {h}: {:?}", run[h]);
        }
        // Not reproduced: the deepening. The LES tops pass 2.5 km by 20:30
        // UTC; ours, where there is cloud at all, stay under 1.5 km
        // (measured 1.0 km): the 11:30 UTC sounding is stable for cloudy
        // air from 700 to 1300 m (θ +5.7 K/km), which the LES's clouds
        // erode and moisten during the day and ours cannot.
        assert!(les[8].top_m.unwrap()[1] > 2500.0);
        assert!(
            run.iter().all(|h| h.top_m.is_none_or(|t| t < 1500.0)),
            "{name}"
        );
    }
    // Nor with a warmer excess: thermals 1.5 K warmer make clouds from
    // 12:30 UTC on, but no more than 2 % cover (measured ≤ 1.7 %) and no
    // tops over 1.5 km (measured 1.26 km): the environment, not the
    // thermals, stops them. (Hours 1–11; the excess is not a cause the
    // LES share, so only the bounds are held.)
    for (h, w) in warmer.iter().enumerate() {
        eprintln!("paper, Δθ 5.5 K {:05.2} UTC: {w:?}", 11.5 + h as f64);
        assert!(w.cover < 0.02, "hour {h}: {w:?}");
        assert!(w.top_m.is_none_or(|t| t < 1500.0), "hour {h}: {w:?}");
    }
    assert!(
        warmer.iter().any(|w| w.cover > 0.005),
        "the warmer thermals make some cloud"
    );
    // Not reproduced: the rising cloud base. The LES's rises by 454 m
    // from 15:30–16:30 to 21:30–22:30 UTC (hours 4–10, measured 751 →
    // 1205 m) as the mixed layer warms; ours, from a fixed excess in a
    // fixed environment, by less than 50 m (measured ≤ 3 m).
    let les_rise = les[10].base_m.unwrap()[0] - les[4].base_m.unwrap()[0];
    assert!(les_rise > 300.0, "LES base rise {les_rise} m");
    let bases: Vec<f64> = warmer[4..=10].iter().map(|w| w.base_m.unwrap()).collect();
    let spread = bases.iter().cloned().fold(f64::MIN, f64::max)
        - bases.iter().cloned().fold(f64::MAX, f64::min);
    assert!(spread < 50.0, "our base moves by {spread} m");
}
