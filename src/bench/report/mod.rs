//! Writes a bench run: performance.md/.csv, error_vs_runtime.csv/.png,
//! physics_error_vs_runtime.csv/.png, physics_speed.csv, scaling.csv/.png, pruning.csv,
//! reference.png and report.md (every section and the targets), each file
//! atomically. CSV cells left empty mean "not measured / undefined".

use std::path::Path;

use crate::error::{Error, Result};
use crate::output::{write_atomic, write_png_atomic};

use super::BenchResults;
use super::accuracy::{PhysicsError, RenderError};
use super::charts::{pathtraced_chart, physics_error_chart, render_error_chart, scaling_chart};
use super::measure::timing_label;
use super::perf::{PerfRow, PruningRow, ScalingRow, on_off};
use super::plots::{write_chart_png, write_charts_png};

mod markdown;
pub use markdown::{
    Target, performance_md, performance_table, report_md, scaling_targets, targets,
};

/// Plot size. units: px
const PLOT_SIZE: (u32, u32) = (900, 600);

/// A number for a CSV cell: empty when not finite.
fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.6}")
    } else {
        String::new()
    }
}

/// A number for a Markdown cell: "–" when not finite.
fn md(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        "–".into()
    }
}

/// A CSV file's bytes: the header, then one record per row.
pub(super) fn csv_bytes(header: &[&str], rows: &[Vec<String>]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| Error::io("csv", std::io::Error::other(e));
    w.write_record(header).map_err(err)?;
    for r in rows {
        w.write_record(r).map_err(err)?;
    }
    w.into_inner()
        .map_err(|e| Error::io("csv", std::io::Error::other(e.to_string())))
}

fn pass_names() -> Vec<&'static str> {
    crate::render::renderer::all_pass_names()
}

/// performance.csv.
pub fn performance_csv(rows: &[PerfRow]) -> Result<Vec<u8>> {
    let mut head: Vec<String> = [
        "parcels",
        "normals",
        "shadows",
        "physics_ms",
        "physics_share",
        "upload_ms",
        "upload_share",
    ]
    .map(String::from)
    .to_vec();
    for p in pass_names() {
        head.push(format!("{p}_ms"));
        head.push(format!("{p}_share"));
    }
    head.extend(["gpu_ms", "frame_ms", "fps", "frames", "pass_timing"].map(String::from));
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let m = &r.m;
            let share = |v: f64| num(v / m.parts_ms());
            let mut c = vec![
                r.parcels.to_string(),
                on_off(r.normals).into(),
                on_off(r.shadows).into(),
                num(m.physics_ms),
                share(m.physics_ms),
                num(m.upload_ms),
                share(m.upload_ms),
            ];
            for p in pass_names() {
                match m.pass_ms(p) {
                    Some(v) => {
                        c.push(num(v));
                        c.push(share(v));
                    }
                    None => {
                        c.push(String::new());
                        c.push(String::new());
                    }
                }
            }
            c.push(num(m.gpu_ms));
            c.push(num(m.frame_ms));
            c.push(num(m.fps()));
            c.push(m.frames.to_string());
            c.push(timing_label(m.gpu_timestamps).into());
            c
        })
        .collect();
    let head_refs: Vec<&str> = head.iter().map(String::as_str).collect();
    csv_bytes(&head_refs, &body)
}

/// error_vs_runtime.csv (the reference first).
pub fn render_error_csv(e: &RenderError) -> Result<Vec<u8>> {
    let mut body = vec![vec![
        "reference".into(),
        format!(
            "step_m={} octaves={} light_steps={} grid_culling={} early_exit=0",
            e.reference.step_m,
            e.reference.noise_octaves,
            e.reference.light_steps,
            on_off(e.reference.grid_culling)
        ),
        e.width.to_string(),
        e.height.to_string(),
        num(e.reference_ms),
        num(1.0),
        num(0.0),
        num(0.0),
        "false".into(),
    ]];
    for r in &e.rows {
        body.push(vec![
            r.parameter.clone(),
            r.value.clone(),
            r.width.to_string(),
            r.height.to_string(),
            num(r.time_ms),
            num(r.time_ms / e.reference_ms),
            num(r.mean_flip),
            num(r.rmse),
            r.pareto.to_string(),
        ]);
    }
    csv_bytes(
        &[
            "parameter",
            "value",
            "width",
            "height",
            "time_ms",
            "time_over_reference",
            "mean_flip",
            "rmse",
            "pareto",
        ],
        &body,
    )
}

