//! Wind from the sounding: DRCT/SKNT become u(z), v(z) of the environment,
//! bad wind values are rejected with file:line:column, a sounding without
//! wind columns has no wind profile, and the profile drives the parcels' drag
//! unless the scene sets `[wind]`.

use std::path::Path;

use cumulus::atmosphere::{Environment, PressureModel, Sounding, WindLevel, WindProfile};
use cumulus::physics::{
    EmissionConfig, GroundConfig, ParcelSpec, ParcelWorld, PhysicsConfig, WindConfig, WorldConfig,
};
use glam::DVec3;

use crate::common;

/// Knots to metres per second (the reader's conversion). units: m s⁻¹ kn⁻¹
const KNOT_M_S: f64 = 0.514_444;

const HEADER: &str = "\
   PRES   HGHT   TEMP   DWPT   RELH   MIXR   DRCT   SKNT   THTA   THTE   THTV
";

/// A table row with right-aligned 7-character fields (blank = "").
fn row(fields: &[&str]) -> String {
    let mut s: String = fields.iter().map(|f| format!("{f:>7}")).collect();
    s.push('\n');
    s
}

/// Header (line 1) and three rows (lines 2–4) with the given wind on line 3.
fn table(drct: &str, sknt: &str) -> String {
    let mut s = String::from(HEADER);
    s += &row(&["966.0", "345", "22.2", "21.0", "93", "16.50", "180", "10"]);
    s += &row(&["900.0", "950", "18.0", "10.0", "", "", drct, sknt]);
    s += &row(&["700.0", "3096", "7.6", "-9.4", "", "", "270", "40"]);
    s
}

#[test]
fn drct_and_sknt_become_the_environments_u_v_profile() {
    let s = Sounding::parse(&table("225", "20"), Path::new("w.txt")).unwrap();
    let env = s.to_environment().unwrap();
    let w = env.wind().expect("the table has wind");
    assert_eq!(w.levels().len(), 3);
    // 180° (from the south) at 10 kn: blowing north.
    let [u, v] = env.wind_m_s(0.0).unwrap();
    assert!(
        u.abs() < 1e-9 && (v - 10.0 * KNOT_M_S).abs() < 1e-9,
        "{u} {v}"
    );
    // 225° (from the south-west) at 20 kn, 605 m up: blowing north-east.
    let [u, v] = env.wind_m_s(605.0).unwrap();
    let c = 20.0 * KNOT_M_S / 2f64.sqrt();
    assert!((u - c).abs() < 1e-9 && (v - c).abs() < 1e-9, "{u} {v}");
    // Halfway to the 270° level: the mean of the two vectors.
    let [u, _] = env.wind_m_s(0.5 * (605.0 + 2751.0)).unwrap();
    assert!((u - 0.5 * (c + 40.0 * KNOT_M_S)).abs() < 1e-9);
    // The shipped 2011 sounding has a veering, strengthening wind.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/soundings");
    let oun = Sounding::load(&dir.join("oun-2011-05-22-12z.txt")).unwrap();
    let shear = oun
        .to_environment()
        .unwrap()
        .wind()
        .unwrap()
        .bulk_shear_m_s(0.0, 6000.0);
    assert!((10.0..60.0).contains(&shear), "0–6 km shear {shear} m/s");
}

#[test]
fn bad_wind_values_name_file_line_and_column() {
    let cases = [
        (table("400", "20"), 3, 47, "DRCT 400"),
        (table("225", "-5"), 3, 55, "SKNT -5"),
        (table("225", ""), 3, 50, "DRCT without SKNT"),
        (table("", "20"), 3, 43, "SKNT without DRCT"),
    ];
    for (text, line, col, what) in cases {
        let msg = Sounding::parse(&text, Path::new("bad.txt"))
            .expect_err(what)
            .to_string();
        assert!(
            msg.starts_with(&format!("bad.txt:{line}:{col}:")),
            "{what}: {msg}"
        );
        assert!(msg.contains(what), "{what}: {msg}");
    }
}

#[test]
fn a_sounding_without_wind_columns_has_no_wind() {
    let text = "\
   PRES   HGHT   TEMP   DWPT
  966.0    345   22.2   21.0
  900.0    950   18.0   10.0
";
    let env = Sounding::parse(text, Path::new("calm.txt"))
        .unwrap()
        .to_environment()
        .unwrap();
    assert!(env.wind().is_none());
    assert!(env.wind_m_s(500.0).is_none());
}

/// A neutral dry environment (θ constant) with a uniform wind profile.
fn windy_neutral(wind: [f64; 2]) -> Environment {
    sheared_neutral(wind, wind)
}

