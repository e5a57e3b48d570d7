//! The ray-march as a render method ([`CloudMethod`]): `exact` uploads
//! the parcels and the culling grid as uniforms, `baked` splats them into
//! a 3D field (the `bake` pass, only when they moved); both march the
//! same WGSL in a fragment pass over the scene or in a compute pass into
//! the float cloud image (`march`: fragment, compute, or `auto`, which
//! measures both), or one pixel per 2×2 or 4×4 block with the temporal resolve.

use std::any::Any;

use super::auto_march::AutoMarch;
use super::baked::{BakeInfo, BakedField};
use super::exact::ExactField;
use super::pack::{GridUniform, ParcelsUniform};
use super::passes::{self, BAKED, BAKED_FIELD, CLOUDS, CLOUDS_COMPUTE, CLOUDS_TEMPORAL, EXACT};
use super::temporal::TemporalGpu;
use crate::config::{MarchPath, RenderConfig, RenderMethod};
use crate::error::{Error, Result};
use crate::gpu::{GpuContext, begin_pass};
use crate::gpu::frame::FrameInput;
use crate::gpu::layouts::{Layouts, SCENE_FORMAT};
use crate::gpu::method::{Around, CloudMethod, MethodEntry, Needs, Phase, Prepared, Shared};
use crate::gpu::pass::{PassSpec, SLOT_GROUP, Slots, flag};
use crate::gpu::pipelines::{Pipeline, PipelineKey};
use crate::gpu::resources::bind_in_order;
use crate::gpu::timing::{FrameTimings, Recorder, compute_writes, render_writes};
use crate::gpu::uniform::FrameUniform;

/// The registration of the `baked` and `exact` methods.
pub static ENTRY: MethodEntry = MethodEntry {
    methods: &[RenderMethod::Baked, RenderMethod::Exact],
    create: |ctx, layouts, frame| Ok(Box::new(Raymarch::new(ctx, layouts, frame)?)),
    slots: |m| {
        if m == RenderMethod::Exact {
            &EXACT
        } else {
            &BAKED
        }
    },
    passes: &passes::ALL,
    files: passes::FILES,
    marches_shadow: true,
    pass_names: &[
        (Phase::Prepare, "bake"),
        (Phase::Clouds, "clouds"),
        (Phase::Resolve, "temporal"),
    ],
    other_passes: |m| {
        if m == RenderMethod::Baked {
            vec![super::baked::requirement()]
        } else {
            Vec::new()
        }
    },
    unsupported: |info, m| {
        // Measured on Mesa's llvmpipe OpenGL 4.5: the bake's field, written
        // by compute passes into 3D storage textures, reaches the march
        // wrong (clouds spread over the sky, 8/255 mean difference from
        // the same frame on Vulkan), while `exact` draws the Vulkan image.
        (info.backend == wgpu::Backend::Gl && m == RenderMethod::Baked).then_some(
            "its compute bake does not reach the march correctly on wgpu's OpenGL backend",
        )
    },
};

/// The ray-march's GPU state; see the module docs.
pub struct Raymarch {
    exact: ExactField,
    baked: BakedField,
    /// Group 3 under `baked` and the bake generation it holds.
    bind_field: wgpu::BindGroup,
    bound_generation: u64,
    bake_pipelines: u32,
    /// Re-bake every frame (bench: the cost when every parcel moves).
    always_bake: bool,
    auto_march: AutoMarch,
    /// The temporal path's targets and history (`[render] temporal`).
    temporal: Option<TemporalGpu>,
    size: (u32, u32),
}

/// The ray-march's choices for one frame.
#[derive(Debug, Clone, Copy)]
struct Frame {
    draws: bool,
    /// Sprites draw too: the march runs in compute and leaves its depth.
    split: bool,
    temporal: bool,
    /// Side of the temporal path's block (one pixel of each marched).
    block: u32,
    compute: bool,
}

