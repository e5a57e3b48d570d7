//! The `exact` method's GPU data (paper §6.2): the condensed parcels and
//! the culling grid of [`crate::methods::raymarch::pack`] in two uniform buffers,
//! rewritten every frame. More than [`MAX_PARCELS`] condensed parcels is an
//! error naming that limit (from `pack`), never a truncated or empty sky.

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::gpu::uniform::GridInfo;
use crate::methods::raymarch::pack::{self, GridUniform, MAX_PARCELS, ParcelsUniform};
use crate::physics::CloudParcel;

/// Uniform buffers of the exact field and their bind group (group 3 of
/// the slotted passes under `exact`).
pub struct ExactField {
    pub parcels_buf: wgpu::Buffer,
    pub grid_buf: wgpu::Buffer,
    pub bind: wgpu::BindGroup,
}

impl ExactField {
    pub fn new(device: &wgpu::Device, layouts: &crate::gpu::layouts::Layouts) -> Self {
        let buffer = |label: &str, size| crate::gpu::layouts::uniform_buffer(device, label, size);
        let parcels_buf = buffer("parcels uniform", std::mem::size_of::<ParcelsUniform>());
        let grid_buf = buffer("grid uniform", std::mem::size_of::<GridUniform>());
        let bind = crate::gpu::resources::bind_in_order(
            device,
            "exact: parcels and grid",
            &layouts.get(&super::passes::EXACT_FIELD),
            vec![
                parcels_buf.as_entire_binding(),
                grid_buf.as_entire_binding(),
            ],
        );
        Self {
            parcels_buf,
            grid_buf,
            bind,
        }
    }

    /// Packs and uploads `parcels`; the grid the frame marches through.
    pub fn upload(
        &self,
        ctx: &GpuContext,
        parcels: &[CloudParcel],
        shell_m: f32,
        radius_scale: f32,
    ) -> Result<GridInfo> {
        let packed = pack::pack(parcels, shell_m, radius_scale)?;
        let n = packed.info.parcel_count as usize;
        debug_assert!(n <= MAX_PARCELS);
        if n > 0 {
            let q = &ctx.queue;
            q.write_buffer(
                &self.parcels_buf,
                0,
                bytemuck::cast_slice(&packed.parcels.parcels[..n]),
            );
            q.write_buffer(&self.grid_buf, 0, bytemuck::bytes_of(&*packed.grid));
        }
        Ok(packed.info)
    }
}
