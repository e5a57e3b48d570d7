//! The `sprites` render method (Wang 2003) on the GPU: the atlas uploaded
//! once ([`atlas`]), a frame's sprites shaded and sorted on the CPU
//! ([`build`], from [`crate::methods::sprites::model`]) and drawn by one instanced
//! pass (`shaders/sprites/sprites.wgsl`): six vertices per sprite, premultiplied
//! alpha over the sky and terrain, hidden behind the terrain depth. The
//! same instances splat the sprites' shadows into the cloud-shadow map;
//! the clouds beyond the impostor radius are drawn into the ring of
//! impostors ([`ring`]) instead.
//!
//! These draw the renderer's sprite layer, under every method (a scene's
//! `[[sprite_clouds]]` and `[[layers]]`); [`method`] is the `sprites`
//! render method, which hands the frame's parcels to that layer;
//! [`passes`] declares the sprite passes, layouts, slots and files.
//! Nothing here exists until a frame has a sprite: the renderer creates
//! [`SpritesGpu`] (atlas upload, buffer, bind group) and the sprite
//! pipeline only for a scene or method that draws sprites.

pub mod atlas;
pub mod build;
pub mod ring;

use crate::error::{Error, Result};
use crate::gpu::GpuContext;

pub use build::{SpriteScene, SpriteStats};
pub use ring::RingGpu;

/// One sprite as the shader reads it: `SpriteInstance` in
/// shaders/sprites/sprites.wgsl (176 bytes; a test compares the layouts).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SpriteInstance {
    /// Corners (xyz, w = 1) counter-clockwise from bottom-left. units: m
    pub corners: [[f32; 4]; 4],
    /// Per corner: the painted colour level (sRGB-encoded RGB) and alpha ×
    /// formation × facing.
    pub colors: [[f32; 4]; 4],
    /// Per corner: the share of the sun's light.
    pub sun: [f32; 4],
    /// Per corner: the share of the sky's light.
    pub sky: [f32; 4],
    /// Atlas rectangle (u0, v0, u1, v1), v down.
    pub uv: [f32; 4],
}

/// The atlas, the instance buffer and their bind group (group 2).
pub struct SpritesGpu {
    atlas_view: wgpu::TextureView,
    pub(super) sampler: wgpu::Sampler,
    buffer: wgpu::Buffer,
    /// Instances the buffer holds.
    capacity: u64,
    pub bind: wgpu::BindGroup,
    /// Instances uploaded for the current frame.
    pub count: u32,
}

impl SpritesGpu {
    /// Uploads the atlas and makes room for `capacity` sprites.
    pub fn new(ctx: &GpuContext, layout: &wgpu::BindGroupLayout) -> Self {
        let atlas_view = atlas::upload(ctx, &atlas::sheet());
        let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("sprite atlas"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let capacity = 1024;
        let buffer = instance_buffer(ctx, capacity);
        let bind = bind(ctx, layout, &atlas_view, &sampler, &buffer);
        Self {
            atlas_view,
            sampler,
            buffer,
            capacity,
            bind,
            count: 0,
        }
    }

    /// Uploads a frame's sorted instances, growing the buffer (to the next
    /// power of two) when they do not fit; more than the device can bind is
    /// an error naming the limit.
    pub fn upload(
        &mut self,
        ctx: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        instances: &[SpriteInstance],
    ) -> Result<()> {
        let n = instances.len() as u64;
        let size = std::mem::size_of::<SpriteInstance>() as u64;
        if n > self.capacity {
            let max = ctx.device.limits().max_storage_buffer_binding_size / size;
            if n > max {
                return Err(Error::Gpu(format!(
                    "{n} sprites need {} MiB of instances; this device binds at most {max} sprites ({} MiB)",
                    (n * size) >> 20,
                    (max * size) >> 20
                )));
            }
            self.capacity = n.next_power_of_two().min(max);
            self.buffer = instance_buffer(ctx, self.capacity);
            self.bind = bind(ctx, layout, &self.atlas_view, &self.sampler, &self.buffer);
        }
        if !instances.is_empty() {
            ctx.queue
                .write_buffer(&self.buffer, 0, bytemuck::cast_slice(instances));
        }
        self.count = instances.len() as u32;
        Ok(())
    }
}

fn instance_buffer(ctx: &GpuContext, capacity: u64) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("sprite instances"),
        size: capacity * std::mem::size_of::<SpriteInstance>() as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

pub(super) fn bind(
    ctx: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    atlas: &wgpu::TextureView,
    sampler: &wgpu::Sampler,
    buffer: &wgpu::Buffer,
) -> wgpu::BindGroup {
    ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("sprites"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(atlas),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(sampler),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: buffer.as_entire_binding(),
            },
        ],
    })
}

/// A label over each named cloud of `clouds` (centred above its highest
/// sprite), for clouds in front of the camera.
pub fn cloud_labels(
    clouds: &[crate::methods::sprites::model::SpriteCloud],
    camera: &crate::config::Camera,
    width: u32,
    height: u32,
) -> Vec<crate::plots::labels::Label> {
    clouds
        .iter()
        .filter(|c| !c.name.is_empty() && !c.sprites.is_empty())
        .filter_map(|c| {
            let top = c
                .sprites
                .iter()
                .map(|s| s.center_m.z + 0.5 * s.height_m)
                .fold(f32::MIN, f32::max);
            let anchor = glam::Vec3::new(c.center_m.x, c.center_m.y, top);
            let (x, y) = camera.project_to_pixel(anchor, width, height)?;
            Some(crate::plots::labels::Label {
                x,
                y: y - 4.0,
                text: c.name.clone(),
            })
        })
        .collect()
}
pub mod method;
pub mod passes;
