//! Mouse editing of the ellipsoids (src/methods/slices/model/pick.rs and the window's
//! src/app/ellipsoid_mouse.rs), headless: ray–ellipsoid picking, dragging
//! in the plane facing the camera, resizing, outlines and the cursor ray.

use cumulus::app::ellipsoid_mouse::cursor_ray;
use cumulus::config::Camera;
use cumulus::methods::slices::model::pick::{
    RESIZE_PER_STEP, drag_offset, move_by, outline, pick, ray_ellipsoid, resize_by,
};
use cumulus::methods::slices::model::{Ellipsoid, EllipsoidState, Keyframe, state_at};
use glam::Vec3;

fn state(centre: [f32; 3], radii: [f32; 3], rotation_deg: [f32; 3]) -> EllipsoidState {
    state_at(
        &Ellipsoid {
            centre_m: centre,
            radii_m: radii,
            rotation_deg,
            ..Default::default()
        },
        0.0,
        Vec3::ZERO,
    )
}

#[test]
fn rays_hit_ellipsoids_at_their_surface() {
    let e = state([0.0, 0.0, 1000.0], [600.0, 300.0, 200.0], [0.0; 3]);
    // Along x toward the centre: the surface is 600 m before it.
    let t = ray_ellipsoid(&e, Vec3::new(-5000.0, 0.0, 1000.0), Vec3::X).unwrap();
    assert!((t - 4400.0).abs() < 0.05, "{t}");
    // Along y: 300 m before it; a direction of length 2 halves t.
    let t = ray_ellipsoid(&e, Vec3::new(0.0, -5000.0, 1000.0), Vec3::Y * 2.0).unwrap();
    assert!((t - 2350.0).abs() < 0.05, "{t}");
    // Yawed 90°: its 600 m axis now lies along y.
    let r = state([0.0, 0.0, 1000.0], [600.0, 300.0, 200.0], [0.0, 0.0, 90.0]);
    let t = ray_ellipsoid(&r, Vec3::new(0.0, -5000.0, 1000.0), Vec3::Y).unwrap();
    assert!((t - 4400.0).abs() < 0.1, "{t}");
    // Passing above it (z 1250 > 1000 + 200), or pointing away: missed.
    assert!(ray_ellipsoid(&e, Vec3::new(-5000.0, 0.0, 1250.0), Vec3::X).is_none());
    assert!(ray_ellipsoid(&e, Vec3::new(-5000.0, 0.0, 1000.0), -Vec3::X).is_none());
    // From inside: picked at once.
    assert_eq!(
        ray_ellipsoid(&e, Vec3::new(0.0, 0.0, 1000.0), Vec3::X),
        Some(0.0)
    );
}

#[test]
fn the_nearest_drawn_ellipsoid_is_picked() {
    let near = state([0.0, 2000.0, 1000.0], [300.0; 3], [0.0; 3]);
    let far = state([0.0, 6000.0, 1000.0], [900.0; 3], [0.0; 3]);
    let eye = Vec3::new(0.0, -3000.0, 1000.0);
    // The far one first in the list; the near one is hit first.
    let (i, t) = pick(&[far, near], eye, Vec3::Y).unwrap();
    assert_eq!(i, 1);
    assert!((t - 4700.0).abs() < 0.05, "{t}");
    // A faded ellipsoid is not drawn, so not picked.
    let faded = EllipsoidState {
        strength: 0.0,
        ..near
    };
    assert_eq!(pick(&[far, faded], eye, Vec3::Y).map(|p| p.0), Some(0));
    assert!(pick(&[far, near], eye, Vec3::X).is_none());
}

#[test]
fn a_drag_keeps_the_grabbed_point_under_the_cursor_in_the_camera_plane() {
    let eye = Vec3::new(0.0, -10_000.0, 2000.0);
    let forward = (Vec3::new(0.0, 0.0, 1500.0) - eye).normalize();
    let grab = Vec3::new(100.0, -300.0, 1600.0);
    let from = (eye, (grab - eye).normalize());
    let to_dir = (from.1 + Vec3::new(0.05, 0.0, 0.02)).normalize();
    let offset = drag_offset(grab, forward, from, (eye, to_dir));
    // In the plane facing the camera: no move toward or away from it.
    assert!(offset.dot(forward).abs() < 1e-2, "{offset}");
    assert!(offset.length() > 100.0, "{offset}");
    // The moved point lies on the new cursor ray.
    let moved = grab + offset;
    let off_ray = (moved - eye).cross(to_dir).length();
    assert!(off_ray < 0.5, "{off_ray} m from the ray");
    // A ray parallel to the plane does not move it.
    let side = forward.cross(Vec3::Z).normalize();
    assert_eq!(drag_offset(grab, forward, from, (eye, side)), Vec3::ZERO);
}

