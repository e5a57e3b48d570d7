//! The wgpu renderer on the CPU adapter (lavapipe): reference images, the
//! render methods against each other, lighting, noise, temporal
//! amortisation, the slices method, WGSL validation, `cumulus render`, the
//! path-traced comparison and the renderer embedded in another program.

mod cli;
mod clipmap;
mod embed;
mod gl;
mod lighting;
mod methods;
mod noise;
mod pass_paths;
mod pathtraced;
mod renderer;
mod shaders;
mod slices;
mod slices_look;
mod slices_twin;
mod temporal;
mod temporal_landscape;
mod tower_body;
