//! The egui side panel: profile diagram with draggable points and the lifted
//! parcel (paper fig. 5), condensation-level and mixing-ratio handles,
//! emission, wind, time of day, playback, render settings (with the slices
//! method's controls and ellipsoids, `slices_panel`), frame timings and
//! scene save/load. Every profile edit goes through `profile_edit`.

use egui::{Color32, RichText};
use egui_plot::{Line, LineStyle, MarkerShape, Plot, PlotBounds, PlotPoint, Points, Text};

use super::profile_edit::{self as pe, ProfileCurve};
use super::skewt_panel::{self as sk, ProfileView};
use super::state::Model;

const T_COLOR: Color32 = Color32::from_rgb(220, 60, 50);
const TD_COLOR: Color32 = Color32::from_rgb(40, 160, 70);
const PARCEL_COLOR: Color32 = Color32::from_rgb(240, 170, 30);
/// Grab radius of a profile point on the diagram. units: points (egui)
const GRAB_RADIUS: f32 = 12.0;
/// Width of the side panel. units: points (egui)
pub const PANEL_WIDTH: f32 = 380.0;
/// Speed of the "time-lapse" button: two simulated minutes per second.
pub const TIME_LAPSE_SPEED: f64 = 120.0;

/// What the panel asks the window to do beyond editing the model.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct PanelActions {
    /// Render settings changed: the window calls `Renderer::set_config`.
    pub render_changed: bool,
}

/// Panel state kept between frames that is not part of the model.
#[derive(Debug, Default, Clone)]
pub struct PanelState {
    /// The point being dragged on the diagram.
    drag: Option<(ProfileCurve, usize)>,
    /// Top of the diagram's height axis. units: m
    plot_top_m: Option<f64>,
    /// The diagram's plot ↔ screen mapping of the last frame.
    transform: Option<egui_plot::PlotTransform>,
    /// The diagram's temperature range of the last frame. units: °C
    x_range: Option<(f64, f64)>,
    /// Height–temperature or Skew-T log-p diagram.
    pub view: ProfileView,
    /// The environment the diagram was drawn on last frame (its P(z) maps
    /// heights in the Skew-T view).
    view_env: Option<crate::atmosphere::Environment>,
    /// The authored ellipsoid the slices panel edits.
    pub selected_ellipsoid: usize,
    /// Where the visibility slider was drawn last frame.
    visibility_slider: Option<egui::Rect>,
}

impl PanelState {
    /// Where the visibility slider was drawn last frame, in egui points
    /// (for tests that drag it as a user would).
    pub fn visibility_slider(&self) -> Option<egui::Rect> {
        self.visibility_slider
    }

    /// Where (temperature °C, height m) was drawn on the diagram last frame,
    /// in egui points: lets tests press and drag a profile point exactly as
    /// a user would.
    pub fn diagram_pos(&self, t_c: f64, z_m: f64) -> Option<egui::Pos2> {
        let [x, y] = match &self.view_env {
            Some(env) => sk::to_plot(self.view, env, t_c, z_m),
            None => [t_c, z_m],
        };
        self.transform
            .as_ref()
            .map(|t| t.position_from_point(&PlotPoint::new(x, y)))
    }
}

/// An egui context with fonts registered from `epaint_default_fonts`: the
/// crate is built without egui's `default_fonts` feature, and we never read
/// system fonts, so the panel looks the same everywhere.
pub fn egui_context() -> egui::Context {
    use egui::{FontData, FontDefinitions, FontFamily};
    use std::sync::Arc;
    let ctx = egui::Context::default();
    let mut fonts = FontDefinitions::empty();
    for (name, bytes) in [
        ("Ubuntu-Light", epaint_default_fonts::UBUNTU_LIGHT),
        ("Hack", epaint_default_fonts::HACK_REGULAR),
        ("egui-icons", epaint_default_fonts::EGUI_ICONS),
    ] {
        fonts
            .font_data
            .insert(name.to_owned(), Arc::new(FontData::from_static(bytes)));
    }
    fonts.families.insert(
        FontFamily::Proportional,
        vec!["Ubuntu-Light".into(), "Hack".into(), "egui-icons".into()],
    );
    fonts.families.insert(
        FontFamily::Monospace,
        vec!["Hack".into(), "Ubuntu-Light".into(), "egui-icons".into()],
    );
    ctx.set_fonts(fonts);
    ctx
}