impl Raymarch {
    pub fn new(ctx: &GpuContext, layouts: &Layouts, frame_buf: &wgpu::Buffer) -> Result<Self> {
        let limit = ctx.device.limits().max_uniform_buffer_binding_size;
        for (name, size) in [
            ("parcel uniform", std::mem::size_of::<ParcelsUniform>()),
            ("grid uniform", std::mem::size_of::<GridUniform>()),
        ] {
            if size as u64 > limit {
                return Err(Error::Gpu(format!(
                    "the {name} needs {size} bytes but this device binds at most {limit} bytes of uniforms; lower MAX_PARCELS/MAX_GRID_* in src/methods/raymarch/pack.rs"
                )));
            }
        }
        let mut bake_pipelines = 0;
        let baked = BakedField::new(ctx, frame_buf, &mut bake_pipelines)?;
        let bind_field = bind_field(&ctx.device, layouts, &baked);
        Ok(Self {
            exact: ExactField::new(&ctx.device, layouts),
            bound_generation: baked.generation,
            baked,
            bind_field,
            bake_pipelines,
            always_bake: false,
            auto_march: AutoMarch::default(),
            temporal: None,
            size: (1, 1),
        })
    }

    fn frame(&self, cfg: &RenderConfig, around: Around) -> Frame {
        let draws = cfg.clouds && around.any_clouds;
        let split = draws && around.layers;
        // Sprites sort against a full-size cloud depth, which the
        // temporal march (one pixel per block) does not leave: with both, every
        // pixel is marched each frame.
        let block = cfg.temporal.and_then(|t| t.block()).unwrap_or(1);
        let temporal = block > 1 && draws && !around.layers;
        let compute = temporal || self.auto_march.path(cfg.march) == MarchPath::Compute || split;
        Frame {
            draws,
            split,
            temporal,
            block,
            compute,
        }
    }

    /// The cloud pass's pipeline this frame.
    fn cloud_key(
        &self,
        cfg: &RenderConfig,
        around: Around,
        spec: &'static PassSpec,
    ) -> PipelineKey {
        let own = [
            ("USE_NORMALS", flag(cfg.normals)),
            ("HAS_TERRAIN", flag(around.terrain)),
            ("MARCH_STEPS", flag(cfg.debug_march_steps)),
        ];
        spec.key(ray_slots(cfg), cfg, &own, SCENE_FORMAT)
    }

    fn cloud_spec(f: Frame) -> &'static PassSpec {
        match (f.temporal, f.compute) {
            (true, _) => &CLOUDS_TEMPORAL,
            (false, true) => &CLOUDS_COMPUTE,
            (false, false) => &CLOUDS,
        }
    }

    /// What the baked field covers (zeros before the first bake).
    pub fn bake_info(&self) -> BakeInfo {
        self.baked.info()
    }

    /// Re-bake every frame, moved or not.
    pub fn set_always_bake(&mut self, on: bool) {
        self.always_bake = on;
    }

    /// The march path in use: the configured one, or what `auto` chose
    /// (None while it is still measuring); compute on the temporal path.
    pub fn march_path(&self, cfg: &RenderConfig, around: Around) -> Option<MarchPath> {
        if self.frame(cfg, around).temporal {
            return Some(MarchPath::Compute);
        }
        match cfg.march {
            MarchPath::Auto => self.auto_march.chosen(),
            p => Some(p),
        }
    }

    /// Frames drawn on the temporal path since its history began.
    pub fn temporal_frames(&self) -> u32 {
        self.temporal
            .as_ref()
            .filter(|t| t.history_valid)
            .map_or(0, |t| t.frame_index)
    }
}

/// The method's slots under `cfg`.
fn ray_slots(cfg: &RenderConfig) -> &'static Slots {
    (ENTRY.slots)(cfg.method)
}

/// Group 3 under `baked`: the field it last baked.
fn bind_field(device: &wgpu::Device, layouts: &Layouts, baked: &BakedField) -> wgpu::BindGroup {
    let (field, light, occupancy, clip) = baked.field();
    bind_in_order(
        device,
        "baked: field, occupancy, light, clipmap",
        &layouts.get(&BAKED_FIELD),
        vec![
            wgpu::BindingResource::TextureView(field),
            occupancy.as_entire_binding(),
            wgpu::BindingResource::TextureView(light),
            clip.as_entire_binding(),
        ],
    )
}

