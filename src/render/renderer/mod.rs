//! The renderer: owns the GPU resources of the shared passes and one
//! instance of each registered render method ([`crate::methods::METHODS`]),
//! and draws a frame into any texture view (window surface or offscreen)
//! by driving the current method through its trait
//! ([`crate::gpu::method::CloudMethod`]) between the shared passes:
//! the method's Prepare passes (the bake, the slice field) → shadow map
//! (kept from an earlier frame while nothing it shows changed) → sky →
//! terrain → the method's Clouds passes (the march) → the sprite layer
//! (the impostor ring's face first; behind the clouds' depth when both
//! draw) → the method's Resolve passes (temporal resolve, slicing planes)
//! → composite (the method's cloud image, then the sprites in front of
//! the clouds) → tonemap (which blends the cloud image itself where
//! nothing follows it and the scene is not read back: see
//! `passes::folds`). Sky, terrain and clouds write linear radiance
//! into one HDR scene target ([`SCENE_FORMAT`]) and composite there in
//! linear light; the tone-map pass alone writes the output (window surface
//! or headless texture, the same path for both).
//! This file holds the state and the configuration; `passes` says which
//! passes and pipelines a frame needs; `ensure` creates them; `prepare`
//! uploads a frame; `draw` encodes and times it; `shared` encodes the
//! shared passes; `resources` holds the textures and bind groups it
//! creates; `ring` the sprite layer's impostor ring.
//!
//! "Leave out what a scene does not need": [`Features`] decides which passes
//! and resources exist; pipelines come from a cache keyed by pass, slots
//! and `override` constants ([`crate::gpu::pipelines`]), so a toggled
//! setting builds only pipelines it has never seen and clouds appearing
//! never wait for a shader compile. `prepare` uploads (and times the
//! upload); `render` draws and times each pass ([`crate::gpu::timing`]).

use std::time::Instant;

use crate::config::method::{MarchPath, RenderMethod};
use crate::config::{RenderConfig, TemporalMode, TerrainConfig};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::gpu::layouts::Layouts;
use crate::gpu::method::{Around, CloudImage, CloudMethod, Needs};
use crate::gpu::noise;
use crate::gpu::pipelines::PipelineCache;
use crate::gpu::resources::check_size;
use crate::gpu::timing::Timestamps;
use crate::gpu::uniform::{FrameUniform, GridInfo};
use crate::landscape::terrain;
use crate::methods::METHODS;
use crate::methods::raymarch::baked::BakeInfo;
use crate::methods::raymarch::method::Raymarch;
use crate::methods::slices::gpu::method::Slices;
use crate::methods::sprites::gpu::{RingGpu, SpriteScene, SpriteStats, SpritesGpu};
use crate::noise::NoiseVolume;
use crate::render::FrameInput;

mod draw;
mod ensure;
mod passes;
mod prepare;
mod resources;
mod ring;
mod shared;

pub(crate) use crate::gpu::resources::texture_2d;
pub use passes::{all_pass_names, modules, requirements, shader_files, slots};
use resources::{SceneTarget, make_bind_common};

pub use crate::gpu::pipelines::{DEPTH_FORMAT, SCENE_FORMAT, SHADOW_FORMAT};
pub(crate) use crate::gpu::timing::read_buffer;
pub use crate::gpu::timing::{FrameTimings, TimingMode};

/// Most passes one frame encodes (timestamp queries are made for these).
const MAX_PASSES: u32 = 16;

struct TerrainGpu {
    cfg: TerrainConfig,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

/// Which passes and shader code a frame needs ("leave out what a scene
/// does not need"): the frame around the method, what the method draws,
/// and the shared passes that follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Features {
    pub around: Around,
    /// What the current method draws and asks of the shared passes.
    pub method: Needs,
    /// The cloud-shadow map pass: the method's field marched into it
    /// and the sprite layer's shadows splatted in.
    pub shadow_map: bool,
}

impl Features {
    /// The terrain mesh pass.
    pub fn terrain(&self) -> bool {
        self.around.terrain
    }

    /// The sprite layer draws.
    pub fn sprites(&self) -> bool {
        self.around.layers
    }

    /// Cloud shadows on the terrain.
    pub fn shadows(&self) -> bool {
        self.around.shadows
    }
}

/// Draws frames; see the module docs.
pub struct Renderer {
    cfg: RenderConfig,
    format: wgpu::TextureFormat,
    width: u32,
    height: u32,
    features: Features,
    /// The last prepared frame had clouds for the method (true before the
    /// first).
    any_clouds: bool,
    grid_info: GridInfo,
    upload_ms: f64,

