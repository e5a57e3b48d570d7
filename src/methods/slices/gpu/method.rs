//! Schpok's slices as a render method ([`CloudMethod`]): each frame the
//! authored ellipsoids (animated to the frame's time) and the parcels'
//! spheres are sliced by light-aligned planes on the CPU, their vertex
//! field and shadow evaluated on the CPU or by the `slice_field` compute
//! pass, and the planes blended back to front into the float cloud image
//! (the `slices` pass), which the composite lays over the scene. The
//! shadow map marches the same implicit field (`ground_shadow`).

use std::any::Any;

use super::passes::{self, SLICES, SLOTS};
use super::{SlicesGpu, slices_frame};
use crate::config::{RenderConfig, RenderMethod, VertexField};
use crate::error::Result;
use crate::gpu::{GpuContext, begin_pass};
use crate::gpu::frame::FrameInput;
use crate::gpu::layouts::{Layouts, SCENE_FORMAT};
use crate::gpu::method::{Around, CloudMethod, MethodEntry, Needs, Phase, Prepared, Shared};
use crate::gpu::pass::{Slots, flag};
use crate::gpu::pipelines::{Pipeline, PipelineKey};
use crate::gpu::timing::{Recorder, render_writes};
use crate::gpu::uniform::GridInfo;
use crate::methods::slices::model::{Ellipsoid, ParticleConfig, SliceVertex};
use crate::noise::NoiseVolume;

/// The registration of the `slices` method.
pub static ENTRY: MethodEntry = MethodEntry {
    methods: &[RenderMethod::Slices],
    create: |ctx, _, _| Ok(Box::new(Slices::new(&ctx.device))),
    slots: |_| &SLOTS,
    passes: &passes::ALL,
    files: passes::FILES,
    marches_shadow: true,
    pass_names: &[(Phase::Prepare, "slice_field"), (Phase::Resolve, "slices")],
    other_passes: |_| Vec::new(),
    unsupported: |_, _| None,
};

/// The slices' GPU state and the authored clouds they draw.
pub struct Slices {
    gpu: SlicesGpu,
    /// The noise volume on the CPU, for the first octave of the vertex
    /// shadows when the CPU evaluates them.
    noise: Option<(u32, NoiseVolume)>,
    /// Authored clouds drawn besides the parcels.
    ellipsoids: Vec<Ellipsoid>,
    particles: ParticleConfig,
}

impl Slices {
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            gpu: SlicesGpu::new(device),
            noise: None,
            ellipsoids: Vec::new(),
            particles: ParticleConfig::default(),
        }
    }

    /// Sets the authored clouds (a scene's `[[ellipsoids]]` and
    /// `[particles]`) drawn, animated to each frame's time, besides the
    /// frame's parcels.
    pub fn set_authored(&mut self, ellipsoids: &[Ellipsoid], particles: &ParticleConfig) {
        self.ellipsoids = ellipsoids.to_vec();
        self.particles = particles.clone();
    }

    /// Primitives (ellipsoids and parcel spheres) of the last frame.
    pub fn primitives(&self) -> u32 {
        self.gpu.primitives_drawn
    }

    /// The first `count` vertices of the last frame (tests compare the
    /// compute pass with the CPU).
    pub fn vertices(&self, ctx: &GpuContext, count: usize) -> Result<Vec<SliceVertex>> {
        self.gpu.read_vertices(ctx, count)
    }

    fn key(cfg: &RenderConfig, around: Around) -> PipelineKey {
        SLICES.key(
            &SLOTS,
            cfg,
            &[
                ("HAS_TERRAIN", flag(around.terrain)),
                ("EARLY_DISCARD", flag(cfg.slices.early_discard)),
            ],
            SCENE_FORMAT,
        )
    }
}

