//! Skew-T log-p diagram of a sounding and its lifted surface parcel, the
//! chart aerologists read stability from: pressure on a logarithmic axis
//! going up, isotherms skewed 45° to the right, dry adiabats, a few moist
//! adiabats and mixing-ratio lines as background; the environment's
//! temperature and dewpoint and the parcel's temperature on top, with the
//! LCL, LFC and EL marked. A side panel to the right holds the hodograph
//! of the sounding's wind and the summary lines (CAPE, CIN).
//!
//! Coordinates: y = −ln P, x = T[°C] + SKEW · ln(P_BOTTOM / P), so at the
//! bottom edge x is the temperature itself and the x axis can be labelled as
//! temperature.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::atmosphere::lifting::{LevelMark, ParcelAscent, ParcelLevel};
use crate::atmosphere::{Environment, WindProfile, thermo};
use crate::error::Result;

/// Bottom edge of the diagram. units: hPa
const P_BOTTOM_HPA: f64 = 1050.0;
/// Top edge of the diagram. units: hPa
const P_TOP_HPA: f64 = 100.0;
/// Temperature range along the bottom edge. units: °C
const T_RANGE_C: (f64, f64) = (-40.0, 50.0);
/// Skew: °C of x shift per e-fold of pressure. 43 makes isotherms run at
/// about 45° in a 900×1000 px image (the x span is 90 °C over ~790 px, the y
/// span ln 10.5 over ~870 px).
const SKEW_C: f64 = 43.0;
/// Pressures of the labelled isobars. units: hPa
const ISOBARS_HPA: [f64; 12] = [
    1000.0, 925.0, 850.0, 700.0, 600.0, 500.0, 400.0, 300.0, 250.0, 200.0, 150.0, 100.0,
];

/// What to draw.
pub struct SkewT<'a> {
    /// Title line (station, time).
    pub title: String,
    /// Environment (temperature, dewpoint, heights).
    pub env: &'a Environment,
    /// The parcel ascent (for LCL, LFC and EL).
    pub ascent: &'a ParcelAscent,
    /// Parcel curve sampled densely enough to look smooth.
    pub parcel_curve: &'a [ParcelLevel],
    /// Optional path of a dynamically released parcel (`parcel --dynamic`):
    /// (pressure in Pa, temperature in K) along its trajectory, drawn over the
    /// kinematic ascent so overshoot and oscillation show against it (paper fig. 4).
    pub dynamic_path: Option<&'a [(f64, f64)]>,
    /// Wind profile for the hodograph beside the diagram (None: the panel
    /// says the sounding has no wind).
    pub wind: Option<&'a WindProfile>,
    /// Lines printed under the hodograph (CAPE and CIN of the parcels).
    pub summary: &'a [String],
}

/// Width of the side panel (hodograph and summary) right of the diagram. units: px
pub const SIDE_PANEL_PX: u32 = 400;

fn to_xy(t_c: f64, p_hpa: f64) -> (f64, f64) {
    (t_c + SKEW_C * (P_BOTTOM_HPA / p_hpa).ln(), -p_hpa.ln())
}

fn in_box((x, y): (f64, f64)) -> bool {
    (T_RANGE_C.0..=T_RANGE_C.1).contains(&x) && (-P_BOTTOM_HPA.ln()..=-P_TOP_HPA.ln()).contains(&y)
}

