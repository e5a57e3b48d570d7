//! `cumulus export` and the `.vol` writer: the file round-trips (header,
//! dimensions, bounds, values), one analytic sphere exports to the voxel
//! values eq. 18 gives by hand, and bad arguments fail with a clear message
//! leaving no file behind. No GPU needed: the density is evaluated on the CPU.

use cumulus::config::RenderConfig;
use cumulus::export::sidecar::Sidecar;
use cumulus::export::{GridSpec, read_vol, sample_grid, vol_grid, write_vol};
use cumulus::methods::raymarch::field::CloudField;
use cumulus::physics::CloudParcel;
use glam::Vec3;

use crate::common::cli;

#[test]
fn vol_round_trip_keeps_header_dims_bounds_and_values() {
    let spec = GridSpec::covering(
        Vec3::new(-30.0, 5.0, 1000.0),
        Vec3::new(10.0, 25.0, 1010.0),
        10.0,
        1,
    )
    .unwrap();
    assert_eq!(spec.dims, [4, 2, 1]);
    let values: Vec<f32> = (0..8).map(|i| i as f32 * 0.125 - 0.3).collect();
    let grid = vol_grid(&spec, values.clone());
    let mut bytes = Vec::new();
    write_vol(&mut bytes, &grid).unwrap();
    assert_eq!(bytes.len() as u64, grid.file_bytes());
    // Header as Mitsuba 3 reads it: "VOL", version 3, encoding 1 (float32),
    // dims, 1 channel, then the box.
    assert_eq!(&bytes[..4], b"VOL\x03");
    let i32_at = |o: usize| i32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    assert_eq!(
        [i32_at(4), i32_at(8), i32_at(12), i32_at(16), i32_at(20)],
        [1, 4, 2, 1, 1]
    );
    let back = read_vol(&bytes, "t.vol").unwrap();
    assert_eq!(back, grid);
    assert_eq!(back.min, [-30.0, 5.0, 1000.0]);
    assert_eq!(back.max, [10.0, 25.0, 1010.0]);
    assert_eq!(back.values, values);
    // A truncated file is an error naming the file and the expected size.
    let e = read_vol(&bytes[..bytes.len() - 4], "t.vol")
        .unwrap_err()
        .to_string();
    assert!(e.contains("t.vol") && e.contains("80"), "{e}");
}

/// ρ of one sphere without noise, by hand from eq. 18: d = clamp(min((r −
/// |P − c|)/shell, (z − z_plane)/(0.3·shell)), −1, 1), v = f(d + 1) − 1,
/// ρ = smoothstep(0, 1, v).
fn sphere_rho(p: Vec3, c: Vec3, r: f32, shell: f32, plane: f32, f: f32) -> f32 {
    let d = ((r - p.distance(c)) / shell)
        .min((p.z - plane) / (0.3 * shell))
        .clamp(-1.0, 1.0);
    let v = (f * (d + 1.0) - 1.0).clamp(0.0, 1.0);
    v * v * (3.0 - 2.0 * v)
}