/// Draws the panel into the left of `ui`. Returns what the window must do.
pub fn show(ui: &mut egui::Ui, m: &mut Model, ps: &mut PanelState) -> PanelActions {
    let mut actions = PanelActions::default();
    egui::Panel::left("controls")
        .resizable(false)
        .exact_size(PANEL_WIDTH)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading(m.title());
                profile_section(ui, m, ps);
                ui.separator();
                simulation_section(ui, m);
                ui.separator();
                actions.render_changed = render_section(ui, m, ps);
                ui.separator();
                if m.render_cfg.method == crate::config::RenderMethod::Slices {
                    actions.render_changed |=
                        super::slices_panel::slices_section(ui, m, &mut ps.selected_ellipsoid);
                    ui.separator();
                }
                stats_section(ui, m);
                ui.separator();
                // A loaded scene brings its own render settings.
                actions.render_changed |= file_section(ui, m);
            });
        });
    actions
}

fn report(m: &mut Model, r: crate::Result<()>) {
    match r {
        Ok(()) => m.status.clear(),
        Err(e) => m.status = e.to_string(),
    }
}

fn profile_section(ui: &mut egui::Ui, m: &mut Model, ps: &mut PanelState) {
    ui.label(RichText::new("Environment profile").strong());
    ui.label(
        "Drag points: temperature (red), dewpoint (green). Double-click adds a level, \
         right-click removes one. Orange: the lifted surface parcel.",
    );
    ui.horizontal(|ui| {
        ui.selectable_value(&mut ps.view, ProfileView::HeightTemperature, "height–T");
        ui.selectable_value(&mut ps.view, ProfileView::SkewT, "Skew-T log-p");
    });
    let view = ps.view;
    ps.view_env = Some(m.editor.environment().clone());
    let top_default = m
        .editor
        .el_m()
        .map(|el| (el * 1.6).max(3000.0))
        .unwrap_or(6000.0)
        .min(m.editor.points().last().map(|p| p.z_m).unwrap_or(6000.0));
    let plot_top = *ps.plot_top_m.get_or_insert(top_default);
    let (tmin, tmax) = m
        .editor
        .points()
        .iter()
        .filter(|p| p.z_m <= plot_top * 1.2)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(pe::dewpoint_c(p)), b.max(p.t_c))
        });
    // The temperature axis follows the profile, except during a drag: then
    // it stays put, or a point dragged near the edge would widen the axis
    // under a still pointer and creep away from it.
    let (xmin, xmax) = match (ps.drag, ps.x_range) {
        (Some(_), Some(r)) => r,
        _ if view == ProfileView::SkewT => (-30.0, 45.0),
        _ => ((tmin - 5.0).min(-10.0), (tmax + 5.0).max(30.0)),
    };
    ps.x_range = Some((xmin, xmax));

    let mut edit: Option<crate::Result<()>> = None;
    let drag = &mut ps.drag;
    let editor = &mut m.editor;
    let env_now = editor.environment().clone();
    let ps_pa = env_now.surface_pressure_pa();
    let to_plot = |t: f64, z: f64| sk::to_plot(view, &env_now, t, z);
    let shown = sk::configure(Plot::new("profile"), view, ps_pa)
        .height(300.0)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_boxed_zoom(false)
        .allow_double_click_reset(false)
        .show(ui, |plot_ui| {
            // A little room below the ground so the surface points are
            // inside the plot (not on the axis below it) and can be grabbed.
            let ytop = to_plot(0.0, plot_top)[1];
            let below = -0.04 * ytop;
            let bounds = PlotBounds::from_min_max([xmin, below], [xmax, ytop]);
            plot_ui.set_plot_bounds(bounds);
            sk::background(plot_ui, view, ps_pa, bounds);
            let resp = plot_ui.response().clone();
            // The pointer now (egui_plot's pointer_coordinate lags a frame
            // behind while dragging).
            let pointer = resp
                .interact_pointer_pos()
                .or(resp.hover_pos())
                .map(|p| plot_ui.plot_from_screen(p))
                .map(|p| {
                    let (t, z) = sk::from_plot(view, &env_now, p.x, p.y);
                    PlotPoint::new(t, z)
                });
            // A drag starts a few points away from the press: grab what was
            // under the press.
            let grab = plot_ui.ctx().input(|i| i.pointer.press_origin());
            let nearest =
                |plot_ui: &egui_plot::PlotUi<'_>, points: &[crate::atmosphere::AtmospherePoint]| {
                    let pos = grab.or(resp.interact_pointer_pos()).or(resp.hover_pos())?;
                    let mut best: Option<(f32, ProfileCurve, usize)> = None;
                    for (i, p) in points.iter().enumerate() {
                        for (c, x) in [
                            (ProfileCurve::Temperature, p.t_c),
                            (ProfileCurve::Dewpoint, pe::dewpoint_c(p)),
                        ] {
                            let [px, py] = to_plot(x, p.z_m);
                            let d = plot_ui
                                .screen_from_plot(PlotPoint::new(px, py))
                                .distance(pos);
                            if d < GRAB_RADIUS && best.is_none_or(|b| d < b.0) {
                                best = Some((d, c, i));
                            }
                        }
                    }
                    best.map(|(_, c, i)| (c, i))
                };
            if resp.drag_started() {
                *drag = nearest(plot_ui, editor.points());
            }
            if let (Some((c, i)), Some(p)) = (*drag, pointer)
                && (resp.dragged() || resp.drag_stopped())
            {
                edit = Some(pe::move_point(editor, c, i, p.y, p.x));
            }
            if resp.drag_stopped() {
                *drag = None;
            }
            if resp.double_clicked()
                && let Some(p) = pointer
            {
                edit = Some(pe::add_point(editor, p.y).map(|_| ()));
            }
            if resp.secondary_clicked()
                && let Some((_, i)) = nearest(plot_ui, editor.points())
            {
                edit = Some(pe::remove_point(editor, i));
            }

            let pts = editor.points();
            let t: Vec<[f64; 2]> = pts.iter().map(|p| to_plot(p.t_c, p.z_m)).collect();
            let td: Vec<[f64; 2]> = pts
                .iter()
                .map(|p| to_plot(pe::dewpoint_c(p), p.z_m))
                .collect();
            let curve = editor.curve();
            let parcel: Vec<[f64; 2]> = curve
                .levels
                .iter()
                .map(|c| to_plot(c.t_k - 273.15, c.z_m))
                .collect();
            plot_ui.line(Line::new("parcel", parcel).color(PARCEL_COLOR).width(2.0));
            plot_ui.line(
                Line::new("temperature", t.clone())
                    .color(T_COLOR)
                    .width(2.0),
            );
            plot_ui.line(Line::new("dewpoint", td.clone()).color(TD_COLOR).width(2.0));
            plot_ui.points(
                Points::new("T points", t)
                    .color(T_COLOR)
                    .radius(5.0)
                    .shape(MarkerShape::Circle)
                    .filled(true),
            );
            plot_ui.points(
                Points::new("Td points", td)
                    .color(TD_COLOR)
                    .radius(5.0)
                    .shape(MarkerShape::Circle)
                    .filled(true),
            );
            for (label, z) in [("LCL", curve.lcl), ("LFC", curve.lfc), ("EL", curve.el)]
                .map(|(l, mark)| (l, mark.map(|m| m.z_m)))
            {
                if let Some(z) = z {
                    let z = to_plot(0.0, z)[1];
                    let level = vec![[xmin, z], [xmax, z]];
                    plot_ui.line(
                        Line::new(label, level)
                            .color(Color32::GRAY)
                            .style(LineStyle::dashed_dense()),
                    );
                    plot_ui.text(
                        Text::new(label, PlotPoint::new(xmax - 0.12 * (xmax - xmin), z), label)
                            .color(Color32::DARK_GRAY),
                    );
                }
            }
        });
    ps.transform = Some(shown.transform);
    if let Some(r) = edit {
        report(m, r);
        m.sync_handles();
    }
    let show_z = |z: Option<f64>| z.map(|z| format!("{z:.0} m")).unwrap_or("none".into());
    ui.label(format!(
        "LCL {}   LFC {}   EL {}",
        show_z(m.editor.lcl_m()),
        show_z(m.editor.lfc_m()),
        show_z(m.editor.el_m())
    ));
    for (kind, cape, cin) in m.editor.parcel_energies() {
        ui.label(format!(
            "{} parcel: CAPE {cape:.0} J/kg   CIN {cin:.0} J/kg",
            kind.key()
        ));
    }
    ui.label(format!(
        "({} thermodynamics, LFC of the most CAPE, as `cumulus parcel`)",
        crate::app::profile_edit::ENERGY_THERMO.key()
    ));
    sk::hodograph(ui, m.editor.environment().wind());
    ui.add(
        egui::Slider::new(
            ps.plot_top_m.as_mut().expect("set above"),
            1000.0
                ..=m.editor
                    .points()
                    .last()
                    .map(|p| p.z_m)
                    .unwrap_or(12_000.0)
                    .max(1001.0),
        )
        .text("diagram top (m)"),
    );

    let top = m.editor.points().last().map(|p| p.z_m).unwrap_or(1000.0);
    let cl = ui.add(
        egui::Slider::new(&mut m.cond_level_m, 50.0..=top.min(6000.0))
            .text("condensation level (m)"),
    );
    if cl.changed() {
        let r = pe::set_condensation_level(&mut m.editor, m.cond_level_m);
        report(m, r);
        m.surface_qv_g_per_kg = m.editor.surface_mixing_ratio() * 1000.0;
    }
    let qs_g = {
        let p0 = m.editor.points()[0];
        crate::atmosphere::thermo::saturation_mixing_ratio(
            p0.t_c + 273.15,
            m.editor.surface_pressure_pa(),
        ) * 1000.0
    };
    let q = ui.add(
        egui::Slider::new(&mut m.surface_qv_g_per_kg, 0.5..=qs_g.max(0.6))
            .text("surface mixing ratio (g/kg)"),
    );
    if q.changed() {
        let r = pe::set_surface_mixing_ratio(&mut m.editor, m.surface_qv_g_per_kg / 1000.0);
        report(m, r);
        m.cond_level_m = m.editor.lcl_m().unwrap_or(0.0);
    }
}

