//! The `baked` method's GPU data and its compute bake (shaders/raymarch/bake.wgsl):
//! the condensed parcels go up in one read-only storage buffer (any count:
//! one splat dispatch for all of them, in workgroup rows of [`SPLAT_ROW`]),
//! are splatted
//! into a 3D texture of the macro field M = max f·(d+1) − 1 over the
//! levels of a camera-centred clipmap ([`super::clipmap`]: the condensed
//! parcels' box when it fits, else nested levels at 2× voxel steps), and
//! a coarse occupancy pyramid per level (one cell per [`BAKE_BLOCK`]³
//! voxels at its foot) lets the march skip empty space. A light volume,
//! its own 3D texture ([`LIGHT_FORMAT`]) with one texel per coarse cell,
//! holds the optical depth of the parcels toward the sun and straight up
//! over the region's whole height (bake.wgsl `light`); the march samples it
//! with the filtering sampler, so a sample's shadowing and sky visibility
//! cost one hardware-trilinear fetch. (The ground's shadows march the baked
//! field itself, density.wgsl `ground_sun_depth`: the volume's coarse cells
//! would widen them by about a cell.)
//! The bake runs only when the parcels, the shell or the sun changed since
//! the last one: a paused scene never re-bakes.
//!
//! The splat's own work, parcels × box voxels, is what grows with the
//! parcel count. `light` writes the volume as a coarse texture of its own
//! and the sampler filters it where it is read; `resolve` writes only
//! (v, plane). The variants measured against this layout (a gather per
//! brick, a resolve limited to the touched bricks, the light volume
//! upsampled into the field texture) are in docs/notes.md, "Baked field".
//!
//! Voxel size. The macro field is piecewise linear: it rises from −1 to f
//! over two shells across a sphere's surface and over two plane shells
//! (`PLANE_SHELL`·shell, 84 m by default) across the flat base, and is
//! constant inside; trilinear filtering reproduces it except at the creases
//! (union seams, the base). So the voxel is the smaller of a quarter of the
//! median drawn radius (≥ 4 voxels per radius keep the domes round) and one
//! plane shell (the base stays sharp to about one plane shell), rounded to
//! a power of 2^¼ so small radius changes do not reallocate the texture.
//!
//! Memory. The field costs [`BYTES_PER_VOXEL`] bytes a voxel (RGBA16F
//! texture + one u32 key; the light volume's 8 B a coarse cell,
//! ⅛ B a voxel, are left out), at most [`MAX_BAKE_VOXELS`] voxels over all
//! the levels (768 MiB of field): a box that does not fit at the wanted
//! voxel is split into camera-centred levels, and only when no level count
//! fits does the finest voxel grow, counted in [`BakeInfo::coarsened`] and
//! shown by the front ends.

use glam::Vec3;

use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::methods::raymarch::bake_gpu::{
    CLIP_ENTRIES, FRAME_ENTRIES, JOB_ENTRIES, occupancy_buffer, parcel_buffer, pyramid_dispatch,
    source, splat_workgroups, volume_texture,
};
use crate::gpu::uniform::GridInfo;
use crate::methods::raymarch::clipmap::{ClipUniform, Clipmap, clipmap};
use crate::methods::raymarch::pack::{self, GpuParcel};
use crate::physics::CloudParcel;

pub use crate::methods::raymarch::bake_gpu::requirement;
pub use crate::methods::raymarch::bake_info::BakeInfo;
pub use crate::methods::raymarch::clipmap::MAX_BAKE_VOXELS;

/// Voxels per coarse occupancy cell along each axis: BAKE_BLOCK of
/// shaders/raymarch/bake.wgsl (a test compares them).
pub const BAKE_BLOCK: u32 = 4;
/// Keys in the splat's first key buffer (128 MiB, the binding size many
/// devices allow at most); the rest go in a second: KEY_SPLIT of
/// shaders/raymarch/bake.wgsl (a test compares them).
pub const KEY_SPLIT: u64 = 1 << 25;
/// Field texture (RGBA16F, 8 B) + the splat's key (4 B).
pub const BYTES_PER_VOXEL: u64 = 12;
/// Format of the field texture: R = v, G = condensation plane (m); B and A
/// are unused (the smallest format that compute shaders may write and the
/// sampler may filter without optional features: RG16F is neither
/// storage-writable in core WebGPU nor RG32F filterable).
pub const FIELD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Format of the light volume, one texel per coarse cell: R, G, B = optical
/// depth (density × m) toward the sun, straight up and away from the sun;
/// A unused. RGBA16F
/// for the same reason as [`FIELD_FORMAT`]; half floats hold depths up to
/// 65504 (a 60 km path through solid cloud) to 3 significant digits.
pub const LIGHT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Plane shell over sphere shell: PLANE_SHELL of
/// shaders/raymarch/parcel.wgsl (a test compares them).
pub const PLANE_SHELL: f32 = 0.3;
/// Levels of the occupancy pyramid and cells of a level per cell of the
/// level above: OCCUPANCY_LEVELS and OCCUPANCY_FACTOR of
/// shaders/raymarch/occupancy.wgsl (a test compares them). Three levels of
/// 4: cells of 4³, 16³ and 64³ voxels (at 84 m voxels, 5.4 km for the top).
/// The bake's resolve writes level 0; its entry points `pyramid1` and
/// `pyramid2` build the two above, one thread per cell.
pub const OCCUPANCY_LEVELS: u32 = 3;
pub const OCCUPANCY_FACTOR: u32 = 4;