#[test]
fn moving_and_resizing_carry_the_keyframes_along() {
    let mut e = Ellipsoid {
        centre_m: [0.0, 0.0, 1000.0],
        radii_m: [500.0, 400.0, 300.0],
        keyframes: vec![Keyframe {
            time_s: 60.0,
            centre_m: Some([100.0, 0.0, 1200.0]),
            radii_m: Some([600.0, 400.0, 300.0]),
            strength: None,
        }],
        ..Default::default()
    };
    move_by(&mut e, Vec3::new(10.0, -20.0, 30.0));
    assert_eq!(e.centre_m, [10.0, -20.0, 1030.0]);
    assert_eq!(e.keyframes[0].centre_m, Some([110.0, -20.0, 1230.0]));
    resize_by(&mut e, 2.0);
    let f = RESIZE_PER_STEP * RESIZE_PER_STEP;
    assert!((e.radii_m[0] - 500.0 * f).abs() < 1e-2);
    assert!((e.keyframes[0].radii_m.unwrap()[0] - 600.0 * f).abs() < 1e-2);
    resize_by(&mut e, -2.0);
    assert!((e.radii_m[2] - 300.0).abs() < 1e-2);
    // The scene's limits hold: 1 m to 1e5 m.
    resize_by(&mut e, -500.0);
    assert_eq!(e.radii_m, [1.0; 3]);
    cumulus::methods::slices::model::ellipsoid::validate(&e, "e").unwrap();
}

#[test]
fn outlines_lie_on_the_surface() {
    let e = state(
        [500.0, 0.0, 1000.0],
        [600.0, 300.0, 200.0],
        [20.0, 10.0, 35.0],
    );
    for ring in outline(&e, 24) {
        assert_eq!(ring.len(), 25);
        assert_eq!(ring[0], ring[24]);
        for p in ring {
            assert!((e.s2(p) - 1.0).abs() < 1e-4, "s² {}", e.s2(p));
        }
    }
}

#[test]
fn the_cursor_ray_passes_through_what_the_pixel_shows() {
    let camera = Camera {
        position: Vec3::new(-3000.0, -22000.0, 2000.0),
        target: Vec3::new(0.0, 0.0, 5000.0),
        vfov_rad: 45f32.to_radians(),
        near_m: 10.0,
        far_m: 120_000.0,
    };
    let (w, h) = (800, 450);
    // A 3D view right of a 300 px panel.
    let rect = (300, w, h);
    let (_, centre) = cursor_ray(&camera, rect, (300.0 + w as f64 / 2.0, h as f64 / 2.0)).unwrap();
    let forward = (camera.target - camera.position).normalize();
    assert!(centre.dot(forward) > 0.99999, "{centre}");
    let p = Vec3::new(2000.0, 1000.0, 3000.0);
    let (x, y) = camera.project_to_pixel(p, w, h).unwrap();
    let (eye, dir) = cursor_ray(&camera, rect, (x as f64 + 300.0, y as f64)).unwrap();
    let miss = (p - eye).cross(dir).length();
    // Within a metre at 22 km: f32 projection round trip.
    assert!(miss < 1.0, "{miss} m");
    // Over the panel: no ray.
    assert!(cursor_ray(&camera, rect, (100.0, 100.0)).is_none());
}

#[test]
fn the_window_selects_drags_resizes_and_outlines_through_the_model() {
    use cumulus::app::ellipsoid_mouse::{drag, paint_outlines, press, resize};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml");
    let (profile, source) = cumulus::scene::load_scene(Some(&path)).unwrap();
    let mut m = cumulus::app::state::Model::new(profile, source).unwrap();
    let camera = m.render_camera();
    let now = cumulus::methods::slices::model::states_at(
        &m.profile.ellipsoids,
        &m.profile.particles,
        m.world.time_s() as f32,
    );
    // Aim at the cumulus west of the storm as it is drawn now (nothing
    // stands in front of it).
    let target = 15;
    assert_eq!(m.profile.ellipsoids[target].centre_m[0], -11500.0);
    let aim = |p: Vec3| (camera.position, (p - camera.position).normalize());
    let mut selected = 0;
    let mut d = press(&m, aim(now[target].centre_m), &mut selected).expect("a hit");
    assert_eq!(selected, target);
    let before = m.profile.ellipsoids[target].centre_m;
    let right = (camera.target - camera.position).cross(Vec3::Z).normalize();
    drag(
        &mut m,
        &mut d,
        &camera,
        aim(now[target].centre_m + right * 500.0),
    );
    let moved = Vec3::from(m.profile.ellipsoids[target].centre_m) - Vec3::from(before);
    // About 500 m sideways (the grab point is on the near surface, a
    // little closer than the centre, so a little less).
    assert!((moved.dot(right) - 500.0).abs() < 100.0, "{moved}");
    let r = m.profile.ellipsoids[target].radii_m[0];
    assert!(resize(&mut m, selected, 1.0));
    assert!((m.profile.ellipsoids[target].radii_m[0] / r - RESIZE_PER_STEP).abs() < 1e-4);
    // Outlines only when asked for: painted shapes in the egui output.
    let ctx = egui::Context::default();
    let shapes = |m: &cumulus::app::state::Model| {
        let out = ctx.run_ui(egui::RawInput::default(), |ui| {
            paint_outlines(ui.ctx(), m, (0, 800, 450), selected);
        });
        out.shapes.len()
    };
    assert_eq!(shapes(&m), 0);
    m.render_cfg.slices.outlines = true;
    assert!(shapes(&m) >= 3, "three ellipses per ellipsoid in view");
}
