//! The pipeline cache: any pipeline built from its [`PassSpec`] and the
//! method's [`Slots`] (the formats and bind-group layouts are in
//! [`crate::gpu::layouts`]).
//!
//! No stalls: a pipeline is keyed by (pass, slots, `override` constants,
//! target format) and, once built, kept for the renderer's life, so clouds
//! vanishing and reappearing, or an option toggled back, never compile a
//! shader again; the renderer builds the cloud pipelines at creation, ahead
//! of the first condensed parcel, and (in the window) those of the settings
//! one click away on a background thread (src/gpu/prebuild.rs). `built`
//! counts creations on the calling thread, `prebuilt` the background's
//! (tests check both).

use std::collections::HashMap;

use crate::error::Result;
use crate::gpu::GpuContext;
use crate::gpu::pass::{PassKind, PassSpec, Slots};
use crate::gpu::prebuild::Prebuilder;

pub use crate::gpu::layouts::{
    CLOUD_DEPTH_FORMAT, CLOUD_TARGET_FORMAT, DEPTH_FORMAT, Layouts, SCENE_FORMAT, SHADOW_FORMAT,
    TEMPORAL_SCALAR_FORMAT,
};

/// What makes two pipelines different: the pass (or variant), the
/// method's slots (for a slotted pass), the `override` constants and the
/// target format.
#[derive(Debug, Clone)]
pub struct PipelineKey {
    pub pass: &'static PassSpec,
    pub slots: &'static Slots,
    /// `override` constants (name, value bits).
    pub constants: Vec<(&'static str, u64)>,
    pub format: wgpu::TextureFormat,
}

impl PartialEq for PipelineKey {
    fn eq(&self, o: &Self) -> bool {
        self.pass.name == o.pass.name
            && self.slots.name == o.slots.name
            && self.constants == o.constants
            && self.format == o.format
    }
}

impl Eq for PipelineKey {}

impl std::hash::Hash for PipelineKey {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        (
            self.pass.name,
            self.slots.name,
            &self.constants,
            self.format,
        )
            .hash(h);
    }
}

