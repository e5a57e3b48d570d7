//! The `baked` method's GPU data and its compute bake (shaders/bake.wgsl):
//! the condensed parcels go up in a read-only storage buffer, are binned on
//! the CPU into the bricks ([`BAKE_BLOCK`]³ voxels) their boxes overlap, and
//! one workgroup per touched brick gathers the macro field M = max f·(d+1)
//! − 1 from that brick's list into a 3D texture over the region of the
//! condensed parcels; a coarse occupancy grid (one cell per brick) lets the
//! march skip empty space. Bricks no parcel touches are never visited (they
//! hold v = −1 from the texture's clear, or from the bake that emptied
//! them). The bake runs only when the parcels (or the shell) changed since
//! the last one: a paused scene never re-bakes.
//!
//! Why a gather from CPU-binned lists instead of a splat of uniform-buffer
//! chunks with atomic max (the first version): the splat had every parcel
//! atomic-max its whole box and then a resolve pass visit every voxel of
//! the region (up to [`MAX_BAKE_VOXELS`]) each bake, so the bake grew with
//! the region even where it was empty; on llvmpipe it dominated the frame at
//! 4096 parcels. A brick's list indexes parcels of any chunk, so the parcels
//! are a storage buffer; the threads of a brick still all read the same
//! parcel at a time (broadcast).
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
//! Memory. The field costs [`BYTES_PER_VOXEL`] bytes a voxel (the RGBA16F
//! texture; the lists are a few bytes per parcel and brick), at most [`MAX_BAKE_VOXELS`] voxels
//! (128 MiB of field): a larger region (a 40 km × 40 km × 12 km landscape
//! needs ~2.4·10⁷ voxels at 84 m) gets coarser voxels, counted in
//! [`BakeInfo::coarsened`] and shown by the front ends.

use glam::Vec3;

use crate::error::{Error, Result};
use crate::physics::CloudParcel;
use crate::render::gpu::GpuContext;
use crate::render::pack::{self, GpuParcel, GridInfo};

/// Voxels per coarse occupancy cell along each axis. Keep in sync with
/// BAKE_BLOCK in shaders/bake.wgsl.
pub const BAKE_BLOCK: u32 = 4;
/// Most voxels of the baked field.
pub const MAX_BAKE_VOXELS: u64 = 1 << 23;
/// Field texture (RGBA16F).
pub const BYTES_PER_VOXEL: u64 = 8;
/// Workgroups per row of the gather dispatch (under the 65 535 limit).
/// Keep in sync with GATHER_ROW in shaders/bake.wgsl.
const GATHER_ROW: u32 = 32768;
/// Format of the field texture: R = v, G = condensation plane (m).
pub const FIELD_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Plane shell over sphere shell. Keep in sync with PLANE_SHELL in
/// shaders/parcel.wgsl.
pub const PLANE_SHELL: f32 = 0.3;

/// What the last bake covered.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BakeInfo {
    /// Voxel side. units: m
    pub voxel_m: f32,
    /// Voxel side the radii asked for, before the memory cap. units: m
    pub wanted_voxel_m: f32,
    /// How many times the voxel was enlarged to fit [`MAX_BAKE_VOXELS`].
    pub coarsened: u32,
    /// Voxels per axis.
    pub dims: [u32; 3],
    /// GPU memory of the field. units: bytes
    pub bytes: u64,
    /// Bakes run so far (a bake runs only when parcels moved).
    pub bakes: u64,
}

/// Layout of the bake: where the region sits and how it is divided.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Region {
    min: Vec3,
    voxel_m: f32,
    /// Coarse cells per axis (voxels = cells × BAKE_BLOCK).
    cells: [u32; 3],
    wanted_voxel_m: f32,
    coarsened: u32,
}

impl Region {
    fn voxel_dims(&self) -> [u32; 3] {
        self.cells.map(|c| c * BAKE_BLOCK)
    }

