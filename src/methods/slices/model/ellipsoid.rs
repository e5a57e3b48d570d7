//! Implicit ellipsoids (Schpok et al. 2003 §3.1): the artist's coarse shape
//! of a cloud. Each `[[ellipsoids]]` of a scene is one soft primitive; the
//! cloud's density skeleton is the sum of Wyvill's cubic soft-object
//! blending of every primitive, evaluated at the slice vertices (on the
//! CPU through the grid index [`FieldIndex`], or by the renderer's compute
//! pass).

use glam::{EulerRot, Mat3, Vec3};
use serde::{Deserialize, Serialize};

use super::animation::{Keyframe, Motion};
use super::finite_in;
use crate::error::{Error, Result};

/// Most ellipsoids one scene may hold (docs/notes.md, "Authored clouds",
/// says where the number comes from).
pub const MAX_ELLIPSOIDS: usize = 256;

/// One implicit ellipsoid as written in a scene's `[[ellipsoids]]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Ellipsoid {
    /// Centre at time 0 (z up). units: m
    pub centre_m: [f32; 3],
    /// Semi-axes along the ellipsoid's own x, y, z before rotation. units: m
    pub radii_m: [f32; 3],
    /// Rotation of the axes: yaw about z, then pitch about y, then roll
    /// about x (intrinsic z-y-x). units: degrees
    pub rotation_deg: [f32; 3],
    /// Field value at the centre (the blend's weight), 0 to 4.
    pub strength: f32,
    /// Particle dynamics preset applied on top of the keyframes.
    pub motion: Motion,
    /// Keyframes of centre, radii and strength over time (may be empty:
    /// the fields above then hold for all time).
    pub keyframes: Vec<Keyframe>,
    /// A flat base: no field below this altitude (a cumulus's
    /// condensation level), whatever the motion. units: m
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_m: Option<f32>,
}

impl Default for Ellipsoid {
    fn default() -> Self {
        Self {
            centre_m: [0.0, 0.0, 1500.0],
            radii_m: [600.0, 600.0, 400.0],
            rotation_deg: [0.0; 3],
            strength: 1.0,
            motion: Motion::Still,
            keyframes: Vec::new(),
            base_m: None,
        }
    }
}

/// An ellipsoid at one instant, ready to evaluate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipsoidState {
    /// units: m
    pub centre_m: Vec3,
    /// units: m
    pub radii_m: Vec3,
    /// world_from_local rotation.
    pub rotation: Mat3,
    /// Field value at the centre.
    pub strength: f32,
    /// A flat base: the field is 0 below this altitude (a physics parcel's
    /// condensation plane, as the ray-march's half-space cuts it);
    /// `f32::NEG_INFINITY` for none (authored ellipsoids). units: m
    pub base_z_m: f32,
}

/// Wyvill, McPheeters & Wyvill's soft-object blending ("Data structure for
/// soft objects", The Visual Computer 2(4), 1986), the paper's ref. 22:
/// with s = r/R,
///   C(s) = 1 − 4/9·s⁶ + 17/9·s⁴ − 22/9·s²   for s ≤ 1, and 0 beyond.
/// It is a cubic in s² (no square root needed), C(0) = 1, C(1) = 0,
/// C(½) = ½, and its slope is 0 at both ends, so summed primitives blend
/// smoothly and end without a crease. Takes s².
pub fn wyvill(s2: f32) -> f32 {
    if s2 >= 1.0 {
        return 0.0;
    }
    let s4 = s2 * s2;
    1.0 - (4.0 / 9.0) * s4 * s2 + (17.0 / 9.0) * s4 - (22.0 / 9.0) * s2
}

impl EllipsoidState {
    /// The rotation of `rotation_deg` (intrinsic z-y-x: yaw, pitch, roll).
    pub fn rotation_from_deg(rotation_deg: [f32; 3]) -> Mat3 {
        let [roll, pitch, yaw] = rotation_deg.map(f32::to_radians);
        Mat3::from_euler(EulerRot::ZYX, yaw, pitch, roll)
    }

