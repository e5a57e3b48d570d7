//! A tiny `cumulus bench` run (library call, `Mode::Tiny`) on the CPU
//! adapter (lavapipe "llvmpipe"; any adapter when that is absent) into a
//! temporary directory; checks that every table is well formed: CSV headers,
//! one row per (count × variant), finite non-negative numbers and positive
//! times, the Markdown sections, PNGs that decode. Without any adapter it
//! fails (see `common::gpu` for the opt-in skip). Also the binary's
//! `--tiny` flag end to end.

use std::path::Path;

use cumulus::bench::{Mode, Options, Plan, perf::VARIANTS};
use cumulus::render::GpuContext;

use crate::common::{self, cli};

fn context() -> Option<GpuContext> {
    common::context("bench test")
}

/// (header, rows) of a CSV file.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let header = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|rec| rec.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// Every non-empty cell of the columns ending in `suffixes` is a finite number ≥ 0.
fn check_numbers(file: &str, header: &[String], rows: &[Vec<String>], suffixes: &[&str]) {
    for (i, h) in header.iter().enumerate() {
        if !suffixes.iter().any(|s| h.ends_with(s)) {
            continue;
        }
        for row in rows {
            let cell = &row[i];
            if cell.is_empty() {
                continue;
            }
            let v: f64 = cell
                .parse()
                .unwrap_or_else(|_| panic!("{file}: {h} = {cell:?} is not a number"));
            assert!(v.is_finite() && v >= 0.0, "{file}: {h} = {v}");
        }
    }
}

/// The column's cells are all present, finite and > 0.
fn check_positive(file: &str, header: &[String], rows: &[Vec<String>], name: &str) {
    let c = col(header, name);
    for row in rows {
        let v: f64 = row[c]
            .parse()
            .unwrap_or_else(|_| panic!("{file}: {name} = {:?}", row[c]));
        assert!(v.is_finite() && v > 0.0, "{file}: {name} = {v}");
    }
}

fn check_png(path: &Path) {
    let img = image::open(path).unwrap_or_else(|e| panic!("{path:?} does not decode: {e}"));
    assert!(img.width() > 0 && img.height() > 0);
}

