//! The CPU half of the slice renderer (Schpok et al. 2003 §4.1, Table 1,
//! Figure 1): slicing planes parallel or orthogonal to the light, oriented
//! closest to the view direction, tessellated over the cloud's bounds; the
//! implicit field sampled at every vertex; the shadow accumulated along
//! vertices colinear with the light ray (eq. 2); planes emitted back to
//! front for the painter's algorithm. The output is vertex and index
//! arrays a GPU pass draws as they are. This is one stack over one cloud,
//! as the paper slices one cloud; [`super::clouds`] gives every cloud of
//! a scene its own.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::ellipsoid::{EllipsoidState, FieldIndex, bounds_m};
use crate::config::slices::SlicesConfig;
use crate::error::{Error, Result};

/// Most vertices one slicing may produce (planes × (tessellation + 1)²):
/// 2²³ vertices are 168 MB of vertices and about as much of indices.
pub const MAX_SLICE_VERTICES: u64 = 1 << 23;

/// The widest spacing of a stack's vertices across its planes: a 2 km
/// tower must get at least 16 vertices across (issue 33), and a chord of
/// 2 km holds at least 16 lattice points strictly inside it when 17
/// spacings fit in it. units: m
pub const MAX_VERTEX_SPACING_M: f32 = 2000.0 / 17.0;

/// Most vertices the spacing floor above may give one stack (planes ×
/// (cells + 1)²): 2²¹ vertices (50 MB) keep a 15 km cloud at 128 planes
/// within it, and beyond it the stack's vertices spread out instead.
pub const MAX_STACK_VERTICES: u64 = 1 << 21;

/// How the planes sit relative to the light.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SliceOrientation {
    /// Plane normal along the light: light rays cross the planes, and the
    /// colinear vertices are the same grid vertex on successive planes.
    OrthogonalToLight,
    /// Light direction inside the planes: the colinear vertices are a grid
    /// row within each plane.
    ParallelToLight,
}

/// One vertex of the slicing geometry, as the GPU pass takes it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SliceVertex {
    /// units: m
    pub position_m: [f32; 3],
    /// Σ implicits at the vertex (eq. 1 before the plane opacity).
    pub density: f32,
    /// Shadow depth accumulated toward the light (eq. 2), 0 = fully lit.
    pub shadow: f32,
    /// The plane opacity of this vertex's stack (Table 2, compensated for
    /// its cloud: [`CloudScale`]), the same on every vertex of a stack.
    pub plane_opacity: f32,
}

const _: () = assert!(std::mem::size_of::<SliceVertex>() == 24);

/// The paper slices one cloud with planes spanning it, so "plane opacity =
/// Opacity ÷ planes" makes Opacity that cloud's opacity whatever the
/// Quality, and the shadow divided by the vertices along a light ray
/// makes Dirtiness its darkening. A cloud here is a group of primitives
/// (authored ellipsoids or parcel spheres): these factors, its stack's
/// depth over its mean primitive's depth along the planes' normal and
/// along the light, make Opacity and Dirtiness act on one mean primitive
/// of the cloud as the paper's on its cloud, so a tower of eight parcels
/// seen end-on is eight parcels deep, and a cloud of one ellipsoid is
/// exactly the paper's (both factors 1). Plane opacity × planes is still
/// Opacity × that ratio, so Quality, Opacity (and the cut-off) keep the
/// independence of Table 2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudScale {
    /// Along the planes' normal (× the plane opacity and cut-off).
    pub view: f32,
    /// Along the light (× the vertex shadow).
    pub light: f32,
    /// The mean primitive's depth along the light. units: m
    pub mean_depth_light_m: f32,
}

impl CloudScale {
    /// The factors for the cloud `states` (strength > 0 count) sliced
    /// along `normal` with light toward `to_light`; 1 when there is no
    /// primitive.
    pub fn new(states: &[EllipsoidState], normal: Vec3, to_light: Vec3) -> Self {
        let Some((lo, hi)) = bounds_m(states) else {
            return Self {
                view: 1.0,
                light: 1.0,
                mean_depth_light_m: 1.0,
            };
        };
        // Depth along unit `d` of a box of half-extents h: 2·Σ|d_k|·h_k.
        let depth = |d: Vec3, h: Vec3| 2.0 * d.abs().dot(h);
        let live: Vec<Vec3> = states
            .iter()
            .filter(|e| e.strength > 0.0)
            .map(|e| e.half_extent_m())
            .collect();
        let mean = |d: Vec3| {
            let d = d.normalize_or_zero();
            live.iter().map(|h| depth(d, *h)).sum::<f32>() / live.len() as f32
        };
        let ratio = |d: Vec3| depth(d.normalize_or_zero(), (hi - lo) * 0.5) / mean(d);
        Self {
            view: ratio(normal),
            light: ratio(to_light),
            mean_depth_light_m: mean(to_light).max(1.0),
        }
    }
}

