//! The OpenVDB export read back by an independent reader (the `vdb-rs`
//! crate, which shares no code with our writer): at every voxel the value
//! of the `.vol` export of the same frame, only the 8³ leaves holding
//! cloud stored, and the transform putting voxel centres where the `.vol`
//! has them. Every shipped scene with volumetric clouds exports at its
//! start time in both formats; sprite-only and clear scenes fail clearly.
//! No GPU needed.

use std::path::Path;

use cumulus::export::sidecar::Sidecar;
use cumulus::export::{VolGrid, read_vol};
use vdb_rs::{Map, VdbLevel, VdbReader};

use crate::common::cli;

fn read_vdb(path: &Path) -> vdb_rs::Grid<f32> {
    let file = std::fs::File::open(path).unwrap();
    let mut reader = VdbReader::new(std::io::BufReader::new(file))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(reader.available_grids(), vec!["density".to_string()]);
    reader
        .read_grid::<f32>("density")
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Checks `vdb` against the dense `vol` of the same frame: every active
/// voxel holds the `.vol` value at its index (bit for bit), every non-zero
/// `.vol` value is active, the transform maps index (i, j, k) to the cell
/// centre, and fewer leaves are stored than the dense grid has blocks.
fn assert_same_grid(vdb: &vdb_rs::Grid<f32>, vol: &VolGrid, what: &str) {
    let [nx, ny, nz] = vol.dims.map(|d| d as usize);
    let voxel = ((vol.max[0] - vol.min[0]) / nx as f32) as f64;
    let mut active = 0usize;
    for (c, v, level) in vdb.iter() {
        assert!(level == VdbLevel::Voxel, "{what}: no tiles are written");
        let [i, j, k] = [c.x, c.y, c.z].map(|x| x as usize);
        assert!(
            i < nx && j < ny && k < nz,
            "{what}: voxel {c} outside the grid"
        );
        let want = vol.values[(k * ny + j) * nx + i];
        assert_eq!(v.to_bits(), want.to_bits(), "{what}: voxel {c}");
        active += 1;
    }
    let non_zero = vol.values.iter().filter(|&&v| v != 0.0).count();
    assert!(non_zero > 0, "{what}: the frame has cloud");
    assert_eq!(active, non_zero, "{what}: every cloudy voxel is active");

    let Map::ScaleTranslateMap {
        translation,
        voxel_size,
        ..
    } = &vdb.transform
    else {
        panic!("{what}: a scale-translate map, got {:?}", vdb.transform);
    };
    // f32 corners and voxel as written; the centre offset computed in f64.
    for a in 0..3 {
        let centre0 = vol.min[a] as f64 + 0.5 * voxel;
        assert!(
            (translation[a] - centre0).abs() <= 1e-3 * voxel,
            "{what}: axis {a}: voxel (0,0,0) at {} m, its cell centre is {centre0} m",
            translation[a]
        );
        assert!((voxel_size[a] - voxel).abs() <= 1e-5 * voxel, "{what}");
    }

    let leaves: usize = vdb
        .tree
        .root_nodes
        .iter()
        .flat_map(|upper| upper.nodes.values())
        .map(|lower| lower.nodes.len())
        .sum();
    let blocks = [nx, ny, nz]
        .iter()
        .map(|d| d.div_ceil(8))
        .product::<usize>();
    assert!(
        leaves < blocks,
        "{what}: sparse: {leaves} leaves stored of {blocks} blocks"
    );
}

fn export(scene: Option<&str>, extra: &[&str], out: &Path) -> cli::Run {
    let mut c = cli::command();
    c.arg("export");
    if let Some(s) = scene {
        c.arg(s);
    }
    cli::run_command(c.args(extra).arg("--out").arg(out))
}

fn sidecar(path: &Path) -> Sidecar {
    serde_json::from_slice(&std::fs::read(path.with_extension("json")).unwrap()).unwrap()
}

#[test]
fn a_vdb_export_reads_back_with_the_values_of_the_vol_export() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["--stand-in", "--time", "1200", "--voxel", "150"];
    let (vol, vdb) = (dir.path().join("c.vol"), dir.path().join("c.vdb"));
    export(None, &args, &vol).expect_success();
    export(None, &args, &vdb).expect_success();
    let dense = read_vol(&std::fs::read(&vol).unwrap(), "c.vol").unwrap();
    assert_same_grid(&read_vdb(&vdb), &dense, "stand-in");
    let side = sidecar(&vdb);
    assert_eq!(side.volume.file, "c.vdb");
    assert_eq!(side.time_s, 1200.0);
    assert!(
        side.volume.values.contains("OpenVDB"),
        "{}",
        side.volume.values
    );
    assert_eq!(side.volume.dims, dense.dims);

    // A numbered series in OpenVDB too.
    let series = dir.path().join("s.vdb");
    export(
        None,
        &[&args[..], &["--frames", "2", "--every", "90"]].concat(),
        &series,
    )
    .expect_success();
    for (i, t) in [(0, 1200.0), (1, 1290.0)] {
        let frame = dir.path().join(format!("s-000{i}.vdb"));
        assert_eq!(sidecar(&frame).time_s, t);
        assert!(
            read_vdb(&frame).iter().next().is_some(),
            "frame {i} has cloud"
        );
    }
}

/// The scenes whose clouds have a density (parcels or ellipsoids).
const VOLUMETRIC: [&str; 5] = [
    "fair_weather",
    "towering_cumulus",
    "high_based",
    "landscape",
    "authored",
];

#[test]
fn every_shipped_volumetric_scene_exports_at_its_start_time_in_both_formats() {
    let dir = tempfile::tempdir().unwrap();
    for name in VOLUMETRIC {
        let scene = format!("profiles/{name}.toml");
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(&scene);
        let (profile, _) = cumulus::scene::load_scene_with(Some(&path), &[]).unwrap();
        let (vol, vdb) = (
            dir.path().join(format!("{name}.vol")),
            dir.path().join(format!("{name}.vdb")),
        );
        // Default options: the scene's start time, the default voxel.
        export(Some(&scene), &[], &vol).expect_success();
        export(Some(&scene), &[], &vdb).expect_success();
        assert_eq!(sidecar(&vdb).time_s, profile.simulation.start_s, "{name}");
        let dense = read_vol(&std::fs::read(&vol).unwrap(), name).unwrap();
        assert_same_grid(&read_vdb(&vdb), &dense, name);
        // The files are large: one scene's pair at a time.
        std::fs::remove_file(&vol).unwrap();
        std::fs::remove_file(&vdb).unwrap();
    }
    for (name, says) in [
        ("cloud_types", "sprite cloud"),
        ("overcast", "sprite cloud"),
        ("stable_dry", "no cloud"),
    ] {
        let out = dir.path().join(format!("{name}.vdb"));
        export(Some(&format!("profiles/{name}.toml")), &[], &out)
            .expect_failure_containing(&[name, says]);
        assert!(!out.exists() && !out.with_extension("json").exists());
    }
}

#[test]
fn the_committed_blender_sample_is_what_export_writes_today() {
    // benches/blender_vdb.py renders benches/data/sample.vdb in Blender;
    // it must stay the writer's output (re-export it with these arguments
    // when the field or the writer changes on purpose).
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sample.vdb");
    export(
        None,
        &["--stand-in", "--time", "1200", "--voxel", "150"],
        &out,
    )
    .expect_success();
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/data/sample.vdb");
    assert!(
        std::fs::read(&out).unwrap() == std::fs::read(&committed).unwrap(),
        "{} differs from a fresh export",
        committed.display()
    );
}
