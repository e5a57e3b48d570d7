//! Editing the authored ellipsoids with the mouse in the window (`slices`
//! method; the math is `methods::slices::model::pick`): a left click on an ellipsoid
//! selects it in the panel and dragging moves it in the plane through the
//! grabbed point facing the camera (a click beside every ellipsoid orbits
//! the camera, as anywhere else); Shift + scroll resizes the selected one.
//! With `[render.slices] outlines` the ellipsoids' principal ellipses are
//! drawn over the 3D view by egui's painter (no render pass exists for
//! them).

use glam::Vec3;

use super::state::Model;
use crate::config::{Camera, RenderMethod};
use crate::methods::slices::model::{pick, states_at};

/// An ellipsoid being dragged.
#[derive(Debug, Clone, Copy)]
pub struct Drag {
    index: usize,
    /// The grabbed point on its surface, moved along with it. units: m
    grab: Vec3,
    /// The cursor ray of the last move (origin, direction).
    ray: (Vec3, Vec3),
}

/// The world ray (eye, unit direction) through the cursor at `pixel`
/// (physical px in the window) in a 3D view at `rect` = (left edge, width,
/// height); None outside the view.
pub fn cursor_ray(
    camera: &Camera,
    rect: (u32, u32, u32),
    pixel: (f64, f64),
) -> Option<(Vec3, Vec3)> {
    let (x0, w, h) = rect;
    let x = ((pixel.0 - x0 as f64) / w as f64 * 2.0 - 1.0) as f32;
    let y = (1.0 - pixel.1 / h as f64 * 2.0) as f32;
    if x.abs() > 1.0 || y.abs() > 1.0 {
        return None;
    }
    let world_from_clip = camera.clip_from_world(w as f32 / h as f32).inverse();
    // Any depth inside the frustum lies on the ray from the eye.
    let p = world_from_clip.project_point3(Vec3::new(x, y, 0.5));
    Some((camera.position, (p - camera.position).try_normalize()?))
}

fn editing(m: &Model) -> bool {
    m.render_cfg.method == RenderMethod::Slices && !m.profile.ellipsoids.is_empty()
}

/// A press with the cursor ray `ray`: the ellipsoid under it, as it is
/// drawn now, becomes `selected` and starts a drag; None when none is hit.
pub fn press(m: &Model, ray: (Vec3, Vec3), selected: &mut usize) -> Option<Drag> {
    if !editing(m) {
        return None;
    }
    let states = states_at(
        &m.profile.ellipsoids,
        &m.profile.particles,
        m.world.time_s() as f32,
    );
    let (index, t) = pick::pick(&states, ray.0, ray.1)?;
    *selected = index;
    Some(Drag {
        index,
        grab: ray.0 + ray.1 * t,
        ray,
    })
}

/// Moves the dragged ellipsoid to follow the cursor's new `ray`; a move
/// the scene would refuse (past ±1e6 m) is not made and says why.
pub fn drag(m: &mut Model, d: &mut Drag, camera: &Camera, ray: (Vec3, Vec3)) {
    let forward = (camera.target - camera.position).normalize_or_zero();
    let offset = pick::drag_offset(d.grab, forward, d.ray, ray);
    let Some(e) = m.profile.ellipsoids.get_mut(d.index) else {
        return;
    };
    let before = e.clone();
    pick::move_by(e, offset);
    if let Err(err) = crate::methods::slices::model::ellipsoid::validate(e, "ellipsoid") {
        *e = before;
        m.status = err.to_string();
        return;
    }
    d.grab += offset;
    d.ray = ray;
}

/// Resizes the selected ellipsoid by `steps` scroll steps; false when
/// there is none to resize (the scroll then zooms).
pub fn resize(m: &mut Model, selected: usize, steps: f32) -> bool {
    if !editing(m) {
        return false;
    }
    let i = selected.min(m.profile.ellipsoids.len() - 1);
    pick::resize_by(&mut m.profile.ellipsoids[i], steps);
    true
}

/// Paints the outlines of every ellipsoid (the selected one brighter) over
/// the 3D view at `rect` (physical px), when `outlines` is on.
pub fn paint_outlines(ctx: &egui::Context, m: &Model, rect: (u32, u32, u32), selected: usize) {
    if !(editing(m) && m.render_cfg.slices.outlines) {
        return;
    }
    let (x0, w, h) = rect;
    let camera = m.render_camera();
    let ppp = ctx.pixels_per_point();
    let painter = ctx.layer_painter(egui::LayerId::background());
    let states = states_at(
        &m.profile.ellipsoids,
        &m.profile.particles,
        m.world.time_s() as f32,
    );
    for (i, e) in states.iter().enumerate() {
        let colour = if i == selected {
            egui::Color32::from_rgb(255, 200, 60)
        } else {
            egui::Color32::from_white_alpha(140)
        };
        for ring in pick::outline(e, 48) {
            let points: Option<Vec<egui::Pos2>> = ring
                .iter()
                .map(|p| {
                    let (x, y) = camera.project_to_pixel(*p, w, h)?;
                    Some(egui::pos2((x + x0 as f32) / ppp, y / ppp))
                })
                .collect();
            // A ring reaching behind the eye is left out whole.
            if let Some(points) = points {
                painter.add(egui::Shape::line(points, egui::Stroke::new(1.0, colour)));
            }
        }
    }
}
