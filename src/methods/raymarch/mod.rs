//! Ray-marched methods (paper eq. 18): `exact` evaluates the union of
//! parcels per sample from uniform buffers (the paper's path); `baked`
//! splats the parcels into a 3D texture by compute passes and marches that.
//! Both share the march, density and lighting WGSL (shaders/raymarch/clouds.wgsl,
//! density.wgsl, lighting.wgsl); they differ only in the macro field
//! (shaders/raymarch/field_exact.wgsl, field_baked.wgsl) and in what reaches the GPU,
//! which these submodules own.

pub mod auto_march;
pub mod baked;
pub mod exact;
pub mod field;
pub mod method;
pub mod pack;
pub mod passes;
pub(crate) mod region;
pub mod temporal;