    fn voxels(&self) -> u64 {
        self.voxel_dims().iter().map(|&d| d as u64).product()
    }
}

/// The bricks a bake visits and their parcel lists.
#[derive(Debug, Clone, Default, PartialEq)]
struct Bins {
    /// Header (brick count) then per brick: index, list start, list
    /// length, 0. The layout of `bricks` in shaders/bake.wgsl.
    bricks: Vec<[u32; 4]>,
    /// Parcel indices, brick after brick.
    lists: Vec<u32>,
    /// Bricks with a non-empty list (the next bake empties those it drops).
    active: Vec<u32>,
}

/// Bins `live` into the bricks of `r` that each parcel's voxel box (the
/// voxels whose centres its sphere or plane shell can reach, as the field
/// is evaluated there, plus one voxel all round so every voxel a filtered
/// fetch near cloud reads is rewritten) overlaps; `previous` bricks that
/// no parcel touches now get an empty list, so the gather writes v = −1
/// there. Counting sort: O(parcels × bricks each + bricks of the region).
fn bin(live: &[GpuParcel], r: &Region, shell_m: f32, previous: &[u32]) -> Bins {
    let cells = r.cells;
    let dims = r.voxel_dims();
    let n_bricks = cells.iter().map(|&c| c as usize).product::<usize>();
    let brick_range = |p: &GpuParcel| {
        let c = Vec3::from_slice(&p.center_radius[..3]);
        let reach = p.center_radius[3] + shell_m;
        let mut lo = c - Vec3::splat(reach);
        let hi = c + Vec3::splat(reach);
        lo.z = lo.z.max(p.fill_plane[1] - PLANE_SHELL * shell_m).min(hi.z);
        let a = ((lo - r.min) / r.voxel_m - Vec3::splat(0.5)).floor() - Vec3::ONE;
        let b = ((hi - r.min) / r.voxel_m - Vec3::splat(0.5)).ceil() + Vec3::ONE;
        let clamp = |v: f32, a: usize| (v.max(0.0) as u32).min(dims[a] - 1) / BAKE_BLOCK;
        (
            [clamp(a.x, 0), clamp(a.y, 1), clamp(a.z, 2)],
            [clamp(b.x, 0), clamp(b.y, 1), clamp(b.z, 2)],
        )
    };
    // Calls `f(parcel, brick)` for every brick each parcel's box overlaps.
    let visit = |f: &mut dyn FnMut(u32, usize)| {
        for (i, p) in live.iter().enumerate() {
            let (a, b) = brick_range(p);
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        f(i as u32, (x + cells[0] * (y + cells[1] * z)) as usize);
                    }
                }
            }
        }
    };
    let mut count = vec![0u32; n_bricks];
    visit(&mut |_, k| count[k] += 1);
    let mut start = vec![0u32; n_bricks];
    let mut total = 0u32;
    for k in 0..n_bricks {
        start[k] = total;
        total += count[k];
    }
    let mut lists = vec![0u32; total as usize];
    let mut fill = start.clone();
    visit(&mut |i, k| {
        lists[fill[k] as usize] = i;
        fill[k] += 1;
    });
    let active: Vec<u32> = (0..n_bricks as u32).filter(|&k| count[k as usize] > 0).collect();
    let mut bricks = vec![[0u32; 4]];
    bricks.extend(active.iter().map(|&k| [k, start[k as usize], count[k as usize], 0]));
    bricks.extend(
        previous
            .iter()
            .filter(|&&k| (k as usize) < n_bricks && count[k as usize] == 0)
            .map(|&k| [k, 0, 0, 0]),
    );
    bricks[0][0] = (bricks.len() - 1) as u32;
    Bins {
        bricks,
        lists,
        active,
    }
}

