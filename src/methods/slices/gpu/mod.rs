//! The `slices` render method on the GPU (Schpok et al. 2003 §4, Table 1):
//! each frame the CPU half ([`crate::methods::slices::model::clouds`]) groups
//! the authored ellipsoids and the physics' parcels (each a sphere of the
//! rendered radius) into clouds, slices each cloud with its own stack of
//! light-aligned planes and stores field and shadow at the vertices; this module uploads those
//! vertices, the noise-octave transforms ([`OctaveUniform`]) and the
//! qualitative controls ([`SlicesParams`]) into the buffers of
//! [`buffers`]; [`method`] (the render-method trait) draws them with
//! `shaders/slices/slices.wgsl` into the float cloud image, which the
//! composite pass blends over sky and terrain; [`passes`] declares the
//! passes, layouts, slots and files. With `vertex_field =
//! "gpu"` the vertex values come from a compute pass instead
//! ([`gpu_field`]); the same primitives and grid index feed the
//! cloud-shadow map on the terrain (shaders/slices/shadow_field.wgsl).
//! [`field`] is the CPU twin of the noise-detailed density the planes
//! draw (the export samples it).

pub mod buffers;
pub mod field;
pub mod gpu_field;
pub mod method;
pub mod passes;

pub use buffers::SlicesGpu;
pub use passes::VERTEX_ATTRIBUTES;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::config::RenderConfig;
use crate::error::Result;
use crate::methods::slices::model::ellipsoid::FieldIndex;
use crate::methods::slices::model::clouds::CloudSlices;
use crate::methods::slices::model::ellipsoid::{EllipsoidState, bounds_m};
use crate::methods::slices::model::octaves::{OctaveUniform, octave_uniform};
use crate::methods::slices::model::slicing::CloudScale;
use crate::methods::slices::model::{Ellipsoid, ParticleConfig, states_at};
use crate::noise::NoiseVolume;
use crate::physics::CloudParcel;

/// The qualitative controls as the shaders take them: WGSL
/// `struct SlicesParams` in shaders/slices/implicit.wgsl (80 bytes; a test
/// compares the layouts). The plane opacity is per stack, in the vertices
/// ([`crate::methods::slices::model::CloudScale`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SlicesParams {
    /// Sharpness: the alpha cutoff in units of the plane opacity (Table 2).
    pub sharpness: f32,
    pub _pad2: f32,
    pub _pad3: f32,
    pub _pad4: f32,
    /// Lit cloud colour as painted (sRGB-encoded).
    pub cloud_colour: [f32; 3],
    pub _pad0: f32,
    /// Fully shadowed cloud colour as painted.
    pub shadow_colour: [f32; 3],
    pub _pad1: f32,
    /// The primitives' grid index minimum (see [`FieldIndex::flatten`]).
    /// units: m
    pub index_min: [f32; 3],
    pub cells_per_axis: f32,
    /// The index's cell size. units: m
    pub index_cell: [f32; 3],
    /// The slices' extinction per unit of field × media for the
    /// cloud-shadow map, Opacity ÷ the mean primitive's depth along the
    /// light: the optical depth the planes give one mean primitive, spread
    /// along the sun ray. units: 1/m
    pub shadow_extinction_per_m: f32,
}

const _: () = assert!(std::mem::size_of::<SlicesParams>() == 80);

impl SlicesParams {
    /// The derived quantities of `[render.slices]` (Table 2) for the
    /// primitives `states` lit from `to_light`, with their grid `index`
    /// ([`FlatIndex`]).
    pub fn new(
        cfg: &crate::methods::slices::model::SlicesConfig,
        states: &[EllipsoidState],
        to_light: Vec3,
        index: &FlatIndex,
    ) -> Self {
        let mean_depth_light_m = CloudScale::new(states, to_light, to_light).mean_depth_light_m;
        Self {
            sharpness: cfg.sharpness,
            _pad2: 0.0,
            _pad3: 0.0,
            _pad4: 0.0,
            cloud_colour: cfg.cloud_colour,
            _pad0: 0.0,
            shadow_colour: cfg.shadow_colour,
            _pad1: 0.0,
            index_min: index.min_m.to_array(),
            cells_per_axis: index.cells_per_axis as f32,
            index_cell: index.cell_m.to_array(),
            shadow_extinction_per_m: cfg.opacity / mean_depth_light_m,
        }
    }
}

/// The primitives' grid index as the GPU reads it (see
/// [`FieldIndex::flatten`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FlatIndex {
    /// units: m
    pub min_m: Vec3,
    /// units: m
    pub cell_m: Vec3,
    pub cells_per_axis: u32,
    /// n³ + 1 list offsets into this array, then the lists.
    pub lists: Vec<u32>,
}

impl FlatIndex {
    pub fn new(states: &[EllipsoidState]) -> Self {
        let (min_m, cell_m, cells_per_axis, lists) = FieldIndex::new(states).flatten();
        Self {
            min_m,
            cell_m,
            cells_per_axis,
            lists,
        }
    }
}

