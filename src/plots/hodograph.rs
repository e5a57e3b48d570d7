//! The hodograph beside the Skew-T: the tip of the wind vector (u, v) from
//! the ground up, coloured by height layer, on rings of equal speed. Its
//! curvature and length are the shear forecasters read next to CAPE
//! (SHARPpy and MetPy's sounding layouts put it in the same place). Below it,
//! the diagram's summary lines (CAPE, CIN, shear).

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::atmosphere::WindProfile;

/// Height layers of the trace and their colours (the usual 0–1, 1–3, 3–6,
/// 6–9 km bands, then the rest). units: m
pub const LAYERS: [(f64, f64, RGBColor); 5] = [
    (0.0, 1000.0, RGBColor(220, 30, 30)),
    (1000.0, 3000.0, RGBColor(30, 160, 40)),
    (3000.0, 6000.0, RGBColor(200, 150, 0)),
    (6000.0, 9000.0, RGBColor(30, 80, 220)),
    (9000.0, f64::INFINITY, RGBColor(140, 40, 170)),
];
/// Sampling step of the trace. units: m
const TRACE_DZ_M: f64 = 100.0;
/// Highest height drawn (the hodograph is read for the troposphere). units: m
const TRACE_TOP_M: f64 = 12_000.0;

/// Draws the hodograph in the upper part of `area` (a square) and `summary`
/// below it. Without a wind profile it says so instead. Returns the first
/// row of `area`'s pixels below the summary, where more can go.
pub fn draw_side_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    wind: Option<&WindProfile>,
    summary: &[String],
) -> Result<i32, String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    let (w, h) = area.dim_in_pixel();
    let (top, bottom) = area.split_vertically(w.min(h));
    let text = |a: &DrawingArea<DB, Shift>, s: &str, y: i32, size: u32| {
        a.draw_text(
            s,
            &TextStyle::from(("sans-serif", size).into_font()).pos(Pos::new(HPos::Left, VPos::Top)),
            (12, y),
        )
        .map_err(|x| e(&x))
    };
    match wind {
        Some(wind) => draw_hodograph(&top, wind)?,
        None => {
            text(&top, "no wind in the sounding", 60, 18)?;
            text(&top, "(DRCT/SKNT blank): no hodograph", 84, 16)?;
        }
    }
    let row = |i: usize| 8 + 22 * i as i32;
    for (i, line) in summary.iter().enumerate() {
        text(&bottom, line, row(i), 16)?;
    }
    Ok(w.min(h) as i32 + row(summary.len()))
}

/// The hodograph itself: rings every 10 m/s, the trace, a legend of layers.
fn draw_hodograph<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    wind: &WindProfile,
) -> Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    let top = TRACE_TOP_M.min(wind.levels().last().map(|l| l.z_m).unwrap_or(0.0));
    let n = (top / TRACE_DZ_M).ceil().max(1.0) as usize;
    let trace: Vec<(f64, [f64; 2])> = (0..=n)
        .map(|i| {
            let z = (i as f64 * TRACE_DZ_M).min(top);
            (z, wind.at(z))
        })
        .collect();
    let max_speed = trace
        .iter()
        .map(|(_, [u, v])| u.hypot(*v))
        .fold(0.0, f64::max);
    // Rings every 10 m/s, at least two, one beyond the fastest wind.
    let rings = ((max_speed / 10.0).floor() as i32 + 1).max(2);
    let r = rings as f64 * 10.0;
    let mut chart = ChartBuilder::on(area)
        .caption("hodograph (m/s, u east, v north)", ("sans-serif", 18))
        .margin(14)
        .build_cartesian_2d(-r..r, -r..r)
        .map_err(|x| e(&x))?;
    let grey = RGBColor(160, 160, 160);
    for k in 1..=rings {
        let rk = k as f64 * 10.0;
        let ring = (0..=72).map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 72.0;
            (rk * a.cos(), rk * a.sin())
        });
        chart
            .draw_series(LineSeries::new(ring, grey.mix(0.6).stroke_width(1)))
            .map_err(|x| e(&x))?;
        chart
            .draw_series(std::iter::once(Text::new(
                format!("{rk:.0}"),
                (rk * 0.71, rk * 0.71),
                ("sans-serif", 12).into_font().color(&grey),
            )))
            .map_err(|x| e(&x))?;
    }
    for seg in [[(-r, 0.0), (r, 0.0)], [(0.0, -r), (0.0, r)]] {
        chart
            .draw_series(LineSeries::new(seg, grey.stroke_width(1)))
            .map_err(|x| e(&x))?;
    }
    for (lo, hi, color) in LAYERS {
        let pts: Vec<(f64, f64)> = trace
            .iter()
            .filter(|(z, _)| *z >= lo && *z <= hi)
            .map(|(_, [u, v])| (*u, *v))
            .collect();
        if pts.len() < 2 {
            continue;
        }
        let label = if hi.is_finite() {
            format!("{:.0}–{:.0} km", lo / 1000.0, hi / 1000.0)
        } else {
            format!("above {:.0} km", lo / 1000.0)
        };
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(3)))
            .map_err(|x| e(&x))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(|x| e(&x))?;
    Ok(())
}
