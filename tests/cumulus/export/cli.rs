//! The `cumulus export` command's defaults and refusals: it opens at the
//! scene's start time as `render` does (a numbered series too), a default
//! grid over `--max-memory-mib` gets the finest voxel that fits and says
//! so while a forced `--voxel` that does not fit is an error naming one
//! that does, and an `--out` other than `.vol` or `.vdb` is refused before anything
//! is written. The stand-in field keeps them fast; no GPU needed.

use std::path::Path;

use cumulus::export::read_vol;
use cumulus::export::sidecar::Sidecar;

use crate::common::cli;

fn sidecar(path: &Path) -> Sidecar {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

#[test]
fn export_opens_at_the_scene_start_time_and_numbers_a_series() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("start.vol");
    // The stand-in field at a coarse voxel, its scene opening at 600 s:
    // neither the embedded scene's start_s (1800 s) nor the old fixed
    // default (1800 s).
    let export = |extra: &[&str], to: &Path| {
        cli::run_command(
            cli::command()
                .args(["export", "--stand-in", "--set", "simulation.start_s=600"])
                .args(["--voxel", "300"])
                .args(extra)
                .arg("--out")
                .arg(to),
        )
        .expect_success();
    };
    export(&[], &out);
    assert_eq!(sidecar(&dir.path().join("start.json")).time_s, 600.0);

    let series = dir.path().join("series.vol");
    export(&["--frames", "2", "--every", "90"], &series);
    assert!(!series.exists(), "a series writes numbered files only");
    for (i, t) in [(0, 600.0), (1, 690.0)] {
        let vol = dir.path().join(format!("series-000{i}.vol"));
        let side = sidecar(&vol.with_extension("json"));
        assert_eq!(side.time_s, t);
        let grid = read_vol(&std::fs::read(&vol).unwrap(), "series").unwrap();
        assert_eq!(side.volume.dims, grid.dims);
    }
}

#[test]
fn a_default_grid_over_the_memory_cap_gets_coarser_voxels_a_forced_one_fails() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fit.vol");
    // The stand-in's 10 km of towers at the default voxel take far more
    // than 1 MiB.
    let stderr = cli::run_command(
        cli::command()
            .args(["export", "--stand-in", "--max-memory-mib", "1", "--out"])
            .arg(&out),
    )
    .expect_success();
    assert!(
        stderr.contains("instead of") && stderr.contains("--max-memory-mib 1"),
        "says why the voxel is coarser: {stderr}"
    );
    let grid = read_vol(&std::fs::read(&out).unwrap(), "fit.vol").unwrap();
    assert!(grid.values.len() * 4 <= 1 << 20, "{:?}", grid.dims);
    assert!(grid.values.iter().any(|&v| v > 0.0));

    let forced = dir.path().join("forced.vol");
    cli::run_command(
        cli::command()
            .args([
                "export",
                "--stand-in",
                "--max-memory-mib",
                "1",
                "--voxel",
                "20",
                "--out",
            ])
            .arg(&forced),
    )
    .expect_failure_containing(&["--voxel", "--max-memory-mib", "or more fits"]);
    assert!(!forced.exists() && !forced.with_extension("json").exists());
}

#[test]
fn export_refuses_an_extension_it_cannot_write() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["clouds.vd", "clouds.json", "clouds.png", "clouds"] {
        let out = dir.path().join(name);
        cli::run_command(
            cli::command()
                .args(["export", "--stand-in", "--voxel", "300", "--out"])
                .arg(&out),
        )
        .expect_failure_containing(&["--out", name, ".vol", ".vdb"]);
    }
    // Nothing written, not even a temporary file.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