/// A neutral dry environment with wind linear from `ground` at 0 m to
/// `top` at 10 km.
fn sheared_neutral(ground: [f64; 2], top: [f64; 2]) -> Environment {
    let lv = |z_m: f64| {
        let f = z_m / 10_000.0;
        WindLevel {
            z_m,
            u_m_s: ground[0] + (top[0] - ground[0]) * f,
            v_m_s: ground[1] + (top[1] - ground[1]) * f,
        }
    };
    Environment::new(
        vec![
            common::level(0.0, 300.0, 0.0),
            common::level(10_000.0, 300.0, 0.0),
        ],
        100_000.0,
        PressureModel::Hydrostatic,
    )
    .unwrap()
    .with_wind(Some(WindProfile::new(vec![lv(0.0), lv(10_000.0)]).unwrap()))
}

/// Horizontal velocity of a neutral parcel released at rest at 1500 m
/// after 30 min.
fn drift(env: Environment, wind: Option<WindConfig>) -> DVec3 {
    drift_at(env, wind, 1500.0)
}

fn drift_at(env: Environment, wind: Option<WindConfig>, z_m: f64) -> DVec3 {
    let cfg = WorldConfig {
        physics: PhysicsConfig {
            mixing: false,
            ..PhysicsConfig::default()
        },
        emission: EmissionConfig {
            enabled: false,
            ..EmissionConfig::default()
        },
        wind,
        ground: GroundConfig {
            size_m: [100_000.0, 100_000.0],
            ..Default::default()
        },
    };
    let mut w = ParcelWorld::new(env, cfg, 1).unwrap();
    let spec =
        ParcelSpec::from_environment(w.environment(), DVec3::new(0.0, 0.0, z_m), 0.0, 0.0, 150.0);
    w.spawn_parcel(spec).unwrap();
    for _ in 0..900 {
        w.step(2.0);
    }
    w.parcels()[0].velocity_m_s
}

#[test]
fn sounding_wind_drives_the_drag_unless_the_scene_sets_wind() {
    // Drag relaxes the slip as 1/(1 + k|u0|t) with 1/(k|u0|) ≈ 150 s (see
    // physics_world's drag test): after 1800 s about 8 % of the slip is
    // left, so the parcel moves with whichever wind drags it within 1 m/s.
    let sounding_wind = [6.0, -3.0];
    let v = drift(windy_neutral(sounding_wind), None);
    assert!(
        (v.x - 6.0).abs() < 1.0 && (v.y + 3.0).abs() < 1.0,
        "calm scene: {v}"
    );
    let scene = WindConfig {
        surface_m_s: [-4.0, 2.0],
        aloft_m_s: [-4.0, 2.0],
        aloft_z_m: 1000.0,
    };
    let v = drift(windy_neutral(sounding_wind), Some(scene));
    assert!(
        (v.x + 4.0).abs() < 1.0 && (v.y - 2.0).abs() < 1.0,
        "[wind] overrides: {v}"
    );
}

#[test]
fn an_explicit_calm_wind_table_silences_the_soundings_wind() {
    // The scene's [wind] is an Option: present, it drives the drag even when
    // it is calm; absent, the sounding's wind does. Parsed from TOML so the
    // scene file's own field is what is tested.
    let calm: cumulus::scene::SceneProfile =
        toml::from_str("[wind]\nsurface_m_s = [0.0, 0.0]\naloft_m_s = [0.0, 0.0]\n").unwrap();
    let none: cumulus::scene::SceneProfile = toml::from_str("").unwrap();
    let (calm, none) = (calm.world_tables(), none.world_tables());
    assert_eq!(calm.wind, Some(WindConfig::default()));
    assert_eq!(none.wind, None);
    let sounding_wind = [6.0, -3.0];
    // Same 1 m/s as above: 8 % of the slip is left after 30 min.
    let v = drift(windy_neutral(sounding_wind), calm.wind);
    assert!(v.x.abs() < 1.0 && v.y.abs() < 1.0, "calm [wind]: {v}");
    let v = drift(windy_neutral(sounding_wind), none.wind);
    assert!(
        (v.x - 6.0).abs() < 1.0 && (v.y + 3.0).abs() < 1.0,
        "no [wind]: {v}"
    );
    // A scene without [wind] saves without one (the sounding stays in charge).
    let text = toml::to_string(&cumulus::scene::SceneProfile::default()).unwrap();
    assert!(!text.contains("[wind]"), "{text}");
}

#[test]
fn sounding_shear_carries_high_parcels_faster() {
    // u from 0 at the ground to 20 m/s at 10 km: a neutral parcel at 1 km
    // drifts with 2 m/s, one at 6 km with 12 m/s (within 1 m/s, as above),
    // so a tower's top runs ahead of its base.
    let v_low = drift_at(sheared_neutral([0.0, 0.0], [20.0, 0.0]), None, 1000.0);
    let v_high = drift_at(sheared_neutral([0.0, 0.0], [20.0, 0.0]), None, 6000.0);
    assert!((v_low.x - 2.0).abs() < 1.0, "{v_low}");
    assert!((v_high.x - 12.0).abs() < 1.0, "{v_high}");
}
