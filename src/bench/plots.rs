//! Bench charts (PNG, plotters with the embedded font): log–log scatter and
//! line plots; Pareto points drawn larger and ringed.

use std::path::Path;

use plotters::coord::combinators::{BindKeyPoints, IntoLogRange};
use plotters::prelude::*;

use crate::error::Result;

/// One data series.
pub struct Series {
    pub label: String,
    /// (x, y); points with a non-positive or non-finite coordinate are not drawn.
    pub points: Vec<(f64, f64)>,
    /// Per point: highlight (Pareto front). Empty = none.
    pub highlight: Vec<bool>,
    /// Join the points with a line.
    pub line: bool,
    pub color: RGBColor,
}

/// A chart to draw.
pub struct Chart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub series: Vec<Series>,
}

/// Colours for series, in order.
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// A tick label with as many decimals as the magnitude needs.
fn tick(v: &f64) -> String {
    let a = v.abs();
    if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.1}")
    } else if a >= 0.001 {
        format!("{v:.3}")
    } else {
        format!("{v:.1e}")
    }
}

fn usable(p: &(f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite() && p.0 > 0.0 && p.1 > 0.0
}

/// (lo, hi) of the values padded by a factor on a log scale.
fn log_range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for v in vals {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo > hi {
        return (0.1, 10.0);
    }
    // Wide enough for a few labelled ticks (1, 2, 5 × 10^k).
    if hi / lo < 6.0 {
        let mid = (hi * lo).sqrt();
        return (mid / 2.5, mid * 2.5);
    }
    (lo / 1.5, hi * 1.5)
}

/// Labelled ticks for a log axis over lo..hi: 1, 2, 5 × 10^k.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let mut k = lo.log10().floor() as i32;
    while 10f64.powi(k) <= hi {
        for m in [1.0, 2.0, 5.0] {
            let v = m * 10f64.powi(k);
            if v >= lo && v <= hi {
                out.push(v);
            }
        }
        k += 1;
    }
    out
}

fn draw(chart: &Chart, buf: &mut [u8], w: u32, h: u32) -> std::result::Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    let root = BitMapBackend::with_buffer(buf, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let all = || {
        chart
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(|p| usable(p))
    };
    let (x0, x1) = log_range(all().map(|p| p.0));
    let (y0, y1) = log_range(all().map(|p| p.1));
    let mut c = ChartBuilder::on(&root)
        .caption(chart.title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
            (y0..y1).log_scale().with_key_points(log_ticks(y0, y1)),
        )
        .map_err(|x| e(&x))?;
    c.configure_mesh()
        .x_desc(chart.x_label)
        .y_desc(chart.y_label)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()
        .map_err(|x| e(&x))?;
    for s in &chart.series {
        let color = s.color;
        let pts: Vec<(usize, (f64, f64))> = s
            .points
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, p)| usable(p))
            .collect();
        if s.line {
            c.draw_series(LineSeries::new(
                pts.iter().map(|(_, p)| *p),
                color.stroke_width(2),
            ))
            .map_err(|x| e(&x))?;
        }
        c.draw_series(pts.iter().map(|(_, p)| Circle::new(*p, 4, color.filled())))
            .map_err(|x| e(&x))?
            .label(s.label.as_str())
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, color.filled()));
        let ringed: Vec<(f64, f64)> = pts
            .iter()
            .filter(|(i, _)| s.highlight.get(*i).copied().unwrap_or(false))
            .map(|(_, p)| *p)
            .collect();
        if !ringed.is_empty() {
            c.draw_series(
                ringed
                    .iter()
                    .map(|p| Circle::new(*p, 9, BLACK.stroke_width(2))),
            )
            .map_err(|x| e(&x))?;
        }
    }
    if chart.series.iter().any(|s| s.highlight.iter().any(|&b| b)) {
        // Legend entry for the rings.
        c.draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(|x| e(&x))?
            .label("Pareto front (ringed)")
            .legend(|(x, y)| Circle::new((x + 8, y), 6, BLACK.stroke_width(2)));
    }
    c.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))?;
    Ok(())
}

/// Draws `chart` and writes it atomically as a `w`×`h` PNG.
pub fn write_chart_png(path: &Path, chart: &Chart, w: u32, h: u32) -> Result<()> {
    crate::plots::write_rgb_png(path, chart.title, w, h, |rgb| draw(chart, rgb, w, h))
}

/// Draws `charts` side by side, each `w`×`h`, into one PNG written atomically.
pub fn write_charts_png(path: &Path, charts: &[&Chart], w: u32, h: u32) -> Result<()> {
    let n = charts.len().max(1);
    let title = charts.first().map_or("chart", |c| c.title);
    crate::plots::write_rgb_png(path, title, w * n as u32, h, |rgb| {
        let row = 3 * w as usize;
        let mut panel = vec![0u8; row * h as usize];
        for (i, c) in charts.iter().enumerate() {
            draw(c, &mut panel, w, h)?;
            for (y, src) in panel.chunks_exact(row).enumerate() {
                let at = (y * n + i) * row;
                rgb[at..at + row].copy_from_slice(src);
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ticks_are_1_2_5() {
        assert_eq!(log_ticks(0.015, 0.3), vec![0.02, 0.05, 0.1, 0.2]);
        assert_eq!(log_ticks(3.0, 12.0), vec![5.0, 10.0]);
    }

    #[test]
    fn draws_a_chart_with_zero_and_nan_points() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.png");
        let chart = Chart {
            title: "t",
            x_label: "x",
            y_label: "y",
            series: vec![Series {
                label: "s".into(),
                points: vec![(1.0, 0.1), (10.0, 0.01), (100.0, 0.0), (f64::NAN, 1.0)],
                highlight: vec![true, false, false, false],
                line: true,
                color: PALETTE[0],
            }],
        };
        write_chart_png(&path, &chart, 320, 240).unwrap();
        let img = image::open(&path).unwrap();
        assert_eq!((img.width(), img.height()), (320, 240));
    }
}
