//! `cumulus parcel` end to end: JSON keys and values (CAPE/CIN of the sb,
//! ml and mu parcels), `--parcel`, the Skew-T PNG with its hodograph, and a
//! bad sounding's error message and exit status.

use std::path::Path;

use crate::common::cli;

const OUN_2011: &str = "profiles/soundings/oun-2011-05-22-12z.txt";

#[test]
fn json_has_the_documented_keys_and_values() {
    let out = cli::run(["parcel", "--sounding", OUN_2011, "--json"]);
    out.expect_success();
    let v: serde_json::Value =
        serde_json::from_slice(&out.output.stdout).expect("exactly one JSON object");
    let obj = v.as_object().unwrap();
    for key in [
        "lcl_hpa", "lcl_m", "lfc_hpa", "lfc_m", "el_hpa", "el_m", "levels",
    ] {
        assert!(obj.contains_key(key), "missing {key}");
    }
    // MetPy's LCL on this sounding is 949.0 hPa (atmosphere::metpy).
    let lcl = v["lcl_hpa"].as_f64().unwrap();
    assert!((lcl - 949.0).abs() < 5.0, "{lcl}");
    // 966 → 949 hPa is about 150 m.
    let lcl_m = v["lcl_m"].as_f64().unwrap();
    assert!((100.0..250.0).contains(&lcl_m), "{lcl_m}");
    // The capping inversion near 890 hPa holds the parcel down to ~740 hPa,
    // and the tropopause stops it near 200 hPa.
    let lfc = v["lfc_hpa"].as_f64().unwrap();
    let el = v["el_hpa"].as_f64().unwrap();
    assert!(
        (650.0..850.0).contains(&lfc) && (150.0..300.0).contains(&el),
        "{lfc} {el}"
    );
    let levels = v["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 70, "one entry per usable sounding level");
    let first = &levels[0];
    for key in [
        "p_hpa", "z_m", "t_k", "tv_k", "env_t_k", "env_tv_k", "qv_gkg", "ql_gkg",
    ] {
        assert!(first[key].is_number(), "levels[0].{key}");
    }
    assert_eq!(first["p_hpa"].as_f64().unwrap(), 966.0);
    assert_eq!(first["z_m"].as_f64().unwrap(), 0.0);
    assert!((first["t_k"].as_f64().unwrap() - 295.35).abs() < 1e-9);
    let last = levels.last().unwrap();
    assert!((last["p_hpa"].as_f64().unwrap() - 100.0).abs() < 1e-9);
    assert_eq!(last["z_m"].as_f64().unwrap(), 16_410.0 - 345.0);
    // By default the forecasters' pseudo-adiabatic parcel: its condensate
    // falls out, and the output says so.
    assert_eq!(v["thermo"], "standard");
    assert_eq!(v["lfc_choice"], "most_cape");
    assert_eq!(last["ql_gkg"].as_f64().unwrap(), 0.0, "pseudo-adiabatic");
    let model = cli::run([
        "parcel",
        "--sounding",
        OUN_2011,
        "--json",
        "--thermo",
        "model",
    ]);
    model.expect_success();
    let m: serde_json::Value = serde_json::from_slice(&model.output.stdout).unwrap();
    assert_eq!(m["thermo"], "model");
    let last = m["levels"].as_array().unwrap().last().unwrap().clone();
    assert!(
        last["ql_gkg"].as_f64().unwrap() > 10.0,
        "the model's reversible parcel keeps its water"
    );
}

#[test]
fn plot_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("skewt.png");
    cli::run_command(
        cli::command()
            .args(["parcel", "--sounding", OUN_2011, "--plot"])
            .arg(&png),
    )
    .expect_success();
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    let img = image::load_from_memory(&bytes).unwrap();
    // 900 px of diagram and the 400 px side panel with the hodograph.
    assert_eq!((img.width(), img.height()), (1300, 1000));
    // Something is drawn: many non-white pixels, and the red environment curve.
    let rgb = img.to_rgb8();
    let ink = rgb.pixels().filter(|p| p.0 != [255, 255, 255]).count();
    assert!(ink > 50_000, "{ink} drawn pixels");
    assert!(
        rgb.pixels().any(|p| p.0 == [210, 20, 20]),
        "environment temperature curve"
    );
    // The hodograph's 0–1 km trace (its red) is in the side panel only.
    let side_has = |c: [u8; 3]| rgb.enumerate_pixels().any(|(x, _, p)| x >= 900 && p.0 == c);
    assert!(side_has([220, 30, 30]), "0–1 km hodograph trace");
    assert!(side_has([30, 160, 40]), "1–3 km hodograph trace");
}