impl CloudMethod for Raymarch {
    fn slots(&self, cfg: &RenderConfig) -> &'static Slots {
        ray_slots(cfg)
    }

    fn needs(&self, cfg: &RenderConfig, around: Around) -> Needs {
        let f = self.frame(cfg, around);
        Needs {
            draws: f.draws,
            feeds_layer: false,
            marches_shadow: f.draws,
            shadow_in_region: f.draws,
            cloud_image: f.draws && ((!f.temporal && cfg.march != MarchPath::Fragment) || f.split),
            composite: f.draws && f.compute,
            cloud_depth: f.split,
        }
    }

    fn pipeline_keys(&self, cfg: &RenderConfig, around: Around) -> Vec<PipelineKey> {
        let f = self.frame(cfg, around);
        if !f.draws {
            return Vec::new();
        }
        let mut keys = vec![self.cloud_key(cfg, around, Self::cloud_spec(f))];
        if f.temporal {
            keys.push(passes::TEMPORAL.key(ray_slots(cfg), cfg, &[], SCENE_FORMAT));
        }
        // Both paths while `auto` is still measuring (it alternates), with
        // the compute path's composite.
        if cfg.march == MarchPath::Auto && self.auto_march.chosen().is_none() && !f.temporal {
            let other = if f.compute { &CLOUDS } else { &CLOUDS_COMPUTE };
            keys.push(self.cloud_key(cfg, around, other));
            keys.push(crate::gpu::passes::COMPOSITE.key(ray_slots(cfg), cfg, &[], SCENE_FORMAT));
        }
        keys
    }

    fn prepare(
        &mut self,
        ctx: &GpuContext,
        layouts: &Layouts,
        cfg: &RenderConfig,
        input: &FrameInput<'_>,
    ) -> Result<Prepared> {
        let (shell, scale) = (cfg.shell_m, cfg.radius_scale);
        let grid = if cfg.method == RenderMethod::Exact {
            self.exact.upload(ctx, input.parcels, shell, scale)?
        } else {
            let sun = input.sun.direction.normalize();
            let eye = input.camera.position;
            self.baked.update(ctx, input.parcels, shell, scale, sun, eye)?
        };
        if self.always_bake {
            self.baked.invalidate();
        }
        if self.baked.generation != self.bound_generation {
            self.bind_field = bind_field(&ctx.device, layouts, &self.baked);
            self.bound_generation = self.baked.generation;
        }
        Ok(Prepared {
            grid,
            any_clouds: grid.parcel_count > 0,
            layer_parcels: Vec::new(),
        })
    }

    fn prepared(&mut self, ctx: &GpuContext, frame: &FrameUniform) {
        if let Some(t) = self.temporal.as_mut() {
            let eye = glam::Vec4::from(frame.camera_pos).truncate();
            t.prepare(
                &ctx.queue,
                glam::Mat4::from_cols_array_2d(&frame.eye_from_clip).inverse(),
                eye,
            );
        }
    }

    fn ensure(
        &mut self,
        ctx: &GpuContext,
        layouts: &Layouts,
        cfg: &RenderConfig,
        around: Around,
        size: (u32, u32),
    ) -> Result<()> {
        if size != self.size {
            self.temporal = None;
            self.size = size;
        }
        let f = self.frame(cfg, around);
        if !f.temporal {
            self.temporal = None;
        } else if self.temporal.as_ref().is_none_or(|t| t.block != f.block) {
            let t = TemporalGpu::new(&ctx.device, layouts, size.0, size.1, f.block);
            self.temporal = Some(t);
        }
        Ok(())
    }

    fn resize(&mut self) {
        self.temporal = None;
    }

    fn settings_changed(&mut self) {
        // Another march (step, noise, light…) gives other images: the
        // temporal history starts again.
        if let Some(t) = self.temporal.as_mut() {
            t.history_valid = false;
        }
    }

    fn pass_names(&self, cfg: &RenderConfig, around: Around, phase: Phase) -> Vec<&'static str> {
        let f = self.frame(cfg, around);
        let on = match phase {
            Phase::Prepare => f.draws && cfg.method == RenderMethod::Baked,
            Phase::Clouds => f.draws,
            Phase::Resolve => f.temporal,
        };
        let name = ENTRY.pass_names.iter().find(|(p, _)| *p == phase);
        name.filter(|_| on).map(|(_, n)| *n).into_iter().collect()
    }

    fn encode(&mut self, phase: Phase, rec: &mut Recorder<'_>, shared: &Shared<'_>) {
        let (cfg, around) = (shared.cfg, shared.around);
        let f = self.frame(cfg, around);
        if !f.draws {
            return;
        }
        match phase {
            Phase::Prepare => {
                if cfg.method == RenderMethod::Baked && self.baked.dirty() {
                    let baked = &mut self.baked;
                    rec.pass("bake", |enc, ts| baked.encode(enc, ts));
                }
            }
            Phase::Clouds => {
                let key = self.cloud_key(cfg, around, Self::cloud_spec(f));
                let slot = self.slot_group(cfg);
                match shared.pipelines.get(&key) {
                    Some(Pipeline::Compute(p)) => rec.pass("clouds", |enc, ts| {
                        let mut cp = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                            label: Some("clouds"),
                            timestamp_writes: compute_writes(ts),
                        });
                        cp.set_pipeline(p);
                        cp.set_bind_group(0, shared.common, &[]);
                        cp.set_bind_group(1, shared.depth, &[]);
                        cp.set_bind_group(SLOT_GROUP, slot, &[]);
                        let (x, y) = match (&self.temporal, shared.cloud_image) {
                            (Some(t), _) if f.temporal => {
                                cp.set_bind_group(2, &t.march_bind, &[]);
                                t.march_workgroups()
                            }
                            (_, Some(image)) => {
                                cp.set_bind_group(2, &image.compute_out, &[]);
                                full(shared.size)
                            }
                            _ => unreachable!("ensure made the compute march's target"),
                        };
                        cp.dispatch_workgroups(x, y, 1);
                    }),
                    Some(Pipeline::Render(p)) => rec.pass("clouds", |enc, ts| {
                        let (scene, load) = (shared.scene, wgpu::LoadOp::Load);
                        let mut rp =
                            begin_pass(enc, "clouds", scene, load, None, render_writes(ts));
                        rp.set_pipeline(p);
                        rp.set_bind_group(0, shared.common, &[]);
                        rp.set_bind_group(1, shared.depth, &[]);
                        rp.set_bind_group(SLOT_GROUP, slot, &[]);
                        rp.draw(0..3, 0..1);
                    }),
                    None => panic!("ensure built the cloud pipeline"),
                }
            }
            Phase::Resolve => {
                let (Some(t), true) = (&self.temporal, f.temporal) else {
                    return;
                };
                let key = passes::TEMPORAL.key(ray_slots(cfg), cfg, &[], SCENE_FORMAT);
                let Some(Pipeline::Compute(p)) = shared.pipelines.get(&key) else {
                    panic!("ensure built the temporal resolve");
                };
                rec.pass("temporal", |enc, ts| {
                    let mut cp = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some("temporal"),
                        timestamp_writes: compute_writes(ts),
                    });
                    cp.set_pipeline(p);
                    cp.set_bind_group(0, shared.common, &[]);
                    cp.set_bind_group(1, t.resolve_bind(), &[]);
                    let (x, y) = full(shared.size);
                    cp.dispatch_workgroups(x, y, 1);
                });
            }
        }
    }

    fn slot_group(&self, cfg: &RenderConfig) -> Option<&wgpu::BindGroup> {
        Some(if cfg.method == RenderMethod::Exact {
            &self.exact.bind
        } else {
            &self.bind_field
        })
    }

    fn composite_input<'a>(&'a self, shared: &'a Shared<'a>) -> Option<&'a wgpu::BindGroup> {
        match &self.temporal {
            Some(t) => Some(t.composite_bind()),
            None => shared.cloud_image.map(|c| &c.composite_in),
        }
    }

    fn composite_foldable(&self, cfg: &RenderConfig, around: Around) -> bool {
        // Undecided `auto` knows a compute frame by its composite pass.
        self.march_path(cfg, around).is_some()
    }

    fn shadow_reusable(&self, cfg: &RenderConfig) -> bool {
        // The map shows the `baked` clouds of the last bake until the
        // parcels, the shell or the sun move.
        cfg.method == RenderMethod::Baked && !self.baked.dirty()
    }

    fn frame_drawn(&mut self, cfg: &RenderConfig, around: Around, t: &FrameTimings) -> bool {
        if let Some(t) = self.temporal.as_mut() {
            t.finish_frame();
        }
        let f = self.frame(cfg, around);
        // The temporal path, and frames with sprites (which sort against
        // the compute march's cloud depth), always march in compute: such
        // frames say nothing about fragment against compute.
        if f.temporal || f.split {
            return false;
        }
        if f.draws {
            self.auto_march.drew();
        }
        let was = self.auto_march.chosen();
        self.auto_march.record(t);
        was != self.auto_march.chosen()
    }

    fn own_pipelines(&self) -> u32 {
        self.bake_pipelines
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// Workgroups (8×8) covering a frame of `size` pixels.
fn full(size: (u32, u32)) -> (u32, u32) {
    (size.0.div_ceil(8), size.1.div_ceil(8))
}