/// Cells of the whole occupancy pyramid over a level-0 grid of `cells`
/// (occupancy.wgsl's layout: the levels one after the other).
pub fn occupancy_cells(cells: [u32; 3]) -> u64 {
    let mut d = cells;
    let mut total = 0u64;
    for _ in 0..OCCUPANCY_LEVELS {
        total += d.iter().map(|&c| c as u64).product::<u64>();
        d = d.map(|c| c.div_ceil(OCCUPANCY_FACTOR));
    }
    total
}

/// Workgroups per row of the splat's dispatch (one workgroup a parcel;
/// rows along y): SPLAT_ROW of shaders/raymarch/bake.wgsl (a test compares
/// them). Under the 65535 per dimension every device allows.
pub const SPLAT_ROW: u32 = 32768;
pub(super) const PARCEL_BYTES: u64 = std::mem::size_of::<GpuParcel>() as u64;


struct Store {
    /// The levels it holds (their sizes set the dispatches).
    map: Clipmap,
    /// The splat's per-voxel keys (the first [`KEY_SPLIT`], the rest),
    /// kept alive for the bind group.
    _keys: [wgpu::Buffer; 2],
    occupancy: wgpu::Buffer,
    /// The light volume, one texel per coarse cell.
    light_view: wgpu::TextureView,
    view: wgpu::TextureView,
    bind: wgpu::BindGroup,
}

/// The baked field; see the module docs.
pub struct BakedField {
    layout: wgpu::BindGroupLayout,
    bind_frame: wgpu::BindGroup,
    splat: wgpu::ComputePipeline,
    light: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    /// Levels 1 and 2 of the occupancy pyramid, each from the one below.
    pyramid: [wgpu::ComputePipeline; OCCUPANCY_LEVELS as usize - 1],
    /// The condensed parcels (read-only storage), room for `capacity`.
    parcels: wgpu::Buffer,
    capacity: u64,
    store: Option<Store>,
    /// Placeholder field (1 voxel, v = −1), light volume (1 cell, no
    /// cloud) and occupancy before any bake.
    empty_view: wgpu::TextureView,
    empty_light_view: wgpu::TextureView,
    empty_occupancy: wgpu::Buffer,
    /// The clipmap's levels as the shaders read them (group 3, binding 3
    /// of the bake and of the march).
    clip_buf: wgpu::Buffer,
    clip_bind: wgpu::BindGroup,
    /// Parcels, shell and sun direction of the last bake (re-bake only when
    /// they change).
    last: Option<(Vec<GpuParcel>, f32, Vec3)>,
    /// The levels of the last bake (re-bake when the camera moves them).
    map: Option<Clipmap>,
    parcel_count: u32,
    dirty: bool,
    info: BakeInfo,
    /// Bumped whenever the field texture or occupancy buffer is replaced
    /// (the renderer then rebinds them).
    pub generation: u64,
}