/// Runs `cumulus parcel --json` with extra arguments and parses the object.
fn parcel_json(extra: &[&str]) -> serde_json::Value {
    let out = cli::run(
        ["parcel", "--sounding", OUN_2011, "--json"]
            .iter()
            .chain(extra),
    );
    out.expect_success();
    serde_json::from_slice(&out.output.stdout).expect("exactly one JSON object")
}

#[test]
fn json_has_cape_and_cin_of_the_three_parcels() {
    let v = parcel_json(&[]);
    // Top level: the surface parcel (MetPy: 3297 J/kg, −129 J/kg; the 5 %
    // agreement is atmosphere::cape, here only plausibility).
    let cape = v["cape_j_per_kg"].as_f64().unwrap();
    let cin = v["cin_j_per_kg"].as_f64().unwrap();
    assert!(
        (3000.0..3600.0).contains(&cape) && (-200.0..-50.0).contains(&cin),
        "{cape} {cin}"
    );
    assert_eq!(v["lifted_parcel"], "sb");
    let parcels = v["parcels"].as_object().unwrap();
    assert_eq!(parcels.len(), 3);
    for key in ["sb", "ml", "mu"] {
        let p = parcels[key]
            .as_object()
            .unwrap_or_else(|| panic!("parcels.{key}"));
        for k in [
            "lcl_hpa",
            "lcl_m",
            "lfc_hpa",
            "lfc_m",
            "el_hpa",
            "el_m",
            "cape_j_per_kg",
            "cin_j_per_kg",
            "start_hpa",
            "start_m",
            "start_t_c",
            "start_td_c",
        ] {
            assert!(p[k].is_number(), "parcels.{key}.{k} = {}", p[k]);
        }
    }
    // The top level repeats the surface parcel.
    assert_eq!(v["parcels"]["sb"]["cape_j_per_kg"], v["cape_j_per_kg"]);
    assert_eq!(v["parcels"]["sb"]["lcl_hpa"], v["lcl_hpa"]);
    // MetPy's MU parcel starts at 886 hPa, above the nocturnal surface layer.
    // (1e-9: the pressure comes back through exp(ln P) interpolation.)
    assert!((v["parcels"]["mu"]["start_hpa"].as_f64().unwrap() - 886.0).abs() < 1e-9);
}

#[test]
fn parcel_option_chooses_the_lifted_parcel() {
    let v = parcel_json(&["--parcel", "mu"]);
    assert_eq!(v["lifted_parcel"], "mu");
    // Its levels start at its own start, 886 hPa; the top level stays sb.
    let first = &v["levels"][0];
    assert!((first["p_hpa"].as_f64().unwrap() - 886.0).abs() < 1e-9);
    assert_eq!(v["parcels"]["sb"]["cape_j_per_kg"], v["cape_j_per_kg"]);
    cli::run([
        "parcel",
        "--sounding",
        OUN_2011,
        "--parcel",
        "mu",
        "--dynamic",
    ])
    .expect_failure_containing(&["--parcel sb or ml"]);
    // "sb": it lists the allowed values.
    cli::run(["parcel", "--sounding", OUN_2011, "--parcel", "xx"])
        .expect_failure_containing(&["sb"]);
}

#[test]
fn bad_sounding_fails_with_file_line_column() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.txt");
    let good =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(OUN_2011)).unwrap();
    // Line 10 is the 936.9 hPa row; put text in its TEMP column.
    let text: String = good
        .lines()
        .enumerate()
        .map(|(i, l)| if i == 9 { l.replacen("  20.8", "  x0.8", 1) } else { l.to_string() } + "\n")
        .collect();
    std::fs::write(&bad, text).unwrap();
    let out = cli::run_command(
        cli::command()
            .args(["parcel", "--sounding"])
            .arg(&bad)
            .arg("--json"),
    );
    out.expect_failure_containing(&[&format!("{}:10:18:", bad.display()), "\"x0.8\"", "TEMP"]);
    assert!(out.output.stdout.is_empty(), "no JSON on failure");
}

