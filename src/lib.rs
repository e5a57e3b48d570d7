//! cumulus grows cumulus clouds from atmospheric parcel physics (Goswami &
//! Neyret 2016) and renders them on the GPU, with Wang 2003's sprites and
//! Schpok 2003's slices as further render methods of the same cloud field.
//!
//! # Entry points
//!
//! - A scene: [`scene::SceneProfile::load`] reads a profile (TOML), checks
//!   every table and names the file, line and key of a bad value;
//!   [`scene::SceneProfile::embedded_default`] is the built-in one.
//! - The physics: [`physics::ParcelWorld::new`] from the scene's
//!   atmosphere ([`scene::SceneProfile::build_atmosphere`], whose errors
//!   name the profile and its `sounding` line) and
//!   [`scene::SceneProfile::world_config`]; [`physics::ParcelWorld::step`]
//!   advances it, [`physics::ParcelWorld::cloud_parcels`] gives the
//!   condensed parcels the renderer draws.
//! - The renderer: [`render::GpuContext`] opens a device (or wraps another
//!   program's, [`render::GpuContext::from_host`]);
//!   [`render::Renderer::new`] takes a [`config::RenderConfig`];
//!   [`render::Renderer::prepare`] uploads a [`render::FrameInput`] (the
//!   parcels, a [`config::Camera`], a [`sky::Sun`], the time) and
//!   [`render::Renderer::render`] draws sky, terrain, clouds and the tone
//!   map into a texture view, or [`render::Renderer::render_clouds_over`]
//!   only the clouds into another program's HDR target
//!   (`examples/embed.rs`). [`render::headless::Headless`] renders to
//!   memory.
//! - A render method: [`gpu::method::CloudMethod`], implemented by each
//!   folder of [`methods`] and registered in [`methods::METHODS`]; the
//!   renderer drives the current one between the shared passes
//!   ([`gpu::passes`]).
//! - Aerology without a GPU: [`atmosphere`] (soundings, lifted parcels,
//!   CAPE/CIN); the stiff cases: [`stability`]; tables: [`bench`](mod@bench).
//!
//! docs/ARCHITECTURE.md in the repository describes the pass order, the
//! shaders and how to add a pass, a render method or a setting;
//! docs/notes.md keeps the variants that were tried and not kept, with
//! their numbers.
//!
//! # Layers
//!
//! Each top-level module may import only the modules listed before it
//! (the `layering` integration test reads this list and checks every
//! `crate::` path in `src/` against it, so the import graph has no cycle):
//!
//! 1. [`error`]: the error type, and positions in text;
//! 2. [`output`]: files written whole or not at all;
//! 3. [`landscape`]: the ground's height and the terrain mesh (CPU);
//! 4. [`noise`]: the tiling 3D noise of the hypertexture (CPU);
//! 5. [`atmosphere`]: thermodynamics, environment profiles, soundings;
//! 6. [`sun`]: the sun's position from a clock;
//! 7. [`sky`]: sun and sky colours from an atmosphere model;
//! 8. [`physics`]: parcels, SPH, mixing, condensation, emission;
//! 9. [`plots`]: diagrams and labels drawn on the CPU (Skew-T, hodograph);
//! 10. [`config`]: the `[render]` and `[camera]` tables, plain data;
//! 11. [`gpu`]: the GPU core: device, layouts, pass specs, pipeline
//!     cache, shader assembly, the shared passes, timing;
//! 12. [`methods`]: the render methods, each in its folder with its CPU
//!     model and its GPU side (ray-march, sprites, slices);
//! 13. [`scene`]: a scene profile (TOML) → validated configuration;
//! 14. [`render`]: the renderer composing the shared passes and a method
//!     (headless or to a window surface);
//! 15. [`export`]: the cloud density for offline renderers;
//! 16. [`stability`]: the matrix of stiff and extreme physics cases;
//! 17. [`bench`](mod@bench): performance and error tables;
//! 18. [`app`]: the window.
//!
//! The CPU models (layers 3–8 and each method's `model/` folder) import no
//! GPU core, scene, renderer or front end, so they build, run and test
//! without a GPU; each method imports the layers below it and no other
//! method. The command line (`src/cli`, in the binary) sits above
//! everything.

// Input checks are written `!(x > 0.0)` on purpose: the negated comparison
// is also true for NaN, which must be an error, never a silent pass.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod app;
pub mod atmosphere;
pub mod bench;
pub mod config;
pub mod error;
pub mod export;
pub mod gpu;
pub mod landscape;
pub mod methods;
pub mod noise;
pub mod output;
pub mod physics;
pub mod plots;
pub mod render;
pub mod scene;
pub mod sky;
pub mod stability;
pub mod sun;

pub use error::{Error, Result};
