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

    // Every value is the extinction the slices draw there (each cloud's
    // field × media filter, its opacity per metre, the Sharpness cut-off)
    // over the sidecar's scale: the CPU twin's, bit for bit.
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
    let scale = field.max_extinction_per_m().unwrap();
    let side: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("auth-0000.json")).unwrap()).unwrap();
    assert_eq!(
        side["medium"]["extinction_scale_per_m"].as_f64().unwrap() as f32,
        scale,
        "the sidecar's scale is the slices' extinction per unit value"
    );
    let (lo, hi) = field.bounds().unwrap();
    let spec = GridSpec::covering(lo, hi, 400.0, 1024).unwrap();
    assert_eq!(spec.dims, a.dims);
    let [nx, ny, nz] = spec.dims;
    for (x, y, z) in [(nx / 2, ny / 2, 3), (1, 1, 1), (nx / 3, ny / 2, 5)] {
        let i = (x + nx * (y + ny * z)) as usize;
        let want = field.extinction_per_m(spec.centre(x, y, z)) / scale;
        assert_eq!(a.values[i], want, "cell ({x}, {y}, {z})");
    }
    // The slices discard a fragment whose field × media is at or under
    // Sharpness: where even all clouds' together are, nothing is exported,
    // and the cut-off removes a shell the plain field × media would keep.
    let sharpness = cfg.slices.sharpness;
    let mut shell = 0;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let d = field.density(spec.centre(x, y, z));
                let v = a.values[(x + nx * (y + ny * z)) as usize];
                if d <= sharpness {
                    assert_eq!(
                        v, 0.0,
                        "cell ({x}, {y}, {z}): density {d} under the cut-off"
                    );
                    shell += (d > 0.0) as usize;
                }
            }
        }
    }
    assert!(
        shell > 0,
        "the cut-off removed no cell: the test proves nothing"
    );
}