fn simulation_section(ui: &mut egui::Ui, m: &mut Model) {
    ui.label(RichText::new("Simulation").strong());
    if let Some(done) = m.warm_up_progress() {
        ui.add(egui::ProgressBar::new(done as f32).text(format!(
            "simulating to the start: {:.0} of {:.0} s",
            m.world.time_s(),
            m.start_s
        )));
    }
    ui.horizontal(|ui| {
        let label = if m.playback.playing { "Pause" } else { "Play" };
        if ui.button(label).clicked() {
            m.playback.playing = !m.playback.playing;
        }
        if ui
            .add_enabled(!m.playback.playing, egui::Button::new("Step"))
            .clicked()
        {
            m.playback.step_once = true;
        }
        if ui.button("Reset").clicked() {
            let r = m.reset();
            report(m, r);
        }
    });
    ui.horizontal(|ui| {
        ui.add(
            egui::Slider::new(&mut m.playback.speed, 0.1..=600.0)
                .logarithmic(true)
                .text("time speed (×)"),
        );
        if ui.button("time-lapse").clicked() {
            m.playback.speed = TIME_LAPSE_SPEED;
        }
    });
    let mut cfg = m.world_cfg.clone();
    let mut changed = ui
        .add(
            egui::Slider::new(&mut cfg.emission.rate_per_km2_per_h, 0.0..=300.0)
                .text("emission (per km² per h)"),
        )
        .changed();
    changed |= ui
        .add(egui::Slider::new(&mut m.wind.speed_m_s, 0.0..=25.0).text("wind aloft (m/s)"))
        .changed();
    changed |= ui
        .add(egui::Slider::new(&mut m.wind.from_deg, 0.0..=360.0).text("wind from (° from north)"))
        .changed();
    if changed {
        let r = m.apply_world_config(cfg);
        report(m, r);
    }
    let mut hour = m.time_of_day_h();
    if ui
        .add(egui::Slider::new(&mut hour, 0.0..=23.99).text("time of day (h)"))
        .changed()
    {
        let r = m.set_time_of_day_h(hour);
        report(m, r);
    }
    if let Some(c) = m.clock {
        let t = m.world.time_s();
        let p = c.position(t);
        let held = if p.elevation_deg < crate::sun::MIN_LIGHT_ELEVATION_DEG {
            " (below the horizon: light held low, dimmed)"
        } else {
            ""
        };
        ui.label(format!(
            "sun az {:.0}°  el {:.1}°  {}{held}",
            p.azimuth_deg,
            p.elevation_deg,
            c.local_date(t)
        ));
    } else {
        ui.label("sun pinned by the scene ([render] azimuth/elevation)");
    }
    let d = m.world.diagnostics();
    ui.label(format!(
        "t = {:.0} s   parcels {}   condensed {}",
        d.time_s, d.parcels, d.condensed_parcels
    ));
    let show = |z: Option<f64>| z.map(|z| format!("{z:.0} m")).unwrap_or("-".into());
    ui.label(format!(
        "cloud base {}   top {}   escaped {}",
        show(d.cloud_base_m),
        show(d.cloud_top_m),
        d.escaped
    ));
    super::clamps_panel::show(ui, &d);
}

