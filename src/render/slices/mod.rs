//! The `slices` render method on the GPU (Schpok et al. 2003 §4, Table 1):
//! each frame the CPU half ([`crate::authored::slicing`]) slices the
//! implicit field of the authored ellipsoids and of the physics' parcels
//! (each a sphere of the rendered radius) with light-aligned planes and
//! stores field and shadow at the vertices; this module uploads those
//! vertices, the noise-octave transforms ([`OctaveUniform`]) and the
//! qualitative controls ([`SlicesParams`]), and the renderer draws them
//! with `shaders/slices.wgsl` into the float cloud target, which the
//! composite pass blends over sky and terrain.

pub mod field;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::authored::ellipsoid::{EllipsoidState, bounds_m};
use crate::authored::octaves::{OctaveUniform, octave_uniform};
use crate::authored::slicing::{SliceGeometry, SliceVertex, build_slices};
use crate::authored::{Ellipsoid, ParticleConfig, states_at};
use crate::error::Result;
use crate::physics::CloudParcel;
use crate::render::RenderConfig;
use crate::render::gpu::GpuContext;

/// Maps the sun's irradiance scale (≈ 2.2 for nominal daylight, see
/// [`crate::render::Sun`]) to the colour multiplier of the lit cloud, so a
/// `cloud_colour` of 1 tone-maps to about 0.86 through `output_color`, near
/// the ray-marched methods' sunlit tops.
pub const SUN_TO_COLOUR: f32 = 0.8;

/// The qualitative controls as the fragment shader takes them: WGSL
/// `struct SlicesParams` in shaders/slices.wgsl (48 bytes; keep in sync).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SlicesParams {
    /// x: plane opacity (Opacity ÷ planes) × the view's [`CloudscapeScale`];
    /// y: alpha cutoff (Sharpness × that plane opacity); z:
    /// [`SUN_TO_COLOUR`]; w: the light's [`CloudscapeScale`] (× shadow).
    pub opacity: [f32; 4],
    /// rgb: lit cloud colour (linear); w: 0.
    pub cloud_colour: [f32; 4],
    /// rgb: fully shadowed cloud colour (linear); w: 0.
    pub shadow_colour: [f32; 4],
}

const _: () = assert!(std::mem::size_of::<SlicesParams>() == 48);

/// The paper slices one cloud, so its planes span that cloud and "plane
/// opacity = Opacity ÷ planes" makes Opacity the cloud's opacity whatever
/// the Quality. We slice a whole cloudscape with one stack of planes over
/// the bounds of every primitive, so a cloud crosses only the fraction
/// (its depth ÷ the bounds' depth) of the planes, and the same for the
/// vertices its shadow sums along a light ray (slicing.rs divides by all
/// of them). These factors, the bounds' depth over the mean primitive's
/// depth along the view-side normal and along the light, restore the
/// paper's meaning: Opacity (and Dirtiness) act on one mean primitive as
/// they would on the paper's single cloud. Neither depends on Quality or
/// Opacity, so the compensations of Table 2 still hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudscapeScale {
    /// Along the planes' normal (multiplies the plane opacity and cutoff).
    pub view: f32,
    /// Along the light (multiplies the vertex shadow).
    pub light: f32,
}

impl CloudscapeScale {
    /// The factors for `states` (strength > 0 count) sliced along `normal`
    /// with light toward `to_light`; 1 when there is no primitive.
    pub fn new(states: &[EllipsoidState], normal: Vec3, to_light: Vec3) -> Self {
        let Some((lo, hi)) = bounds_m(states) else {
            return Self {
                view: 1.0,
                light: 1.0,
            };
        };
        // Depth along unit `d` of a box of half-extents h: 2·Σ|d_k|·h_k.
        let depth = |d: Vec3, h: Vec3| 2.0 * d.abs().dot(h);
        let ratio = |d: Vec3| {
            let d = d.normalize_or_zero();
            let live: Vec<Vec3> = states
                .iter()
                .filter(|e| e.strength > 0.0)
                .map(|e| e.half_extent_m())
                .collect();
            let mean = live.iter().map(|h| depth(d, *h)).sum::<f32>() / live.len() as f32;
            depth(d, (hi - lo) * 0.5) / mean
        };
        Self {
            view: ratio(normal),
            light: ratio(to_light),
        }
    }
}

impl SlicesParams {
    /// The derived quantities of `[render.slices]` (Table 2), scaled for
    /// the cloudscape by `scale`.
    pub fn new(cfg: &crate::authored::SlicesConfig, scale: CloudscapeScale) -> Self {
        Self {
            opacity: [
                cfg.plane_opacity() * scale.view,
                cfg.alpha_cutoff() * scale.view,
                SUN_TO_COLOUR,
                scale.light,
            ],
            cloud_colour: [
                cfg.cloud_colour[0],
                cfg.cloud_colour[1],
                cfg.cloud_colour[2],
                0.0,
            ],
            shadow_colour: [
                cfg.shadow_colour[0],
                cfg.shadow_colour[1],
                cfg.shadow_colour[2],
                0.0,
            ],
        }
    }
}

/// The physics' condensed parcels as implicit spheres: the rendered radius
/// of the ray-marched methods (radius × `radius_scale`, paper §6.1 of the
/// physics paper) and full strength. Parcels with no fill or radius are
/// left out, as `pack` leaves them out of the ray-march.
pub fn parcel_spheres(parcels: &[CloudParcel], radius_scale: f32) -> Vec<EllipsoidState> {
    parcels
        .iter()
        .filter(|p| p.fill > 0.0 && p.radius_m > 0.0)
        .map(|p| EllipsoidState {
            centre_m: p.center_m,
            radii_m: Vec3::splat(p.radius_m * radius_scale),
            rotation: glam::Mat3::IDENTITY,
            strength: 1.0,
        })
        .collect()
}

