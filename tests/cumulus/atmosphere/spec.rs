//! The `[atmosphere]` table: inline points and sounding files, pressure
//! models, validation messages, and sampling a sounding into editable points.

use std::path::Path;

use cumulus::atmosphere::lifting::{LiftOptions, lift_surface_parcel};
use cumulus::atmosphere::{AtmospherePoint, AtmosphereSpec, PressureModel, Sounding, thermo};
use cumulus::scene::SceneProfile;

fn spec(toml_atmosphere: &str) -> cumulus::Result<AtmosphereSpec> {
    let text = format!("name = \"t\"\ndescription = \"t\"\n[atmosphere]\n{toml_atmosphere}");
    SceneProfile::from_toml(&text, Path::new("t.toml")).map(|s| s.atmosphere)
}

fn profiles() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/profiles"))
}

#[test]
fn sounding_path_is_relative_to_the_profile_directory() {
    let s = spec("sounding = \"soundings/oun-1999-05-04-00z.txt\"\n").unwrap();
    assert_eq!(s.pressure_model(), PressureModel::Observed);
    let env = s.build(profiles()).unwrap();
    let direct = Sounding::load(&profiles().join("soundings/oun-1999-05-04-00z.txt"))
        .unwrap()
        .to_environment()
        .unwrap();
    assert_eq!(env, direct);
    // From another directory the same relative path is not found, and the
    // error names the path it tried.
    let msg = s.build(Path::new("/nonexistent")).unwrap_err().to_string();
    assert!(
        msg.contains("/nonexistent/soundings/oun-1999-05-04-00z.txt"),
        "{msg}"
    );
}

#[test]
fn sounding_with_hydrostatic_pressure_stays_close_to_observed() {
    // Recomputing pressure from the sounding's own θ_v must agree with the
    // radiosonde's pressures to the accuracy of its heights (±~10 m ≈ 1 hPa)
    // plus linear interpolation of θ between levels: 3 hPa at 300 hPa.
    let s = spec("sounding = \"soundings/oun-2011-05-22-12z.txt\"\npressure = \"hydrostatic\"\n")
        .unwrap();
    let env = s.build(profiles()).unwrap();
    let obs = spec("sounding = \"soundings/oun-2011-05-22-12z.txt\"\n")
        .unwrap()
        .build(profiles())
        .unwrap();
    for z in [1000.0, 5000.0, 9000.0] {
        let (a, b) = (env.pressure_pa(z) / 100.0, obs.pressure_pa(z) / 100.0);
        assert!((a - b).abs() < 3.0, "z = {z}: {a} vs {b} hPa");
    }
}

#[test]
fn inline_points_give_back_their_temperature_and_humidity() {
    let s = spec(
        "surface_pressure_hpa = 950.0\n\
         [[atmosphere.points]]\nz_m = 0.0\nt_c = 20.0\nrh_percent = 50.0\n\
         [[atmosphere.points]]\nz_m = 3000.0\nt_c = 0.0\ntd_c = -5.0\n",
    )
    .unwrap();
    let env = s.build(Path::new(".")).unwrap();
    assert!((env.pressure_pa(0.0) - 95_000.0).abs() < 1e-6);
    assert!((env.temperature_k(3000.0) - 273.15).abs() < 0.01);
    assert!((env.dewpoint_k(3000.0) - 268.15).abs() < 0.01);
    let p0 = env.pressure_pa(0.0);
    let rh =
        thermo::vapour_pressure_pa(env.qv(0.0), p0) / thermo::saturation_vapour_pressure_pa(293.15);
    assert!((rh - 0.5).abs() < 1e-9, "RH {rh}");
}

#[test]
fn paper_exponential_pressure_is_the_papers_formula() {
    let s = spec(
        "pressure = \"paper_exponential\"\n\
         [[atmosphere.points]]\nz_m = 0.0\nt_c = 20.0\ntd_c = 10.0\n\
         [[atmosphere.points]]\nz_m = 5000.0\nt_c = -12.0\ntd_c = -20.0\n",
    )
    .unwrap();
    let env = s.build(Path::new(".")).unwrap();
    let expect = 100_000.0 * (-0.143_f64 * 5.0).exp();
    assert!((env.pressure_pa(5000.0) - expect).abs() < 1e-6);
    assert!((env.temperature_k(5000.0) - 261.15).abs() < 1e-9);
}