/// Slicing planes ready to draw.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SliceGeometry {
    /// Unit plane normal, pointing away from the viewer (normal · view ≥ 0).
    pub normal: Vec3,
    /// `None` when there is nothing to slice (no primitive with strength).
    pub orientation: Option<SliceOrientation>,
    /// Plane offsets along `normal` in draw order (back to front: decreasing).
    /// units: m
    pub plane_offsets_m: Vec<f32>,
    /// Vertices, plane after plane in draw order, (tessellation + 1)² each.
    pub vertices: Vec<SliceVertex>,
    /// Triangle list, plane after plane in draw order.
    pub indices: Vec<u32>,
    /// The cloud's compensation factors ([`CloudScale::light`] scales the
    /// shadow; the view factor is in the vertices' plane opacity).
    pub scale: Option<CloudScale>,
}

/// The slicing rule of §4.1: the candidates are the light direction itself
/// (planes orthogonal to the light) and the direction perpendicular to the
/// light closest to the view (planes parallel to the light); the normal is
/// the candidate closest to the view direction, i.e. orthogonal when
/// |view · light| ≥ |view − (view · light)·light|. The normal is returned
/// with normal · view ≥ 0. Both arguments must be non-zero.
pub fn slice_normal(to_light: Vec3, view_dir: Vec3) -> (SliceOrientation, Vec3) {
    let l = to_light.normalize();
    let v = view_dir.normalize();
    let along = v.dot(l);
    let across = v - along * l;
    if along.abs() >= across.length() {
        (
            SliceOrientation::OrthogonalToLight,
            if along >= 0.0 { l } else { -l },
        )
    } else {
        (SliceOrientation::ParallelToLight, across.normalize())
    }
}

fn unit(name: &str, v: Vec3) -> Result<Vec3> {
    v.try_normalize()
        .filter(|_| v.is_finite())
        .ok_or_else(|| Error::invalid(name, format!("{v:?}"), "a finite, non-zero direction"))
}

/// Builds the slicing planes of `states` for the light toward `to_light`
/// and a viewer looking along `view_dir`, with the planes, tessellation,
/// plane opacity and shadow magnitude of `cfg`: [`slice_grid`], then
/// [`SliceGeometry::evaluate`] without the noise octave in the shadow.
pub fn build_slices(
    states: &[EllipsoidState],
    cfg: &SlicesConfig,
    to_light: Vec3,
    view_dir: Vec3,
) -> Result<SliceGeometry> {
    let mut g = slice_grid(states, cfg, to_light, view_dir)?;
    g.evaluate(states, cfg, to_light, None)?;
    Ok(g)
}

/// Cells across a stack whose planes are `extent_m` wide, with `planes`
/// planes: the configured tessellation, but no finer than
/// `min_spacing_m` (0: no such bound), and more where it would space the
/// vertices wider than [`MAX_VERTEX_SPACING_M`], within
/// [`MAX_STACK_VERTICES`].
pub fn stack_cells(cfg: &SlicesConfig, planes: usize, extent_m: f32, min_spacing_m: f32) -> usize {
    let mut t = cfg.tessellation as usize;
    if min_spacing_m > 0.0 {
        t = t.min((extent_m / min_spacing_m).ceil().max(1.0) as usize);
    }
    let fine = (extent_m / MAX_VERTEX_SPACING_M).ceil().max(1.0) as usize;
    let most = ((MAX_STACK_VERTICES / planes.max(1) as u64) as f64).sqrt() as usize - 1;
    t.max(fine.min(most))
}

/// The tessellated planes alone (field and shadow 0 at every vertex): the
/// static geometry of §4.1, over the bounds of the cloud `states`, with
/// its plane opacity ([`CloudScale`]) at every vertex.
pub fn slice_grid(
    states: &[EllipsoidState],
    cfg: &SlicesConfig,
    to_light: Vec3,
    view_dir: Vec3,
) -> Result<SliceGeometry> {
    slice_grid_spaced(states, cfg, to_light, view_dir, 0.0)
}