/// Everything the slices pass draws in one frame.
pub struct SlicesFrame {
    /// Every primitive at this frame's time: the authored ellipsoids, then
    /// the parcel spheres.
    pub states: Vec<EllipsoidState>,
    pub geometry: SliceGeometry,
    pub octaves: OctaveUniform,
    pub params: SlicesParams,
}

/// Builds the frame at `time_s` (units: s): the authored `ellipsoids`
/// animated by their keyframes and `particles`, plus the `parcels` as
/// spheres, sliced for the light toward `to_light` and a viewer looking
/// along `view_dir`, with the noise octaves of `cfg.slices` pivoting on the
/// authored clouds' centre at time 0 (so the pivot does not drift with
/// them; the origin when there are none).
pub fn slices_frame(
    ellipsoids: &[Ellipsoid],
    particles: &ParticleConfig,
    parcels: &[CloudParcel],
    cfg: &RenderConfig,
    time_s: f32,
    to_light: Vec3,
    view_dir: Vec3,
) -> Result<SlicesFrame> {
    let s = &cfg.slices;
    let mut states = states_at(ellipsoids, particles, time_s);
    states.extend(parcel_spheres(parcels, cfg.radius_scale));
    let pivot_m = bounds_m(&states_at(ellipsoids, particles, 0.0))
        .map_or(Vec3::ZERO, |(lo, hi)| (lo + hi) * 0.5);
    let geometry = build_slices(&states, s, to_light, view_dir)?;
    let octaves = octave_uniform(
        &s.tiers,
        &s.base,
        s.lacunarity(),
        s.octaves as usize,
        pivot_m,
        time_s,
    );
    let scale = CloudscapeScale::new(&states, geometry.normal, to_light);
    Ok(SlicesFrame {
        states,
        geometry,
        octaves,
        params: SlicesParams::new(s, scale),
    })
}

/// The group-2 layout of the slices pass: the octave transforms and the
/// controls. Keep in sync with shaders/slices.wgsl.
pub fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    let entry = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("slices: octaves and controls"),
        entries: &[entry(0), entry(1)],
    })
}

/// Vertex layout of [`SliceVertex`]: position, field, shadow.
pub const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32, 2 => Float32];

/// GPU buffers of the slices pass, grown as needed and reused.
pub struct SlicesGpu {
    octaves: wgpu::Buffer,
    params: wgpu::Buffer,
    /// Group 2 of the slices pass.
    pub bind: wgpu::BindGroup,
    vertices: Option<wgpu::Buffer>,
    indices: Option<wgpu::Buffer>,
    /// Indices of the last uploaded frame.
    pub index_count: u32,
    /// Primitives (ellipsoids and parcel spheres) of the last frame.
    pub primitives: u32,
}

impl SlicesGpu {
    pub fn new(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> Self {
        let uniform = |label, size: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let octaves = uniform("slices: octaves", std::mem::size_of::<OctaveUniform>());
        let params = uniform("slices: controls", std::mem::size_of::<SlicesParams>());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("slices: octaves and controls"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: octaves.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: params.as_entire_binding(),
                },
            ],
        });
        Self {
            octaves,
            params,
            bind,
            vertices: None,
            indices: None,
            index_count: 0,
            primitives: 0,
        }
    }

    /// Uploads a frame, growing the vertex and index buffers when it needs
    /// more room (never shrinking them: a frame rarely needs less for long).
    pub fn upload(&mut self, ctx: &GpuContext, frame: &SlicesFrame) {
        let q = &ctx.queue;
        q.write_buffer(&self.octaves, 0, bytemuck::bytes_of(&frame.octaves));
        q.write_buffer(&self.params, 0, bytemuck::bytes_of(&frame.params));
        let g = &frame.geometry;
        self.primitives = frame.states.len() as u32;
        self.index_count = g.indices.len() as u32;
        if g.indices.is_empty() {
            return;
        }
        let ensure = |buf: &mut Option<wgpu::Buffer>, bytes: &[u8], usage, label| {
            if buf.as_ref().is_none_or(|b| b.size() < bytes.len() as u64) {
                *buf = Some(ctx.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size: bytes.len() as u64,
                    usage: usage | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }));
            }
            q.write_buffer(buf.as_ref().expect("just made"), 0, bytes);
        };
        ensure(
            &mut self.vertices,
            bytemuck::cast_slice::<SliceVertex, u8>(&g.vertices),
            wgpu::BufferUsages::VERTEX,
            "slices: vertices",
        );
        ensure(
            &mut self.indices,
            bytemuck::cast_slice::<u32, u8>(&g.indices),
            wgpu::BufferUsages::INDEX,
            "slices: indices",
        );
    }

    /// Draws the uploaded planes (pipeline and groups 0–1 already set).
    pub fn draw(&self, rp: &mut wgpu::RenderPass<'_>) {
        let (Some(v), Some(i)) = (&self.vertices, &self.indices) else {
            return;
        };
        if self.index_count == 0 {
            return;
        }
        rp.set_bind_group(2, &self.bind, &[]);
        rp.set_vertex_buffer(0, v.slice(..));
        rp.set_index_buffer(i.slice(..), wgpu::IndexFormat::Uint32);
        rp.draw_indexed(0..self.index_count, 0, 0..1);
    }
}
