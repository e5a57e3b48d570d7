//! The panel of the `slices` render method (Schpok et al. 2003 §5, Table
//! 2): the qualitative controls grouped as the paper groups them (global
//! rendering, media shaping, media animation, particle animation), common
//! controls first and advanced ones folded; and the authored ellipsoids:
//! add, select, remove, move and resize with fields. Every change shows in
//! the next frame; a value the scene would refuse is reverted with the
//! reason in the status line.

use egui::{DragValue, RichText};

use super::state::Model;
use crate::config::slices::OPACITY_RANGE;
use crate::methods::slices::model::{Ellipsoid, MediaFilter, Motion, NoiseMotion, VertexField};

/// Three drag fields for a vector, with a label.
fn vec3(ui: &mut egui::Ui, label: &str, v: &mut [f32; 3], speed: f64) {
    ui.horizontal(|ui| {
        ui.label(label);
        for (c, x) in ["x", "y", "z"].iter().zip(v.iter_mut()) {
            ui.add(DragValue::new(x).speed(speed).prefix(format!("{c} ")));
        }
    });
}

fn motion_fields(ui: &mut egui::Ui, m: &mut NoiseMotion) {
    vec3(ui, "wind (m/s)", &mut m.wind_m_s, 0.1);
    vec3(ui, "torque (°/s)", &mut m.torque_deg_s, 0.01);
}

/// Draws the slices controls and the ellipsoid editor. `selected` is the
/// ellipsoid being edited. Returns whether the render settings changed
/// (the window then calls `Renderer::set_config`); ellipsoid edits need
/// nothing more (the window hands them to the renderer every frame).
pub fn slices_section(ui: &mut egui::Ui, m: &mut Model, selected: &mut usize) -> bool {
    let before = m.render_cfg.slices.clone();
    let s = &mut m.render_cfg.slices;

    ui.label(RichText::new("Global rendering").strong());
    ui.add(
        egui::Slider::new(&mut s.opacity, OPACITY_RANGE.0..=OPACITY_RANGE.1)
            .logarithmic(true)
            .text("Opacity"),
    );
    ui.add(
        egui::Slider::new(&mut s.quality, 8..=512)
            .logarithmic(true)
            .text("Quality (planes)"),
    );
    egui::CollapsingHeader::new("advanced rendering")
        .default_open(false)
        .show(ui, |ui| {
            ui.add(egui::Slider::new(&mut s.tessellation, 1..=128).text("tessellation"));
            ui.horizontal(|ui| {
                ui.label("cloud");
                ui.color_edit_button_rgb(&mut s.cloud_colour);
                ui.label("shadow");
                ui.color_edit_button_rgb(&mut s.shadow_colour);
            });
            ui.horizontal(|ui| {
                ui.checkbox(&mut s.sky, "sky");
                ui.label("else background");
                ui.color_edit_button_rgb(&mut s.background_colour);
            });
            ui.checkbox(&mut s.shadow_octave, "first octave in the shadows");
            ui.horizontal(|ui| {
                ui.label("vertex field on");
                for m in [VertexField::Cpu, VertexField::Gpu] {
                    ui.selectable_value(&mut s.vertex_field, m, m.name());
                }
            });
            ui.checkbox(&mut s.outlines, "outline the ellipsoids");
        });

    ui.label(RichText::new("Media shaping").strong());
    ui.add(egui::Slider::new(&mut s.detail, 1.1..=4.0).text("Detail (lacunarity)"));
    ui.add(egui::Slider::new(&mut s.dirtiness, 0.0..=16.0).text("Dirtiness"));
    ui.add(egui::Slider::new(&mut s.sharpness, 0.0..=1.0).text("Sharpness"));
    egui::CollapsingHeader::new("advanced media (tiers)")
        .default_open(false)
        .show(ui, |ui| {
            ui.add(egui::Slider::new(&mut s.octaves, 1..=8).text("octaves"));
            for (i, t) in s.tiers.iter_mut().enumerate() {
                ui.label(format!("tier {i}"));
                ui.add(
                    DragValue::new(&mut t.bottom_m)
                        .speed(50.0)
                        .prefix("bottom m "),
                );
                egui::ComboBox::from_id_salt(("media", i))
                    .selected_text(t.media.name())
                    .show_ui(ui, |ui| {
                        for f in MediaFilter::ALL {
                            ui.selectable_value(&mut t.media, f, f.name());
                        }
                    });
                ui.add(
                    DragValue::new(&mut t.scale_m)
                        .speed(20.0)
                        .prefix("scale m "),
                );
                ui.add(
                    DragValue::new(&mut t.stretch_along_wind)
                        .speed(0.05)
                        .prefix("stretch "),
                );
            }
        });

    ui.label(RichText::new("Media animation").strong());
    ui.label("Base tier (every tier's first octave):");
    motion_fields(ui, &mut s.base);
    egui::CollapsingHeader::new("advanced animation (per tier)")
        .default_open(false)
        .show(ui, |ui| {
            for (i, t) in s.tiers.iter_mut().enumerate() {
                ui.label(format!("tier {i}"));
                vec3(ui, "wind (m/s)", &mut t.wind_m_s, 0.1);
                vec3(ui, "torque (°/s)", &mut t.torque_deg_s, 0.01);
            }
        });

    let mut changed = m.render_cfg.slices != before;
    if changed && let Err(e) = m.render_cfg.slices.validate() {
        m.render_cfg.slices = before;
        m.status = e.to_string();
        changed = false;
    }
    particle_section(ui, m, selected);
    changed
}

