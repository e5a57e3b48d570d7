//! The render-method trait. A method (the ray-march, Wang's sprites,
//! Schpok's slices; `src/methods/`) owns its pipelines' specs, its GPU
//! resources, its upload and the encoding of its passes; the renderer
//! ([`crate::render::Renderer`]) owns what the methods share (the frame
//! uniform, the HDR scene target, the depth, the cloud-shadow map, the
//! float cloud image, the sprite layer, the sky, the terrain, the tone map
//! and the timing) and the pass order, and drives the method through this
//! trait in three phases:
//!
//! ```text
//! Prepare (bake, slice field) → shadow map → sky → terrain
//!   → Clouds (the march) → sprite layer → Resolve (temporal, slicing planes)
//!   → composite (the method's cloud image) → tone map
//! ```
//!
//! A method registers once ([`MethodEntry`], one line in
//! [`crate::methods::METHODS`]).

use std::any::Any;

use crate::config::{RenderConfig, RenderMethod};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::gpu::frame::FrameInput;
use crate::gpu::layouts::Layouts;
use crate::gpu::pass::{PassSpec, Slots};
use crate::gpu::pipelines::{PipelineCache, PipelineKey};
use crate::gpu::timing::{FrameTimings, Recorder};
use crate::gpu::uniform::{FrameUniform, GridInfo};
use crate::physics::CloudParcel;

/// Where in the frame a method's passes run (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Before the shadow map: compute work the frame's field needs.
    Prepare,
    /// After the sky and the terrain, before the sprite layer: the clouds,
    /// into the scene target or the cloud image.
    Clouds,
    /// After the sprite layer, before the composite: work on the cloud
    /// image.
    Resolve,
}

impl Phase {
    pub const ALL: [Phase; 3] = [Phase::Prepare, Phase::Clouds, Phase::Resolve];
}

/// The frame around the method: what the renderer draws besides it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Around {
    /// The last prepared frame had clouds for the method (true before
    /// the first, so pipelines are built ahead of the first cloud).
    pub any_clouds: bool,
    /// The terrain is drawn (its depth exists).
    pub terrain: bool,
    /// The sprite layer draws this frame (the scene's sprite clouds, or
    /// the parcels a method hands it).
    pub layers: bool,
    /// Cloud shadows fall on the terrain this frame.
    pub shadows: bool,
}

/// What the method draws this frame and asks of the shared passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Needs {
    /// It draws clouds of its own this frame.
    pub draws: bool,
    /// It hands its parcels to the sprite layer (which then draws).
    pub feeds_layer: bool,
    /// The shadow map marches its field (the `ground_shadow` slot).
    pub marches_shadow: bool,
    /// Ground inside its clouds' region marches its own sun ray
    /// (the terrain's `SHADOW_IN_REGION`).
    pub shadow_in_region: bool,
    /// It draws into the shared float cloud image (and its depth).
    pub cloud_image: bool,
    /// The composite blends its cloud image over the scene.
    pub composite: bool,
    /// It leaves a cloud depth the sprite layer sorts against (the sprite
    /// fragments behind it are drawn before the composite, those in front
    /// after).
    pub cloud_depth: bool,
}

/// What a method's upload tells the renderer.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The box and grid the frame uniform carries (exact: the culling
    /// grid; baked: the occupancy grid; slices: the primitives' bounds);
    /// its `parcel_count` > 0 when there are clouds to draw.
    pub grid: GridInfo,
    /// The frame has clouds for this method.
    pub any_clouds: bool,
    /// Parcels for the sprite layer (as drawn: radius scaled).
    pub layer_parcels: Vec<CloudParcel>,
}

/// The shared resources a method encodes with.
pub struct Shared<'a> {
    pub cfg: &'a RenderConfig,
    pub pipelines: &'a PipelineCache,
    /// Group 0.
    pub common: &'a wgpu::BindGroup,
    /// Group 1 of the passes that test the terrain depth.
    pub depth: &'a wgpu::BindGroup,
    /// The HDR scene target.
    pub scene: &'a wgpu::TextureView,
    /// The float cloud image (colour view, its compute-output bind group
    /// with the cloud depth, its composite bind group), when it exists.
    pub cloud_image: Option<&'a CloudImage>,
    /// Frame size. units: px
    pub size: (u32, u32),
    pub around: Around,
}

/// The float cloud image the compute march writes and the planes blend
/// into, with its cloud depth; the composite reads it.
pub struct CloudImage {
    pub view: wgpu::TextureView,
    /// Group 2 of the compute march: the image and the cloud depth.
    pub compute_out: wgpu::BindGroup,
    /// Group 1 of the composite.
    pub composite_in: wgpu::BindGroup,
    pub depth: wgpu::TextureView,
}

/// A render method; see the module docs.
pub trait CloudMethod {
    /// The files it binds to the shared shaders' slots under `cfg`.
    fn slots(&self, cfg: &RenderConfig) -> &'static Slots;

