//! The renderer: owns the GPU resources of the shared passes, the render
//! method's cloud data ([`crate::methods::raymarch`],
//! [`crate::methods::sprites::gpu`], [`crate::methods::slices::gpu`]) and the
//! pipelines, and draws a frame into any texture view (window surface or
//! offscreen).
//! Pass order ([`Pass::ALL`]): bake (`baked` method, only when the
//! parcels, the shell or the sun moved) → slice_field (`slices` with
//! `vertex_field = "gpu"`) → shadow map (kept from an earlier frame while
//! nothing it shows changed) → sky → terrain → clouds (fragment, or
//! compute) → sprites (the impostor ring's face first; behind the clouds'
//! depth when both draw) → temporal resolve → slicing planes into the
//! float cloud target → composite (of the compute march, the temporal
//! image or the planes, then the sprites in front of the clouds) →
//! tonemap. Sky, terrain and clouds write linear radiance into one HDR
//! scene target ([`SCENE_FORMAT`]) and composite there in linear light;
//! the tone-map pass alone writes the output (window surface or headless
//! texture, the same path for both).
//! This file holds the state and the configuration; `prepare` uploads a
//! frame; `passes` says which passes and pipelines a frame needs;
//! `ensure` creates them; `draw` encodes and times a frame; `resources`
//! holds the textures and bind groups it creates; `ring` the impostor
//! ring's GPU side and [`temporal`] the temporal amortisation.
//!
//! "Leave out what a scene does not need": [`Features`] decides which passes
//! and resources exist; pipelines come from a cache keyed by pass, method
//! and `override` constants ([`crate::gpu::pipelines`]), so a toggled
//! setting builds only pipelines it has never seen and clouds appearing
//! never wait for a shader compile. `prepare` uploads (and times the
//! upload); `render` draws and times each pass ([`crate::gpu::timing`]).

use std::time::Instant;

use crate::config::method::{MarchPath, RenderMethod};
use crate::config::{RenderConfig, TerrainConfig};
use crate::error::{Error, Result};
use crate::gpu::GpuContext;
use crate::gpu::layouts::Layouts;
use crate::gpu::noise;
use crate::gpu::pipelines::{PipelineCache, PipelineKey};
use crate::gpu::timing::Timestamps;
use crate::gpu::uniform::{FrameUniform, GridInfo};
use crate::landscape::terrain;
use crate::methods::raymarch::auto_march::AutoMarch;
use crate::methods::raymarch::baked::{BakeInfo, BakedField};
use crate::methods::raymarch::exact::ExactField;
use crate::methods::raymarch::pack::{GridUniform, ParcelsUniform};
use crate::methods::slices::gpu::{SlicesGpu, slices_frame};
use crate::methods::sprites::gpu::{RingGpu, SpriteScene, SpriteStats, SpritesGpu};
use crate::noise::NoiseVolume;
use crate::physics::CloudParcel;
use crate::render::{Features, FrameInput};

mod draw;
mod ensure;
mod passes;
pub use passes::{Pass, modules, shader_files, slots};
mod prepare;
mod resources;
mod ring;

use crate::gpu::resources::check_size;
pub(crate) use crate::gpu::resources::texture_2d;
use crate::methods::raymarch::temporal;
use resources::{CloudTarget, SceneTarget, make_bind_common, make_bind_field};

pub use crate::gpu::pipelines::{DEPTH_FORMAT, SCENE_FORMAT, SHADOW_FORMAT};
pub(crate) use crate::gpu::timing::read_buffer;
pub use crate::gpu::timing::{FrameTimings, TimingMode};

struct TerrainGpu {
    cfg: TerrainConfig,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

/// Draws frames; see the module docs.
pub struct Renderer {
    cfg: RenderConfig,
    format: wgpu::TextureFormat,
    width: u32,
    height: u32,
    features: Features,
    /// The last prepared frame had parcels (true before the first).
    any_clouds: bool,
    grid_info: GridInfo,
    upload_ms: f64,

    frame_buf: wgpu::Buffer,
    exact: ExactField,
    baked: BakedField,
    /// `baked.generation` that `bind_field` holds.
    bound_generation: u64,
    /// Group 3 under `baked`: its field, occupancy and light volume.
    bind_field: wgpu::BindGroup,
    noise_texels: u32,
    noise_view: wgpu::TextureView,
    repeat_sampler: wgpu::Sampler,
    clamp_sampler: wgpu::Sampler,
    layouts: Layouts,
    bind_common: wgpu::BindGroup,