    /// One instance of each registered method ([`METHODS`]), made with the
    /// renderer and kept, so a method switched back finds its state.
    methods: Vec<Box<dyn CloudMethod>>,

    frame_buf: wgpu::Buffer,
    noise_texels: u32,
    noise_view: wgpu::TextureView,
    repeat_sampler: wgpu::Sampler,
    clamp_sampler: wgpu::Sampler,
    layouts: Layouts,
    bind_common: wgpu::BindGroup,

    depth_view: Option<wgpu::TextureView>,
    dummy_depth_view: wgpu::TextureView,
    shadow_view: Option<(u32, wgpu::TextureView)>,
    /// Group 2 of the compute shadow march: the map it writes (with the
    /// map, where the adapter marches it in compute).
    bind_shadow_out: Option<wgpu::BindGroup>,
    /// Per registered method ([`METHODS`]): the adapter can march its
    /// shadow map in a compute shader, and whether it does (else a
    /// full-screen fragment one; see `Renderer::set_compute_shadow`).
    shadow_compute_ok: Vec<bool>,
    shadow_compute: Vec<bool>,
    /// The shadow map holds what the current frame would draw into it if
    /// the method's clouds did not move (see `Renderer::shadow_reusable`).
    shadow_fresh: bool,
    /// Keep the HDR scene target whole (the clouds composited into it by
    /// a pass of their own) for a read-back; else the tone map blends the
    /// cloud image where nothing is drawn after it (see `folds`).
    scene_whole: bool,
    /// The last frame left its clouds to the tone map: the HDR scene
    /// target lacks them.
    scene_folded: bool,
    white_view: wgpu::TextureView,
    terrain: Option<TerrainGpu>,

    pipelines: PipelineCache,
    bind_terrain: Option<wgpu::BindGroup>,
    /// Group 1 of the passes that test the terrain depth.
    bind_depth: Option<wgpu::BindGroup>,
    timestamps: Option<Timestamps>,
    /// How passes are timed (GPU modes fall back to Cpu without timestamps).
    timing: TimingMode,
    /// The float cloud image a method draws into (and its depth).
    cloud_image: Option<CloudImage>,
    /// Cloud depth bound while no cloud image exists (never read then).
    dummy_cloud_depth_view: wgpu::TextureView,
    /// Group 1 of the sprite pipelines (terrain and cloud depth).
    bind_sprites: Option<wgpu::BindGroup>,
    /// Box around this frame's directly drawn sprites (min, max; None
    /// without any): the cloud-shadow map covers it. units: m
    sprite_box: Option<(glam::Vec3, glam::Vec3)>,
    /// The HDR scene target (made by `ensure`, dropped on resize).
    scene: Option<SceneTarget>,
    /// The sprite layer: the scene's sprite clouds (and the `sprites`
    /// method's parcels) and their per-sprite state.
    sprite_scene: SpriteScene,
    /// Atlas and instances, created with the first sprite.
    sprites: Option<SpritesGpu>,
    /// The impostor ring (`[render.sprites] impostor_radius_m`).
    ring: Option<RingGpu>,
}

