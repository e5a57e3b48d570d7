//! GPU buffers of the slices passes: the planes' vertices and indices, the
//! octave transforms, the controls, and the primitives with their grid
//! index (group 2, shaders/slices/implicit.wgsl), grown as needed and reused.

use bytemuck::{Pod, Zeroable};

use super::SlicesFrame;
use super::gpu_field::FieldPass;
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::methods::slices::model::octaves::OctaveUniform;
use crate::methods::slices::model::slicing::SliceVertex;
use crate::methods::slices::model::{EllipsoidState, VertexField};

/// One primitive as the shaders take it: WGSL `struct Primitive` in
/// shaders/slices/implicit.wgsl (64 bytes; a test compares the layouts).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuPrimitive {
    /// The rows of [`EllipsoidState::unit_from_world`].
    pub row0: [f32; 3],
    pub strength: f32,
    pub row1: [f32; 3],
    /// Flat base altitude (−1e30 for none). units: m
    pub base_z_m: f32,
    pub row2: [f32; 3],
    pub _pad0: f32,
    /// units: m
    pub centre_m: [f32; 3],
    pub _pad1: f32,
}

const _: () = assert!(std::mem::size_of::<GpuPrimitive>() == 64);

impl GpuPrimitive {
    pub fn new(e: &EllipsoidState) -> Self {
        let m = e.unit_from_world().transpose();
        Self {
            row0: m.x_axis.to_array(),
            strength: e.strength,
            row1: m.y_axis.to_array(),
            base_z_m: e.base_z_m.max(-1.0e30),
            row2: m.z_axis.to_array(),
            _pad0: 0.0,
            centre_m: e.centre_m.to_array(),
            _pad1: 0.0,
        }
    }
}

