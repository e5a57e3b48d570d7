//! The slice vertices' field and shadow evaluated on the CPU against the
//! compute pass (Schpok et al. 2003 §4.1: "on the CPU (or a compute pass:
//! measure both)"): `slices.csv` and `slices.md`, the authored scene at
//! Quality 32 and 128 with `[render.slices] vertex_field = "cpu"` and
//! `"gpu"`. The CPU's cost is in the upload (slicing, field and shadows
//! on the CPU, buffer writes); the GPU's in the `slice_field` pass.

use std::path::Path;

use crate::error::Result;
use crate::methods::slices::model::VertexField;
use crate::render::GpuContext;
use crate::render::headless::Headless;

use super::measure::Repeats;

/// The Quality (slicing planes) of the rows.
pub const QUALITIES: [u32; 2] = [32, 128];
/// Rows of the table: every Quality on both sides.
pub const ROWS: usize = QUALITIES.len() * 2;

/// One row of `slices.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct SlicesRow {
    pub quality: u32,
    pub vertex_field: VertexField,
    /// Slice vertices evaluated per frame.
    pub vertices: u64,
    /// Median upload: slicing, the CPU's field and shadows when it
    /// evaluates them, and the buffer writes. units: ms
    pub upload_ms: f64,
    /// Median `slice_field` compute pass (0 on the CPU side). units: ms
    pub field_pass_ms: f64,
    /// Median frame (upload + GPU). units: ms
    pub frame_ms: f64,
}

/// Measures the rows on `profiles/authored.toml` (with the bench's `--set`
/// `overrides`) at `size`; `tick` after each.
pub fn slices_rows(
    ctx: &GpuContext,
    size: (u32, u32),
    reps: Repeats,
    overrides: &[String],
    mut tick: impl FnMut(&str),
) -> Result<Vec<SlicesRow>> {
    let l = super::methods::load("authored.toml", overrides)?;
    let mut rows = Vec::new();
    for quality in QUALITIES {
        for mode in [VertexField::Cpu, VertexField::Gpu] {
            let mut cfg = l.profile.render.clone();
            cfg.method = crate::config::RenderMethod::Slices;
            cfg.slices.quality = quality;
            cfg.slices.vertex_field = mode;
            let mut hl = Headless::new(ctx, &cfg, size.0, size.1)?;
            hl.renderer
                .set_authored(&l.profile.ellipsoids, &l.profile.particles);
            let m = l.measure(ctx, &mut hl, reps)?;
            let side = cfg.slices.tessellation as u64 + 1;
            rows.push(SlicesRow {
                quality,
                vertex_field: mode,
                vertices: quality as u64 * side * side,
                upload_ms: m.upload_ms,
                field_pass_ms: m
                    .passes
                    .iter()
                    .find(|(n, _)| n == "slice_field")
                    .map_or(0.0, |p| p.1),
                frame_ms: m.render_ms,
            });
            tick(&format!("slices: quality {quality}, {}", mode.name()));
        }
    }
    Ok(rows)
}

/// `slices.csv`: quality, vertex_field, vertices, upload_ms,
/// field_pass_ms, frame_ms.
pub fn slices_csv(rows: &[SlicesRow]) -> Result<Vec<u8>> {
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.quality.to_string(),
                r.vertex_field.name().to_string(),
                r.vertices.to_string(),
                format!("{:.3}", r.upload_ms),
                format!("{:.3}", r.field_pass_ms),
                format!("{:.3}", r.frame_ms),
            ]
        })
        .collect();
    super::report::csv_bytes(
        &[
            "quality",
            "vertex_field",
            "vertices",
            "upload_ms",
            "field_pass_ms",
            "frame_ms",
        ],
        &body,
    )
}

/// `slices.md`: the same table with a line per Quality comparing the sides.
pub fn slices_md(rows: &[SlicesRow], width: u32, height: u32) -> String {
    let mut s = format!(
        "# Slice vertices: CPU against compute pass\n\n{width}×{height}, profiles/authored.toml; \
         medians. Upload = slicing + (on the CPU side) the field and shadows at every vertex + \
         buffer writes; field pass = the `slice_field` compute pass (GPU side only).\n\n\
         | quality | vertex field | vertices | upload (ms) | field pass (ms) | frame (ms) |\n\
         |---:|---|---:|---:|---:|---:|\n"
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {:.2} | {:.2} | {:.2} |\n",
            r.quality,
            r.vertex_field.name(),
            r.vertices,
            r.upload_ms,
            r.field_pass_ms,
            r.frame_ms
        ));
    }
    for q in QUALITIES {
        let find = |m| rows.iter().find(|r| r.quality == q && r.vertex_field == m);
        if let (Some(c), Some(g)) = (find(VertexField::Cpu), find(VertexField::Gpu)) {
            s.push_str(&format!(
                "\nQuality {q}: the field and shadows take {:.2} ms on the CPU (upload difference) \
                 and {:.2} ms in the compute pass; frames {:.2} against {:.2} ms.\n",
                (c.upload_ms - g.upload_ms).max(0.0),
                g.field_pass_ms,
                c.frame_ms,
                g.frame_ms
            ));
        }
    }
    s
}

/// Writes `slices.csv` and `slices.md` into `dir`.
pub fn write(dir: &Path, rows: &[SlicesRow], width: u32, height: u32) -> Result<()> {
    crate::output::write_atomic(&dir.join("slices.csv"), &slices_csv(rows)?)?;
    crate::output::write_atomic(
        &dir.join("slices.md"),
        slices_md(rows, width, height).as_bytes(),
    )
}