impl Renderer {
    pub fn new(
        ctx: &GpuContext,
        cfg: &RenderConfig,
        target_format: wgpu::TextureFormat,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        cfg.validate()?;
        check_method(ctx, cfg.method)?;
        check_size(ctx, width, height)?;
        let device = &ctx.device;
        let limits = device.limits();
        let frame_size = std::mem::size_of::<FrameUniform>();
        if cfg.noise_texels > limits.max_texture_dimension_3d
            || cfg.shadow_texels > limits.max_texture_dimension_2d
        {
            return Err(Error::Gpu(format!(
                "noise texture {}³ or shadow map {}² exceeds the device's texture limits ({}³, {}²)",
                cfg.noise_texels,
                cfg.shadow_texels,
                limits.max_texture_dimension_3d,
                limits.max_texture_dimension_2d
            )));
        }

        let frame_buf = crate::gpu::layouts::uniform_buffer(device, "frame uniform", frame_size);
        let layouts = Layouts::new(device);
        let methods = METHODS
            .iter()
            .map(|e| (e.create)(ctx, &layouts, &frame_buf))
            .collect::<Result<Vec<_>>>()?;

        let repeat_sampler = noise::repeat_sampler(device);
        let clamp_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("clamp"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let noise_view =
            noise::texture(&NoiseVolume::new(cfg.noise_texels), &ctx.device, &ctx.queue);
        let (dummy_depth_view, dummy_cloud_depth_view, white_view) = resources::placeholders(ctx);
        let timestamps = ctx.timestamps.then(|| Timestamps::new(device, MAX_PASSES));
        let caps = crate::gpu::requires::Capabilities::of(ctx);
        let shadow_compute_ok: Vec<bool> = METHODS
            .iter()
            .map(|e| passes::compute_shadow(&caps, (e.slots)(e.methods[0])))
            .collect();
        let bind_common = make_bind_common(
            device,
            &layouts,
            &frame_buf,
            &noise_view,
            &repeat_sampler,
            &clamp_sampler,
        );
        let mut r = Self {
            cfg: cfg.clone(),
            format: target_format,
            width,
            height,
            // Placeholder; set below for a frame with clouds, ahead of the
            // first condensed parcel (no compile when it appears).
            features: Features {
                around: Around {
                    any_clouds: true,
                    terrain: false,
                    layers: false,
                    shadows: false,
                },
                method: Needs::default(),
                shadow_map: false,
            },
            any_clouds: true,
            grid_info: GridInfo::EMPTY,
            upload_ms: 0.0,
            methods,
            frame_buf,
            noise_texels: cfg.noise_texels,
            noise_view,
            repeat_sampler,
            clamp_sampler,
            layouts,
            bind_common,
            depth_view: None,
            dummy_depth_view,
            shadow_view: None,
            bind_shadow_out: None,
            shadow_compute: shadow_compute_ok.clone(),
            shadow_compute_ok,
            shadow_fresh: false,
            scene_whole: false,
            scene_folded: false,
            white_view,
            terrain: None,
            pipelines: PipelineCache::default(),
            bind_terrain: None,
            bind_depth: None,
            timestamps,
            timing: TimingMode::GpuBlocking,
            cloud_image: None,
            dummy_cloud_depth_view,
            bind_sprites: None,
            sprite_box: None,
            scene: None,
            sprite_scene: SpriteScene::default(),
            sprites: None,
            ring: None,
        };
        r.features = r.features_for(&r.cfg, true, false);
        r.ensure(ctx)?;
        Ok(r)
    }

    /// The current method.
    fn method(&self) -> &dyn CloudMethod {
        self.methods[crate::methods::index_of(self.cfg.method)].as_ref()
    }

    /// The registered method of type `M` (the accessors of one method).
    fn method_of<M: 'static>(&self) -> &M {
        self.methods
            .iter()
            .find_map(|m| m.as_any().downcast_ref::<M>())
            .expect("every registered method is made with the renderer")
    }

