//! Goswami & Neyret 2016's ray-march (paper eq. 18) as two render
//! methods: `exact` evaluates the union of parcels per sample from uniform
//! buffers (the paper's path); `baked` splats the parcels into a 3D
//! texture by compute passes and marches that. Both share the march,
//! density and lighting WGSL (`shaders/raymarch/`); they differ only in
//! the macro field (`field_exact.wgsl`, `field_baked.wgsl`, the `<field>`
//! slot) and in what reaches the GPU.
//!
//! - CPU side: the parcels come from [`crate::physics`]; [`pack`] packs
//!   them and the culling grid for `exact`; [`field`] is the CPU twin of
//!   the density (the export samples it), culled by [`parcel_grid`], the
//!   same grid without the uniform arrays' limits;
//! - GPU side: [`method`] implements the render-method trait; [`passes`]
//!   declares its passes, layouts, slots and files; [`exact`] and
//!   [`baked`] upload the field; [`temporal`] is the one-pixel-per-block march's
//!   history; [`auto_march`] picks the faster march path.

pub mod auto_march;
mod bake_gpu;
mod bake_info;
pub mod baked;
pub mod clipmap;
pub mod exact;
pub mod field;
pub mod method;
pub mod pack;
pub mod parcel_grid;
pub mod passes;
pub(crate) mod region;
pub mod temporal;
