//! Slices per cloud (paper 001 slices one cloud; issue 33): the
//! primitives of a frame are grouped into clouds, each cloud gets its own
//! light-aligned stack of planes over its own bounds ([`slice_grid`], so a
//! small cloud is sliced as finely as the paper's one cloud), and the
//! stacks are put in draw order, farthest first (painter's algorithm
//! between clouds as between planes).
//!
//! A cloud is a group of primitives whose bounding spheres touch and
//! whose boxes overlap ([`touching_groups`]), through chains: their
//! fields may overlap, so they must be summed in one stack; primitives
//! apart have disjoint fields, so their stacks only meet on screen. Many small clouds (hundreds of fair-weather
//! parcels) would each pay a full stack, so past [`MAX_STACKS`] clouds
//! the join distance grows by √2 steps until at most that many remain: neighbouring
//! small clouds then share one stack, which is the one-stack slicing of
//! a few clouds (correct, only coarser). And where the clouds' planes
//! together would hold more than [`PLANE_VERTEX_BUDGET`] vertices, their
//! vertices are spaced no closer than the spacing that fits
//! ([`min_spacing_m`]): the small clouds' stacks lose the cells they had
//! beyond need, a large cloud keeps its floor of one vertex per
//! [`MAX_VERTEX_SPACING_M`]. The budget is per plane so that Quality
//! never changes the tessellation.

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use super::ellipsoid::{EllipsoidState, bounds_m};
use super::slicing::{MAX_VERTEX_SPACING_M, SliceGeometry, slice_grid_spaced, stack_cells};
use crate::config::slices::SlicesConfig;
use crate::error::Result;
use crate::physics::clusters::touching_groups;

/// Vertices of one plane of every stack together, beyond which the small
/// clouds' vertices spread out: 2¹³ (about 90²), 7.5 × the one-stack
/// slicing's 33². The fair-weather field's 20 clouds at 33² each were
/// 2.7× that.
pub const PLANE_VERTEX_BUDGET: usize = 1 << 13;

/// Most stacks a frame draws (the GPU field pass's table holds as many:
/// `MAX_STACKS` in shaders/slices/vertex_field.wgsl).
pub const MAX_STACKS: usize = 32;

/// One cloud's stack of slicing planes.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudStack {
    /// Its primitives, a range of [`CloudSlices::states`].
    pub primitives: Range<usize>,
    /// Its planes, back to front, with their vertex values once evaluated.
    pub geometry: SliceGeometry,
    /// Distance from the eye to the centre of its bounds. units: m
    pub distance_m: f32,
}

/// Every cloud's stack of one frame, in draw order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CloudSlices {
    /// The primitives, grouped by cloud (each cloud's a contiguous range,
    /// clouds in draw order).
    pub states: Vec<EllipsoidState>,
    /// The stacks, farthest first.
    pub stacks: Vec<CloudStack>,
}

/// The clouds of `states` (those with strength > 0; the others draw
/// nothing and are left out): a cloud index per primitive, at most
/// [`MAX_STACKS`] clouds, the join distance growing from touching
/// bounding spheres and overlapping boxes (both grown about their centres
/// by that factor) until so.
pub fn cloud_groups(states: &[EllipsoidState]) -> Vec<usize> {
    let spheres: Vec<(Vec3, f32)> = states
        .iter()
        .map(|e| (e.centre_m, e.radii_m.max_element()))
        .collect();
    let half: Vec<Vec3> = states.iter().map(|e| e.half_extent_m()).collect();
    let mut reach = 1.0;
    loop {
        let boxes_meet = |i: usize, j: usize| {
            let gap = (states[i].centre_m - states[j].centre_m).abs();
            gap.cmplt(reach * (half[i] + half[j])).all()
        };
        let groups = touching_groups(&spheres, reach, &boxes_meet);
        if groups.iter().all(|&g| g < MAX_STACKS) {
            return groups;
        }
        // √2 steps: neighbours merge before the next ring of them.
        reach *= std::f32::consts::SQRT_2;
    }
}

