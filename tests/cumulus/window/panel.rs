//! The window's panel driven by synthetic mouse input, headless (egui needs
//! no display or GPU): pressing and dragging a point on the profile diagram,
//! and the condensation-level slider, edit the profile through
//! `app::profile_edit`, move the lifted parcel's LCL, and reach the running
//! simulation on the next frame.

use cumulus::app::panel::{self, PanelState};
use cumulus::app::profile_edit::dewpoint_c;
use cumulus::app::state::Model;
use egui::{Event, Modifiers, PointerButton, Pos2, RawInput, Rect, pos2, vec2};

/// One egui frame of the panel with `events`; `t` advances the clock.
struct Harness {
    ctx: egui::Context,
    ps: PanelState,
    m: Model,
    t: f64,
    /// Screen height in points (tall enough to show the whole panel
    /// without scrolling where a test needs a lower section).
    height: f32,
}

impl Harness {
    fn new() -> Self {
        Self::with_height(760.0)
    }

    fn with_height(height: f32) -> Self {
        let (profile, source) = cumulus::scene::load_scene(None).unwrap();
        let mut h = Self {
            ctx: panel::egui_context(),
            ps: PanelState::default(),
            m: Model::new(profile, source).unwrap(),
            t: 0.0,
            height,
        };
        // Two frames to lay out (fonts, plot bounds).
        h.frame(vec![]);
        h.frame(vec![]);
        h
    }

    fn frame(&mut self, events: Vec<Event>) {
        self.t += 0.05;
        let input = RawInput {
            screen_rect: Some(Rect::from_min_size(Pos2::ZERO, vec2(1280.0, self.height))),
            time: Some(self.t),
            events,
            ..Default::default()
        };
        let (m, ps) = (&mut self.m, &mut self.ps);
        let _ = self.ctx.run_ui(input, |ui| {
            panel::show(ui, m, ps);
        });
        // What the window does after the panel each frame.
        self.m.advance(0.0);
    }

    /// Press at `from`, move in small steps to `to`, release.
    fn drag(&mut self, from: Pos2, to: Pos2) {
        let button = |pos, pressed| Event::PointerButton {
            pos,
            button: PointerButton::Primary,
            pressed,
            modifiers: Modifiers::default(),
        };
        self.frame(vec![Event::PointerMoved(from)]);
        self.frame(vec![button(from, true)]);
        for i in 1..=8 {
            let p = from + (to - from) * (i as f32 / 8.0);
            self.frame(vec![Event::PointerMoved(p)]);
        }
        self.frame(vec![button(to, false)]);
        self.frame(vec![]);
    }
}

#[test]
fn dragging_the_surface_dewpoint_moves_the_lcl_and_the_world() {
    let mut h = Harness::new();
    let p0 = h.m.editor.points()[0];
    let td0 = dewpoint_c(&p0);
    let lcl0 = h.m.editor.lcl_m().unwrap();
    let rev0 = h.m.editor.revision();
    let from = h.ps.diagram_pos(td0, 0.0).expect("diagram drawn");
    // Two degrees to the right on the diagram, in screen points.
    let to_x = h.ps.diagram_pos(td0 + 2.0, 0.0).unwrap().x;
    h.drag(from, pos2(to_x, from.y - 40.0));

    let p = h.m.editor.points()[0];
    assert!(h.m.editor.revision() > rev0, "the drag edited the profile");
    // The surface point stays on the ground however the mouse moves.
    assert_eq!(p.z_m, 0.0);
    // The pointer lands within a fraction of a screen point of the target:
    // 0.1 °C is a few hundredths of the diagram's width.
    assert!((dewpoint_c(&p) - (td0 + 2.0)).abs() < 0.1, "{p:?}");
    assert_eq!(p.t_c, p0.t_c, "only the dewpoint was dragged");
    // 2 K less dewpoint depression: ~250 m lower LCL (Espy, 125 m/K), give
    // or take 20%.
    let lcl = h.m.editor.lcl_m().unwrap();
    assert!((lcl0 - lcl - 250.0).abs() < 50.0, "LCL {lcl0} → {lcl}");
    // The running world has the edited environment.
    assert_eq!(
        h.m.world.environment().qv(0.0),
        h.m.editor.environment().qv(0.0)
    );
}