fn particle_section(ui: &mut egui::Ui, m: &mut Model, selected: &mut usize) {
    ui.label(RichText::new("Particle animation").strong());
    let before = (m.profile.ellipsoids.clone(), m.profile.particles.clone());
    vec3(
        ui,
        "scene wind (m/s)",
        &mut m.profile.particles.wind_m_s,
        0.1,
    );
    let list = &mut m.profile.ellipsoids;
    ui.horizontal(|ui| {
        if ui.button("Add ellipsoid").clicked() {
            // A new one beside the last, so it does not hide inside it.
            let mut e = Ellipsoid::default();
            if let Some(last) = list.last() {
                e.centre_m = last.centre_m;
                e.centre_m[0] += 2.0 * last.radii_m[0];
            }
            list.push(e);
            *selected = list.len() - 1;
        }
        if !list.is_empty() && ui.button("Remove").clicked() {
            list.remove((*selected).min(list.len() - 1));
        }
    });
    if list.is_empty() {
        ui.small("no ellipsoids: add one");
    } else {
        *selected = (*selected).min(list.len() - 1);
        egui::ComboBox::from_label("ellipsoid")
            .selected_text(format!("#{}", *selected))
            .show_ui(ui, |ui| {
                for i in 0..list.len() {
                    ui.selectable_value(selected, i, format!("#{i}"));
                }
            });
        let e = &mut list[*selected];
        vec3(ui, "centre (m)", &mut e.centre_m, 20.0);
        vec3(ui, "radii (m)", &mut e.radii_m, 10.0);
        vec3(ui, "rotation (°)", &mut e.rotation_deg, 1.0);
        ui.add(egui::Slider::new(&mut e.strength, 0.0..=4.0).text("strength"));
        egui::ComboBox::from_label("motion")
            .selected_text(format!("{:?}", e.motion))
            .show_ui(ui, |ui| {
                for mo in [
                    Motion::Still,
                    Motion::Rising,
                    Motion::Expanding,
                    Motion::Shrinking,
                    Motion::Anvil,
                ] {
                    ui.selectable_value(&mut e.motion, mo, format!("{mo:?}"));
                }
            });
        if !e.keyframes.is_empty() {
            ui.small(format!(
                "{} keyframes (centre, radii, strength above are the key at 0 s)",
                e.keyframes.len()
            ));
        }
    }
    let checked = crate::methods::slices::model::ellipsoid::validate_all(&m.profile.ellipsoids)
        .and_then(|()| m.profile.particles.validate());
    if let Err(e) = checked {
        (m.profile.ellipsoids, m.profile.particles) = before;
        m.status = e.to_string();
    }
}