/// physics_error_vs_runtime.csv.
pub fn physics_error_csv(e: &PhysicsError) -> Result<Vec<u8>> {
    let body: Vec<Vec<String>> = e
        .rows
        .iter()
        .map(|r| {
            vec![
                num(r.dt_s),
                r.substeps.to_string(),
                num(e.duration_s / r.substeps as f64),
                num(r.time_ms),
                num(r.position_rms_m),
                num(r.cloud_top_err_m),
                num(r.water_rel_err),
                num(r.order),
                r.pareto.to_string(),
            ]
        })
        .collect();
    csv_bytes(
        &[
            "dt_s",
            "substeps",
            "mean_substep_s",
            "time_ms",
            "position_rms_m",
            "cloud_top_err_m",
            "water_rel_err",
            "observed_order",
            "pareto",
        ],
        &body,
    )
}

/// scaling.csv.
pub fn scaling_csv(rows: &[ScalingRow]) -> Result<Vec<u8>> {
    let opt = |v: Option<f64>| v.map_or_else(String::new, num);
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.parcels.to_string(),
                r.method.to_string(),
                num(r.frame_ms),
                num(r.clouds_ms),
                num(r.bake_ms),
                opt(r.mean_list),
            ]
        })
        .collect();
    csv_bytes(
        &[
            "parcels",
            "method",
            "frame_ms",
            "clouds_ms",
            "bake_ms",
            "mean_list",
        ],
        &body,
    )
}

/// pruning.csv.
pub fn pruning_csv(rows: &[PruningRow]) -> Result<Vec<u8>> {
    let all = rows.first().map_or(f64::NAN, |r| r.frame_ms);
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.variant.into(),
                r.passes.clone(),
                num(r.frame_ms),
                num(r.frame_ms / all),
            ]
        })
        .collect();
    csv_bytes(&["variant", "passes", "frame_ms", "frame_over_all"], &body)
}

/// Writes every file of the run into `dir`.
pub fn write_all(dir: &Path, r: &BenchResults) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    write_atomic(
        &dir.join("performance.md"),
        performance_md(&r.info, &r.performance).as_bytes(),
    )?;
    write_atomic(
        &dir.join("performance.csv"),
        &performance_csv(&r.performance)?,
    )?;
    write_atomic(
        &dir.join("error_vs_runtime.csv"),
        &render_error_csv(&r.render_error)?,
    )?;
    write_atomic(
        &dir.join("physics_error_vs_runtime.csv"),
        &physics_error_csv(&r.physics_error)?,
    )?;
    write_atomic(
        &dir.join("physics_speed.csv"),
        &super::physics_speed::physics_speed_csv(&r.physics_speed),
    )?;
    write_atomic(&dir.join("scaling.csv"), &scaling_csv(&r.scaling)?)?;
    write_atomic(&dir.join("pruning.csv"), &pruning_csv(&r.pruning)?)?;
    let (w, h) = PLOT_SIZE;
    let render_chart = render_error_chart(&r.render_error);
    match &r.pathtraced {
        Some(rows) => write_charts_png(
            &dir.join("error_vs_runtime.png"),
            &[&render_chart, &pathtraced_chart(rows)],
            w,
            h,
        )?,
        None => write_chart_png(&dir.join("error_vs_runtime.png"), &render_chart, w, h)?,
    }
    write_chart_png(
        &dir.join("physics_error_vs_runtime.png"),
        &physics_error_chart(&r.physics_error),
        w,
        h,
    )?;
    write_chart_png(&dir.join("scaling.png"), &scaling_chart(&r.scaling), w, h)?;
    let e = &r.render_error;
    write_png_atomic(
        &dir.join("reference.png"),
        e.width,
        e.height,
        &e.reference_rgba,
    )?;
    write_atomic(&dir.join("report.md"), report_md(r).as_bytes())?;
    Ok(())
}