#[test]
fn dragging_an_inversion_point_up_raises_the_cloud_top() {
    let mut h = Harness::new();
    let el0 = h.m.editor.el_m().unwrap();
    // The inversion top: the first level warmer than the one below.
    let pts = h.m.editor.points().to_vec();
    let i = (1..pts.len())
        .find(|&i| pts[i].t_c > pts[i - 1].t_c)
        .unwrap();
    // The cloud layer's lapse rate below the inversion base (i − 1).
    let (a, b) = (pts[i - 2], pts[i - 1]);
    let lapse = (a.t_c - b.t_c) / (b.z_m - a.z_m);
    // Move the inversion top up 400 m, then its base, continuing the cloud
    // layer's lapse rate (top first so the heights stay in order).
    for (j, dt) in [(i, 0.0), (i - 1, -lapse * 400.0)] {
        let p = h.m.editor.points()[j];
        let from = h.ps.diagram_pos(p.t_c, p.z_m).unwrap();
        let to = h.ps.diagram_pos(p.t_c + dt, p.z_m + 400.0).unwrap();
        h.drag(from, to);
        let moved = h.m.editor.points()[j];
        // Pointer placement: a screen point is ~10 m of height and ~0.1 K.
        assert!(
            (moved.z_m - (p.z_m + 400.0)).abs() < 15.0,
            "{p:?} → {moved:?}"
        );
        assert!((moved.t_c - (p.t_c + dt)).abs() < 0.2, "{p:?} → {moved:?}");
    }
    let el = h.m.editor.el_m().unwrap();
    // The buoyant cloud layer below the cap is 400 m deeper.
    assert!(el > el0 + 200.0, "EL {el0} → {el}");
}

#[test]
fn clicks_beside_points_do_not_edit() {
    let mut h = Harness::new();
    let p = h.m.editor.points()[1];
    let at = h.ps.diagram_pos(p.t_c, p.z_m).unwrap() + vec2(40.0, 0.0);
    h.drag(at, at + vec2(30.0, -30.0));
    assert_eq!(h.m.editor.revision(), 0, "nothing was grabbed");
}

#[test]
fn double_click_adds_a_level_and_right_click_removes_it() {
    let mut h = Harness::new();
    let n = h.m.editor.points().len();
    let env0 = h.m.editor.environment().clone();
    // Double-click on empty diagram space at 3 km.
    let at = h.ps.diagram_pos(0.0, 3000.0).unwrap();
    let click = |pressed, button| Event::PointerButton {
        pos: at,
        button,
        pressed,
        modifiers: Modifiers::default(),
    };
    h.frame(vec![Event::PointerMoved(at)]);
    h.frame(vec![click(true, PointerButton::Primary)]);
    h.frame(vec![click(false, PointerButton::Primary)]);
    h.frame(vec![click(true, PointerButton::Primary)]);
    h.frame(vec![click(false, PointerButton::Primary)]);
    h.frame(vec![]);
    let pts = h.m.editor.points().to_vec();
    assert_eq!(pts.len(), n + 1);
    let new = pts
        .iter()
        .position(|p| (p.z_m - 3000.0).abs() < 15.0)
        .expect("a level at 3 km");
    // Interpolated from the profile: the environment is unchanged there
    // (θ within the T-vs-θ interpolation difference, < 0.05 K).
    let z = pts[new].z_m;
    assert!((h.m.editor.environment().theta_k(z) - env0.theta_k(z)).abs() < 0.05);

    // Right-click on its temperature point removes it again.
    let on = h.ps.diagram_pos(pts[new].t_c, z).unwrap();
    let rclick = |pressed| Event::PointerButton {
        pos: on,
        button: PointerButton::Secondary,
        pressed,
        modifiers: Modifiers::default(),
    };
    h.frame(vec![Event::PointerMoved(on)]);
    h.frame(vec![rclick(true)]);
    h.frame(vec![rclick(false)]);
    h.frame(vec![]);
    assert_eq!(h.m.editor.points().len(), n);
    assert!(h.m.editor.points().iter().all(|p| (p.z_m - z).abs() > 1.0));
}