impl CloudMethod for Slices {
    fn slots(&self, _: &RenderConfig) -> &'static Slots {
        &SLOTS
    }

    fn needs(&self, cfg: &RenderConfig, around: Around) -> Needs {
        let draws = cfg.clouds && around.any_clouds;
        Needs {
            draws,
            marches_shadow: draws,
            cloud_image: draws,
            composite: draws,
            ..Needs::default()
        }
    }

    fn pipeline_keys(&self, cfg: &RenderConfig, around: Around) -> Vec<PipelineKey> {
        if self.needs(cfg, around).draws {
            vec![Self::key(cfg, around)]
        } else {
            Vec::new()
        }
    }

    fn prepare(
        &mut self,
        ctx: &GpuContext,
        layouts: &Layouts,
        cfg: &RenderConfig,
        input: &FrameInput<'_>,
    ) -> Result<Prepared> {
        let mode = cfg.slices.vertex_field;
        let texels = cfg.noise_texels;
        let cpu = mode == VertexField::Cpu;
        if cpu && self.noise.as_ref().map(|(n, _)| *n) != Some(texels) {
            self.noise = Some((texels, NoiseVolume::new(texels)));
        }
        let frame = slices_frame(
            &self.ellipsoids,
            &self.particles,
            input.parcels,
            cfg,
            input.time_s,
            input.sun.direction,
            input.camera.position,
            input.camera.target - input.camera.position,
            self.noise.as_ref().filter(|_| cpu).map(|(_, v)| v),
        )?;
        self.gpu.upload(ctx, layouts, &frame, mode)?;
        // No ray-march grid: "parcel_count" counts the primitives when
        // there are planes to draw, and the grid box is the primitives'
        // bounds, which the cloud-shadow map covers (shadow_rect,
        // shadow.wgsl, slices/shadow_field.wgsl).
        let mut grid = GridInfo::EMPTY;
        if self.gpu.index_count > 0 {
            grid.parcel_count = self.gpu.primitives_drawn;
            if let Some((lo, hi)) =
                crate::methods::slices::model::ellipsoid::bounds_m(&frame.slices.states)
            {
                grid.min = lo;
                grid.cell = (hi - lo).max(glam::Vec3::ONE);
            }
        }
        Ok(Prepared {
            grid,
            any_clouds: grid.parcel_count > 0,
            layer_parcels: Vec::new(),
        })
    }

    fn pass_names(&self, cfg: &RenderConfig, around: Around, phase: Phase) -> Vec<&'static str> {
        let draws = self.needs(cfg, around).draws;
        match phase {
            Phase::Prepare if draws && self.gpu.field_pending() => vec!["slice_field"],
            Phase::Resolve if draws => vec!["slices"],
            _ => Vec::new(),
        }
    }

    fn encode(&mut self, phase: Phase, rec: &mut Recorder<'_>, shared: &Shared<'_>) {
        if !self.needs(shared.cfg, shared.around).draws {
            return;
        }
        match phase {
            Phase::Prepare if self.gpu.field_pending() => {
                let gpu = &self.gpu;
                rec.pass("slice_field", |enc, ts| {
                    gpu.encode_field(enc, shared.common, ts)
                });
            }
            Phase::Resolve => {
                let Some(Pipeline::Render(p)) =
                    shared.pipelines.get(&Self::key(shared.cfg, shared.around))
                else {
                    panic!("ensure built the slices pipeline");
                };
                let image = shared.cloud_image.expect("ensure made the cloud image");
                let gpu = &self.gpu;
                rec.pass("slices", |enc, ts| {
                    let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
                    let mut rp =
                        begin_pass(enc, "slices", &image.view, clear, None, render_writes(ts));
                    rp.set_pipeline(p);
                    rp.set_bind_group(0, shared.common, &[]);
                    rp.set_bind_group(1, shared.depth, &[]);
                    gpu.draw(&mut rp);
                });
            }
            _ => {}
        }
    }

    fn slot_group(&self, _: &RenderConfig) -> Option<&wgpu::BindGroup> {
        self.gpu.bind.as_ref()
    }

    fn background(&self, cfg: &RenderConfig) -> Option<[f32; 3]> {
        // The paper's Background control: a flat colour instead of the sky.
        (!cfg.slices.sky).then_some(cfg.slices.background_colour)
    }

    fn own_pipelines(&self) -> u32 {
        self.gpu.field_pipelines
    }

    fn prebuild(&mut self, ctx: &GpuContext, layouts: &Layouts) -> Result<()> {
        self.gpu.make_field_pass(ctx, layouts)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