/// [`slice_grid`] with its vertices no closer than `min_spacing_m` where
/// the tessellation would put them closer ([`stack_cells`]).
pub fn slice_grid_spaced(
    states: &[EllipsoidState],
    cfg: &SlicesConfig,
    to_light: Vec3,
    view_dir: Vec3,
    min_spacing_m: f32,
) -> Result<SliceGeometry> {
    let l = unit("to_light", to_light)?;
    let v = unit("view_dir", view_dir)?;
    let (orientation, n) = slice_normal(l, v);
    let Some((lo, hi)) = bounds_m(states) else {
        return Ok(SliceGeometry {
            normal: n,
            ..SliceGeometry::default()
        });
    };
    let planes = cfg.planes() as usize;
    let side = cfg.tessellation as usize + 1;
    let count = planes as u64 * (side * side) as u64;
    if count > MAX_SLICE_VERTICES {
        return Err(Error::invalid(
            "render.slices.tessellation",
            cfg.tessellation,
            format!(
                "quality × (tessellation + 1)² at most {MAX_SLICE_VERTICES} vertices (it is {count})"
            ),
        ));
    }
    // In-plane axes: for planes parallel to the light, u is the light itself
    // so each grid row along u is one light ray.
    let (u, w) = match orientation {
        SliceOrientation::ParallelToLight => (l, n.cross(l)),
        SliceOrientation::OrthogonalToLight => n.any_orthonormal_pair(),
    };
    let corners = (0..8).map(|c| {
        Vec3::new(
            if c & 1 == 0 { lo.x } else { hi.x },
            if c & 2 == 0 { lo.y } else { hi.y },
            if c & 4 == 0 { lo.z } else { hi.z },
        )
    });
    let range = |axis: Vec3| {
        corners
            .clone()
            .map(|p| axis.dot(p))
            .fold((f32::MAX, f32::MIN), |(a, b), x| (a.min(x), b.max(x)))
    };
    let ((u0, u1), (w0, w1), (n0, n1)) = (range(u), range(w), range(n));
    let t = stack_cells(cfg, planes, (u1 - u0).max(w1 - w0), min_spacing_m);
    let side = t + 1;
    let scale = CloudScale::new(states, n, l);
    let plane_opacity = cfg.plane_opacity() * scale.view;
    // Back to front: the viewer looks along +n, so the largest offset is
    // the farthest plane. Plane k sits mid-way in its slab.
    let plane_offsets_m: Vec<f32> = (0..planes)
        .rev()
        .map(|k| n0 + (k as f32 + 0.5) * (n1 - n0) / planes as f32)
        .collect();
    let lattice =
        |i: usize, extent: (f32, f32)| extent.0 + i as f32 * (extent.1 - extent.0) / t as f32;
    let mut vertices = Vec::with_capacity(planes * side * side);
    for &d in &plane_offsets_m {
        for j in 0..side {
            for i in 0..side {
                let p = u * lattice(i, (u0, u1)) + w * lattice(j, (w0, w1)) + n * d;
                vertices.push(SliceVertex {
                    position_m: p.into(),
                    density: 0.0,
                    shadow: 0.0,
                    plane_opacity,
                });
            }
        }
    }
    let indices = plane_indices(planes, side);
    Ok(SliceGeometry {
        normal: n,
        orientation: Some(orientation),
        plane_offsets_m,
        vertices,
        indices,
        scale: Some(scale),
    })
}

/// The light rays through the vertices, as eq. 2 walks them: ray r starts
/// at vertex `r · start_stride + start_offset` (the one nearest the light)
/// and visits `count` vertices `step` apart; each adds `shadow_step` ×
/// density (× the octave weight) to the running shadow. The CPU walk below
/// and the compute pass (shaders/slices/vertex_field.wgsl) both follow it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowRays {
    pub rays: u32,
    pub start_stride: u32,
    pub start_offset: u32,
    pub step: i32,
    pub count: u32,
    /// Shadow magnitude × plane opacity ÷ vertices along a ray (eq. 2,
    /// §5.2), × the cloud's [`CloudScale::light`].
    pub shadow_step: f32,
}

impl ShadowRays {
    /// Vertex `t` of ray `r`.
    pub fn vertex(&self, r: u32, t: u32) -> usize {
        (r as i64 * self.start_stride as i64
            + self.start_offset as i64
            + t as i64 * self.step as i64) as usize
    }
}

impl SliceGeometry {
    /// Vertices per side of a plane (tessellation + 1); 0 when empty.
    pub fn side(&self) -> usize {
        let planes = self.plane_offsets_m.len();
        if planes == 0 {
            return 0;
        }
        ((self.vertices.len() / planes) as f64).sqrt().round() as usize
    }

