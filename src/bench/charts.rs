//! The bench's charts: error against run time (ours against the internal
//! reference, and against the path tracer), the physics time-step sweep and
//! the scaling by parcel count, as data for `plots` to draw.

use super::accuracy::{PhysicsError, RenderError};
use super::pathtraced::PathTracedRow;
use super::perf::ScalingRow;
use super::plots::{Chart, PALETTE, Series};

pub(super) fn render_error_chart(e: &RenderError) -> Chart<'static> {
    let mut params: Vec<&str> = Vec::new();
    for r in &e.rows {
        if !params.contains(&r.parameter.as_str()) {
            params.push(&r.parameter);
        }
    }
    let series = params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let rows: Vec<_> = e.rows.iter().filter(|r| r.parameter == *p).collect();
            Series {
                label: p.to_string(),
                points: rows.iter().map(|r| (r.time_ms, r.mean_flip)).collect(),
                highlight: rows.iter().map(|r| r.pareto).collect(),
                line: false,
                color: PALETTE[i % PALETTE.len()],
            }
        })
        .collect();
    Chart {
        title: "Render: mean FLIP against frame time",
        x_label: "frame time, ms (log)",
        y_label: "mean FLIP vs reference (log)",
        series,
    }
}

/// Our settings against the path tracer (its own row left out: error 0).
pub(super) fn pathtraced_chart(rows: &[PathTracedRow]) -> Chart<'static> {
    let ours: Vec<&PathTracedRow> = rows.iter().filter(|r| r.setting != "pathtraced").collect();
    Chart {
        title: "Render: mean FLIP against the path tracer",
        x_label: "frame time, ms (log)",
        y_label: "mean FLIP vs Mitsuba volpath (log)",
        series: vec![Series {
            label: "settings (default ringed)".into(),
            points: ours.iter().map(|r| (r.time_ms, r.mean_flip)).collect(),
            highlight: ours.iter().map(|r| r.setting == "default").collect(),
            line: false,
            color: PALETTE[0],
        }],
    }
}

pub(super) fn physics_error_chart(e: &PhysicsError) -> Chart<'static> {
    Chart {
        title: "Physics: position error against run time",
        x_label: "run time, ms (log)",
        y_label: "RMS position error, m (log)",
        series: vec![Series {
            label: "time-step sweep".into(),
            points: e
                .rows
                .iter()
                .map(|r| (r.time_ms, r.position_rms_m))
                .collect(),
            highlight: e.rows.iter().map(|r| r.pareto).collect(),
            line: true,
            color: PALETTE[0],
        }],
    }
}

pub(super) fn scaling_chart(rows: &[ScalingRow]) -> Chart<'static> {
    let series = ["baked", "exact", "brute"]
        .into_iter()
        .enumerate()
        .map(|(i, method)| Series {
            label: method.into(),
            points: rows
                .iter()
                .filter(|r| r.method == method)
                .map(|r| (r.parcels as f64, r.frame_ms))
                .collect(),
            highlight: vec![],
            line: true,
            color: PALETTE[i],
        })
        .collect();
    Chart {
        title: "GPU frame time against condensed parcels",
        x_label: "condensed parcels (log)",
        y_label: "frame time, ms (log)",
        series,
    }
}