/// The closest vertex spacing the `clouds` may have for one plane of each
/// together to hold at most [`PLANE_VERTEX_BUDGET`] vertices (0: the
/// tessellation fits), found by bisection on the cells [`stack_cells`]
/// gives each; a cloud's extent across its planes is taken as its box's
/// diagonal (an upper bound whatever the orientation). units: m
pub fn min_spacing_m(clouds: &[Vec<EllipsoidState>], cfg: &SlicesConfig) -> f32 {
    let planes = cfg.planes() as usize;
    let extents: Vec<f32> = clouds
        .iter()
        .filter_map(|c| bounds_m(c).map(|(lo, hi)| (hi - lo).length()))
        .collect();
    let vertices = |s: f32| -> usize {
        extents
            .iter()
            .map(|&e| (stack_cells(cfg, planes, e, s) + 1).pow(2))
            .sum()
    };
    if vertices(0.0) <= PLANE_VERTEX_BUDGET {
        return 0.0;
    }
    // Past MAX_VERTEX_SPACING_M every cloud is at its floor: the budget
    // cannot be met by spacing alone, and the floor wins.
    let (mut lo, mut hi) = (0.0f32, MAX_VERTEX_SPACING_M);
    for _ in 0..24 {
        let mid = 0.5 * (lo + hi);
        if vertices(mid) <= PLANE_VERTEX_BUDGET {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

impl CloudSlices {
    /// The stacks of `states` for the light toward `to_light` and an eye
    /// at `eye_m` looking along `view_dir`: each cloud sliced for the
    /// direction from the eye to its centre (the view direction when the
    /// eye is at the centre), the stacks sorted farthest first. Vertex
    /// values are zero until [`Self::evaluate`].
    pub fn grid(
        states: &[EllipsoidState],
        cfg: &SlicesConfig,
        to_light: Vec3,
        eye_m: Vec3,
        view_dir: Vec3,
    ) -> Result<Self> {
        let live: Vec<EllipsoidState> =
            states.iter().filter(|e| e.strength > 0.0).cloned().collect();
        let groups = cloud_groups(&live);
        let clouds = groups.iter().copied().max().map_or(0, |m| m + 1);
        let mut members: Vec<Vec<EllipsoidState>> = vec![Vec::new(); clouds];
        for (e, &g) in live.iter().zip(&groups) {
            members[g].push(*e);
        }
        let spacing = min_spacing_m(&members, cfg);
        // The clouds are independent: sliced on every core.
        let mut stacks = members
            .into_par_iter()
            .map(|cloud| {
                let (lo, hi) = bounds_m(&cloud).expect("a cloud has a primitive with strength");
                let to_cloud = (lo + hi) * 0.5 - eye_m;
                let dir = if to_cloud.length() > 1.0 { to_cloud } else { view_dir };
                let geometry = slice_grid_spaced(&cloud, cfg, to_light, dir, spacing)?;
                Ok((cloud, geometry, to_cloud.length()))
            })
            .collect::<Result<Vec<_>>>()?;
        // Farthest first; ties keep the clouds' order (a stable sort).
        stacks.sort_by(|a, b| b.2.total_cmp(&a.2));
        let mut out = Self::default();
        for (cloud, geometry, distance_m) in stacks {
            let start = out.states.len();
            out.states.extend(cloud);
            out.stacks.push(CloudStack {
                primitives: start..out.states.len(),
                geometry,
                distance_m,
            });
        }
        Ok(out)
    }

    /// Evaluates every stack's vertex field and shadow from its own
    /// primitives ([`SliceGeometry::evaluate`]): a stack's bounds may
    /// reach into another cloud, whose field its planes must not draw
    /// again.
    pub fn evaluate(
        &mut self,
        cfg: &SlicesConfig,
        to_light: Vec3,
        octave_weight: Option<&(dyn Fn(Vec3) -> f32 + Sync)>,
    ) -> Result<()> {
        let states = &self.states;
        self.stacks.par_iter_mut().try_for_each(|s| {
            let own = &states[s.primitives.clone()];
            let weight = octave_weight.map(|f| f as &dyn Fn(Vec3) -> f32);
            s.geometry.evaluate(own, cfg, to_light, weight)
        })
    }

    /// Every stack's vertices, in draw order.
    pub fn vertices(&self) -> Vec<super::slicing::SliceVertex> {
        self.stacks
            .iter()
            .flat_map(|s| s.geometry.vertices.iter().copied())
            .collect()
    }

    /// Every stack's triangles, in draw order, indexing [`Self::vertices`].
    /// With `skip_empty` (the vertex values are evaluated) a triangle whose
    /// three vertices hold no field is left out: its fragments interpolate
    /// a density of exactly 0, which the cut-off (Sharpness × plane
    /// opacity ≥ 0) discards whatever the noise, so the image is the same
    /// and most of a stack's box, empty air, is never rasterised.
    pub fn indices(&self, skip_empty: bool) -> Vec<u32> {
        let mut base = 0u32;
        let mut out = Vec::new();
        for s in &self.stacks {
            let v = &s.geometry.vertices;
            let drawn = s.geometry.indices.chunks_exact(3).filter(|t| {
                !skip_empty || t.iter().any(|&i| v[i as usize].density > 0.0)
            });
            out.extend(drawn.flatten().map(|i| i + base));
            base += v.len() as u32;
        }
        out
    }

    /// Vertices of every stack together.
    pub fn vertex_count(&self) -> usize {
        self.stacks.iter().map(|s| s.geometry.vertices.len()).sum()
    }
}