/// A parcel's implicit sphere, in units of its ray-marched radius. The
/// hypertextured sphere is dense out to its radius; the Wyvill blend falls
/// to half at half its own radius and to 0.13 at 1/1.3 of it, so a blend
/// 1.3 times the sphere is dense over about the same body. Measured
/// against the path tracer on the parcels of four frames (fair weather,
/// towering cumulus, a tower and a deck, 160×120): 1 leaves the slices'
/// clouds small, soft balls with sky between them (0.101 / 0.130 / 0.038 /
/// 0.067 mean FLIP with the former controls), 1.3 gives 0.074 / 0.103 /
/// 0.040 / 0.045 with today's, 1.44 0.075 / 0.102 / 0.037 / 0.041.
pub const PARCEL_BLEND_SCALE: f32 = 1.3;

/// The physics' condensed parcels as implicit spheres: PARCEL_BLEND_SCALE
/// × the rendered radius of the ray-marched methods (radius ×
/// `radius_scale`, paper §6.1 of the physics paper), full strength and a
/// flat base at the condensation plane, as the ray-march's half-space cuts
/// them. Parcels with no fill or radius are left out, as `pack` leaves
/// them out of the ray-march.
pub fn parcel_spheres(parcels: &[CloudParcel], radius_scale: f32) -> Vec<EllipsoidState> {
    parcels
        .iter()
        .filter(|p| p.fill > 0.0 && p.radius_m > 0.0)
        .map(|p| EllipsoidState {
            centre_m: p.center_m,
            radii_m: Vec3::splat(p.radius_m * radius_scale * PARCEL_BLEND_SCALE),
            rotation: glam::Mat3::IDENTITY,
            strength: 1.0,
            base_z_m: p.cond_plane_z_m,
        })
        .collect()
}

/// Everything the slices pass draws in one frame.
pub struct SlicesFrame {
    /// Every cloud's stack, farthest first, and every primitive with
    /// strength at this frame's time (the authored ellipsoids and the
    /// parcel spheres) grouped by cloud in that order (`slices.states`).
    pub slices: CloudSlices,
    pub octaves: OctaveUniform,
    pub params: SlicesParams,
    /// The primitives' grid index (the GPU's field reads it).
    pub index: FlatIndex,
    /// Whether the vertices hold their field and shadow (evaluated on the
    /// CPU) or only positions (the compute pass fills them).
    pub values_on_cpu: bool,
    /// Unit vector toward the light the planes were sliced for.
    pub to_light: Vec3,
    /// The `[render.slices]` settings of the frame.
    pub cfg: crate::methods::slices::model::SlicesConfig,
}

/// Builds the frame at `time_s` (units: s): the authored `ellipsoids`
/// animated by their keyframes and `particles`, plus the `parcels` as
/// spheres, a stack per cloud, sliced for the light toward `to_light` and
/// an eye at `eye_m` looking along `view_dir`, with the noise octaves of `cfg.slices` pivoting on the
/// authored clouds' centre at time 0 (so the pivot does not drift with
/// them; the origin when there are none). With `cpu_noise` the vertices'
/// field and shadow are evaluated here on the CPU (the noise volume gives
/// the shadow's first octave when `shadow_octave` is on); without it the
/// vertices carry only positions, for the compute pass or for callers that
/// need the primitives alone (`cumulus export`).
#[allow(clippy::too_many_arguments)]
pub fn slices_frame(
    ellipsoids: &[Ellipsoid],
    particles: &ParticleConfig,
    parcels: &[CloudParcel],
    cfg: &RenderConfig,
    time_s: f32,
    to_light: Vec3,
    eye_m: Vec3,
    view_dir: Vec3,
    cpu_noise: Option<&NoiseVolume>,
) -> Result<SlicesFrame> {
    let s = &cfg.slices;
    let mut states = states_at(ellipsoids, particles, time_s);
    states.extend(parcel_spheres(parcels, cfg.radius_scale));
    let pivot_m = bounds_m(&states_at(ellipsoids, particles, 0.0))
        .map_or(Vec3::ZERO, |(lo, hi)| (lo + hi) * 0.5);
    let mut slices = CloudSlices::grid(&states, s, to_light, eye_m, view_dir)?;
    let octaves = octave_uniform(
        &s.tiers,
        &s.base,
        s.lacunarity(),
        s.octaves as usize,
        pivot_m,
        time_s,
    );
    if let Some(noise) = cpu_noise {
        let weight = |p: Vec3| field::first_octave_weight(&octaves, noise, p);
        let weight: Option<&(dyn Fn(Vec3) -> f32 + Sync)> = s.shadow_octave.then_some(&weight);
        slices.evaluate(s, to_light, weight)?;
    }
    let index = FlatIndex::new(&slices.states);
    Ok(SlicesFrame {
        params: SlicesParams::new(s, &slices.states, to_light, &index),
        slices,
        octaves,
        index,
        values_on_cpu: cpu_noise.is_some(),
        to_light: to_light.normalize_or_zero(),
        cfg: s.clone(),
    })
}