#[test]
fn validation_names_the_field_and_what_is_allowed() {
    let cases = [
        (
            "sounding = \"x.txt\"\n[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\ntd_c = 0.0\n",
            "atmosphere.points",
            "not both",
        ),
        (
            "pressure = \"observed\"\n[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\ntd_c = 0.0\n[[atmosphere.points]]\nz_m = 10.0\nt_c = 1.0\ntd_c = 0.0\n",
            "atmosphere.pressure",
            "needs a sounding",
        ),
        (
            "[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\ntd_c = 0.0\n",
            "atmosphere.points",
            "at least 2",
        ),
        (
            "[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\ntd_c = 3.0\n[[atmosphere.points]]\nz_m = 10.0\nt_c = 1.0\ntd_c = 0.0\n",
            "atmosphere.points[0].td_c",
            "up to the temperature",
        ),
        (
            "[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\ntd_c = 0.0\n[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\ntd_c = 0.0\n",
            "atmosphere.points[1].z_m",
            "increase strictly",
        ),
        (
            "[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\n[[atmosphere.points]]\nz_m = 10.0\nt_c = 1.0\ntd_c = 0.0\n",
            "atmosphere.points[0].td_c",
            "exactly one of td_c and rh_percent",
        ),
        (
            "surface_pressure_hpa = 2000.0\n[[atmosphere.points]]\nz_m = 0.0\nt_c = 1.0\ntd_c = 0.0\n[[atmosphere.points]]\nz_m = 10.0\nt_c = 1.0\ntd_c = 0.0\n",
            "atmosphere.surface_pressure_hpa",
            "between 500 and 1100 hPa",
        ),
    ];
    for (text, field, allowed) in cases {
        let msg = spec(text).unwrap().validate().unwrap_err().to_string();
        assert!(msg.contains(field) && msg.contains(allowed), "{msg}");
    }
    // Unknown keys are TOML errors with line and column.
    let msg = spec("sondage = \"x\"\n").unwrap_err().to_string();
    assert!(msg.starts_with("t.toml:4:1:"), "{msg}");
}

#[test]
fn sampled_points_rebuild_a_similar_atmosphere() {
    let env = Sounding::load(&profiles().join("soundings/oun-1999-05-04-00z.txt"))
        .unwrap()
        .to_environment()
        .unwrap();
    let s = AtmosphereSpec::inline_points_from(&env, 30);
    assert_eq!(s.points.len(), 30);
    assert_eq!(s.points[0].z_m, 0.0);
    s.validate().unwrap();
    let rebuilt = s.build(Path::new(".")).unwrap();
    // Points are rounded to 0.1 °C; hydrostatic pressure recomputed from the
    // sampled θ_v differs from the radiosonde's by ~1 hPa: 0.5 K in T.
    for p in &s.points {
        let d = rebuilt.temperature_k(p.z_m) - env.temperature_k(p.z_m);
        assert!(d.abs() < 0.5, "z = {}: ΔT = {d}", p.z_m);
    }
    // The surface parcel sees nearly the same LCL (sampling smooths the
    // profile between points but the surface values are kept).
    let a = lift_surface_parcel(&env, &LiftOptions::default()).unwrap();
    let b = lift_surface_parcel(&rebuilt, &LiftOptions::default()).unwrap();
    let (za, zb) = (a.lcl.unwrap().z_m, b.lcl.unwrap().z_m);
    assert!((za - zb).abs() < 30.0, "{za} vs {zb}");
    // The TOML written back by the window parses to the same spec.
    let text = toml::to_string(&s).unwrap();
    let back: AtmosphereSpec = toml::from_str(&text).unwrap();
    assert_eq!(back, s);
}

#[test]
fn default_spec_is_a_valid_fair_weather_profile() {
    let s = AtmosphereSpec::default();
    s.validate().unwrap();
    assert!(s.points.iter().all(|p: &AtmospherePoint| p.td_c.is_some()));
    s.build(Path::new(".")).unwrap();
}

#[test]
fn a_scene_without_an_atmosphere_table_gets_the_fair_weather_default() {
    let scene = SceneProfile::from_toml("name = \"t\"\n", Path::new("t.toml")).unwrap();
    assert_eq!(scene.atmosphere, AtmosphereSpec::default());
    // A table without points or sounding is an error, not a silent default.
    let msg = spec("surface_pressure_hpa = 950.0\n")
        .unwrap()
        .validate()
        .unwrap_err()
        .to_string();
    assert!(msg.contains("at least 2 points"), "{msg}");
}

#[test]
fn sampled_points_keep_the_capping_inversion() {
    // 12 evenly spaced points over the 16 km of the 2011 sounding would be
    // 1.5 km apart and step over the 890 hPa inversion (18.8 °C at 650 m
    // above the ground, 23.2 °C at 875 m: +4.4 K); significant-level
    // sampling keeps at least half of that warming.
    let env = Sounding::load(&profiles().join("soundings/oun-2011-05-22-12z.txt"))
        .unwrap()
        .to_environment()
        .unwrap();
    let s = AtmosphereSpec::inline_points_from(&env, 12);
    assert_eq!(s.points.len(), 12);
    let rise = s
        .points
        .windows(2)
        .filter(|w| w[1].z_m < 1500.0)
        .map(|w| w[1].t_c - w[0].t_c)
        .fold(f64::MIN, f64::max);
    assert!(
        rise >= 2.0,
        "warming with height below 1.5 km: {rise} K; {:?}",
        s.points
    );
    // Fewer levels than asked for: padded to n with strictly rising heights.
    let few = AtmosphereSpec::default().build(Path::new(".")).unwrap();
    let s = AtmosphereSpec::inline_points_from(&few, 20);
    assert_eq!(s.points.len(), 20);
    s.validate().unwrap();
}