    fn method_of_mut<M: 'static>(&mut self) -> &mut M {
        self.methods
            .iter_mut()
            .find_map(|m| m.as_any_mut().downcast_mut::<M>())
            .expect("every registered method is made with the renderer")
    }

    /// Sets the authored clouds (a scene's `[[ellipsoids]]` and
    /// `[particles]`) that the `slices` method draws, animated to each
    /// frame's `time_s`, besides the frame's parcels. The other methods
    /// ignore them. Takes effect at the next `prepare`.
    pub fn set_authored(
        &mut self,
        ellipsoids: &[crate::methods::slices::model::Ellipsoid],
        particles: &crate::methods::slices::model::ParticleConfig,
    ) {
        self.method_of_mut::<Slices>()
            .set_authored(ellipsoids, particles);
    }

    /// Primitives (ellipsoids and parcel spheres) the `slices` method drew
    /// in the last prepared frame.
    pub fn slice_primitives(&self) -> u32 {
        self.method_of::<Slices>().primitives()
    }

    /// The slices' vertex buffer after the last frame (tests compare the
    /// compute pass with the CPU): the first `count` vertices.
    pub fn slice_vertices(
        &self,
        ctx: &GpuContext,
        count: usize,
    ) -> Result<Vec<crate::methods::slices::model::SliceVertex>> {
        self.method_of::<Slices>().vertices(ctx, count)
    }

    /// The current configuration.
    pub fn config(&self) -> &RenderConfig {
        &self.cfg
    }

    /// The features the current frame uses.
    pub fn features(&self) -> Features {
        self.features
    }

    /// Where the last frame's grid sits and how full it is (exact: the
    /// culling grid; baked: the coarse occupancy grid over the bake region).
    pub fn grid_info(&self) -> GridInfo {
        self.grid_info
    }

    /// What the baked field covers (zeros before the first bake).
    pub fn bake_info(&self) -> BakeInfo {
        self.method_of::<Raymarch>().bake_info()
    }

    /// Times passes with GPU timestamps (when the device has them; the
    /// default) or with the CPU clock and a queue sync per pass.
    pub fn set_gpu_timestamps(&mut self, on: bool) {
        self.set_timing_mode(if on {
            TimingMode::GpuBlocking
        } else {
            TimingMode::Cpu
        });
    }

    /// Chooses how passes are timed; see [`TimingMode`].
    pub fn set_timing_mode(&mut self, mode: TimingMode) {
        self.timing = mode;
    }

    /// The timing actually used: GPU modes need timestamp support.
    pub fn timing_mode(&self) -> TimingMode {
        match (self.timing, self.timestamps.is_some()) {
            (TimingMode::Cpu, _) | (_, false) => TimingMode::Cpu,
            (mode, true) => mode,
        }
    }

    /// Re-bake the baked field every frame, moved or not (for the bench:
    /// the cost of a frame whose parcels all moved).
    pub fn set_always_bake(&mut self, on: bool) {
        self.method_of_mut::<Raymarch>().set_always_bake(on);
    }

    /// Frames drawn on the temporal path since its history began (0 when
    /// it is off or has just restarted).
    pub fn temporal_frames(&self) -> u32 {
        self.method_of::<Raymarch>().temporal_frames()
    }

    /// The march path in use: the configured one, or what `auto` chose
    /// (None while it is still measuring).
    pub fn march_path(&self) -> Option<MarchPath> {
        self.method_of::<Raymarch>()
            .march_path(&self.cfg, self.features.around)
    }

    /// Keep the HDR scene target whole from the next frame on (true:
    /// the clouds are composited into it by a pass of their own, as a
    /// read-back of it needs) or let the tone map blend them (false, the
    /// default: one full-screen pass less).
    pub fn set_scene_whole(&mut self, whole: bool) {
        self.scene_whole = whole;
    }

    /// Whether the last frame's HDR scene target lacks its clouds (the
    /// tone map blended them; see [`Renderer::set_scene_whole`]).
    pub fn scene_folded(&self) -> bool {
        self.scene_folded
    }

    /// March the cloud-shadow map in a compute shader where the adapter
    /// can (true, the default) or always in the full-screen fragment
    /// shader (false): the same routine per texel, so the same map.
    pub fn set_compute_shadow(&mut self, ctx: &GpuContext, on: bool) -> Result<()> {
        self.shadow_compute = self.shadow_compute_ok.iter().map(|ok| on && *ok).collect();
        // Drawn again by the path now chosen (the same map).
        self.shadow_fresh = false;
        self.ensure(ctx)
    }

    /// Whether this frame's shadow map is marched in a compute shader.
    pub fn compute_shadow(&self) -> bool {
        self.shadow_compute[crate::methods::index_of(self.cfg.method)]
    }

    /// Frame size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Changes the frame size (recreates the depth buffer).
    pub fn resize(&mut self, ctx: &GpuContext, width: u32, height: u32) -> Result<()> {
        check_size(ctx, width, height)?;
        if (width, height) != (self.width, self.height) {
            self.width = width;
            self.height = height;
            self.depth_view = None;
            self.bind_depth = None;
            self.cloud_image = None;
            self.scene = None;
            for m in &mut self.methods {
                m.resize();
            }
            self.ensure(ctx)?;
        }
        Ok(())
    }

    /// Applies new settings, rebuilding only what depends on what changed.
    /// A new method takes effect at the next `prepare`.
    pub fn set_config(&mut self, ctx: &GpuContext, cfg: &RenderConfig) -> Result<()> {
        cfg.validate()?;
        check_method(ctx, cfg.method)?;
        if cfg.noise_texels != self.noise_texels {
            self.noise_view =
                noise::texture(&NoiseVolume::new(cfg.noise_texels), &ctx.device, &ctx.queue);
            self.noise_texels = cfg.noise_texels;
            self.bind_common = make_bind_common(
                &ctx.device,
                &self.layouts,
                &self.frame_buf,
                &self.noise_view,
                &self.repeat_sampler,
                &self.clamp_sampler,
            );
        }
        self.cfg = cfg.clone();
        self.shadow_fresh = false;
        // The method's own sprites come from the settings; besides them only
        // the scene's sprite clouds (the last method's sprites, or its
        // impostor ring, must not carry over into the next method).
        self.features = self.features_for(cfg, self.any_clouds, !self.sprite_scene.is_empty());
        for m in &mut self.methods {
            m.settings_changed();
        }
        self.ensure(ctx)
    }

    /// Sets the scene's own sprite clouds (`[[sprite_clouds]]` and
    /// `[[layers]]`, from [`crate::scene::SceneProfile::build_sprite_clouds`]), drawn
    /// under every method from the next `prepare`.
    pub fn set_sprite_clouds(
        &mut self,
        ctx: &GpuContext,
        clouds: Vec<crate::methods::sprites::model::SpriteCloud>,
    ) -> Result<()> {
        self.sprite_scene = SpriteScene::new(clouds);
        self.features =
            self.features_for(&self.cfg, self.any_clouds, !self.sprite_scene.is_empty());
        self.ensure(ctx)
    }

    /// What the last frame's sprites cost (zeros without sprites).
    pub fn sprite_stats(&self) -> SpriteStats {
        self.sprite_scene.stats
    }

    /// The scene's sprite clouds.
    pub fn sprite_clouds(&self) -> &[crate::methods::sprites::model::SpriteCloud] {
        self.sprite_scene.clouds()
    }
}

