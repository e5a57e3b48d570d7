//! `--set TABLE.KEY=VALUE` scene overrides (src/scene/set.rs): applied to
//! the TOML before validation, so they pass the file's checks; errors name
//! the key, the value and what is allowed; wired into `cumulus simulate`.

use std::path::Path;

use crate::common::{self, cli};

use cumulus::methods::slices::model::MediaFilter;
use cumulus::scene::load_scene_with;

fn authored() -> &'static Path {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/profiles/authored.toml"
    ))
}

fn set(overrides: &[&str]) -> cumulus::Result<cumulus::scene::SceneProfile> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    load_scene_with(Some(authored()), &o).map(|(p, _)| p)
}

fn err(overrides: &[&str]) -> String {
    set(overrides).unwrap_err().to_string()
}

#[test]
fn overrides_set_values_tables_and_array_entries() {
    let plain = set(&[]).unwrap();
    assert_eq!(plain.render.slices.quality, 128);
    let p = set(&[
        "render.slices.quality=64",
        "render.slices.opacity = 0.5",
        "render.slices.base.torque_deg_s=[0.0, 0.0, 2.0]",
        "ellipsoids[4].strength=0.25",
        "render.slices.tiers[1].media=cirrus",
        "physics.mixing=false",
        "render.slices.quality=32",
    ])
    .unwrap();
    assert_eq!(p.render.slices.quality, 32, "later overrides win");
    assert_eq!(p.render.slices.opacity, 0.5);
    assert_eq!(p.render.slices.base.torque_deg_s, [0.0, 0.0, 2.0]);
    assert_eq!(p.ellipsoids[4].strength, 0.25);
    assert_eq!(
        p.render.slices.tiers[1].media,
        MediaFilter::Cirrus,
        "a bare word is a string"
    );
    assert!(!p.physics.mixing);
    // Everything else is untouched.
    assert_eq!(p.ellipsoids[3], plain.ellipsoids[3]);
    assert_eq!(p.render.slices.tiers[0], plain.render.slices.tiers[0]);
    // A table the file leaves out is created.
    let q = load_scene_with(None, &["render.terrain.height_scale_m=123.0".to_string()])
        .unwrap()
        .0;
    assert_eq!(q.render.terrain.height_scale_m, 123.0);
}

#[test]
fn bad_overrides_name_the_key_the_value_and_what_is_allowed() {
    assert_eq!(
        err(&["render.slices.quality=4"]),
        "invalid --set render.slices.quality = 4: 8 to 1024 slicing planes"
    );
    let e = err(&["render.slices.cloud_colour=[1.0, 7.0, 1.0]"]);
    assert_eq!(
        e,
        "invalid --set render.slices.cloud_colour = [1.0, 7.0, 1.0]: render.slices.cloud_colour[1] = 7: painted (sRGB) RGB, each 0 to 1"
    );
    let e = err(&["render.step_m=abc"]);
    assert!(
        e.starts_with("invalid --set render.step_m = abc:") && e.contains("expected"),
        "{e}"
    );
    let e = err(&["render.slices.qualty=3"]);
    assert!(
        e.starts_with("invalid --set render.slices.qualty = 3:")
            && e.contains("unknown field `qualty`"),
        "{e}"
    );
    let e = err(&["ellipsoids[18].strength=1"]);
    assert!(
        e.contains("--set ellipsoids[18].strength") && e.contains("has 18 entries"),
        "{e}"
    );
    let e = err(&["render.sun_azimuth_deg.x=1"]);
    assert!(
        e.contains("`render.sun_azimuth_deg` is a value, not a table"),
        "{e}"
    );
    // A key the file leaves out is created as a table, which its type refuses.
    let e = err(&["render.step_m.x=1"]);
    assert!(
        e.starts_with("invalid --set render.step_m.x = 1:") && e.contains("expected f32"),
        "{e}"
    );
    let e = err(&["render.slices.tiers[0].media=sparkly"]);
    assert!(
        e.contains("--set render.slices.tiers[0].media") && e.contains("sparkly"),
        "{e}"
    );
    assert!(err(&["render.slices.quality"]).contains("no '='"));
    assert!(err(&["render..quality=3"]).contains("is not a key"));
    assert!(err(&["render.slices.quality="]).contains("no value"));
    assert!(err(&["ellipsoids[x].strength=1"]).contains("not a whole number"));
    // NaN is a value TOML can write, and is refused like in the file.
    assert_eq!(
        err(&["ellipsoids[0].strength=nan"]),
        "invalid --set ellipsoids[0].strength = nan: 0 to 4"
    );
}

#[test]
fn the_file_keeps_its_own_errors_and_overrides_can_fix_them() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(
        &path,
        format!(
            "name = \"x\"\n\n[render.slices]\nquality = 2\n{}",
            common::ATMOSPHERE_TOML
        ),
    )
    .unwrap();
    let e = load_scene_with(Some(&path), &["render.slices.opacity=0.5".to_string()])
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        format!(
            "{}:4:1: invalid render.slices.quality = 2: 8 to 1024 slicing planes",
            path.display()
        )
    );
    let fixed = load_scene_with(Some(&path), &["render.slices.quality=16".to_string()])
        .unwrap()
        .0;
    assert_eq!(fixed.render.slices.quality, 16);
}

#[test]
fn simulate_takes_set_overrides() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.csv");
    let run = |set: &str| {
        cli::run_command(
            cli::command()
                .args([
                    "simulate",
                    "--duration",
                    "4",
                    "--dt",
                    "2",
                    "--set",
                    set,
                    "--out",
                ])
                .arg(&out),
        )
    };
    run("physics.stiffness=-3")
        .expect_failure_containing(&["invalid --set physics.stiffness = -3"]);
    assert!(!out.exists(), "nothing written on bad input");
    run("emission.enabled=false").expect_success();
    let csv = std::fs::read_to_string(&out).unwrap();
    // Header and two frames; no emission → no parcels.
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(
        csv.lines()
            .skip(1)
            .all(|l| l.split(',').nth(1) == Some("0")),
        "{csv}"
    );
}

#[test]
fn bench_takes_set_overrides() {
    // The methods table's scenes load with the overrides, validated as a
    // file is, and an override that does not suit one names that scene.
    let o = |s: &str| vec![s.to_string()];
    let p = cumulus::bench::methods::load_profile("authored.toml", &o("render.slices.quality=16"))
        .unwrap();
    assert_eq!(p.render.slices.quality, 16);
    let e =
        cumulus::bench::methods::load_profile("fair_weather.toml", &o("ellipsoids[0].strength=1"))
            .unwrap_err()
            .to_string();
    assert!(
        e.contains("--set ellipsoids[0].strength") && e.contains("bench scene fair_weather.toml"),
        "{e}"
    );
    // The binary checks them before opening a device or measuring.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    cli::run_command(
        cli::command()
            .args([
                "bench",
                "--tiny",
                "--set",
                "render.slices.quality=4",
                "--out",
            ])
            .arg(&out),
    )
    .expect_failure_containing(&[
        "invalid --set render.slices.quality = 4: 8 to 1024 slicing planes",
    ]);
    assert!(!out.exists(), "nothing written on bad input");
}