    /// The map from world offsets (p − centre) to the unit ball's
    /// coordinates: diag(1/radii) · rotationᵀ. The GPU's primitives carry
    /// it (src/methods/slices/gpu/buffers.rs), so both sides compute s² alike.
    pub fn unit_from_world(&self) -> glam::Mat3 {
        Mat3::from_diagonal(self.radii_m.recip()) * self.rotation.transpose()
    }

    /// Squared ellipsoidal distance s² of `p`: 1 on the surface, 0 at the centre.
    pub fn s2(&self, p: Vec3) -> f32 {
        (self.unit_from_world() * (p - self.centre_m)).length_squared()
    }

    /// This primitive's contribution to the field at `p`: strength × C(s²),
    /// 0 below the flat base.
    pub fn field(&self, p: Vec3) -> f32 {
        if p.z < self.base_z_m {
            return 0.0;
        }
        self.strength * wyvill(self.s2(p))
    }

    /// Half-extent of the world-axis-aligned box around the ellipsoid: along
    /// world axis k it is sqrt(Σ_j (R_kj·r_j)²) (exact for an ellipsoid).
    pub fn half_extent_m(&self) -> Vec3 {
        let m = self.rotation;
        let r = self.radii_m;
        let row = |k: usize| {
            let v = Vec3::new(m.x_axis[k] * r.x, m.y_axis[k] * r.y, m.z_axis[k] * r.z);
            v.length()
        };
        Vec3::new(row(0), row(1), row(2))
    }
}

/// The implicit field at `p`: Σ strength_i · C(s_i) over every primitive
/// (paper eq. 1 before the plane opacity). Not clamped: overlapping
/// primitives add, as the paper's sum does.
pub fn field_at(states: &[EllipsoidState], p: Vec3) -> f32 {
    states.iter().map(|e| e.field(p)).sum()
}

/// Cells per axis of a [`FieldIndex`] at most: 32³ lists.
const INDEX_CELLS: usize = 32;

/// [`field_at`] over many primitives without visiting them all: a uniform
/// grid over the primitives' bounds lists, per cell, the primitives whose
/// box overlaps it (in their order), so a point sums only those. Outside a
/// primitive's box its blend is 0 and adding 0 changes no sum, so the
/// value is [`field_at`]'s, except within float rounding of a box's face,
/// where the blend left out is ~0 anyway (C(s) and its slope vanish at s = 1).
#[derive(Debug, Clone)]
pub struct FieldIndex<'a> {
    states: &'a [EllipsoidState],
    min: Vec3,
    /// units: m
    cell: Vec3,
    dims: [usize; 3],
    lists: Vec<Vec<u32>>,
}

