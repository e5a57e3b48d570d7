//! The renderer (paper §6): draws the cloud field by one of the render
//! methods registered in [`crate::methods::METHODS`] (the ray-march's
//! `baked` and `exact` paths, Wang's `sprites`, Schpok's `slices`) over a
//! sky and a terrain with cloud shadows. One `render` path serves the
//! window, headless commands and tests. Its settings are plain data in
//! [`crate::config`]; the device, pipelines and shared passes are the GPU
//! core's ([`crate::gpu`]).
//!
//! [`renderer`] owns the shared resources and one instance of each
//! method, and orders the passes around the method's phases;
//! [`headless`] renders to an offscreen texture and reads it back.
//!
//! Use (window, bench, tests alike):
//!
//! ```text
//! let ctx = GpuContext::new_headless(None)?;            // or new_for_surface(instance, &surface)
//! let mut r = Renderer::new(&ctx, &cfg, format, w, h)?;  // cfg: RenderConfig, validated
//! r.prepare(&ctx, &FrameInput { camera, parcels: &parcels, sun: cfg.sun(), time_s })?;
//! let timings = r.render(&ctx, &view);                   // FrameTimings per pass
//! r.set_config(&ctx, &new_cfg)?;  r.resize(&ctx, w2, h2)?;
//! // headless: headless::render_to_rgba(&ctx, &cfg, &input, w, h)? -> (rgba, w, h)
//! ```
//!
//! The passes and their shaders are described in the headers of the
//! files in `shaders/` (grouped by owner, see [`crate::gpu::shaders`]);
//! the density of the hypertexture (paper eq. 18) in
//! `shaders/raymarch/density.wgsl`.

pub mod headless;
pub mod renderer;
#[cfg(test)]
pub(crate) mod twins;

pub use crate::gpu::GpuContext;
pub use crate::gpu::frame::FrameInput;
pub use renderer::{Features, FrameTimings, Renderer, TimingMode};