/// Why `method` cannot draw on this adapter, if it cannot: the first of
/// its passes' [`requirements`] the device does not meet, or a backend
/// known to draw it wrong.
pub fn unsupported(ctx: &GpuContext, method: RenderMethod) -> Option<String> {
    let caps = crate::gpu::requires::Capabilities::of(ctx);
    requirements(method)
        .iter()
        .find_map(|r| r.check(&caps).err())
        .map(|m| m.to_string())
        .or_else(|| {
            let entry = METHODS[crate::methods::index_of(method)];
            (entry.unsupported)(&ctx.adapter.get_info(), method).map(str::to_string)
        })
}

/// `method` can draw on this adapter, or the error naming the adapter,
/// what it lacks and the fix.
pub fn check_method(ctx: &GpuContext, method: RenderMethod) -> Result<()> {
    let Some(why) = unsupported(ctx, method) else {
        return Ok(());
    };
    let others: Vec<&str> = RenderMethod::ALL
        .into_iter()
        .filter(|m| unsupported(ctx, *m).is_none())
        .map(|m| m.name())
        .collect();
    let instead = if others.is_empty() {
        "No method can draw on this adapter: give wgpu".to_string()
    } else {
        format!(
            "Use --method {} (or set [render] method), or give wgpu",
            others.join(" or --method ")
        )
    };
    Err(Error::Unsupported(format!(
        "the {method} method cannot draw on {} ({}): {why}. {instead} a Vulkan adapter (Debian/Ubuntu: apt-get install mesa-vulkan-drivers libvulkan1; unset WGPU_BACKEND)",
        ctx.adapter_name(),
        ctx.backend(),
    )))
}

/// The method to draw with on this adapter: `cfg.method` when it can, or
/// (when the user did not ask for it: `asked` false) the first method that
/// can, with a note saying so.
pub fn method_for(
    ctx: &GpuContext,
    cfg: &RenderConfig,
    asked: bool,
) -> (RenderMethod, Option<String>) {
    match unsupported(ctx, cfg.method) {
        Some(why) if !asked => {
            let m = RenderMethod::ALL
                .into_iter()
                .find(|m| unsupported(ctx, *m).is_none())
                .unwrap_or(cfg.method);
            let note = format!(
                "note: drawing with the {m} method: {} cannot draw on {} ({}): {why}",
                cfg.method,
                ctx.adapter_name(),
                ctx.backend()
            );
            (m, Some(note))
        }
        _ => (cfg.method, None),
    }
}

/// Ground rectangle (min x, min y, max x, max y) whose sun rays can cross
/// the grid box: the box's footprint and its shadow cast from its top.
pub fn shadow_rect(g: &GridInfo, sun: glam::Vec3) -> [f32; 4] {
    shadow_rect_of(g.min, g.max(), sun)
}

/// [`shadow_rect`] of the box (`lo`, `hi`).
pub fn shadow_rect_of(lo: glam::Vec3, hi: glam::Vec3, sun: glam::Vec3) -> [f32; 4] {
    let sun = sun.normalize();
    // Along the sun ray from ground (x, y, 0), height z is reached at x + z·s.
    let s = glam::Vec2::new(sun.x, sun.y) / sun.z.max(0.03);
    let a = lo.truncate() - s * hi.z;
    let b = hi.truncate() - s * hi.z;
    let c = lo.truncate() - s * lo.z.max(0.0);
    let d = hi.truncate() - s * lo.z.max(0.0);
    let min = a.min(c).min(b).min(d);
    let max = a.max(c).max(b).max(d);
    [min.x, min.y, max.x, max.y]
}