    /// The light rays of eq. 2 for this geometry (None when empty):
    ///   shadow_i = shadow_{i−1} + shadow magnitude × opacity_i ÷ N,
    /// with opacity_i = plane opacity × density_i (eq. 1) and shadow
    /// magnitude = Dirtiness ÷ plane opacity (Table 2), so each step is
    /// Dirtiness × density_i ÷ N. N is the number of vertices along the
    /// light ray: §5.2 says that "as slicing planes increase, the
    /// accumulated shadow grows, so this term is divided by the number of
    /// slicing planes", which is N when the planes cross the light; when
    /// they contain it, N is the row length (tessellation + 1). Either way
    /// the shadow is a Riemann sum of the density across the cloud's
    /// bounds, and Quality does not darken it: behind a full-strength block
    /// as deep as the bounds it is Dirtiness. A vertex's own opacity counts
    /// toward its shadow, as eq. 2 has it. The step is then scaled by the
    /// cloud's [`CloudScale::light`], so the shadow is an optical depth
    /// toward the light for one mean primitive's Dirtiness.
    pub fn shadow_rays(&self, cfg: &SlicesConfig, to_light: Vec3) -> Option<ShadowRays> {
        let orientation = self.orientation?;
        let planes = self.plane_offsets_m.len();
        let side = self.side();
        if planes == 0 || side == 0 {
            return None;
        }
        let per_plane = side * side;
        let light_along_normal = self.normal.dot(to_light) > 0.0;
        let (rays, start_stride, start_offset, step, count) = match orientation {
            // Planes are in draw order of decreasing offset: plane 0 is
            // nearest the light when the light is on the +normal side.
            SliceOrientation::OrthogonalToLight if light_along_normal => {
                (per_plane, 1, 0, per_plane as i32, planes)
            }
            SliceOrientation::OrthogonalToLight => (
                per_plane,
                1,
                (planes - 1) * per_plane,
                -(per_plane as i32),
                planes,
            ),
            // u = light: the vertex with the largest i in a row is nearest
            // it; ray r = k·side + j is row j of plane k.
            SliceOrientation::ParallelToLight => (planes * side, side, side - 1, -1, side),
        };
        Some(ShadowRays {
            rays: rays as u32,
            start_stride: start_stride as u32,
            start_offset: start_offset as u32,
            step,
            count: count as u32,
            shadow_step: cfg.shadow_magnitude() * cfg.plane_opacity() / count as f32
                * self.scale.map_or(1.0, |s| s.light),
        })
    }

    /// Evaluates density and shadow at the existing vertices for `states`,
    /// keeping the positions: the paper's split (§4.1) where the
    /// tessellated planes stay as static geometry and only the per-vertex
    /// values are refreshed. `octave_weight`, when given, multiplies each
    /// vertex's density in the shadow sum (the first noise octave, see
    /// `methods::slices::gpu::field::first_octave_weight`). Valid while the light
    /// and view keep the same slicing (orientation and normal) and the
    /// states fit in the old bounds; otherwise rebuild with [`slice_grid`].
    pub fn evaluate(
        &mut self,
        states: &[EllipsoidState],
        cfg: &SlicesConfig,
        to_light: Vec3,
        octave_weight: Option<&dyn Fn(Vec3) -> f32>,
    ) -> Result<()> {
        let l = unit("to_light", to_light)?;
        let Some(rays) = self.shadow_rays(cfg, l) else {
            return Ok(());
        };
        let index = FieldIndex::new(states);
        for v in &mut self.vertices {
            v.density = index.field(Vec3::from(v.position_m));
        }
        for r in 0..rays.rays {
            let mut shadow = 0.0;
            for t in 0..rays.count {
                let v = &mut self.vertices[rays.vertex(r, t)];
                let weight = match octave_weight {
                    Some(f) if v.density > 0.0 => f(Vec3::from(v.position_m)),
                    _ => 1.0,
                };
                shadow += rays.shadow_step * v.density * weight;
                v.shadow = shadow;
            }
        }
        Ok(())
    }

    /// [`Self::evaluate`] without the noise octave in the shadow.
    pub fn refresh(
        &mut self,
        states: &[EllipsoidState],
        cfg: &SlicesConfig,
        to_light: Vec3,
    ) -> Result<()> {
        self.evaluate(states, cfg, to_light, None)
    }
}

/// Two triangles per grid cell, plane after plane.
fn plane_indices(planes: usize, side: usize) -> Vec<u32> {
    let cells = side - 1;
    let mut out = Vec::with_capacity(planes * cells * cells * 6);
    for k in 0..planes {
        let base = (k * side * side) as u32;
        for j in 0..cells as u32 {
            for i in 0..cells as u32 {
                let a = base + j * side as u32 + i;
                let b = a + side as u32;
                out.extend_from_slice(&[a, a + 1, b + 1, a, b + 1, b]);
            }
        }
    }
    out
}