/// Returns whether a render setting changed.
fn render_section(ui: &mut egui::Ui, m: &mut Model, ps: &mut PanelState) -> bool {
    ui.label(RichText::new("Rendering").strong());
    let before = m.render_cfg.clone();
    let r = &mut m.render_cfg;
    ui.horizontal(|ui| {
        ui.label("method");
        for method in crate::config::RenderMethod::ALL {
            ui.radio_value(&mut r.method, method, method.name());
        }
    });
    ui.add(
        egui::Slider::new(&mut r.step_m, 10.0..=200.0)
            .logarithmic(true)
            .text("march step (m)"),
    );
    ui.add(egui::Slider::new(&mut r.noise_octaves, 1..=6).text("noise octaves"));
    ui.add(
        egui::Slider::new(&mut r.exposure_ev, -4.0..=4.0)
            .step_by(0.1)
            .text("exposure (EV)"),
    )
    .on_hover_text("exposure compensation of the tone curve, in stops");
    // Every new visibility rebuilds the sky's LUTs (25 ms on two cores), so
    // a drag shows its value and applies it when the drag ends.
    let v = crate::sky::VISIBILITY_KM;
    let pending_id = egui::Id::unique("visibility_km dragged");
    let mut visibility = ui
        .data(|d| d.get_temp::<f32>(pending_id))
        .unwrap_or(r.visibility_km);
    let slider = ui
        .add(
            egui::Slider::new(&mut visibility, *v.start() as f32..=*v.end() as f32)
                .logarithmic(true)
                .text("visibility (km)"),
        )
        .on_hover_text(
            "how far one sees through the haze near the ground: sets the aerosol of the sky \
             and the air (applied when the drag ends)",
        );
    ps.visibility_slider = Some(slider.rect);
    if slider.dragged() {
        ui.data_mut(|d| d.insert_temp(pending_id, visibility));
    } else {
        ui.data_mut(|d| d.remove::<f32>(pending_id));
        r.visibility_km = visibility;
    }
    ui.horizontal(|ui| {
        ui.checkbox(&mut r.normals, "normals");
        ui.checkbox(&mut r.shadows, "shadows");
        ui.checkbox(&mut r.terrain.enabled, "terrain");
        // Unset: the window's default, 4x4.
        let shown = r.temporal.unwrap_or_default().name();
        egui::ComboBox::from_label("temporal")
            .selected_text(shown)
            .show_ui(ui, |ui| {
                for m in crate::config::TemporalMode::ALL {
                    ui.selectable_value(&mut r.temporal, Some(m), m.name());
                }
            });
    });
    ui.checkbox(&mut r.aerial_perspective, "aerial perspective")
        .on_hover_text(
            "the air between the eye and the ground and clouds (the sky's atmosphere model)",
        );
    if ui.button("Reset view").clicked() {
        m.camera = m.default_camera;
    }
    ui.small(
        "drag: orbit · right-drag: look around · W A S D / Q E: fly · wheel: zoom · \
         R: reset view · space: play/pause",
    );
    if m.render_cfg == before {
        return false;
    }
    // A value the renderer would refuse is reverted here, with the reason.
    if let Err(e) = m.render_cfg.validate() {
        m.render_cfg = before;
        m.status = e.to_string();
        return false;
    }
    true
}

