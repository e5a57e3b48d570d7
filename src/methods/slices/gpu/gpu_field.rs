//! The slice vertices' field and shadow in a compute pass (`[render.slices]
//! vertex_field = "gpu"`, shaders/slices/vertex_field.wgsl): one dispatch
//! evaluates the Wyvill sum of its stack's own primitives at every vertex,
//! a second walks every light ray of every stack's [`ShadowRays`]
//! accumulating eq. 2, both into the vertex buffer
//! the planes are then drawn from. The CPU's `SliceGeometry::evaluate` is
//! the reference it is tested against. Its pipelines are made at the first
//! frame that asks for them, never when the CPU evaluates the vertices.

use bytemuck::{Pod, Zeroable};

use glam::Vec3;

use super::SlicesFrame;
use super::passes::{FIELD_JOB, PRIMITIVES, SLICE_FIELD, SLOTS};
use crate::methods::slices::model::SlicesConfig;
use crate::methods::slices::model::clouds::{CloudSlices, MAX_STACKS};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::gpu::layouts::{COMMON, Layouts, uniform_buffer};
use crate::gpu::pass::SLOT_GROUP;
#[cfg(doc)]
use crate::methods::slices::model::slicing::ShadowRays;

/// Threads per workgroup of both entry points (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;
/// Most workgroups along x (WebGPU's minimum limit); more go along y.
const MAX_GROUPS_X: u32 = 65535;

/// One stack's share of the job: WGSL `struct StackJob` in
/// shaders/slices/vertex_field.wgsl (48 bytes). Ray starts are relative to
/// the stack's first vertex.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct StackJob {
    pub first_vertex: u32,
    pub end_vertex: u32,
    pub first_ray: u32,
    pub end_ray: u32,
    /// Vertex index stride between ray starts.
    pub ray_stride: u32,
    /// Vertex index of the first ray's start.
    pub ray_offset: u32,
    /// Vertex index step along a ray.
    pub vertex_step: i32,
    /// Vertices per ray.
    pub ray_vertices: i32,
    /// [`ShadowRays::shadow_step`].
    pub shadow_step: f32,
    /// The stack's primitives, a range of the primitive buffer.
    pub first_primitive: u32,
    pub end_primitive: u32,
    pub _pad: u32,
}

const _: () = assert!(std::mem::size_of::<StackJob>() == 48);

/// WGSL `struct FieldJob` in shaders/slices/vertex_field.wgsl (16 + 48 ×
/// [`MAX_STACKS`] bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FieldJob {
    pub vertices: u32,
    pub rays: u32,
    pub stack_count: u32,
    /// 1: the shadow weighs the first noise octave.
    pub first_octave: i32,
    pub stacks: [StackJob; MAX_STACKS],
}

const _: () = assert!(std::mem::size_of::<FieldJob>() == 16 + 48 * MAX_STACKS);

impl FieldJob {
    /// The job of every stack of `slices`, drawn with `cfg`, lit from
    /// `to_light`.
    pub fn new(slices: &CloudSlices, cfg: &SlicesConfig, to_light: Vec3) -> Self {
        let mut job = Self::zeroed();
        job.first_octave = cfg.shadow_octave as i32;
        for (k, s) in slices.stacks.iter().enumerate() {
            let g = &s.geometry;
            let first_vertex = job.vertices;
            job.vertices += g.vertices.len() as u32;
            let mut stack = StackJob {
                first_vertex,
                end_vertex: job.vertices,
                first_ray: job.rays,
                end_ray: job.rays,
                first_primitive: s.primitives.start as u32,
                end_primitive: s.primitives.end as u32,
                ..StackJob::zeroed()
            };
            if let Some(rays) = g.shadow_rays(cfg, to_light) {
                job.rays += rays.rays;
                stack.end_ray = job.rays;
                stack.ray_stride = rays.start_stride;
                stack.ray_offset = rays.start_offset;
                stack.vertex_step = rays.step;
                stack.ray_vertices = rays.count as i32;
                stack.shadow_step = rays.shadow_step;
            }
            job.stacks[k] = stack;
            job.stack_count = k as u32 + 1;
        }
        job
    }
}

/// Workgroups (x, y) covering `threads` one-dimensional invocations.
fn groups(threads: u32) -> (u32, u32) {
    let n = threads.div_ceil(WORKGROUP);
    (n.min(MAX_GROUPS_X), n.div_ceil(MAX_GROUPS_X))
}

/// The compute pass's pipelines and its group 1 (job and vertices).
pub struct FieldPass {
    layout: wgpu::BindGroupLayout,
    field: wgpu::ComputePipeline,
    shadow: wgpu::ComputePipeline,
    job: wgpu::Buffer,
    bind: Option<wgpu::BindGroup>,
    vertices: u32,
    rays: u32,
}

impl FieldPass {
    pub fn new(ctx: &GpuContext, layouts: &Layouts) -> Result<Self> {
        let device = &ctx.device;
        let layout = layouts.get(&FIELD_JOB);
        let (field, shadow) = crate::gpu::catching(device, "creating the slice_field pass", || {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("slice field"),
            source: wgpu::ShaderSource::Wgsl(SLICE_FIELD.source(&SLOTS).into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("slice field"),
            bind_group_layouts: &[
                Some(&layouts.get(&COMMON)),
                Some(&layout),
                None,
                Some(&layouts.get(&PRIMITIVES)),
            ],
            immediate_size: 0,
        });
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("slice field"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        (pipeline("cs_field"), pipeline("cs_shadow"))
        })?;
        let job = uniform_buffer(device, "slice field: job", std::mem::size_of::<FieldJob>());
        Ok(Self {
            layout,
            field,
            shadow,
            job,
            bind: None,
            vertices: 0,
            rays: 0,
        })
    }

    /// Writes the job of `frame` (whose vertices are in `vertices`; a new
    /// buffer when `rebind`).
    pub fn prepare(
        &mut self,
        ctx: &GpuContext,
        frame: &SlicesFrame,
        vertices: &wgpu::Buffer,
        rebind: bool,
    ) {
        let job = FieldJob::new(&frame.slices, &frame.cfg, frame.to_light);
        self.vertices = job.vertices;
        self.rays = job.rays;
        ctx.queue
            .write_buffer(&self.job, 0, bytemuck::bytes_of(&job));
        if rebind || self.bind.is_none() {
            self.bind = Some(ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("slice field: job and vertices"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.job.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: vertices.as_entire_binding(),
                    },
                ],
            }));
        }
    }

    /// Encodes both dispatches (the field, then the shadows along the rays).
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        common: &wgpu::BindGroup,
        slices: &wgpu::BindGroup,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        let Some(bind) = &self.bind else {
            return;
        };
        let mut cp = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("slice field"),
            timestamp_writes: timestamps.map(|(set, i)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            }),
        });
        cp.set_bind_group(0, common, &[]);
        cp.set_bind_group(1, bind, &[]);
        cp.set_bind_group(SLOT_GROUP, slices, &[]);
        for (pipeline, threads) in [(&self.field, self.vertices), (&self.shadow, self.rays)] {
            if threads == 0 {
                continue;
            }
            // The shadow walk reads the densities the field dispatch wrote:
            // dispatches in one pass are ordered for storage (WebGPU usage
            // scopes are per dispatch).
            let (x, y) = groups(threads);
            cp.set_pipeline(pipeline);
            cp.dispatch_workgroups(x, y, 1);
        }
    }
}