/// Region and voxel size for `live` parcels (not empty), see the module docs.
fn region(live: &[GpuParcel], shell_m: f32) -> Region {
    let mut radii: Vec<f32> = live.iter().map(|p| p.center_radius[3]).collect();
    radii.sort_by(f32::total_cmp);
    let median = radii[radii.len() / 2];
    let raw = (0.25 * median).min(PLANE_SHELL * shell_m).max(1.0);
    let wanted = 2f32.powf((raw.log2() * 4.0).round() / 4.0);
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for p in live {
        let c = Vec3::from_slice(&p.center_radius[..3]);
        let reach = p.center_radius[3] + shell_m;
        let mut a = c - Vec3::splat(reach);
        let b = c + Vec3::splat(reach);
        a.z = a.z.max(p.fill_plane[1] - PLANE_SHELL * shell_m).min(b.z);
        lo = lo.min(a);
        hi = hi.max(b);
    }
    let mut voxel_m = wanted;
    let mut coarsened = 0;
    loop {
        // One empty voxel of padding all round: outside the region the
        // clamped texture then reads v = −1, as far from every parcel.
        let min = lo - Vec3::splat(voxel_m);
        let ext = hi - lo + Vec3::splat(2.0 * voxel_m);
        let cell = voxel_m * BAKE_BLOCK as f32;
        let cells = [0, 1, 2].map(|a| ((ext[a] / cell).ceil() as u32).max(1));
        let r = Region {
            min,
            voxel_m,
            cells,
            wanted_voxel_m: wanted,
            coarsened,
        };
        if r.voxels() <= MAX_BAKE_VOXELS {
            return r;
        }
        voxel_m *= (r.voxels() as f64 / MAX_BAKE_VOXELS as f64)
            .cbrt()
            .max(1.01) as f32;
        coarsened += 1;
    }
}

struct Store {
    dims: [u32; 3],
    occupancy: wgpu::Buffer,
    view: wgpu::TextureView,
    /// The texture is new: the next bake clears every voxel first.
    fresh: bool,
}

/// A storage buffer that grows (to the next power of two) when a bake needs
/// more than it holds.
struct Growing {
    label: &'static str,
    buffer: wgpu::Buffer,
}

impl Growing {
    fn new(device: &wgpu::Device, label: &'static str) -> Self {
        Self {
            label,
            buffer: Self::make(device, label, 256),
        }
    }

    fn make(device: &wgpu::Device, label: &'static str, size: u64) -> wgpu::Buffer {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// Writes `data`; returns whether the buffer was replaced.
    fn write(&mut self, ctx: &GpuContext, data: &[u8]) -> bool {
        let need = (data.len() as u64).max(16);
        let grown = need > self.buffer.size();
        if grown {
            self.buffer = Self::make(&ctx.device, self.label, need.next_power_of_two());
        }
        ctx.queue.write_buffer(&self.buffer, 0, data);
        grown
    }
}

/// The baked field; see the module docs.
pub struct BakedField {
    layout: wgpu::BindGroupLayout,
    bind_frame: wgpu::BindGroup,
    gather: wgpu::ComputePipeline,
    clear: wgpu::ComputePipeline,
    parcels: Growing,
    lists: Growing,
    bricks: Growing,
    /// Bricks the last bake filled (the next one empties those it drops).
    active: Vec<u32>,
    /// Bricks the next bake dispatches.
    brick_count: u32,
    store: Option<Store>,
    /// Group 1 of the bake over the current buffers and store.
    bind: Option<wgpu::BindGroup>,
    /// Placeholder field (1 voxel, v = −1) and occupancy before any bake.
    empty_view: wgpu::TextureView,
    empty_occupancy: wgpu::Buffer,
    /// Parcels and shell of the last bake (re-bake only when they change).
    last: Option<(Vec<GpuParcel>, f32)>,
    region: Option<Region>,
    parcel_count: u32,
    dirty: bool,
    info: BakeInfo,
    /// Bumped whenever the field texture or occupancy buffer is replaced
    /// (the renderer then rebinds them).
    pub generation: u64,
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn field_texture(device: &wgpu::Device, dims: [u32; 3]) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("baked macro field"),
        size: wgpu::Extent3d {
            width: dims[0],
            height: dims[1],
            depth_or_array_layers: dims[2],
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: FIELD_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    })
}

