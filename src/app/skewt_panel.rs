//! The profile diagram's two views and the panel's hodograph. The editor's
//! diagram shows either height against temperature or a Skew-T log-p chart
//! (as SHARPpy): y = ln(P_surface / P), labelled in hPa, and x = T + SKEW·y,
//! so isotherms lean 45°-ish to the right. Points are drawn and dragged
//! through [`to_plot`] and [`from_plot`], so dragging works the same in
//! either view; the edit itself is `profile_edit::move_point` in both.

use egui::Color32;
use egui_plot::{Line, Plot, PlotBounds};

use crate::atmosphere::{Environment, WindProfile, thermo};

/// Skew of the panel's Skew-T: °C of x shift per e-fold of pressure. 35
/// gives isotherms at about 45° in the 380×300 point diagram (its x span of
/// ~70 °C against a y span of ~1.6 e-folds to 200 hPa).
pub const SKEW_C: f64 = 35.0;

/// Isobars drawn and labelled on the panel's Skew-T. units: hPa
const ISOBARS_HPA: [f64; 9] = [
    1000.0, 925.0, 850.0, 700.0, 500.0, 400.0, 300.0, 200.0, 100.0,
];

/// Which coordinates the profile diagram uses.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub enum ProfileView {
    /// x = temperature (°C), y = height above the ground (m).
    #[default]
    HeightTemperature,
    /// Skew-T log-p: x = T + SKEW·y (°C), y = ln(P_surface / P).
    SkewT,
}

/// Plot coordinates of temperature `t_c` (°C) at height `z_m` (m).
pub fn to_plot(view: ProfileView, env: &Environment, t_c: f64, z_m: f64) -> [f64; 2] {
    match view {
        ProfileView::HeightTemperature => [t_c, z_m],
        ProfileView::SkewT => {
            let y = (env.surface_pressure_pa() / env.pressure_pa(z_m)).ln();
            [t_c + SKEW_C * y, y]
        }
    }
}

/// Temperature (°C) and height (m) at plot coordinates (x, y): the inverse
/// of [`to_plot`]. Below the ground the height is 0; above the profile's top
/// the height continues with the top's scale height R_d T / g.
pub fn from_plot(view: ProfileView, env: &Environment, x: f64, y: f64) -> (f64, f64) {
    match view {
        ProfileView::HeightTemperature => (x, y),
        ProfileView::SkewT => {
            let p = env.surface_pressure_pa() * (-y).exp();
            let top = env.top_m();
            let z = if p >= env.surface_pressure_pa() {
                0.0
            } else {
                env.height_at_pressure_m(p).unwrap_or_else(|| {
                    let scale_m = thermo::R_DRY * env.temperature_k(top) / thermo::GRAVITY;
                    top + scale_m * (env.pressure_pa(top) / p).ln()
                })
            };
            (x - SKEW_C * y, z)
        }
    }
}