fn check_outputs(dir: &Path) {
    let plan = Plan::for_mode(Mode::Tiny);

    let (h, rows) = read_csv(&dir.join("performance.csv"));
    for name in [
        "parcels",
        "frame_ms",
        "physics_ms",
        "normals",
        "shadows",
        "fps",
    ] {
        col(&h, name);
    }
    assert_eq!(rows.len(), plan.counts.len() * VARIANTS.len());
    let pc = col(&h, "parcels");
    for &n in &plan.counts {
        let k = rows.iter().filter(|r| r[pc] == n.to_string()).count();
        assert_eq!(k, VARIANTS.len(), "rows for {n} parcels");
    }
    check_numbers("performance.csv", &h, &rows, &["_ms", "_share", "fps"]);
    check_positive("performance.csv", &h, &rows, "frame_ms");
    check_positive("performance.csv", &h, &rows, "clouds_ms");

    let (h, rows) = read_csv(&dir.join("error_vs_runtime.csv"));
    for name in ["parameter", "time_ms", "mean_flip", "rmse", "pareto"] {
        col(&h, name);
    }
    // Reference + default + one point per swept parameter.
    assert!(rows.len() >= 3, "{rows:?}");
    check_numbers(
        "error_vs_runtime.csv",
        &h,
        &rows,
        &["_ms", "flip", "rmse", "reference"],
    );
    check_positive("error_vs_runtime.csv", &h, &rows, "time_ms");
    let pareto = col(&h, "pareto");
    assert!(
        rows.iter().any(|r| r[pareto] == "true"),
        "a non-empty sweep has a Pareto front"
    );
    // Issue 9: each method and each march path against the reference.
    let (parameter, value) = (col(&h, "parameter"), col(&h, "value"));
    for (p, v) in [
        ("method", "baked"),
        ("method", "exact"),
        ("march", "fragment"),
        ("march", "compute"),
    ] {
        assert!(
            rows.iter().any(|r| r[parameter] == p && r[value] == v),
            "error_vs_runtime.csv lacks {p}={v}"
        );
    }

    let (h, rows) = read_csv(&dir.join("physics_error_vs_runtime.csv"));
    assert_eq!(rows.len(), plan.physics_dts.len());
    check_numbers(
        "physics_error_vs_runtime.csv",
        &h,
        &rows,
        &["_s", "_ms", "_m", "_err", "order"],
    );
    check_positive("physics_error_vs_runtime.csv", &h, &rows, "time_ms");

    let (h, rows) = read_csv(&dir.join("scaling.csv"));
    for name in [
        "parcels",
        "method",
        "frame_ms",
        "clouds_ms",
        "bake_ms",
        "mean_list",
    ] {
        col(&h, name);
    }
    // One row per count and method (tiny counts are ≤ brute_max: all three).
    assert_eq!(rows.len(), 3 * plan.scaling_counts.len());
    let m = col(&h, "method");
    for method in ["baked", "exact", "brute"] {
        let k = rows.iter().filter(|r| r[m] == method).count();
        assert_eq!(k, plan.scaling_counts.len(), "{method} rows");
    }
    check_positive("scaling.csv", &h, &rows, "frame_ms");
    check_positive("scaling.csv", &h, &rows, "clouds_ms");
    // The baked rows re-bake every frame: the bake was timed.
    let bake = col(&h, "bake_ms");
    assert!(
        rows.iter()
            .filter(|r| r[m] == "baked")
            .all(|r| r[bake].parse::<f64>().unwrap() > 0.0)
    );
    check_numbers("scaling.csv", &h, &rows, &["_ms", "_list"]);

    // slices.csv: every Quality with the vertex field on the CPU and in
    // the compute pass; only the GPU rows time a slice_field pass.
    let (h, rows) = read_csv(&dir.join("slices.csv"));
    assert_eq!(rows.len(), cumulus::bench::slices_field::ROWS);
    check_positive("slices.csv", &h, &rows, "frame_ms");
    check_numbers("slices.csv", &h, &rows, &["_ms"]);
    let (mode, pass) = (col(&h, "vertex_field"), col(&h, "field_pass_ms"));
    for r in &rows {
        let ms: f64 = r[pass].parse().unwrap();
        assert_eq!(ms > 0.0, r[mode] == "gpu", "{r:?}");
    }

    let (h, rows) = read_csv(&dir.join("pruning.csv"));
    // all, then terrain, shadows, normals and the aerial perspective left out.
    assert_eq!(rows.len(), 5);
    check_positive("pruning.csv", &h, &rows, "frame_ms");

    // methods.csv: exactly these columns, one row per case; FLIP against
    // the exact march where the scene has parcels, empty where it has none.
    let (h, rows) = read_csv(&dir.join("methods.csv"));
    assert_eq!(
        h,
        [
            "scene",
            "method",
            "impostors",
            "frame_ms",
            "mean_flip_vs_exact"
        ]
    );
    let cases = cumulus::bench::methods::cases();
    assert_eq!(rows.len(), cases.len());
    // The paper's Figure 15: the overcast with the impostor ring on and off.
    for on in ["on", "off"] {
        assert!(
            rows.iter().any(|r| r[0] == "overcast" && r[2] == on),
            "overcast with impostors {on}: {rows:?}"
        );
    }
    check_positive("methods.csv", &h, &rows, "frame_ms");
    for (row, case) in rows.iter().zip(&cases) {
        assert_eq!(row[1], case.method.name());
        let flip = &row[4];
        assert_eq!(row[2], if case.impostors { "on" } else { "off" });
        // The overcast and the authored scene have no parcels, so no exact
        // ray-march to compare with.
        if ["overcast.toml", "authored.toml"].contains(&case.scene) {
            assert!(flip.is_empty(), "no exact frame without parcels: {row:?}");
        } else {
            let f: f64 = flip.parse().unwrap_or_else(|_| panic!("{row:?}"));
            assert!((0.0..=1.0).contains(&f), "{row:?}");
        }
    }
    assert!(
        std::fs::read_to_string(dir.join("methods.md"))
            .unwrap()
            .contains("overdraw")
    );

    // landscape.csv: temporal off, 2x2, 4x4, the FLIP of the upscaled
    // frames against the full march in 0..1 (0 for the full march).
    let (h, rows) = read_csv(&dir.join("landscape.csv"));
    let modes: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(modes, ["off", "2x2", "4x4"], "{rows:?}");
    check_positive("landscape.csv", &h, &rows, "frame_ms");
    let flip = col(&h, "mean_flip_vs_full");
    assert_eq!(rows[0][flip], "0.0000");
    for row in &rows[1..] {
        let f: f64 = row[flip].parse().unwrap();
        assert!((0.0..=1.0).contains(&f), "{rows:?}");
    }

    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for section in [
        "## Landscape",
        "## Performance",
        "## Error against run time",
        "### Render settings",
        "### Physics time step",
        "## Scaling",
        "## Pruning savings",
        "## Targets",
    ] {
        assert!(report.contains(section), "report.md lacks {section}");
    }
    // Six targets (85/8 parcels with shadows on and off, normals, physics
    // share, baked against exact, error at run time), each with a verdict
    // or "not measured".
    let verdicts = report.matches("**pass**").count()
        + report.matches("**FAIL**").count()
        + report.matches("| not measured |").count();
    assert_eq!(verdicts, 6, "{report}");
    assert!(report.contains("baked against exact at the same settings"));
    // performance.md's frame columns say what they hold (issue 9).
    let perf = std::fs::read_to_string(dir.join("performance.md")).unwrap();
    assert!(perf.contains("| GPU frame ms |"), "{perf}");
    assert!(
        perf.contains("from its first to its last timestamp"),
        "{perf}"
    );
    for key in [
        "adapter",
        "driver",
        "backend",
        "resolution",
        "build profile",
        "commit",
    ] {
        assert!(perf.contains(key), "performance.md header lacks {key}");
    }

    for png in [
        "error_vs_runtime.png",
        "physics_error_vs_runtime.png",
        "scaling.png",
        "reference.png",
    ] {
        check_png(&dir.join(png));
    }
}