impl BakedField {
    /// The bake's pipelines (counted in `built`) over the frame uniform.
    pub fn new(ctx: &GpuContext, frame_buf: &wgpu::Buffer, built: &mut u32) -> Result<Self> {
        let device = &ctx.device;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake: frame"),
            entries: FRAME_ENTRIES,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake: parcels and field"),
            entries: JOB_ENTRIES,
        });
        let bind_frame = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake: frame"),
            layout: &frame_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame_buf.as_entire_binding(),
            }],
        });
        let clip_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake: clipmap"),
            entries: CLIP_ENTRIES,
        });
        let clip_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bake: clipmap levels"),
            size: std::mem::size_of::<ClipUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let clip_bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake: clipmap"),
            layout: &clip_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 3,
                resource: clip_buf.as_entire_binding(),
            }],
        });
        let source = source().map_err(|e| Error::Gpu(format!("assembling the bake: {e}")))?;
        let (splat, light, resolve, pyramid) = crate::gpu::catching(device, "creating the bake pipelines", || {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bake"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bake"),
            bind_group_layouts: &[Some(&frame_layout), Some(&layout), None, Some(&clip_layout)],
            immediate_size: 0,
        });
        let compute = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        (
            compute("splat"),
            compute("light"),
            compute("resolve"),
            [compute("pyramid1"), compute("pyramid2")],
        )
        })?;
        *built += 5;
        let empty = volume_texture(device, "baked macro field", FIELD_FORMAT, [1, 1, 1]);
        // IEEE half-precision −1 (v far from every parcel), then G, B, A = 0.
        // (The empty light volume keeps wgpu's zero fill: no cloud.)
        let minus_one: [u16; 4] = [0xBC00, 0, 0, 0];
        ctx.queue.write_texture(
            empty.as_image_copy(),
            bytemuck::cast_slice(&minus_one),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(8),
                rows_per_image: Some(1),
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
        Ok(Self {
            layout,
            bind_frame,
            splat,
            light,
            resolve,
            pyramid,
            parcels: parcel_buffer(device, 1),
            capacity: 1,
            store: None,
            empty_view: empty.create_view(&Default::default()),
            empty_light_view: volume_texture(device, "bake: light volume", LIGHT_FORMAT, [1, 1, 1])
                .create_view(&Default::default()),
            empty_occupancy: occupancy_buffer(device, 1),
            clip_buf,
            clip_bind,
            last: None,
            map: None,
            parcel_count: 0,
            dirty: false,
            info: BakeInfo::default(),
            generation: 0,
        })
    }

    /// The field texture, light volume, occupancy buffer and clipmap
    /// uniform the march reads.
    pub fn field(&self) -> (&wgpu::TextureView, &wgpu::TextureView, &wgpu::Buffer, &wgpu::Buffer) {
        match &self.store {
            Some(s) => (&s.view, &s.light_view, &s.occupancy, &self.clip_buf),
            None => (
                &self.empty_view,
                &self.empty_light_view,
                &self.empty_occupancy,
                &self.clip_buf,
            ),
        }
    }

    /// The levels of the last bake (None before any).
    pub fn clipmap(&self) -> Option<&Clipmap> {
        self.map.as_ref().filter(|_| self.parcel_count > 0)
    }

    /// What the last bake covered.
    pub fn info(&self) -> BakeInfo {
        self.info
    }

    /// Bakes again at the next `render` even if nothing moved (the bench
    /// measures the cost of a frame whose parcels all moved).
    pub fn invalidate(&mut self) {
        if self.store.is_some() && self.parcel_count > 0 {
            self.dirty = true;
        }
    }

    /// Whether `render` must bake before marching.
    pub fn dirty(&self) -> bool {
        self.dirty
    }

    /// Takes this frame's parcels: when they (or the shell, or the sun
    /// direction `sun`, or the clipmap's levels around the `camera`)
    /// changed since the last bake, uploads them and marks the field for a
    /// bake. Returns the coarse grid the march uses (the frame's grid: the
    /// clipmap's last level, the whole box).
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        parcels: &[CloudParcel],
        shell_m: f32,
        radius_scale: f32,
        sun: Vec3,
        camera: Vec3,
    ) -> Result<GridInfo> {
        let live = pack::gpu_parcels(parcels, shell_m, radius_scale)?;
        let map = (!live.is_empty()).then(|| clipmap(&live, shell_m, camera));
        let unchanged = self.map == map
            && self
                .last
                .as_ref()
                .is_some_and(|(p, s, d)| *s == shell_m && *d == sun && *p == live);
        if !unchanged {
            self.upload(ctx, &live, map)?;
            self.last = Some((live, shell_m, sun));
        }
        Ok(self.grid_info())
    }

    fn grid_info(&self) -> GridInfo {
        match self.clipmap() {
            Some(m) => {
                let top = m.top();
                GridInfo {
                    min: top.min,
                    cell: Vec3::splat(top.cell_m()),
                    dims: top.cells,
                    parcel_count: self.parcel_count,
                    entry_count: 0,
                    coarsened: m.coarsened,
                }
            }
            None => GridInfo::EMPTY,
        }
    }

    fn upload(&mut self, ctx: &GpuContext, live: &[GpuParcel], map: Option<Clipmap>) -> Result<()> {
        self.parcel_count = live.len() as u32;
        self.map = map;
        let Some(map) = self.map.clone() else {
            self.dirty = false;
            return Ok(());
        };
        let device = &ctx.device;
        let dims = map.stacked_dims();
        let finest = map.levels[0].voxel_m;
        let max3 = device.limits().max_texture_dimension_3d;
        if dims.iter().any(|&d| d > max3) {
            return Err(Error::Gpu(format!(
                "the baked cloud field needs {}×{}×{} voxels (finest {:.0} m, {} levels stacked), more than this device's 3D texture limit of {max3} per side",
                dims[0], dims[1], dims[2], finest, map.levels.len()
            )));
        }
        let n = live.len() as u64;
        if n > self.capacity {
            // Room to grow by half again before the next reallocation.
            self.capacity = n + n / 2;
            self.parcels = parcel_buffer(device, self.capacity);
            self.store = None;
        }
        ctx.queue
            .write_buffer(&self.parcels, 0, bytemuck::cast_slice(live));
        ctx.queue
            .write_buffer(&self.clip_buf, 0, bytemuck::bytes_of(&map.uniform()));
        // A new texture when the stacked sizes or the buffers' offsets
        // change (the levels' positions alone are in the uniform).
        let same = |s: &Store| {
            s.map.stacked_dims() == dims
                && s.map.voxels() == map.voxels()
                && s.map.occupancy_cells() == map.occupancy_cells()
        };
        if !self.store.as_ref().is_some_and(same) {
            self.store = Some(self.make_store(device, &map));
            self.generation += 1;
        } else if let Some(s) = self.store.as_mut() {
            s.map = map.clone();
        }
        self.dirty = true;
        self.info = BakeInfo {
            voxel_m: finest,
            levels: map.levels.len() as u32,
            wanted_voxel_m: map.wanted_voxel_m,
            coarsened: map.coarsened,
            dims,
            bytes: map.voxels() * BYTES_PER_VOXEL,
            bakes: self.info.bakes,
        };
        Ok(())
    }

    fn make_store(&self, device: &wgpu::Device, map: &Clipmap) -> Store {
        let n = map.voxels();
        let keys = [n.min(KEY_SPLIT), n.saturating_sub(KEY_SPLIT)].map(|k| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("bake: voxel keys"),
                size: 4 * k.max(1),
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        });
        let occupancy = occupancy_buffer(device, map.occupancy_cells());
        let light_view =
            volume_texture(device, "bake: light volume", LIGHT_FORMAT, map.stacked_cells())
                .create_view(&Default::default());
        let dims = map.stacked_dims();
        let view = volume_texture(device, "baked macro field", FIELD_FORMAT, dims)
            .create_view(&Default::default());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake: parcels and field"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.parcels.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: keys[0].as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: occupancy.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::TextureView(&light_view),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: keys[1].as_entire_binding(),
                },
            ],
        });
        Store {
            map: map.clone(),
            _keys: keys,
            occupancy,
            light_view,
            view,
            bind,
        }
    }

    /// Encodes the bake (one splat dispatch for every parcel, then the
    /// light volume and resolve) when the parcels changed; `timestamps` =
    /// (query set, first index) times it as one pass.
    pub fn encode(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        let Some(store) = self.store.as_ref().filter(|_| self.dirty) else {
            return;
        };
        enc.clear_buffer(&store.occupancy, 0, None);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bake: splat"),
            timestamp_writes: timestamps.map(|(set, i)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: None,
            }),
        });
        pass.set_pipeline(&self.splat);
        pass.set_bind_group(0, &self.bind_frame, &[]);
        pass.set_bind_group(1, &store.bind, &[]);
        pass.set_bind_group(3, &self.clip_bind, &[]);
        let [x, y] = splat_workgroups(self.parcel_count);
        pass.dispatch_workgroups(x, y, store.map.levels.len() as u32);
        drop(pass);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bake: resolve"),
            timestamp_writes: timestamps.map(|(set, i)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: None,
                end_of_pass_write_index: Some(i + 1),
            }),
        });
        pass.set_bind_group(0, &self.bind_frame, &[]);
        pass.set_bind_group(1, &store.bind, &[]);
        pass.set_bind_group(3, &self.clip_bind, &[]);
        // The light volume reads the splat's accumulators before resolve
        // clears them (wgpu orders the two dispatches); resolve does not
        // read it.
        pass.set_pipeline(&self.light);
        let c = store.map.stacked_cells();
        pass.dispatch_workgroups(c[0].div_ceil(4), c[1].div_ceil(4), c[2].div_ceil(4));
        pass.set_pipeline(&self.resolve);
        let d = store.map.stacked_dims();
        pass.dispatch_workgroups(d[0] / 4, d[1] / 4, d[2] / 4);
        // The pyramids' upper levels, each from the finished level below
        // (wgpu orders the dispatches).
        for (i, pipeline) in self.pyramid.iter().enumerate() {
            let [x, y, z] = pyramid_dispatch(&store.map, i as u32 + 1);
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(x, y, z);
        }
        drop(pass);
        self.dirty = false;
        self.info.bakes += 1;
    }
}