    depth_view: Option<wgpu::TextureView>,
    dummy_depth_view: wgpu::TextureView,
    shadow_view: Option<(u32, wgpu::TextureView)>,
    /// The shadow map holds the `baked` clouds of the last bake under the
    /// current settings (see [`Renderer::shadow_reusable`]).
    shadow_fresh: bool,
    white_view: wgpu::TextureView,
    terrain: Option<TerrainGpu>,

    pipelines: PipelineCache,
    bake_pipelines: u32,
    bind_terrain: Option<wgpu::BindGroup>,
    bind_clouds: Option<wgpu::BindGroup>,
    timestamps: Option<Timestamps>,
    /// How passes are timed (GPU modes fall back to Cpu without timestamps).
    timing: TimingMode,
    /// Re-bake every frame (bench: the cost when every parcel moves).
    always_bake: bool,
    /// The compute march's output: (view, its storage bind group, its
    /// sampled bind group for the composite, the cloud-depth view).
    cloud_target: Option<CloudTarget>,
    /// Cloud depth bound while no march target exists (never read then).
    dummy_cloud_depth_view: wgpu::TextureView,
    /// Group 1 of the sprite pipelines (terrain and cloud depth).
    bind_sprites: Option<wgpu::BindGroup>,
    /// Box around this frame's directly drawn sprites (min, max; None
    /// without any): the cloud-shadow map covers it. units: m
    sprite_box: Option<(glam::Vec3, glam::Vec3)>,
    /// `march = "auto"`: measurements and decision.
    auto_march: AutoMarch,
    /// The HDR scene target (made by `ensure`, dropped on resize).
    scene: Option<SceneTarget>,
    /// The scene's sprite clouds and their per-sprite state.
    sprite_scene: SpriteScene,
    /// Atlas and instances, created with the first sprite.
    sprites: Option<SpritesGpu>,
    /// The `slices` method's buffers.
    slices: SlicesGpu,
    /// The noise volume on the CPU (its side), for the first octave of the
    /// vertex shadows when the CPU evaluates them (`slices` method).
    slices_noise: Option<(u32, NoiseVolume)>,
    /// Authored clouds the `slices` method draws besides the parcels.
    authored: (
        Vec<crate::methods::slices::model::Ellipsoid>,
        crate::methods::slices::model::ParticleConfig,
    ),
    /// The impostor ring (`[render.sprites] impostor_radius_m`).
    ring: Option<RingGpu>,
    /// The temporal path's targets and history (`[render] temporal`).
    temporal: Option<temporal::TemporalGpu>,
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
        check_size(ctx, width, height)?;
        let device = &ctx.device;
        let limits = device.limits();
        for (name, size) in [
            ("frame uniform", std::mem::size_of::<FrameUniform>()),
            ("parcel uniform", std::mem::size_of::<ParcelsUniform>()),
            ("grid uniform", std::mem::size_of::<GridUniform>()),
        ] {
            if size as u64 > limits.max_uniform_buffer_binding_size {
                return Err(Error::Gpu(format!(
                    "the {name} needs {size} bytes but this device binds at most {} bytes of uniforms; lower MAX_PARCELS/MAX_GRID_* in src/methods/raymarch/pack.rs",
                    limits.max_uniform_buffer_binding_size
                )));
            }
        }
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

        let frame_buf = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniform"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layouts = Layouts::new(device);
        let exact = ExactField::new(device, &layouts);
        let mut bake_pipelines = 0;
        let baked = BakedField::new(ctx, &frame_buf, &mut bake_pipelines)?;