/// Splits a curve into the runs that lie inside the diagram, so that lines
/// end at the frame instead of running over the labels.
fn clipped(points: impl IntoIterator<Item = (f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    let mut runs = vec![Vec::new()];
    for p in points {
        if in_box(p) {
            runs.last_mut().unwrap().push(p);
        } else if !runs.last().unwrap().is_empty() {
            runs.push(Vec::new());
        }
    }
    runs.retain(|r| r.len() > 1);
    runs
}

/// Pressures from the bottom to the top of the diagram, evenly in ln P. units: hPa
fn pressures(n: usize) -> impl Iterator<Item = f64> + Clone {
    (0..=n).map(move |i| P_BOTTOM_HPA * (P_TOP_HPA / P_BOTTOM_HPA).powf(i as f64 / n as f64))
}

/// A pseudo-adiabat through (`t_k`, 1000 hPa), by the same saturation
/// adjustment as the parcel ascent with the condensate dropped each step.
fn moist_adiabat(t_start_k: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut t = t_start_k;
    let mut p_prev = 100_000.0;
    // Downward first: the same curve below 1000 hPa is the reverse process.
    let below: f64 = P_BOTTOM_HPA * 100.0;
    let n = 200;
    let mut q = thermo::saturation_mixing_ratio(t, p_prev);
    let mut up = Vec::new();
    for i in 1..=n {
        let p = 100_000.0 * (P_TOP_HPA / 1000.0).powf(i as f64 / n as f64);
        let a = thermo::saturation_adjust(t * (p / p_prev).powf(thermo::KAPPA), q, 0.0, p, 1.0);
        t = a.t_k;
        q = a.qv;
        p_prev = p;
        up.push(to_xy(t - 273.15, p / 100.0));
    }
    // Below 1000 hPa the curve is short: extend it along its lowest slope.
    let (x0, y0) = to_xy(t_start_k - 273.15, 1000.0);
    let (x1, y1) = up[0];
    let k = (x1 - x0) / (y1 - y0);
    let yb = -(below / 100.0).ln();
    out.push((x0 + k * (yb - y0), yb));
    out.push((x0, y0));
    out.extend(up);
    out
}

/// Draws the diagram into an RGB buffer of `width`×`height`.
fn draw(
    chart_data: &SkewT,
    buf: &mut [u8],
    width: u32,
    height: u32,
) -> std::result::Result<(), String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let full = BitMapBackend::with_buffer(buf, (width, height)).into_drawing_area();
    full.fill(&WHITE).map_err(|x| e(&x))?;
    let (root, side) = full.split_horizontally(width.saturating_sub(SIDE_PANEL_PX));
    let below_summary =
        super::hodograph::draw_side_panel(&side, chart_data.wind, chart_data.summary)?;
    // The curves' legend, filled as they are drawn and drawn in the side
    // panel (inside the diagram it hid the traces near its top).
    let mut legend: Vec<LegendEntry> = Vec::new();
    let mut chart = ChartBuilder::on(&root)
        .caption(&chart_data.title, ("sans-serif", 24))
        .margin(12)
        .margin_right(70)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(
            T_RANGE_C.0..T_RANGE_C.1,
            -P_BOTTOM_HPA.ln()..-P_TOP_HPA.ln(),
        )
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .disable_x_mesh()
        .y_labels(0)
        .x_labels(10)
        .x_label_formatter(&|t| format!("{t:.0}"))
        .x_desc("temperature at 1050 hPa (°C); isotherms skewed 45°")
        .y_desc("pressure (hPa)")
        .axis_desc_style(("sans-serif", 18))
        .label_style(("sans-serif", 16))
        .draw()
        .map_err(|x| e(&x))?;

    let light = |c: RGBColor| c.mix(0.35).stroke_width(1);
    // Isobars with pressure labels (left) and heights above the ground (right).
    for &p in &ISOBARS_HPA {
        let y = -p.ln();
        chart
            .draw_series(LineSeries::new(
                [(T_RANGE_C.0, y), (T_RANGE_C.1, y)],
                light(BLACK),
            ))
            .map_err(|x| e(&x))?;
        let (px, py) = chart.backend_coord(&(T_RANGE_C.0, y));
        let style = TextStyle::from(("sans-serif", 16).into_font())
            .pos(Pos::new(HPos::Right, VPos::Center));
        root.draw_text(&format!("{p:.0}"), &style, (px - 6, py))
            .map_err(|x| e(&x))?;
        if let Some(z) = chart_data.env.height_at_pressure_m(p * 100.0) {
            let (qx, qy) = chart.backend_coord(&(T_RANGE_C.1, y));
            let style = TextStyle::from(("sans-serif", 15).into_font())
                .pos(Pos::new(HPos::Left, VPos::Center))
                .color(&RGBColor(90, 90, 90));
            root.draw_text(&format!("{:.1} km", z / 1000.0), &style, (qx + 6, qy))
                .map_err(|x| e(&x))?;
        }
    }
    let (rx, ry) = chart.backend_coord(&(T_RANGE_C.1, -P_TOP_HPA.ln()));
    root.draw_text(
        "height AGL",
        &TextStyle::from(("sans-serif", 14).into_font())
            .pos(Pos::new(HPos::Left, VPos::Bottom))
            .color(&RGBColor(90, 90, 90)),
        (rx + 2, ry - 4),
    )
    .map_err(|x| e(&x))?;

    // Skewed isotherms every 10 °C.
    for t in (-12..=5).map(|i| i as f64 * 10.0) {
        let color = if t == 0.0 {
            BLUE.mix(0.5).stroke_width(1)
        } else {
            light(RGBColor(40, 40, 160))
        };
        for run in clipped(pressures(60).map(|p| to_xy(t, p))) {
            chart
                .draw_series(LineSeries::new(run, color))
                .map_err(|x| e(&x))?;
        }
    }
    // Dry adiabats every 10 K of θ.
    for theta in (25..=46).map(|i| i as f64 * 10.0) {
        let pts = pressures(80).map(|p| {
            to_xy(
                thermo::temperature_from_theta_k(theta, p * 100.0) - 273.15,
                p,
            )
        });
        for run in clipped(pts) {
            chart
                .draw_series(LineSeries::new(run, light(RGBColor(200, 100, 0))))
                .map_err(|x| e(&x))?;
        }
    }
    // Pseudo-adiabats through 0, 5, … 35 °C at 1000 hPa.
    for t in (0..=7).map(|i| 273.15 + 5.0 * i as f64) {
        for run in clipped(moist_adiabat(t)) {
            chart
                .draw_series(DashedLineSeries::new(
                    run,
                    6,
                    4,
                    light(RGBColor(0, 130, 60)),
                ))
                .map_err(|x| e(&x))?;
        }
    }
    // Mixing-ratio lines, lower troposphere only.
    for q_g in [1.0, 2.0, 4.0, 8.0, 16.0] {
        let pts = pressures(60).filter(|&p| p >= 600.0).map(|p| {
            to_xy(
                thermo::dewpoint_from_mixing_ratio_k(q_g / 1000.0, p * 100.0) - 273.15,
                p,
            )
        });
        for run in clipped(pts) {
            let label_at = *run.last().unwrap();
            chart
                .draw_series(DashedLineSeries::new(
                    run,
                    2,
                    4,
                    light(RGBColor(120, 0, 120)),
                ))
                .map_err(|x| e(&x))?;
            chart
                .draw_series(std::iter::once(Text::new(
                    format!("{q_g:.0}"),
                    label_at,
                    ("sans-serif", 12).into_font().color(&RGBColor(120, 0, 120)),
                )))
                .map_err(|x| e(&x))?;
        }
    }

    // Buoyant (CAPE, warm colour) and inhibited (CIN, cool colour) layers
    // between the parcel and environment curves, signed by virtual
    // temperature: positive above the LFC, negative below it.
    let lfc_z = chart_data.ascent.lfc.map(|m| m.z_m);
    let el_z = chart_data.ascent.el.map(|m| m.z_m).unwrap_or(f64::INFINITY);
    // One polygon per run of same-signed segments (adjacent thin polygons
    // would leave hairline seams): parcel points up, environment points back.
    let kind_of = |a: &ParcelLevel, b: &ParcelLevel| {
        let buoyancy = 0.5 * (a.tv_k - a.env_tv_k + b.tv_k - b.env_tv_k);
        match lfc_z {
            Some(lfc) if a.z_m >= lfc && b.z_m <= el_z && buoyancy > 0.0 => 1,
            Some(lfc) if b.z_m <= lfc && buoyancy < 0.0 => -1,
            _ => 0,
        }
    };
    let curve = chart_data.parcel_curve;
    let mut i = 0;
    while i + 1 < curve.len() {
        let kind = kind_of(&curve[i], &curve[i + 1]);
        let mut j = i + 1;
        while j + 1 < curve.len() && kind_of(&curve[j], &curve[j + 1]) == kind {
            j += 1;
        }
        let run = &curve[i..=j];
        i = j;
        let color = match kind {
            1 => RGBColor(255, 120, 60).mix(0.25),
            -1 => RGBColor(60, 120, 255).mix(0.18),
            _ => continue,
        };
        let poly: Vec<(f64, f64)> = run
            .iter()
            .map(|l| to_xy(l.t_k - 273.15, l.p_pa / 100.0))
            .chain(
                run.iter()
                    .rev()
                    .map(|l| to_xy(l.env_t_k - 273.15, l.p_pa / 100.0)),
            )
            .collect();
        if poly.iter().all(|&q| in_box(q)) {
            chart
                .draw_series(std::iter::once(Polygon::new(poly, color.filled())))
                .map_err(|x| e(&x))?;
        }
    }

    // Environment temperature and dewpoint, parcel temperature.
    let env = chart_data.env;
    let env_pts = |f: &dyn Fn(f64) -> f64| {
        env.levels()
            .iter()
            .map(|l| {
                let p = env.pressure_pa(l.z_m);
                to_xy(f(l.z_m) - 273.15, p / 100.0)
            })
            .collect::<Vec<_>>()
    };
    type Series = (&'static str, Vec<(f64, f64)>, RGBColor);
    let series: [Series; 3] = [
        (
            "environment temperature",
            env_pts(&|z| env.temperature_k(z)),
            RGBColor(210, 20, 20),
        ),
        (
            "environment dewpoint",
            env_pts(&|z| env.dewpoint_k(z)),
            RGBColor(20, 150, 40),
        ),
        (
            "parcel temperature",
            chart_data
                .parcel_curve
                .iter()
                .map(|l| to_xy(l.t_k - 273.15, l.p_pa / 100.0))
                .collect(),
            BLACK,
        ),
    ];
    for (name, pts, color) in series {
        let style = color.stroke_width(3);
        let runs = clipped(pts);
        if !runs.is_empty() {
            legend.push((name, style, false));
        }
        for run in runs {
            chart
                .draw_series(LineSeries::new(run, style))
                .map_err(|x| e(&x))?;
        }
    }

    if let Some(path) = chart_data.dynamic_path {
        let color = RGBColor(30, 90, 220);
        let pts: Vec<(f64, f64)> = path
            .iter()
            .map(|&(p_pa, t_k)| to_xy(t_k - 273.15, p_pa / 100.0))
            .collect();
        let runs = clipped(pts);
        if !runs.is_empty() {
            legend.push((
                "released parcel (full dynamics)",
                color.stroke_width(2),
                false,
            ));
        }
        for run in runs {
            chart
                .draw_series(LineSeries::new(run, color.stroke_width(2)))
                .map_err(|x| e(&x))?;
        }
    }

    // The parcel's virtual (density) temperature, which decides buoyancy.
    let tv: Vec<(f64, f64)> = chart_data
        .parcel_curve
        .iter()
        .map(|l| to_xy(l.tv_k - 273.15, l.p_pa / 100.0))
        .collect();
    let style = RGBColor(90, 90, 90).stroke_width(1);
    let runs = clipped(tv);
    if !runs.is_empty() {
        legend.push(("parcel virtual temperature", style, true));
    }
    for run in runs {
        chart
            .draw_series(DashedLineSeries::new(run, 5, 4, style))
            .map_err(|x| e(&x))?;
    }

    // LCL, LFC, EL: a tick across the parcel curve and a label beside it.
    let parcel_t_at = |m: &LevelMark| {
        let c = chart_data.parcel_curve;
        let i = c
            .partition_point(|l| l.z_m < m.z_m)
            .clamp(1, c.len().max(2) - 1);
        if c.len() < 2 {
            return None;
        }
        let (a, b) = (&c[i - 1], &c[i]);
        let w = ((m.z_m - a.z_m) / (b.z_m - a.z_m)).clamp(0.0, 1.0);
        Some(a.t_k + (b.t_k - a.t_k) * w)
    };
    let a = chart_data.ascent;
    for (name, mark) in [("LCL", a.lcl), ("LFC", a.lfc), ("EL", a.el)] {
        let Some(m) = mark else { continue };
        let Some(t) = parcel_t_at(&m) else { continue };
        let (x, y) = to_xy(t - 273.15, m.p_pa / 100.0);
        if !in_box((x, y)) {
            continue;
        }
        chart
            .draw_series(LineSeries::new(
                [(x - 3.0, y), (x + 3.0, y)],
                BLACK.stroke_width(2),
            ))
            .map_err(|x| e(&x))?;
        let (px, py) = chart.backend_coord(&(x + 3.5, y));
        root.draw_text(
            &format!("{name} {:.0} hPa, {:.2} km", m.p_pa / 100.0, m.z_m / 1000.0),
            &TextStyle::from(("sans-serif", 16).into_font())
                .pos(Pos::new(HPos::Left, VPos::Center)),
            (px, py),
        )
        .map_err(|x| e(&x))?;
    }

    let bottom = draw_legend(&side, below_summary + LEGEND_GAP_PX, &legend)?;
    if bottom > height as i32 {
        return Err(format!(
            "the legend ends at row {bottom}, below the image's {height} rows"
        ));
    }
    full.present().map_err(|x| e(&x))?;
    Ok(())
}

/// A curve's legend line: its name, its style, whether it is dashed.
type LegendEntry = (&'static str, ShapeStyle, bool);

/// Space between the side panel's summary and the legend, and between the
/// legend's curves and its key to the background lines. units: px
const LEGEND_GAP_PX: i32 = 14;

/// Key to the background lines, each in its colour.
const BACKGROUND_KEY: [(&str, RGBColor); 5] = [
    ("isotherms (10 °C)", RGBColor(40, 40, 160)),
    ("dry adiabats (10 K)", RGBColor(200, 100, 0)),
    ("moist adiabats (dashed)", RGBColor(0, 130, 60)),
    ("mixing ratio g/kg (dotted)", RGBColor(120, 0, 120)),
    ("shaded: CAPE (orange), CIN (blue)", RGBColor(200, 90, 40)),
];

/// Draws the curves' legend from row `top` of the side panel `area`, one
/// row per curve (a sample of its line, then its name), then the key to
/// the background lines, each below the last so none overlaps. Returns
/// the row below the key.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    top: i32,
    entries: &[LegendEntry],
) -> std::result::Result<i32, String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let (x0, x1, text_x) = (12, 40, 48);
    let mut y = top;
    for &(name, style, dashed) in entries {
        let mid = y + 10;
        let segments: Vec<[(i32, i32); 2]> = if dashed {
            vec![[(x0, mid), (x0 + 9, mid)], [(x0 + 14, mid), (x0 + 23, mid)]]
        } else {
            vec![[(x0, mid), (x1, mid)]]
        };
        for seg in segments {
            area.draw(&PathElement::new(seg.to_vec(), style))
                .map_err(|x| e(&x))?;
        }
        area.draw_text(
            name,
            &TextStyle::from(("sans-serif", 16).into_font())
                .pos(Pos::new(HPos::Left, VPos::Center)),
            (text_x, mid),
        )
        .map_err(|x| e(&x))?;
        y += 21;
    }
    y += LEGEND_GAP_PX;
    for (text, color) in BACKGROUND_KEY {
        area.draw_text(
            text,
            &TextStyle::from(("sans-serif", 14).into_font())
                .pos(Pos::new(HPos::Left, VPos::Top))
                .color(&color),
            (x0, y),
        )
        .map_err(|x| e(&x))?;
        y += 18;
    }
    Ok(y)
}

/// Draws the diagram and writes it atomically as a PNG of `width`×`height`
/// (the rightmost [`SIDE_PANEL_PX`] are the side panel).
pub fn write_skew_t_png(path: &Path, chart: &SkewT, width: u32, height: u32) -> Result<()> {
    super::write_rgb_png(path, "the Skew-T", width, height, |rgb| {
        draw(chart, rgb, width, height)
    })
}
