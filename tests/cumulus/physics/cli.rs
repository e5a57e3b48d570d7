//! `cumulus simulate` end to end: a short run writes a CSV with one row per
//! frame; bad arguments fail with a clear message.

use crate::common::cli;

#[test]
fn simulate_writes_one_row_per_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diag.csv");
    let err = cli::run_command(
        cli::command()
            .args([
                "simulate",
                "--duration",
                "120",
                "--dt",
                "2",
                "--seed",
                "3",
                "--out",
            ])
            .arg(&out),
    )
    .expect_success();
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("time_s,parcels,condensed_parcels,cloud_base_m,cloud_top_m,total_water_kg,kinetic_energy_j,substeps"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 60);
    let cols = header.split(',').count();
    for r in &rows {
        assert_eq!(r.split(',').count(), cols, "{r}");
        assert!(!r.contains("NaN") && !r.contains("inf"), "{r}");
    }
    assert!(rows[59].starts_with("120.000,"));
    // The clamp summary is a readable line, not Rust's Debug text.
    let line = err
        .lines()
        .find(|l| l.contains("clamps:"))
        .expect("a clamp line");
    assert!(
        !line.contains("ClampCounts") && !line.contains('{'),
        "{line}"
    );
    let counts = line.split("clamps: ").nth(1).unwrap();
    assert!(
        counts == "none" || counts.split(", ").all(|kv| kv.split(' ').count() == 2),
        "{counts}"
    );
}

#[test]
fn an_empty_profile_says_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, out) = (dir.path().join("empty.toml"), dir.path().join("d.csv"));
    std::fs::write(&scene, "").unwrap();
    cli::run_command(
        cli::command()
            .args(["simulate", "--duration", "10", "--out"])
            .arg(&out)
            .arg(&scene),
    )
    .expect_failure_containing(&["empty.toml", "[atmosphere]", "sounding"]);
    assert!(!out.exists(), "nothing is written on error");
}

#[test]
fn simulate_rejects_a_bad_step() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diag.csv");
    cli::run_command(
        cli::command()
            .args(["simulate", "--duration", "10", "--dt", "0", "--out"])
            .arg(&out),
    )
    .expect_failure_containing(&["--dt"]);
    assert!(!out.exists(), "nothing is written on error");
}

/// The CSV has one cumulative column per clamp kind (no `clamps_total`,
/// and no `opaque`: that is the display column `opaque_parcel_frames`) and
/// a `suppressed` column; the summary prints the same counts. A speed cap
/// of 0.5 m/s (thermals of a 2 K excess rise at metres per second) and room
/// for 3 parcels (the ground emits tens in 2 minutes) make both fire, so
/// the test fails if either is not reported.
#[test]
fn simulate_reports_clamps_by_kind_and_suppressed_emissions() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diag.csv");
    let err = cli::run_command(
        cli::command()
            .args(["simulate", "--duration", "120", "--dt", "2", "--seed", "3"])
            .args(["--set", "physics.max_speed_m_s=0.5"])
            .args(["--set", "emission.max_parcels=3"])
            .args(["--set", "emission.diurnal=false"])
            .args(["--set", "emission.rate_per_km2_per_h=300"])
            .arg("--out")
            .arg(&out),
    )
    .expect_success();
    let mut rdr = csv::Reader::from_path(&out).unwrap();
    let headers = rdr.headers().unwrap().clone();
    let names: Vec<&str> = headers.iter().collect();
    for kind in cumulus::physics::ClampCounts::default()
        .kinds()
        .map(|(k, _)| k)
    {
        assert!(
            names.contains(&format!("clamp_{kind}").as_str()),
            "{kind}: {names:?}"
        );
    }
    assert!(!names.contains(&"clamps_total"), "{names:?}");
    assert!(
        !names.contains(&"clamp_opaque"),
        "opaque is not a clamp: {names:?}"
    );
    assert!(names.contains(&"opaque_parcel_frames") && names.contains(&"suppressed"));
    let last = rdr.records().map(Result::unwrap).last().unwrap();
    let col = |n: &str| -> u64 {
        last[names.iter().position(|h| *h == n).unwrap()]
            .parse()
            .unwrap()
    };
    let (speed, suppressed) = (col("clamp_speed"), col("suppressed"));
    assert!(speed > 0, "a 0.5 m/s cap must clamp");
    assert!(suppressed > 0, "3 parcels at most must refuse emissions");
    let line = |start: &str| {
        err.lines()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no {start} line in {err}"))
            .to_string()
    };
    assert!(line("clamps:").contains(&format!("speed {speed}")), "{err}");
    assert!(
        line("suppressed:").contains(&format!("{suppressed} emissions refused at max_parcels")),
        "{err}"
    );
}

/// A scene that forms no cloud says so: it printed "cloud base  m, top  m"
/// and "first condensed parcel at t = never; peak 0 condensed parcels at
/// t = 0 s". A cloudy run keeps its numbers.
#[test]
fn simulate_says_when_no_cloud_formed() {
    let stderr =
        cli::run(["simulate", "profiles/stable_dry.toml", "--duration", "600"]).expect_success();
    assert!(
        stderr.contains("0 condensed, no cloud at the end;"),
        "{stderr}"
    );
    assert!(
        stderr.contains("no cloud formed: no parcel condensed in 600 s"),
        "{stderr}"
    );
    for empty in [" m, top ", "never", "peak 0"] {
        assert!(!stderr.contains(empty), "{empty:?} in {stderr}");
    }
    let stderr = cli::run(["simulate", "--duration", "600"]).expect_success();
    assert!(stderr.contains("cloud base "), "{stderr}");
    assert!(
        stderr.contains("first condensed parcel at t = "),
        "{stderr}"
    );
}
