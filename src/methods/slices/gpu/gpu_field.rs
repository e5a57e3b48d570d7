//! The slice vertices' field and shadow in a compute pass (`[render.slices]
//! vertex_field = "gpu"`, shaders/slices/vertex_field.wgsl): one dispatch
//! evaluates the Wyvill sum at every vertex, a second walks every light
//! ray of [`ShadowRays`] accumulating eq. 2, both into the vertex buffer
//! the planes are then drawn from. The CPU's `SliceGeometry::evaluate` is
//! the reference it is tested against. Its pipelines are made at the first
//! frame that asks for them, never when the CPU evaluates the vertices.

use bytemuck::{Pod, Zeroable};

use super::SlicesFrame;
use super::passes::{FIELD_JOB, PRIMITIVES, SLICE_FIELD, SLOTS};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::gpu::layouts::{COMMON, Layouts, uniform_buffer};
use crate::gpu::pass::SLOT_GROUP;
use crate::methods::slices::model::slicing::ShadowRays;

/// Threads per workgroup of both entry points (`@workgroup_size(64)`).
const WORKGROUP: u32 = 64;
/// Most workgroups along x (WebGPU's minimum limit); more go along y.
const MAX_GROUPS_X: u32 = 65535;

/// WGSL `struct FieldJob` in shaders/slices/vertex_field.wgsl (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FieldJob {
    pub vertices: u32,
    pub rays: u32,
    /// Vertex index stride between ray starts.
    pub ray_stride: u32,
    /// Vertex index of the first ray's start.
    pub ray_offset: u32,
    /// Vertex index step along a ray.
    pub vertex_step: i32,
    /// Vertices per ray.
    pub ray_vertices: i32,
    /// 1: the shadow weighs the first noise octave.
    pub first_octave: i32,
    /// units: m
    pub shadow_step: f32,
}

const _: () = assert!(std::mem::size_of::<FieldJob>() == 32);

impl FieldJob {
    pub fn new(vertices: u32, rays: &ShadowRays, shadow_octave: bool) -> Self {
        Self {
            vertices,
            rays: rays.rays,
            ray_stride: rays.start_stride,
            ray_offset: rays.start_offset,
            vertex_step: rays.step,
            ray_vertices: rays.count as i32,
            first_octave: shadow_octave as i32,
            shadow_step: rays.shadow_step,
        }
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
        let g = &frame.geometry;
        self.vertices = g.vertices.len() as u32;
        self.rays = 0;
        if let Some(rays) = g.shadow_rays(&frame.cfg, frame.to_light) {
            self.rays = rays.rays;
            let job = FieldJob::new(self.vertices, &rays, frame.cfg.shadow_octave);
            ctx.queue
                .write_buffer(&self.job, 0, bytemuck::bytes_of(&job));
        }
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