impl BakedField {
    /// The bake's pipelines (counted in `built`) over the frame uniform.
    pub fn new(ctx: &GpuContext, frame_buf: &wgpu::Buffer, built: &mut u32) -> Result<Self> {
        let device = &ctx.device;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake: frame"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake: parcels, lists and field"),
            entries: &[
                storage_entry(0, true),
                storage_entry(1, true),
                storage_entry(2, true),
                storage_entry(3, false),
                wgpu::BindGroupLayoutEntry {
                    binding: 4,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: FIELD_FORMAT,
                        view_dimension: wgpu::TextureViewDimension::D3,
                    },
                    count: None,
                },
            ],
        });
        let bind_frame = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake: frame"),
            layout: &frame_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame_buf.as_entire_binding(),
            }],
        });
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bake"),
            source: wgpu::ShaderSource::Wgsl(
                crate::render::shaders::Pass::Bake
                    .source(crate::render::RenderMethod::Baked)
                    .into(),
            ),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bake"),
            bind_group_layouts: &[Some(&frame_layout), Some(&layout)],
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
        let gather = compute("gather");
        let clear = compute("clear");
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(Error::Gpu(format!("creating the bake pipelines: {e}")));
        }
        *built += 2;
        let empty = field_texture(device, [1, 1, 1]);
        // IEEE half-precision −1 (v far from every parcel), then G, B, A = 0.
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
            gather,
            clear,
            parcels: Growing::new(device, "bake: parcels"),
            lists: Growing::new(device, "bake: brick lists"),
            bricks: Growing::new(device, "bake: bricks"),
            active: Vec::new(),
            brick_count: 0,
            store: None,
            bind: None,
            empty_view: empty.create_view(&Default::default()),
            empty_occupancy: occupancy_buffer(device, 1),
            last: None,
            region: None,
            parcel_count: 0,
            dirty: false,
            info: BakeInfo::default(),
            generation: 0,
        })
    }

    /// The field texture and occupancy buffer the march reads.
    pub fn field(&self) -> (&wgpu::TextureView, &wgpu::Buffer) {
        match &self.store {
            Some(s) => (&s.view, &s.occupancy),
            None => (&self.empty_view, &self.empty_occupancy),
        }
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

    /// Takes this frame's parcels: when they (or the shell) changed since
    /// the last bake, uploads them and marks the field for a bake. Returns
    /// the coarse grid the march uses (the frame's grid).
    pub fn update(
        &mut self,
        ctx: &GpuContext,
        parcels: &[CloudParcel],
        shell_m: f32,
        radius_scale: f32,
    ) -> Result<GridInfo> {
        let live = pack::gpu_parcels(parcels, shell_m, radius_scale)?;
        let unchanged = self
            .last
            .as_ref()
            .is_some_and(|(p, s)| *s == shell_m && *p == live);
        if !unchanged {
            self.upload(ctx, &live, shell_m)?;
            self.last = Some((live, shell_m));
        }
        Ok(self.grid_info())
    }

    fn grid_info(&self) -> GridInfo {
        match self.region.filter(|_| self.parcel_count > 0) {
            Some(r) => GridInfo {
                min: r.min,
                cell: Vec3::splat(r.voxel_m * BAKE_BLOCK as f32),
                dims: r.cells,
                parcel_count: self.parcel_count,
                entry_count: 0,
                coarsened: r.coarsened,
            },
            None => GridInfo::EMPTY,
        }
    }

    fn upload(&mut self, ctx: &GpuContext, live: &[GpuParcel], shell_m: f32) -> Result<()> {
        self.parcel_count = live.len() as u32;
        if live.is_empty() {
            self.dirty = false;
            return Ok(());
        }
        let device = &ctx.device;
        let r = region(live, shell_m);
        let dims = r.voxel_dims();
        let max3 = device.limits().max_texture_dimension_3d;
        if dims.iter().any(|&d| d > max3) {
            return Err(Error::Gpu(format!(
                "the baked cloud field needs {}×{}×{} voxels of {:.0} m, more than this device's 3D texture limit of {max3} per side",
                dims[0], dims[1], dims[2], r.voxel_m
            )));
        }
        if self.store.as_ref().map(|s| s.dims) != Some(dims) {
            self.store = Some(self.make_store(device, dims, r.cells));
            // A fresh texture is cleared whole: nothing was filled before.
            self.active.clear();
            self.generation += 1;
            self.bind = None;
        }
        let bins = bin(live, &r, shell_m, &self.active);
        let mut grown = self.parcels.write(ctx, bytemuck::cast_slice(live));
        grown |= self.lists.write(ctx, bytemuck::cast_slice(&bins.lists));
        grown |= self.bricks.write(ctx, bytemuck::cast_slice(&bins.bricks));
        if grown {
            self.bind = None;
        }
        if self.bind.is_none() {
            self.bind = Some(self.make_bind(device));
        }
        self.brick_count = bins.bricks[0][0];
        self.active = bins.active;
        self.region = Some(r);
        self.dirty = true;
        self.info = BakeInfo {
            voxel_m: r.voxel_m,
            wanted_voxel_m: r.wanted_voxel_m,
            coarsened: r.coarsened,
            dims,
            bytes: r.voxels() * BYTES_PER_VOXEL,
            bakes: self.info.bakes,
        };
        Ok(())
    }

    fn make_store(&self, device: &wgpu::Device, dims: [u32; 3], cells: [u32; 3]) -> Store {
        Store {
            dims,
            occupancy: occupancy_buffer(device, cells.iter().map(|&c| c as u64).product()),
            view: field_texture(device, dims).create_view(&Default::default()),
            fresh: true,
        }
    }

    fn make_bind(&self, device: &wgpu::Device) -> wgpu::BindGroup {
        let store = self.store.as_ref().expect("the store is made before binding");
        let buffers = [&self.parcels.buffer, &self.lists.buffer, &self.bricks.buffer, &store.occupancy];
        let mut entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        entries.push(wgpu::BindGroupEntry {
            binding: 4,
            resource: wgpu::BindingResource::TextureView(&store.view),
        });
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake: parcels, lists and field"),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Encodes the bake (a clear of a fresh texture, then the gather over
    /// the touched bricks) when the parcels changed; `timestamps` = (query
    /// set, first index) times it as one pass.
    pub fn encode(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        timestamps: Option<(&wgpu::QuerySet, u32)>,
    ) {
        let (Some(store), Some(bind)) = (self.store.as_mut().filter(|_| self.dirty), &self.bind)
        else {
            return;
        };
        enc.clear_buffer(&store.occupancy, 0, None);
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("bake"),
            timestamp_writes: timestamps.map(|(set, i)| wgpu::ComputePassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(i),
                end_of_pass_write_index: Some(i + 1),
            }),
        });
        pass.set_bind_group(0, &self.bind_frame, &[]);
        pass.set_bind_group(1, bind, &[]);
        if store.fresh {
            pass.set_pipeline(&self.clear);
            let d = store.dims;
            pass.dispatch_workgroups(d[0] / BAKE_BLOCK, d[1] / BAKE_BLOCK, d[2] / BAKE_BLOCK);
            store.fresh = false;
        }
        pass.set_pipeline(&self.gather);
        let n = self.brick_count;
        if n > 0 {
            pass.dispatch_workgroups(n.min(GATHER_ROW), n.div_ceil(GATHER_ROW), 1);
        }
        drop(pass);
        self.dirty = false;
        self.info.bakes += 1;
    }
}