#[test]
fn a_point_held_near_the_diagram_edge_stays_under_the_pointer() {
    let mut h = Harness::new();
    let p0 = h.m.editor.points()[0];
    let from = h.ps.diagram_pos(p0.t_c, 0.0).unwrap();
    // Near the right edge of the temperature axis (which is tmax + 5 °C).
    let to = h.ps.diagram_pos(p0.t_c + 4.5, 0.0).unwrap();
    let button = |pos, pressed| Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::default(),
    };
    h.frame(vec![Event::PointerMoved(from)]);
    h.frame(vec![button(from, true)]);
    for i in 1..=8 {
        h.frame(vec![Event::PointerMoved(
            from + (to - from) * (i as f32 / 8.0),
        )]);
    }
    let reached = h.m.editor.points()[0].t_c;
    // Hold still: the axis must not widen under the pointer and drag the
    // point further each frame.
    for _ in 0..20 {
        h.frame(vec![Event::PointerMoved(to)]);
    }
    h.frame(vec![button(to, false)]);
    let held = h.m.editor.points()[0].t_c;
    // Pointer placement on the diagram: ~0.1 K per screen point.
    assert!((reached - (p0.t_c + 4.5)).abs() < 0.1, "{reached}");
    assert!(
        (held - reached).abs() < 1e-6,
        "crept from {reached} to {held}"
    );
}