impl PipelineKey {
    /// The pipeline of `pass` under a method's `slots` (an unslotted pass
    /// takes [`Slots::NONE`], one pipeline for every method). Panics on a
    /// constant that the module does not declare ([`PassSpec::overrides`]):
    /// wgpu would refuse the pipeline.
    pub fn new(
        pass: &'static PassSpec,
        slots: &'static Slots,
        constants: &[(&'static str, f64)],
        format: wgpu::TextureFormat,
    ) -> Self {
        let slots = pass.slots_for(slots);
        for (name, _) in constants {
            assert!(
                pass.declares(slots, name),
                "{} ({}) declares no override {name}",
                pass.name,
                slots.name
            );
        }
        Self {
            pass,
            slots,
            constants: constants.iter().map(|(n, v)| (*n, v.to_bits())).collect(),
            format,
        }
    }
}

/// A render or compute pipeline.
pub enum Pipeline {
    Render(wgpu::RenderPipeline),
    Compute(wgpu::ComputePipeline),
}

/// Every pipeline built so far; see the module docs.
#[derive(Default)]
pub struct PipelineCache {
    modules: ShaderModules,
    pipelines: HashMap<PipelineKey, Pipeline>,
    /// Pipelines created on the calling thread (a frame waited for them).
    pub built: u32,
    /// Pipelines the background builder created and handed over.
    pub prebuilt: u32,
    /// Builds pipelines the next settings may need on another thread
    /// (None: off, every pipeline is built when first needed).
    prebuilder: Option<Prebuilder>,
}

impl PipelineCache {
    pub fn get(&self, key: &PipelineKey) -> Option<&Pipeline> {
        self.pipelines.get(key)
    }

    /// Builds the pipeline of `key` unless it exists: taken from the
    /// background builder if it has it (waiting for it if it is building
    /// it), else built here. Shader or pipeline errors become an Error, not
    /// wgpu's panic.
    pub fn ensure(&mut self, ctx: &GpuContext, layouts: &Layouts, key: &PipelineKey) -> Result<()> {
        self.collect();
        if self.pipelines.contains_key(key) {
            return Ok(());
        }
        if let Some(pre) = self.prebuilder.as_mut()
            && pre.is_pending(key)
        {
            let done = pre.wait_for(key);
            self.take(done);
            if self.pipelines.contains_key(key) {
                return Ok(());
            }
            // It failed over there: build it here for the error message.
        }
        let what = format!("creating the {} pass ({})", key.pass.name, key.slots.name);
        let pipeline = match crate::gpu::catching(&ctx.device, &what, || {
            self.modules.build(&ctx.device, layouts, key)
        }) {
            Ok(p) => p,
            Err(e) => {
                self.modules.forget(key);
                return Err(e);
            }
        };
        self.built += 1;
        self.pipelines.insert(key.clone(), pipeline);
        Ok(())
    }

    /// Starts or stops building ahead on a background thread.
    pub fn set_prebuild(&mut self, device: Option<(&wgpu::Device, &Layouts)>) {
        self.prebuilder = device.map(|(d, l)| Prebuilder::new(d.clone(), l.clone()));
    }

    /// Whether a background builder is on.
    pub fn prebuilding(&self) -> bool {
        self.prebuilder.is_some()
    }

    /// Asks the background builder for `key` unless it exists (nothing
    /// without one).
    pub fn request(&mut self, key: &PipelineKey) {
        if !self.pipelines.contains_key(key)
            && let Some(pre) = self.prebuilder.as_mut()
        {
            pre.request(key);
        }
    }

    /// Takes what the background builder has finished (does not wait).
    pub fn collect(&mut self) {
        if let Some(pre) = self.prebuilder.as_mut() {
            let done = pre.finished();
            self.take(done);
        }
    }

    /// Waits until the background builder has finished everything asked
    /// of it, and takes it.
    pub fn wait_prebuilt(&mut self) {
        if let Some(pre) = self.prebuilder.as_mut() {
            let done = pre.wait_all();
            self.take(done);
        }
    }

    fn take(&mut self, done: Vec<(PipelineKey, Option<Pipeline>)>) {
        for (key, pipeline) in done {
            if let Some(p) = pipeline
                && !self.pipelines.contains_key(&key)
            {
                self.prebuilt += 1;
                self.pipelines.insert(key, p);
            }
        }
    }
}

/// Shader modules by (root file, slots), compiled once each.
#[derive(Default)]
pub(crate) struct ShaderModules(HashMap<(&'static str, &'static str), wgpu::ShaderModule>);

impl ShaderModules {
    /// Drops the module of `key` (after an error, so a retry recompiles).
    pub(crate) fn forget(&mut self, key: &PipelineKey) {
        self.0.remove(&(key.pass.root, key.slots.name));
    }

    /// Creates the pipeline of `key` (errors go to the device's error
    /// scope).
    pub(crate) fn build(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        key: &PipelineKey,
    ) -> Pipeline {
        let pass = key.pass;
        let module = self
            .0
            .entry((pass.root, key.slots.name))
            .or_insert_with(|| {
                device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(pass.name),
                    source: wgpu::ShaderSource::Wgsl(pass.source(key.slots).into()),
                })
            });
        let groups: Vec<Option<wgpu::BindGroupLayout>> = pass
            .layout_list(key.slots)
            .into_iter()
            .map(|g| g.map(|spec| layouts.get(spec)))
            .collect();
        let group_refs: Vec<Option<&wgpu::BindGroupLayout>> =
            groups.iter().map(Option::as_ref).collect();
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(pass.name),
            bind_group_layouts: &group_refs,
            immediate_size: 0,
        });
        let constants: Vec<(&str, f64)> = key
            .constants
            .iter()
            .map(|(n, b)| (*n, f64::from_bits(*b)))
            .collect();
        let options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            ..Default::default()
        };
        let (vertex, target, blend, depth) = match pass.kind {
            PassKind::Compute { entry } => {
                return Pipeline::Compute(device.create_compute_pipeline(
                    &wgpu::ComputePipelineDescriptor {
                        label: Some(pass.name),
                        layout: Some(&layout),
                        module,
                        entry_point: Some(entry),
                        compilation_options: options,
                        cache: None,
                    },
                ));
            }
            PassKind::Render {
                vertex,
                target,
                blend,
                depth,
            } => (vertex, target, blend, depth),
        };
        let buffers: Vec<Option<wgpu::VertexBufferLayout>> = vertex
            .iter()
            .map(|v| {
                Some(wgpu::VertexBufferLayout {
                    array_stride: v.stride,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: v.attributes,
                })
            })
            .collect();
        let targets = [Some(wgpu::ColorTargetState {
            format: target.unwrap_or(key.format),
            blend,
            write_mask: wgpu::ColorWrites::ALL,
        })];
        Pipeline::Render(
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(pass.name),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: options.clone(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: depth.then(|| wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_main"),
                    compilation_options: options,
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            }),
        )
    }
}