impl<'a> FieldIndex<'a> {
    /// Indexes `states` (those with strength > 0; the others add nothing).
    pub fn new(states: &'a [EllipsoidState]) -> Self {
        let (min, max) = bounds_m(states).unwrap_or((Vec3::ZERO, Vec3::ONE));
        let size = (max - min).max(Vec3::splat(1.0));
        let n = INDEX_CELLS.min(states.len().max(1).next_power_of_two());
        let dims = [n; 3];
        let cell = size / n as f32;
        let mut lists = vec![Vec::new(); n * n * n];
        let clampi = |v: f32| (v.max(0.0) as usize).min(n - 1);
        for (i, e) in states.iter().enumerate().filter(|(_, e)| e.strength > 0.0) {
            let h = e.half_extent_m();
            let a = ((e.centre_m - h - min) / cell).to_array().map(clampi);
            let b = ((e.centre_m + h - min) / cell).to_array().map(clampi);
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        lists[x + n * (y + n * z)].push(i as u32);
                    }
                }
            }
        }
        Self {
            states,
            min,
            cell,
            dims,
            lists,
        }
    }

    /// The index as flat arrays for the GPU: (grid minimum, cell size,
    /// cells per axis, list offsets then items). `cells[c]..cells[c + 1]`
    /// index, past the n³ + 1 offsets, the primitives of cell
    /// c = x + n·(y + n·z).
    pub fn flatten(&self) -> (Vec3, Vec3, u32, Vec<u32>) {
        let cells = self.lists.len();
        let items: usize = self.lists.iter().map(Vec::len).sum();
        let mut out = Vec::with_capacity(cells + 1 + items);
        let mut start = (cells + 1) as u32;
        for l in &self.lists {
            out.push(start);
            start += l.len() as u32;
        }
        out.push(start);
        for l in &self.lists {
            out.extend_from_slice(l);
        }
        (self.min, self.cell, self.dims[0] as u32, out)
    }

    /// The field at `p`: `field_at(states, p)` (see the type's docs).
    pub fn field(&self, p: Vec3) -> f32 {
        let q = (p - self.min) / self.cell;
        let [nx, ny, nz] = self.dims;
        if q.min_element() < 0.0 || q.x >= nx as f32 || q.y >= ny as f32 || q.z >= nz as f32 {
            // Outside every box (the grid spans them all): only zeros.
            return 0.0;
        }
        let (x, y, z) = (q.x as usize, q.y as usize, q.z as usize);
        self.lists[x + nx * (y + ny * z)]
            .iter()
            .map(|&i| self.states[i as usize].field(p))
            .sum()
    }
}

/// World-axis-aligned bounds (min, max) of every primitive with a non-zero
/// strength, or `None` when there is none. units: m
pub fn bounds_m(states: &[EllipsoidState]) -> Option<(Vec3, Vec3)> {
    states
        .iter()
        .filter(|e| e.strength > 0.0)
        .map(|e| {
            (
                e.centre_m - e.half_extent_m(),
                e.centre_m + e.half_extent_m(),
            )
        })
        .reduce(|(a0, a1), (b0, b1)| (a0.min(b0), a1.max(b1)))
}

/// Checks one `[[ellipsoids]]` entry; `name` is its place (`"ellipsoids[2]"`).
pub fn validate(e: &Ellipsoid, name: &str) -> Result<()> {
    for (k, v) in e.centre_m.iter().enumerate() {
        finite_in(
            &format!("{name}.centre_m[{k}]"),
            *v,
            -1.0e6,
            1.0e6,
            "-1e6 to 1e6 m",
        )?;
    }
    validate_shape(e.radii_m, e.strength, name)?;
    for (k, v) in e.rotation_deg.iter().enumerate() {
        finite_in(
            &format!("{name}.rotation_deg[{k}]"),
            *v,
            -360.0,
            360.0,
            "-360 to 360 degrees",
        )?;
    }
    if let Some(b) = e.base_m {
        finite_in(&format!("{name}.base_m"), b, -1.0e6, 1.0e6, "-1e6 to 1e6 m")?;
    }
    super::animation::validate_keyframes(&e.keyframes, name)
}

/// Radii and strength, shared by an ellipsoid and its keyframes.
pub(super) fn validate_shape(radii_m: [f32; 3], strength: f32, name: &str) -> Result<()> {
    for (k, v) in radii_m.iter().enumerate() {
        finite_in(
            &format!("{name}.radii_m[{k}]"),
            *v,
            1.0,
            1.0e5,
            "1 to 1e5 m",
        )?;
    }
    finite_in(&format!("{name}.strength"), strength, 0.0, 4.0, "0 to 4")
}

/// Checks a scene's whole `[[ellipsoids]]` list.
pub fn validate_all(ellipsoids: &[Ellipsoid]) -> Result<()> {
    if ellipsoids.len() > MAX_ELLIPSOIDS {
        return Err(Error::invalid(
            "ellipsoids",
            format!("{} entries", ellipsoids.len()),
            format!("at most {MAX_ELLIPSOIDS} ellipsoids"),
        ));
    }
    for (i, e) in ellipsoids.iter().enumerate() {
        validate(e, &format!("ellipsoids[{i}]"))?;
    }
    Ok(())
}
