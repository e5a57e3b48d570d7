//! `cumulus export` of an authored scene (Schpok 2003): the density the
//! slices method draws (implicit field × media filter of the noise
//! octaves) at the frames' times, as a numbered series of `.vol` grids
//! with sidecars; the values are those of the CPU twin of the slices pass.
//! No GPU needed.

use std::path::Path;

use cumulus::config::Camera;
use cumulus::export::{GridSpec, read_vol};
use cumulus::methods::slices::gpu::field::AuthoredField;
use cumulus::methods::slices::gpu::slices_frame;

use crate::common::cli;

#[test]
fn an_authored_animation_exports_as_a_numbered_series() {
    let scene_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("auth.vol");
    cli::run_command(
        cli::command()
            .arg("export")
            .arg(&scene_path)
            .args([
                "--time", "0", "--frames", "2", "--every", "400", "--voxel", "400", "--out",
            ])
            .arg(&out),
    )
    .expect_success();
    assert!(!out.exists(), "a series writes numbered files only");
    let read = |name: &str| read_vol(&std::fs::read(dir.path().join(name)).unwrap(), name).unwrap();
    let (a, b) = (read("auth-0000.vol"), read("auth-0001.vol"));
    for side in ["auth-0000.json", "auth-0001.json"] {
        assert!(dir.path().join(side).exists(), "{side} missing");
    }
    // The tower rises 1.2 km and the cumulus drift and grow in 400 s.
    assert_ne!(a.max, b.max, "the second frame's cloud moved");
    assert!(a.values.iter().all(|v| *v >= 0.0 && v.is_finite()));
    assert!(
        a.values.iter().any(|v| *v > 0.2),
        "the tower's core is dense"
    );

    // Every value is the CPU twin's density at that cell's centre.
    let (scene, _) = cumulus::scene::load_scene(Some(&scene_path)).unwrap();
    let cfg = &scene.render;
    let camera = Camera::from(&scene.camera);
    let frame = slices_frame(
        &scene.ellipsoids,
        &scene.particles,
        &[],
        cfg,
        0.0,
        cfg.sun_direction(),
        camera.position,
        camera.target - camera.position,
        None, // the primitives only: no vertex values
    )
    .unwrap();
    let field = AuthoredField::new(&frame, cfg.noise_texels);
    let (lo, hi) = field.bounds().unwrap();
    let spec = GridSpec::covering(lo, hi, 400.0, 1024).unwrap();
    assert_eq!(spec.dims, a.dims);
    let [nx, ny, _] = spec.dims;
    for (x, y, z) in [(nx / 2, ny / 2, 3), (1, 1, 1), (nx / 3, ny / 2, 5)] {
        let i = (x + nx * (y + ny * z)) as usize;
        let want = field.density(spec.centre(x, y, z));
        assert_eq!(a.values[i], want, "cell ({x}, {y}, {z})");
    }
}
