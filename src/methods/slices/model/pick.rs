//! Mouse editing of the ellipsoids (Schpok et al. 2003 §5.4: "select, move
//! and resize"), as pure functions the window calls: picking the ellipsoid
//! under the cursor by ray–ellipsoid intersection, moving it in the plane
//! through the grabbed point facing the camera, and resizing it.

use glam::Vec3;

use super::ellipsoid::{Ellipsoid, EllipsoidState};

/// Distance along the ray `origin + t·dir` (dir need not be unit; t in its
/// units) to the first point of `e`'s surface ahead, or None when the ray
/// misses or the ellipsoid is behind. In the unit ball's coordinates
/// (`unit_from_world`) the ellipsoid is |q| = 1, a quadratic in t.
pub fn ray_ellipsoid(e: &EllipsoidState, origin: Vec3, dir: Vec3) -> Option<f32> {
    let m = e.unit_from_world();
    let (o, d) = (m * (origin - e.centre_m), m * dir);
    let (a, b, c) = (d.dot(d), 2.0 * o.dot(d), o.dot(o) - 1.0);
    let disc = b * b - 4.0 * a * c;
    if a <= 0.0 || disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let (t0, t1) = ((-b - root) / (2.0 * a), (-b + root) / (2.0 * a));
    // Inside (t0 < 0 ≤ t1): the ellipsoid around the eye is picked at 0.
    if t1 < 0.0 { None } else { Some(t0.max(0.0)) }
}

/// The ellipsoid the ray hits first (index into `states`, distance t), of
/// those with strength > 0 (a faded one is not drawn, so not picked).
pub fn pick(states: &[EllipsoidState], origin: Vec3, dir: Vec3) -> Option<(usize, f32)> {
    states
        .iter()
        .enumerate()
        .filter(|(_, e)| e.strength > 0.0)
        .filter_map(|(i, e)| ray_ellipsoid(e, origin, dir).map(|t| (i, t)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// Where the ray meets the plane through `point` with normal `facing` (the
/// camera's forward: the plane faces the camera), or None when parallel or
/// behind.
pub fn ray_plane(origin: Vec3, dir: Vec3, point: Vec3, facing: Vec3) -> Option<Vec3> {
    let denom = dir.dot(facing);
    if denom.abs() < 1e-9 {
        return None;
    }
    let t = (point - origin).dot(facing) / denom;
    (t > 0.0).then(|| origin + dir * t)
}

/// The move of a drag from the ray `from` to the ray `to` (each origin,
/// direction) of a point grabbed at `grab` in the plane facing the camera
/// along `forward`: the offset between where the two rays cross that plane
/// (zero when either misses it). The grabbed point stays under the cursor.
pub fn drag_offset(grab: Vec3, forward: Vec3, from: (Vec3, Vec3), to: (Vec3, Vec3)) -> Vec3 {
    match (
        ray_plane(from.0, from.1, grab, forward),
        ray_plane(to.0, to.1, grab, forward),
    ) {
        (Some(a), Some(b)) => b - a,
        _ => Vec3::ZERO,
    }
}

/// Moves an ellipsoid and its keyframes' centres by `offset` (units: m),
/// so the whole animation moves with it.
pub fn move_by(e: &mut Ellipsoid, offset: Vec3) {
    let shift = |c: &mut [f32; 3]| *c = (Vec3::from(*c) + offset).to_array();
    shift(&mut e.centre_m);
    for k in &mut e.keyframes {
        if let Some(c) = k.centre_m.as_mut() {
            shift(c);
        }
    }
}

/// Radius change per scroll step: 10 %.
pub const RESIZE_PER_STEP: f32 = 1.1;

/// Scales an ellipsoid's radii (and its keyframes') by RESIZE_PER_STEP per
/// `steps` (negative shrinks), each radius kept within the scene's 1 m to
/// 1e5 m (a clamp the validation would otherwise refuse).
pub fn resize_by(e: &mut Ellipsoid, steps: f32) {
    let f = RESIZE_PER_STEP.powf(steps);
    let scale = |r: &mut [f32; 3]| *r = r.map(|x| (x * f).clamp(1.0, 1.0e5));
    scale(&mut e.radii_m);
    for k in &mut e.keyframes {
        if let Some(r) = k.radii_m.as_mut() {
            scale(r);
        }
    }
}

/// Points of the three principal ellipses of `e` (its outline as the
/// window draws it), `segments` each, closed (first point repeated).
pub fn outline(e: &EllipsoidState, segments: usize) -> [Vec<Vec3>; 3] {
    let axes = [
        e.rotation.x_axis * e.radii_m.x,
        e.rotation.y_axis * e.radii_m.y,
        e.rotation.z_axis * e.radii_m.z,
    ];
    [(0, 1), (1, 2), (2, 0)].map(|(a, b)| {
        let mut ring: Vec<Vec3> = (0..segments)
            .map(|k| {
                let t = k as f32 / segments as f32 * std::f32::consts::TAU;
                e.centre_m + axes[a] * t.cos() + axes[b] * t.sin()
            })
            .collect();
        ring.push(ring[0]);
        ring
    })
}