#[test]
fn skew_t_view_drags_points_and_updates_cape_live() {
    use cumulus::app::skewt_panel::ProfileView;
    let mut h = Harness::new();
    h.ps.view = ProfileView::SkewT;
    h.frame(vec![]);
    h.frame(vec![]);
    let (cape0, _) = h.m.editor.cape_cin_j_per_kg();
    let p0 = h.m.editor.points()[0];
    // Warm the surface 2 K by dragging its temperature point along the
    // Skew-T's ground line: in this view x is skewed, so the target comes
    // from the view's own mapping.
    let from = h.ps.diagram_pos(p0.t_c, 0.0).expect("diagram drawn");
    let to = h.ps.diagram_pos(p0.t_c + 2.0, 0.0).unwrap();
    assert!((to.x - from.x) > 2.0, "2 K is a visible distance");
    h.drag(from, to);
    let p = h.m.editor.points()[0];
    // Same placement tolerance as the height view (0.1 K ≈ a screen point).
    assert!((p.t_c - (p0.t_c + 2.0)).abs() < 0.1, "{p0:?} → {p:?}");
    // The panel's CAPE/CIN are the edited environment's, at once (with
    // the panel's thermodynamics, `cumulus parcel`'s default).
    let (cape, cin) = h.m.editor.cape_cin_j_per_kg();
    let fresh = cumulus::atmosphere::cape::parcel_report(
        h.m.editor.environment(),
        cumulus::atmosphere::cape::ParcelKind::Surface,
        &cumulus::atmosphere::lifting::LiftOptions {
            thermo: cumulus::app::profile_edit::ENERGY_THERMO,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((cape, cin), (fresh.cape_j_per_kg, fresh.cin_j_per_kg));
    assert_ne!(cape, cape0, "the edit changed CAPE");

    // A point above the ground dragged up in the Skew-T lands at the height
    // whose pressure is under the pointer.
    let q = h.m.editor.points()[2];
    let from = h.ps.diagram_pos(q.t_c, q.z_m).unwrap();
    let to = h.ps.diagram_pos(q.t_c, q.z_m + 300.0).unwrap();
    h.drag(from, to);
    let moved = h.m.editor.points()[2];
    // A screen point is ~10–15 m of height in this view.
    assert!(
        (moved.z_m - (q.z_m + 300.0)).abs() < 25.0,
        "{q:?} → {moved:?}"
    );
    assert!((moved.t_c - q.t_c).abs() < 0.2, "{q:?} → {moved:?}");
}

#[test]
fn the_visibility_slider_applies_its_value_when_the_drag_ends() {
    // Every new visibility rebuilds the sky's LUTs (25 ms), so a drag must
    // not hand the renderer a new value each frame: only its last one.
    let mut h = Harness::with_height(2400.0);
    let rect = h.ps.visibility_slider().expect("slider drawn");
    let v0 = h.m.render_cfg.visibility_km;
    let mut changes = 0;
    let mut seen = v0;
    let button = |pos, pressed| Event::PointerButton {
        pos,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::default(),
    };
    // Along the rail (the slider's first 100 points, egui's default width).
    let from = pos2(rect.left() + 20.0, rect.center().y);
    let to = pos2(rect.left() + 80.0, rect.center().y);
    h.frame(vec![Event::PointerMoved(from)]);
    h.frame(vec![button(from, true)]);
    for i in 1..=8 {
        h.frame(vec![Event::PointerMoved(
            from + (to - from) * (i as f32 / 8.0),
        )]);
        let v = h.m.render_cfg.visibility_km;
        changes += usize::from(v != seen);
        seen = v;
    }
    assert_eq!(h.m.render_cfg.visibility_km, v0, "applied during the drag");
    h.frame(vec![button(to, false)]);
    h.frame(vec![]);
    let v = h.m.render_cfg.visibility_km;
    changes += usize::from(v != seen);
    assert_ne!(v, v0, "the drag's value was applied on release");
    assert_eq!(changes, 1, "one new value for the whole drag");
    // The applied value is what the slider shows again next frame.
    h.frame(vec![]);
    assert_eq!(h.m.render_cfg.visibility_km, v);
}

/// The panel's clamp report (`app::clamps_panel::clamp_text`, what the
/// simulation section draws): none and plain at the start; after a warm
/// parcel rises under a 0.5 m/s speed cap (its 2 K excess drives it at
/// metres per second, so the cap must fire) the speed clamps by kind, in
/// the attention colour; back to none after a reset.
#[test]
fn the_panel_shows_clamps_by_kind_since_the_reset() {
    use cumulus::app::clamps_panel::clamp_text;
    let mut h = Harness::new();
    // A fresh world (the harness's frames may have pre-simulated a little).
    h.m.reset().unwrap();
    let t = clamp_text(&h.m.world.diagnostics());
    assert!(
        !t.attention && t.heading.ends_with("none") && t.kinds.is_empty(),
        "{t:?}"
    );

    let mut cfg = h.m.world_cfg.clone();
    cfg.physics.max_speed_m_s = 0.5;
    cfg.emission.enabled = false;
    h.m.apply_world_config(cfg).unwrap();
    let spec = cumulus::physics::ParcelSpec::from_environment(
        h.m.world.environment(),
        glam::DVec3::new(0.0, 0.0, 300.0),
        2.0,
        0.0,
        150.0,
    );
    h.m.world.spawn_parcel(spec).unwrap();
    for _ in 0..30 {
        h.m.world.step(2.0);
    }
    let d = h.m.world.diagnostics();
    assert!(d.clamps.speed > 0, "{}", d.clamps);
    let t = clamp_text(&d);
    assert!(t.attention, "{t:?}");
    assert_eq!(
        t.heading,
        format!("clamps since reset: {}", d.clamps.total())
    );
    assert!(
        t.kinds.contains(&format!("speed {}", d.clamps.speed)),
        "{t:?}"
    );
    assert!(
        t.notes.iter().any(|n| n.contains("display, not a clamp")),
        "{t:?}"
    );
    // The section draws it without trouble.
    h.frame(vec![]);

    h.m.reset().unwrap();
    let t = clamp_text(&h.m.world.diagnostics());
    assert!(
        !t.attention && t.kinds.is_empty(),
        "a reset starts the count again: {t:?}"
    );
}