    /// What it draws and needs under `cfg` in a frame `around`.
    fn needs(&self, cfg: &RenderConfig, around: Around) -> Needs;

    /// The pipelines of its passes under `cfg` and `around` (built ahead,
    /// for the frame with and without clouds and for the settings one
    /// click away).
    fn pipeline_keys(&self, cfg: &RenderConfig, around: Around) -> Vec<PipelineKey>;

    /// Uploads the frame's clouds.
    fn prepare(
        &mut self,
        ctx: &GpuContext,
        layouts: &Layouts,
        cfg: &RenderConfig,
        input: &FrameInput<'_>,
    ) -> Result<Prepared>;

    /// After the frame uniform is written: uploads what depends on it.
    fn prepared(&mut self, _ctx: &GpuContext, _frame: &FrameUniform) {}

    /// Creates what this frame needs and drops what it does not (a frame
    /// of `size` pixels; nothing by default).
    fn ensure(
        &mut self,
        _ctx: &GpuContext,
        _layouts: &Layouts,
        _cfg: &RenderConfig,
        _around: Around,
        _size: (u32, u32),
    ) -> Result<()> {
        Ok(())
    }

    /// The frame size changed: drop what depends on it.
    fn resize(&mut self) {}

    /// The settings changed: drop history that no longer matches.
    fn settings_changed(&mut self) {}

    /// Names of its passes of `phase` that exist this frame, in order.
    fn pass_names(&self, cfg: &RenderConfig, around: Around, phase: Phase) -> Vec<&'static str>;

    /// Encodes its passes of `phase`.
    fn encode(&mut self, phase: Phase, rec: &mut Recorder<'_>, shared: &Shared<'_>);

    /// Group [`crate::gpu::pass::SLOT_GROUP`] of the slotted passes (None:
    /// its slot files bind nothing).
    fn slot_group(&self, cfg: &RenderConfig) -> Option<&wgpu::BindGroup>;

    /// Group 1 of the composite: its cloud image this frame.
    fn composite_input<'a>(&'a self, shared: &'a Shared<'a>) -> Option<&'a wgpu::BindGroup> {
        shared.cloud_image.map(|c| &c.composite_in)
    }

    /// Whether the tone map may blend this frame's cloud image instead of
    /// a composite pass (false while the method tells its frames apart by
    /// that pass's timing).
    fn composite_foldable(&self, _cfg: &RenderConfig, _around: Around) -> bool {
        true
    }

    /// Whether the shadow map of an earlier frame still shows its clouds.
    fn shadow_reusable(&self, _cfg: &RenderConfig) -> bool {
        false
    }

    /// The sky pass's clear colour instead of the sky (None: the sky).
    fn background(&self, _cfg: &RenderConfig) -> Option<[f32; 3]> {
        None
    }

    /// After a frame was drawn, with its timings; true when the method
    /// chose other pipelines (the renderer then ensures them).
    fn frame_drawn(&mut self, _cfg: &RenderConfig, _around: Around, _t: &FrameTimings) -> bool {
        false
    }

    /// Pipelines it compiled itself, outside the cache (counted in
    /// `Renderer::pipelines_built`).
    fn own_pipelines(&self) -> u32 {
        0
    }

    /// The window builds ahead: make now what is made on first use.
    fn prebuild(&mut self, _ctx: &GpuContext, _layouts: &Layouts) -> Result<()> {
        Ok(())
    }

    /// For the method's own accessors (`Renderer::bake_info`, …).
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// A method's registration: what it draws and how to make it.
pub struct MethodEntry {
    /// The `render.method` values it draws.
    pub methods: &'static [RenderMethod],
    /// Makes the method on a device, over the frame uniform buffer.
    pub create: fn(&GpuContext, &Layouts, &wgpu::Buffer) -> Result<Box<dyn CloudMethod>>,
    /// Its slots for each of its `methods`.
    pub slots: fn(RenderMethod) -> &'static Slots,
    /// Every pass of its own the pipeline cache builds.
    pub passes: &'static [&'static PassSpec],
    /// Its files under `shaders/`.
    pub files: &'static [(&'static str, &'static str)],
    /// The shadow map marches its field.
    pub marches_shadow: bool,
    /// The names of all its passes (their timings), by phase, in order.
    pub pass_names: &'static [(Phase, &'static str)],
    /// What its pipelines built outside the cache (its own compute jobs)
    /// need from the device under `render.method`; checked with its
    /// `passes` before a renderer is made.
    pub other_passes: fn(RenderMethod) -> Vec<crate::gpu::requires::Requirement>,
    /// Why it cannot draw `render.method` on this adapter although the
    /// adapter meets every requirement (a driver or backend known to draw
    /// it wrong; None: it can).
    pub unsupported: fn(&wgpu::AdapterInfo, RenderMethod) -> Option<&'static str>,
}