        let repeat_sampler = noise::repeat_sampler(device);
        let clamp_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("clamp"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let noise_view =
            noise::texture(&NoiseVolume::new(cfg.noise_texels), &ctx.device, &ctx.queue);

        let slices = SlicesGpu::new(device);

        let dummy_depth_view = texture_2d(
            device,
            "dummy depth",
            1,
            1,
            DEPTH_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&Default::default());
        let dummy_cloud_depth_view = texture_2d(
            device,
            "no cloud depth",
            1,
            1,
            crate::gpu::pipelines::CLOUD_DEPTH_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING,
        )
        .create_view(&Default::default());
        let white = texture_2d(
            device,
            "no shadow",
            1,
            1,
            SHADOW_FORMAT,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        ctx.queue.write_texture(
            white.as_image_copy(),
            &[255],
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(1),
                rows_per_image: None,
            },
            wgpu::Extent3d {
                width: 1,
                height: 1,
                depth_or_array_layers: 1,
            },
        );
        let white_view = white.create_view(&Default::default());

        let timestamps = ctx
            .timestamps
            .then(|| Timestamps::new(device, Pass::ALL.len() as u32));
        let bind_common = make_bind_common(
            device,
            &layouts,
            &frame_buf,
            &noise_view,
            &repeat_sampler,
            &clamp_sampler,
        );
        let bind_field = make_bind_field(device, &layouts, &baked);
        let mut r = Self {
            cfg: cfg.clone(),
            format: target_format,
            width,
            height,
            // Built for a frame with clouds, ahead of the first condensed
            // parcel (no compile when it appears).
            features: Features::new(cfg, true),
            any_clouds: true,
            grid_info: crate::methods::raymarch::pack::pack(&[], cfg.shell_m, cfg.radius_scale)?
                .info,
            upload_ms: 0.0,
            frame_buf,
            bound_generation: baked.generation,
            bind_field,
            exact,
            baked,
            noise_texels: cfg.noise_texels,
            noise_view,
            repeat_sampler,
            clamp_sampler,
            layouts,
            bind_common,
            depth_view: None,
            dummy_depth_view,
            shadow_view: None,
            white_view,
            terrain: None,
            pipelines: PipelineCache::default(),
            bake_pipelines,
            bind_terrain: None,
            bind_clouds: None,
            timestamps,
            timing: TimingMode::GpuBlocking,
            always_bake: false,
            shadow_fresh: false,
            cloud_target: None,
            dummy_cloud_depth_view,
            bind_sprites: None,
            sprite_box: None,
            auto_march: AutoMarch::default(),
            scene: None,
            sprite_scene: SpriteScene::default(),
            sprites: None,
            slices,
            slices_noise: None,
            authored: Default::default(),
            ring: None,
            temporal: None,
        };
        r.ensure(ctx)?;
        Ok(r)
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
        self.authored = (ellipsoids.to_vec(), particles.clone());
    }

    /// Primitives (ellipsoids and parcel spheres) the `slices` method drew
    /// in the last prepared frame.
    pub fn slice_primitives(&self) -> u32 {
        self.slices.primitives_drawn
    }

    /// The slices' vertex buffer after the last frame (tests compare the
    /// compute pass with the CPU): the first `count` vertices.
    pub fn slice_vertices(
        &self,
        ctx: &GpuContext,
        count: usize,
    ) -> Result<Vec<crate::methods::slices::model::SliceVertex>> {
        self.slices.read_vertices(ctx, count)
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
        self.baked.info()
    }

    /// Names of the passes that exist for the current features, in
    /// execution order (the bake, and under `baked` the shadow map, run
    /// only in frames whose parcels or sun moved).
    pub fn pass_names(&self) -> Vec<&'static str> {
        Pass::ALL
            .into_iter()
            .filter(|p| self.needed(*p))
            .map(|p| p.name())
            .collect()
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
        self.always_bake = on;
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
            self.bind_clouds = None;
            self.cloud_target = None;
            self.scene = None;
            self.temporal = None;
            self.ensure(ctx)?;
        }
        Ok(())
    }

    /// Applies new settings, rebuilding only what depends on what changed.
    /// A new method takes effect at the next `prepare`.
    pub fn set_config(&mut self, ctx: &GpuContext, cfg: &RenderConfig) -> Result<()> {
        cfg.validate()?;
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
        self.features = self.features_for(self.any_clouds, !self.sprite_scene.is_empty());
        // Another march (step, noise, light…) gives other images: the
        // temporal history starts again.
        if let Some(t) = self.temporal.as_mut() {
            t.history_valid = false;
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
        self.features = self.features_for(self.any_clouds, !self.sprite_scene.is_empty());
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