#[test]
fn tiny_bench_writes_well_formed_tables() {
    let Some(ctx) = context() else { return };
    let dir = tempfile::tempdir().unwrap();
    let opts = Options {
        mode: Mode::Tiny,
        out: dir.path().to_path_buf(),
        size: None,
        adapter: None,
        progress: false,
        method: Default::default(),
        overrides: Vec::new(),
    };
    let results = cumulus::bench::run_with(&ctx, &opts).unwrap();
    assert!(["debug", "release"].contains(&results.info.profile));
    check_outputs(dir.path());
}

#[test]
fn tiny_bench_binary() {
    if context().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    cli::run_command(cli::command().args(["bench", "--tiny", "--out"]).arg(&out)).expect_success();
    check_outputs(&out);
}

/// The landscape case as the full bench runs it (1920×1080, temporal off,
/// 2x2 and 4x4), alone, for docs/performance.md's figures on a CPU adapter
/// where the whole full run would take too long: `cargo test --release
/// --test cumulus -- --ignored --nocapture bench::run::landscape_at_1080p`.
#[test]
#[ignore]
fn landscape_at_1080p() {
    landscape_alone(Mode::Full);
}

/// The same at the quick run's size (480×270).
#[test]
#[ignore]
fn landscape_quick() {
    landscape_alone(Mode::Quick);
}

fn landscape_alone(mode: Mode) {
    let Some(ctx) = context() else { return };
    let reps = cumulus::bench::measure::Repeats {
        warmup: 1,
        measured: 3,
        budget_ms: 60_000.0,
    };
    let rows = cumulus::bench::landscape::landscape(&ctx, mode, reps, &[]).unwrap();
    println!("{}", cumulus::bench::landscape::landscape_md(&rows));
}