fn stats_section(ui: &mut egui::Ui, m: &mut Model) {
    ui.label(RichText::new("Frame time").strong());
    let s = &m.stats;
    if !s.adapter.is_empty() {
        ui.small(&s.adapter);
    }
    let fps = if s.frame_ms > 0.0 {
        1000.0 / s.frame_ms
    } else {
        0.0
    };
    ui.monospace(format!("frame    {:7.2} ms  ({fps:.1} fps)", s.frame_ms));
    ui.monospace(format!(
        "physics  {:7.2} ms  ({} sub-steps)",
        s.physics_ms, s.substeps
    ));
    for (name, ms) in &s.physics_stages {
        ui.monospace(format!("  {name:<12} {ms:7.2} ms"));
    }
    ui.monospace(format!("upload   {:7.2} ms", s.upload_ms));
    for (name, ms) in &s.passes {
        ui.monospace(format!("{name:<8} {ms:7.2} ms"));
    }
    if !s.passes.is_empty() && !s.gpu_timestamps {
        ui.small("(passes timed on the CPU with a queue sync: no GPU timestamps)");
    }
    ui.monospace(format!("cloud parcels drawn: {}", m.parcels.len()));
    if let Some(note) = &s.bake_note {
        ui.small(note);
    }
}

/// Returns whether a scene was loaded.
fn file_section(ui: &mut egui::Ui, m: &mut Model) -> bool {
    let mut loaded = false;
    ui.label(RichText::new("Scene profile").strong());
    ui.text_edit_singleline(&mut m.path_text);
    ui.horizontal(|ui| {
        if ui.button("Save").clicked() {
            let r = m.path().and_then(|p| m.save(&p).map(|()| p));
            match r {
                Ok(p) => m.status = format!("saved {}", p.display()),
                Err(e) => m.status = e.to_string(),
            }
        }
        if ui.button("Load").clicked() {
            let r = m.path().and_then(|p| m.load(&p));
            loaded = r.is_ok();
            report(m, r);
        }
    });
    if !m.status.is_empty() {
        ui.colored_label(Color32::from_rgb(200, 120, 0), &m.status);
    }
    loaded
}