/// Sets the diagram's axes for `view`: height in m, or pressure in hPa
/// along the log-p axis; x is the temperature (at the surface pressure in
/// the Skew-T).
pub fn configure(plot: Plot<'_>, view: ProfileView, surface_pressure_pa: f64) -> Plot<'_> {
    match view {
        ProfileView::HeightTemperature => plot
            .x_axis_label("temperature (°C)")
            .y_axis_label("height (m)"),
        ProfileView::SkewT => plot
            .x_axis_label("temperature (°C), isotherms skewed")
            .y_axis_label("pressure (hPa)")
            // Grid lines on the standard isobars, labelled in hPa.
            .y_grid_spacer(move |input| {
                ISOBARS_HPA
                    .iter()
                    .map(|p| (surface_pressure_pa / (p * 100.0)).ln())
                    .filter(|&y| y >= input.bounds.0 && y <= input.bounds.1)
                    .map(|value| egui_plot::GridMark {
                        value,
                        step_size: 0.2,
                    })
                    .collect()
            })
            .y_axis_formatter(move |mark, _| {
                format!("{:.0}", surface_pressure_pa * (-mark.value).exp() / 100.0)
            }),
    }
}

/// The Skew-T's background inside `bounds`: isotherms every 10 °C and dry
/// adiabats every 10 K (nothing in the height view, whose grid is enough).
pub fn background(
    plot_ui: &mut egui_plot::PlotUi<'_>,
    view: ProfileView,
    ps_pa: f64,
    bounds: PlotBounds,
) {
    if view != ProfileView::SkewT {
        return;
    }
    let (y0, y1) = (bounds.min()[1].max(0.0), bounds.max()[1]);
    let (x0, x1) = (bounds.min()[0], bounds.max()[0]);
    let ys: Vec<f64> = (0..=24).map(|i| y0 + (y1 - y0) * i as f64 / 24.0).collect();
    let grey = Color32::from_rgba_unmultiplied(120, 120, 160, 90);
    let orange = Color32::from_rgba_unmultiplied(200, 120, 40, 90);
    let inside = |pts: Vec<[f64; 2]>| -> Vec<[f64; 2]> {
        pts.into_iter()
            .filter(|p| p[0] >= x0 && p[0] <= x1)
            .collect()
    };
    let (tlo, thi) = ((x0 - SKEW_C * y1) / 10.0, x1 / 10.0);
    for k in tlo.floor() as i32..=thi.ceil() as i32 {
        let t = k as f64 * 10.0;
        let pts = inside(ys.iter().map(|&y| [t + SKEW_C * y, y]).collect());
        if pts.len() > 1 {
            plot_ui.line(
                Line::new(format!("isotherm {t}"), pts)
                    .color(grey)
                    .width(1.0),
            );
        }
    }
    for k in 25..=45 {
        let theta = k as f64 * 10.0;
        let pts = inside(
            ys.iter()
                .map(|&y| {
                    let t = thermo::temperature_from_theta_k(theta, ps_pa * (-y).exp()) - 273.15;
                    [t + SKEW_C * y, y]
                })
                .collect(),
        );
        if pts.len() > 1 {
            plot_ui.line(
                Line::new(format!("dry adiabat {theta}"), pts)
                    .color(orange)
                    .width(1.0),
            );
        }
    }
}

/// The hodograph of the environment's wind (0–12 km, the layers of the PNG's
/// hodograph), or a line saying there is none.
pub fn hodograph(ui: &mut egui::Ui, wind: Option<&WindProfile>) {
    let Some(wind) = wind else {
        ui.label("Wind: none in the profile (no DRCT/SKNT): the scene's [wind] drags the parcels.");
        return;
    };
    ui.label(format!(
        "Wind from the sounding (drives the drag unless the scene sets [wind]); 0–6 km shear {:.0} m/s",
        wind.bulk_shear_m_s(0.0, 6000.0)
    ));
    let top = wind
        .levels()
        .last()
        .map(|l| l.z_m)
        .unwrap_or(0.0)
        .min(12_000.0);
    Plot::new("hodograph")
        .height(160.0)
        .data_aspect(1.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .x_axis_label("u (m/s)")
        .y_axis_label("v (m/s)")
        .show(ui, |plot_ui| {
            for (lo, hi, c) in crate::plots::hodograph::LAYERS {
                let n = 40;
                let (lo, hi) = (lo.min(top), hi.min(top));
                if hi <= lo {
                    continue;
                }
                let pts: Vec<[f64; 2]> = (0..=n)
                    .map(|i| {
                        let [u, v] = wind.at(lo + (hi - lo) * i as f64 / n as f64);
                        [u, v]
                    })
                    .collect();
                let label = format!("{:.0}–{:.0} km", lo / 1000.0, hi / 1000.0);
                plot_ui.line(
                    Line::new(label, pts)
                        .color(Color32::from_rgb(c.0, c.1, c.2))
                        .width(2.0),
                );
            }
        });
}
