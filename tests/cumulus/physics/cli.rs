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
