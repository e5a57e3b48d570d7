//! `cumulus simulate` end to end: a short run writes a CSV with one row per
//! frame; bad arguments fail with a clear message.

use std::process::Command;

fn cumulus() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cumulus"))
}

#[test]
fn simulate_writes_one_row_per_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diag.csv");
    let status = cumulus()
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
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
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
    let err = String::from_utf8_lossy(&status.stderr);
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
    let o = cumulus()
        .args(["simulate", "--duration", "10", "--out"])
        .arg(&out)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("empty.toml"), "{err}");
    assert!(
        err.contains("[atmosphere]") && err.contains("sounding"),
        "{err}"
    );
    assert!(!out.exists(), "nothing is written on error");
}

#[test]
fn simulate_rejects_a_bad_step() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diag.csv");
    let o = cumulus()
        .args(["simulate", "--duration", "10", "--dt", "0", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--dt"), "{err}");
    assert!(!out.exists(), "nothing is written on error");
}
