//! `cumulus bench --gpu-check` end to end as a user runs it, at a small
//! size on the CPU adapter: one command writes the one-page table
//! (adapter, driver, resolution, commit, a row per goal) and its CSV,
//! every time measured and positive; on a CPU adapter no goal is judged.
//! Without an adapter it fails like every GPU test (`common::gpu`).

use crate::common::{self, cli};

#[test]
fn gpu_check_writes_the_goals_table() {
    if common::context("gpu check").is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("check");
    let run = cli::run_command(
        cli::command()
            .env("CUMULUS_COMMIT", "abc1234")
            .args([
                "bench",
                "--gpu-check",
                "--width",
                "64",
                "--height",
                "36",
                "--out",
            ])
            .arg(&out),
    );
    let stderr = run.expect_success();
    let md = std::fs::read_to_string(out.join("gpu-check.md")).unwrap();
    assert_eq!(run.stdout(), md, "the table is printed as written");
    for want in [
        "| adapter | ",
        "| driver | ",
        "| resolution | 64×36 |",
        "| commit | abc1234 (release build) |",
        "| default scene (fair weather, baked) | 64×36 |",
        "| landscape, full-rate march |",
        "| landscape, temporal amortisation |",
        "| 10000 parcels (bench field, baked) |",
        // The paper's 730×545 scaled like 1920×1080 → 64×36.
        "| 85 parcels (bench field, baked) | 24×18 |",
        "| 100 km overcast by sprites |",
        "| authored scene by slices, Quality 128 |",
    ] {
        assert!(md.contains(want), "{want:?} not in\n{md}\n{stderr}");
    }
    let mut r = csv::Reader::from_path(out.join("gpu-check.csv")).unwrap();
    let rows: Vec<csv::StringRecord> = r.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 8, "{md}");
    for row in &rows {
        for i in [4, 5] {
            let v: f64 = row[i].parse().unwrap();
            assert!(v.is_finite() && v > 0.0, "{row:?}");
        }
        // The parts add up to the clouds' time (each written to 3
        // decimals: within half a thousandth each).
        let parts: Vec<f64> = row[7]
            .split(" · ")
            .map(|p| p.rsplit_once(' ').unwrap().1.parse().unwrap())
            .collect();
        let clouds: f64 = row[4].parse().unwrap();
        let sum: f64 = parts.iter().sum();
        assert!(
            (sum - clouds).abs() <= 5e-4 * parts.len() as f64 + 1e-9,
            "{row:?}"
        );
    }
    // Six goals, each with its verdict: judged on a GPU, not on a CPU one.
    let goals = rows.iter().filter(|r| !r[6].is_empty()).count();
    assert_eq!(goals, 6, "{md}");
    let judged = md.matches("| pass |").count() + md.matches("| **FAIL** |").count();
    if md.contains("not judged (CPU adapter)") {
        assert_eq!(judged, 0, "{md}");
    } else {
        assert_eq!(judged, 6, "{md}");
    }
}
