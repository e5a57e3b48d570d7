//! The window's slices panel (Schpok 2003 controls and the ellipsoid
//! editor), headless (egui needs no display or GPU): it appears only under
//! the slices method, leaves the scene alone while nobody touches it, and
//! the edited scene it saves carries the ellipsoids and controls.

use cumulus::app::panel::{self, PanelActions, PanelState};
use cumulus::app::state::Model;
use egui::{Pos2, RawInput, Rect, vec2};

fn frame(
    ctx: &egui::Context,
    m: &mut Model,
    ps: &mut PanelState,
    t: f64,
) -> (PanelActions, String) {
    let input = RawInput {
        screen_rect: Some(Rect::from_min_size(Pos2::ZERO, vec2(1280.0, 6000.0))),
        time: Some(t),
        ..Default::default()
    };
    let mut actions = PanelActions::default();
    let out = ctx.run_ui(input, |ui| {
        actions = panel::show(ui, m, ps);
    });
    // Every text the panel laid out this frame.
    let mut text = String::new();
    for shape in &out.shapes {
        if let egui::epaint::Shape::Text(t) = &shape.shape {
            text.push_str(t.galley.text());
            text.push('\n');
        }
    }
    (actions, text)
}

#[test]
fn the_slices_panel_shows_the_paper_groups_and_edits_nothing_by_itself() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml");
    let (profile, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
    let mut m = Model::new(profile, source).unwrap();
    let before = m.edited_profile();
    let ctx = panel::egui_context();
    let mut ps = PanelState::default();
    let mut text = String::new();
    for i in 0..3 {
        let (actions, t) = frame(&ctx, &mut m, &mut ps, i as f64 * 0.05);
        assert!(
            !actions.render_changed,
            "frame {i} changed the render settings"
        );
        text = t;
    }
    for group in [
        "Global rendering",
        "Media shaping",
        "Media animation",
        "Particle animation",
        "Add ellipsoid",
    ] {
        assert!(text.contains(group), "no {group:?} in the panel:\n{text}");
    }
    // Advanced controls start folded.
    assert!(!text.contains("tessellation"), "advanced rendering is open");
    let after = m.edited_profile();
    assert_eq!(after.render.slices, before.render.slices);
    assert_eq!(after.ellipsoids, before.ellipsoids);

    // Another method: no slices controls.
    m.render_cfg.method = cumulus::config::RenderMethod::Baked;
    let (_, t) = frame(&ctx, &mut m, &mut ps, 1.0);
    assert!(!t.contains("Media shaping"), "slices controls under baked");
}
