//! A cloud's sprite quads for one view, shaded per corner (paper §5: "we
//! calculate the 4 corners of each sprite after pivoting it to face the
//! camera", then shade each corner). This is the CPU work the vertex cache
//! of §6.1 saves; the sprite renderer uploads its result.

use glam::Vec3;

use super::SpriteCloud;
use super::formation::formation_alpha;
use super::shading::{Lighting, VertexShade, group_centers};

/// One shaded sprite corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpriteVertex {
    /// units: m
    pub position_m: Vec3,
    /// The painted level, its alpha × formation alpha and its shares of
    /// the light.
    pub shade: VertexShade,
}

/// The four corners (counter-clockwise from bottom-left) of a `width` ×
/// `height` quad at `center` with unit `normal`, turned by `rotation_rad`
/// in its plane.
pub fn corners(
    center: Vec3,
    normal: Vec3,
    width: f32,
    height: f32,
    rotation_rad: f32,
) -> [Vec3; 4] {
    // The quad's up is world up projected into its plane (or +y when the quad is flat).
    let up0 = (Vec3::Z - normal * normal.dot(Vec3::Z))
        .try_normalize()
        .unwrap_or(Vec3::Y);
    let right0 = up0.cross(normal);
    let (s, c) = rotation_rad.sin_cos();
    let (right, up) = (right0 * c + up0 * s, up0 * c - right0 * s);
    let (r, u) = (right * 0.5 * width, up * 0.5 * height);
    [
        center - r - u,
        center + r - u,
        center + r + u,
        center - r + u,
    ]
}

/// The shaded quads of `cloud` seen from `camera_m` at formation `progress`
/// (4 vertices per sprite, in sprite order). Flat types (cirrus) lie
/// horizontal; the others face the camera.
pub fn shade_cloud(
    cloud: &SpriteCloud,
    lighting: &Lighting,
    camera_m: Vec3,
    progress: f32,
) -> Vec<SpriteVertex> {
    let groups = group_centers(&cloud.sprites);
    let flat = cloud.kind.is_flat();
    let radius = cloud.radius_m.max(1e-3);
    let mut out = Vec::with_capacity(cloud.sprites.len() * 4);
    for s in &cloud.sprites {
        let normal = if flat {
            Vec3::Z
        } else {
            (camera_m - s.center_m).try_normalize().unwrap_or(Vec3::Z)
        };
        let alpha = formation_alpha(progress, (s.center_m - cloud.center_m).length() / radius);
        let g = groups[s.group as usize];
        for p in corners(s.center_m, normal, s.width_m, s.height_m, s.rotation_rad) {
            out.push(SpriteVertex {
                position_m: p,
                shade: cloud.vertex_shade(lighting, s, g, p, alpha),
            });
        }
    }
    out
}