#[test]
fn one_analytic_sphere_exports_to_the_expected_voxel_values() {
    let c = Vec3::new(0.0, 0.0, 1500.0);
    let (r, shell, plane) = (300.0, 100.0, 1350.0);
    let cfg = RenderConfig {
        noise_amplitude: 0.0,
        radius_scale: 1.0,
        shell_m: shell,
        ..RenderConfig::default()
    };
    let parcel = |f: f32| CloudParcel {
        id: 0,
        center_m: c,
        radius_m: r,
        fill: f,
        cond_plane_z_m: plane,
    };
    let full = CloudField::new(&[parcel(1.0)], &cfg, 0.0).unwrap();
    // Points whose value is known without the formula: the centre is a full
    // shell inside (ρ = 1); half a shell inside the sphere d = ½ → ρ = ½;
    // half the plane's shell above the base d = ½ → ρ = ½; beyond → 0.
    let checks = [
        (c, 1.0),
        (c + Vec3::new(r - 0.5 * shell, 0.0, 0.0), 0.5),
        (Vec3::new(0.0, 0.0, plane + 0.15 * shell), 0.5),
        (c + Vec3::new(0.0, r + 10.0, 0.0), 0.0),
        (Vec3::new(0.0, 0.0, plane - 5.0), 0.0),
    ];
    for (p, want) in checks {
        // 1e-5: float rounding of the distance and of smoothstep only.
        assert!(
            (full.density(p) - want).abs() < 1e-5,
            "{p} {} {want}",
            full.density(p)
        );
    }
    // Every voxel of the exported grid, through the .vol file, equals the
    // hand formula at its centre (f = 0.8: the sponge regime of eq. 18 too).
    for f in [1.0, 0.8] {
        let field = CloudField::new(&[parcel(f)], &cfg, 0.0).unwrap();
        let (lo, hi) = field.bounds();
        let spec = GridSpec::covering(lo, hi, 25.0, 64).unwrap();
        let values = sample_grid(&spec, |p| field.density(p), |_, _| {});
        let mut bytes = Vec::new();
        write_vol(&mut bytes, &vol_grid(&spec, values)).unwrap();
        let back = read_vol(&bytes, "sphere.vol").unwrap();
        let [nx, ny, nz] = spec.dims;
        let mut inside = 0;
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let got = back.values[(x + nx * (y + ny * z)) as usize];
                    let want = sphere_rho(spec.centre(x, y, z), c, r, shell, plane, f);
                    // 1e-5: float rounding only (same formula, same point).
                    assert!(
                        (got - want).abs() < 1e-5,
                        "f {f} cell {x},{y},{z}: {got} vs {want}"
                    );
                    inside += (got > 0.0) as u32;
                }
            }
        }
        assert!(
            inside > 100,
            "the sphere shows up in the grid ({inside} cells)"
        );
    }
}

#[test]
fn export_writes_a_vol_and_its_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("clouds.vol");
    let export = |out: &std::path::Path| {
        cli::run_command(
            cli::command()
                .args([
                    "export",
                    "--stand-in",
                    "--time",
                    "1200",
                    "--voxel",
                    "150",
                    "--out",
                ])
                .arg(out),
        )
        .expect_success()
    };
    let stderr = export(&out);
    assert!(stderr.contains("MiB"), "memory is stated: {stderr}");
    let grid = read_vol(&std::fs::read(&out).unwrap(), "clouds.vol").unwrap();
    let side: Sidecar =
        serde_json::from_slice(&std::fs::read(dir.path().join("clouds.json")).unwrap()).unwrap();
    assert_eq!(side.volume.dims, grid.dims);
    assert_eq!(side.volume.bounds_min_m, grid.min);
    assert_eq!(side.volume.bounds_max_m, grid.max);
    assert_eq!(side.volume.file, "clouds.vol");
    assert!(grid.values.iter().all(|v| (0.0..=1.0).contains(v)));
    assert!(
        grid.values.iter().any(|&v| v > 0.5),
        "the stand-in towers are dense"
    );
    // Deterministic: the same export again is byte-identical.
    let again = dir.path().join("again.vol");
    export(&again);
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn bad_export_arguments_fail_clearly_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let blocker = dir.path().join("a_file");
    std::fs::write(&blocker, b"x").unwrap();
    let cases: [(&[&str], std::path::PathBuf, &str); 5] = [
        (&["--voxel", "0"], dir.path().join("a.vol"), "--voxel"),
        (&["--voxel", "-5"], dir.path().join("b.vol"), "--voxel"),
        (&["--voxel", "NaN"], dir.path().join("c.vol"), "--voxel"),
        // 1 m voxels over a 10 km stand-in field: far over 1 MiB.
        (
            &["--voxel", "1", "--max-memory-mib", "1"],
            dir.path().join("d.vol"),
            "--max-memory-mib",
        ),
        // A directory that cannot exist: its parent is a file.
        (
            &["--voxel", "200"],
            blocker.join("e.vol"),
            "is a file, not a folder",
        ),
    ];
    for (extra, out, needle) in cases {
        cli::run_command(
            cli::command()
                .args(["export", "--stand-in", "--time", "1200"])
                .args(extra)
                .arg("--out")
                .arg(&out),
        )
        .expect_failure_containing(&[needle]);
        assert!(
            !out.exists() && !out.with_extension("json").exists(),
            "{extra:?} left a file"
        );
    }
    // Nothing but the blocker in the directory: no temporary files either.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}