#[test]
fn dynamic_release_reports_summary_trajectory_and_csv() {
    let dir = tempfile::tempdir().unwrap();
    let csv_path = dir.path().join("traj.csv");
    let out = cli::run_command(
        cli::command()
            .args([
                "parcel",
                "--sounding",
                "profiles/soundings/oun-2011-05-22-12z.txt",
                "--json",
                "--dynamic",
                "--temp-excess",
                "3",
                "--duration",
                "900",
                "--csv",
            ])
            .arg(&csv_path),
    );
    out.expect_success();
    let v: serde_json::Value = serde_json::from_slice(&out.output.stdout).unwrap();
    let d = &v["dynamic"];
    let zmax = d["max_altitude_m"].as_f64().unwrap();
    let lcl = v["lcl_m"].as_f64().unwrap();
    // A 3 K warm bubble under this morning's capping inversion (890–850 hPa,
    // ~0.7–1.1 km) rises past the LCL but cannot break the cap: it must top
    // out between the LCL and the top of the inversion.
    assert!(
        zmax > lcl && zmax < 1500.0,
        "max altitude {zmax} m, LCL {lcl} m"
    );
    let traj = d["trajectory"].as_array().unwrap();
    assert_eq!(traj.len(), 901, "one point per 1 s step plus the start");
    let csv = std::fs::read_to_string(&csv_path).unwrap();
    assert!(csv.starts_with("time_s,z_m,"));
    assert_eq!(csv.lines().count(), 902, "header + 901 rows");
}

#[test]
fn dynamic_flags_need_dynamic() {
    cli::run([
        "parcel",
        "--sounding",
        "profiles/soundings/oun-2011-05-22-12z.txt",
        "--mixing",
    ])
    .expect_failure_containing(&["--dynamic"]);
}

#[test]
fn bad_wind_fails_and_missing_wind_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let good =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(OUN_2011)).unwrap();
    // Line 10 is the 936.9 hPa row, wind 190° 28 kn: make the direction 390°.
    let bad = dir.path().join("bad_wind.txt");
    let text: String = good
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let l = if i == 9 {
                format!("{}    390{}", &l[..42], &l[49..])
            } else {
                l.to_string()
            };
            l + "\n"
        })
        .collect();
    std::fs::write(&bad, text).unwrap();
    cli::run_command(cli::command().args(["parcel", "--sounding"]).arg(&bad))
        .expect_failure_containing(&[&format!("{}:10:47:", bad.display()), "DRCT 390", "0 to 360"]);

    // The same sounding cut after DWPT: no wind columns at all is not an
    // error, and the output says there is no wind.
    let calm = dir.path().join("calm.txt");
    let text: String = good
        .lines()
        .map(|l| l.chars().take(28).collect::<String>() + "\n")
        .collect();
    std::fs::write(&calm, text).unwrap();
    let out = cli::run_command(cli::command().args(["parcel", "--sounding"]).arg(&calm));
    out.expect_success();
    let text = out.stdout();
    assert!(text.contains("wind: none in the sounding"), "{text}");
}

#[test]
fn blank_upper_dewpoints_and_no_wind_are_said_not_zeroed() {
    let tropical = "tests/data/soundings/constructed-tropical.txt";
    let out = cli::run(["parcel", "--sounding", tropical, "--json"]);
    out.expect_success();
    let v: serde_json::Value = serde_json::from_slice(&out.output.stdout).unwrap();
    // 1e-6 hPa: exp(ln p) of the observed pressure, rounding only.
    let top = v["humidity_top_hpa"].as_f64().unwrap();
    assert!((top - 400.0).abs() < 1e-6, "{top}");
    let idx = &v["indices"];
    assert!(idx["wind"].is_null(), "{idx}");
    assert_eq!(idx["wind_note"], "no wind data");
    assert!(
        idx["precipitable_water_mm"].as_f64().unwrap() > 40.0,
        "{idx}"
    );
    // The parcel reaches the tropopause, far above the last dewpoint.
    assert!(v["el_hpa"].as_f64().unwrap() < 200.0);
    let run = cli::run(["parcel", "--sounding", tropical]);
    run.expect_success();
    let text = run.stdout();
    for needle in [
        "humidity: no dewpoint above 400 hPa",
        "missing, not zero",
        "wind indices               no wind data",
        "thermodynamics: standard",
    ] {
        assert!(text.contains(needle), "{needle:?} not in\n{text}");
    }
    // Winds that end below 6 km: the 0-6 km indices say why they are missing.
    let nov11 = cli::run([
        "parcel",
        "--sounding",
        "tests/data/soundings/metpy-nov11.txt",
    ]);
    nov11.expect_success();
    let text = nov11.stdout();
    assert!(
        text.contains("bulk shear 0-6 km          n/a (wind data end at"),
        "{text}"
    );
}