fn occupancy_buffer(device: &wgpu::Device, cells: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("bake: occupancy"),
        size: 4 * cells.max(1),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parcel(x: f32, r: f32) -> GpuParcel {
        GpuParcel {
            center_radius: [x, 0.0, 2000.0, r],
            fill_plane: [1.0, 1800.0, 0.0, 0.0],
        }
    }

    #[test]
    fn voxel_follows_radii_and_plane_shell() {
        // Small parcels: a quarter radius (rounded to 2^¼ steps).
        let r = region(&[parcel(0.0, 100.0)], 280.0);
        assert!((r.voxel_m - 25.0).abs() / 25.0 < 0.1, "{}", r.voxel_m);
        // Large parcels: one plane shell (0.3 × 280 m = 84 m).
        let r = region(&[parcel(0.0, 2000.0)], 280.0);
        assert!((r.voxel_m - 84.0).abs() / 84.0 < 0.1, "{}", r.voxel_m);
        assert_eq!(r.coarsened, 0);
    }

    #[test]
    fn bins_list_each_parcel_where_it_reaches_and_empty_dropped_bricks() {
        let shell = 280.0;
        let live = [parcel(0.0, 100.0), parcel(3000.0, 100.0)];
        let r = region(&live, shell);
        let b = bin(&live, &r, shell, &[]);
        let n = b.bricks[0][0] as usize;
        assert_eq!(n, b.active.len());
        assert_eq!(b.bricks.len(), n + 1);
        // Every voxel whose centre a parcel reaches (v > −1) lies in a brick
        // whose list holds that parcel.
        let dims = r.voxel_dims();
        let listed = |k: u32, i: u32| {
            b.bricks[1..].iter().any(|e| {
                e[0] == k && b.lists[e[1] as usize..(e[1] + e[2]) as usize].contains(&i)
            })
        };
        let mut reached = 0;
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let c = r.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * r.voxel_m;
                    for (i, p) in live.iter().enumerate() {
                        let d = (p.center_radius[3] - c.distance(Vec3::from_slice(&p.center_radius[..3]))) / shell;
                        let above = (c.z - p.fill_plane[1]) / (PLANE_SHELL * shell);
                        if d.min(above) > -1.0 {
                            reached += 1;
                            let k = x / BAKE_BLOCK + r.cells[0] * (y / BAKE_BLOCK + r.cells[1] * (z / BAKE_BLOCK));
                            assert!(listed(k, i as u32), "voxel {x} {y} {z}, parcel {i}");
                        }
                    }
                }
            }
        }
        assert!(reached > 100);
        // The two parcels are 3 km apart: most bricks between them are not
        // visited.
        let bricks = r.cells.iter().product::<u32>() as usize;
        assert!(n < bricks / 2, "{n} of {bricks}");
        // Next bake with the second parcel gone: its bricks come back with
        // empty lists (so the gather writes v = −1 there), the first's not.
        let again = bin(&live[..1], &r, shell, &b.active);
        let emptied = again.bricks[1..].iter().filter(|e| e[2] == 0).count();
        assert_eq!(again.active.len() + emptied, n);
        assert!(emptied > 0 && again.active.len() > 0);
    }

    #[test]
    fn a_landscape_fits_the_voxel_budget_with_coarser_voxels() {
        // 40 km × 40 km of parcels 1–12 km high.
        let mut live = Vec::new();
        for i in 0..41 {
            for j in 0..41 {
                live.push(GpuParcel {
                    center_radius: [
                        i as f32 * 1000.0 - 20_000.0,
                        j as f32 * 1000.0 - 20_000.0,
                        1000.0 + (i * j % 12) as f32 * 1000.0,
                        400.0,
                    ],
                    fill_plane: [1.0, 900.0, 0.0, 0.0],
                });
            }
        }
        let r = region(&live, 280.0);
        assert!(r.voxels() <= MAX_BAKE_VOXELS);
        assert!(r.coarsened > 0 && r.voxel_m > r.wanted_voxel_m);
        let v = r.voxel_dims();
        let size = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) * r.voxel_m;
        assert!(size.x >= 40_000.0 && size.z >= 11_000.0, "{size}");
    }
}