/// A buffer of at least `bytes.len()` bytes holding `bytes`: the old one
/// when it is large enough, else a new one (true: the bind groups that
/// reference it must be rebuilt).
fn fill(
    ctx: &GpuContext,
    buf: &mut Option<wgpu::Buffer>,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
    label: &str,
) -> bool {
    let grown = buf.as_ref().is_none_or(|b| b.size() < bytes.len() as u64);
    if grown {
        *buf = Some(ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (bytes.len() as u64).max(16),
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
    }
    ctx.queue
        .write_buffer(buf.as_ref().expect("just made"), 0, bytes);
    grown
}

/// GPU buffers of the slices passes; see the module docs.
pub struct SlicesGpu {
    octaves: wgpu::Buffer,
    params: wgpu::Buffer,
    primitives: Option<wgpu::Buffer>,
    cells: Option<wgpu::Buffer>,
    /// Group 3 of the slices passes (None until the first upload).
    pub bind: Option<wgpu::BindGroup>,
    vertices: Option<wgpu::Buffer>,
    indices: Option<wgpu::Buffer>,
    /// Indices of the last uploaded frame.
    pub index_count: u32,
    /// Primitives (ellipsoids and parcel spheres) of the last frame.
    pub primitives_drawn: u32,
    /// The compute pass of `vertex_field = "gpu"`, made at its first use
    /// (or ahead of it: [`SlicesGpu::make_field_pass`]).
    field: Option<FieldPass>,
    /// Pipelines the field pass creations compiled (2 each).
    pub field_pipelines: u32,
    /// The last frame's vertices await the compute pass.
    field_pending: bool,
}

impl SlicesGpu {
    pub fn new(device: &wgpu::Device) -> Self {
        let uniform = |label, size| crate::gpu::layouts::uniform_buffer(device, label, size);
        Self {
            octaves: uniform("slices: octaves", std::mem::size_of::<OctaveUniform>()),
            params: uniform(
                "slices: controls",
                std::mem::size_of::<super::SlicesParams>(),
            ),
            primitives: None,
            cells: None,
            bind: None,
            vertices: None,
            indices: None,
            index_count: 0,
            primitives_drawn: 0,
            field: None,
            field_pipelines: 0,
            field_pending: false,
        }
    }

    /// Uploads a frame, growing the buffers when it needs more room (never
    /// shrinking them: a frame rarely needs less for long). A frame whose
    /// vertices carry no values (`values_on_cpu` false) is given them by
    /// the compute pass ([`Self::encode_field`]), whose pipelines are made
    /// here the first time.
    pub fn upload(
        &mut self,
        ctx: &GpuContext,
        layouts: &crate::gpu::layouts::Layouts,
        frame: &SlicesFrame,
        mode: VertexField,
    ) -> Result<()> {
        let q = &ctx.queue;
        q.write_buffer(&self.octaves, 0, bytemuck::bytes_of(&frame.octaves));
        q.write_buffer(&self.params, 0, bytemuck::bytes_of(&frame.params));
        let vertices = frame.slices.vertices();
        let indices = frame.slices.indices(frame.values_on_cpu);
        self.primitives_drawn = frame.slices.states.len() as u32;
        self.index_count = indices.len() as u32;
        let storage = wgpu::BufferUsages::STORAGE;
        let packed: Vec<GpuPrimitive> = frame.slices.states.iter().map(GpuPrimitive::new).collect();
        let mut rebind = fill(
            ctx,
            &mut self.primitives,
            bytemuck::cast_slice(&packed),
            storage,
            "slices: primitives",
        );
        rebind |= fill(
            ctx,
            &mut self.cells,
            bytemuck::cast_slice(&frame.index.lists),
            storage,
            "slices: primitive index",
        );
        if rebind || self.bind.is_none() {
            self.bind = Some(self.make_bind(&ctx.device, &layouts.get(&super::passes::PRIMITIVES)));
        }
        self.field_pending = false;
        if indices.is_empty() {
            return Ok(());
        }
        let vertices_grown = fill(
            ctx,
            &mut self.vertices,
            bytemuck::cast_slice::<SliceVertex, u8>(&vertices),
            wgpu::BufferUsages::VERTEX | storage | wgpu::BufferUsages::COPY_SRC,
            "slices: vertices",
        );
        fill(
            ctx,
            &mut self.indices,
            bytemuck::cast_slice::<u32, u8>(&indices),
            wgpu::BufferUsages::INDEX,
            "slices: indices",
        );
        if !frame.values_on_cpu && mode == VertexField::Gpu {
            self.make_field_pass(ctx, layouts)?;
            let vertices = self.vertices.as_ref().expect("filled above");
            let pass = self.field.as_mut().expect("made above");
            pass.prepare(ctx, frame, vertices, vertices_grown);
            self.field_pending = true;
        }
        Ok(())
    }

    /// Creates the vertex field's compute pass unless it exists: two
    /// pipelines, compiled on the calling thread.
    pub fn make_field_pass(
        &mut self,
        ctx: &GpuContext,
        layouts: &crate::gpu::layouts::Layouts,
    ) -> Result<()> {
        if self.field.is_none() {
            self.field = Some(FieldPass::new(ctx, layouts)?);
            self.field_pipelines += 2;
        }
        Ok(())
    }

    fn make_bind(&self, device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        fn buf(b: &Option<wgpu::Buffer>) -> wgpu::BindingResource<'_> {
            b.as_ref()
                .expect("filled before binding")
                .as_entire_binding()
        }
        let resources = [
            self.octaves.as_entire_binding(),
            self.params.as_entire_binding(),
            buf(&self.primitives),
            buf(&self.cells),
        ];
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("slices: octaves, controls, primitives"),
            layout,
            entries: &resources
                .into_iter()
                .enumerate()
                .map(|(i, resource)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource,
                })
                .collect::<Vec<_>>(),
        })
    }

    /// Whether the last upload left the vertex values to the compute pass.
    pub fn field_pending(&self) -> bool {
        self.field_pending
    }

    /// Encodes the compute pass of the vertex field and shadow (group 0:
    /// `common`); nothing when the last upload did not ask for it.
    pub fn encode_field(
        &self,
        enc: &mut wgpu::CommandEncoder,
        common: &wgpu::BindGroup,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        if let (true, Some(pass), Some(bind)) = (self.field_pending, &self.field, &self.bind) {
            pass.encode(enc, common, bind, timestamps);
        }
    }

    /// The vertex buffer's contents (tests compare the compute pass with
    /// the CPU): the first `count` vertices.
    pub fn read_vertices(&self, ctx: &GpuContext, count: usize) -> Result<Vec<SliceVertex>> {
        let Some(v) = &self.vertices else {
            return Ok(Vec::new());
        };
        let size = (count * std::mem::size_of::<SliceVertex>()) as u64;
        let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("slices: vertex readback"),
            size: size.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(v, 0, &staging, 0, size);
        ctx.queue.submit([enc.finish()]);
        let bytes = crate::gpu::timing::read_buffer(ctx, &staging, size)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// Draws the uploaded planes (pipeline and groups 0–1 already set):
    /// one draw, the stacks one after the other in the index buffer, so
    /// the clouds blend back to front as their planes do.
    pub fn draw(&self, rp: &mut wgpu::RenderPass<'_>) {
        let (Some(v), Some(i), Some(bind)) = (&self.vertices, &self.indices, &self.bind) else {
            return;
        };
        if self.index_count == 0 {
            return;
        }
        rp.set_bind_group(crate::gpu::pass::SLOT_GROUP, bind, &[]);
        rp.set_vertex_buffer(0, v.slice(..));
        rp.set_index_buffer(i.slice(..), wgpu::IndexFormat::Uint32);
        rp.draw_indexed(0..self.index_count, 0, 0..1);
    }
}
