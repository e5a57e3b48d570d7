//! Wang's sprites as a render method ([`CloudMethod`]): the frame's
//! condensed parcels become sprite clouds of the renderer's sprite layer
//! (the same layer that draws a scene's `[[sprite_clouds]]` and
//! `[[layers]]` under every method: shading, sorting, the impostor ring
//! and the shadow splats are the layer's). The method itself has no pass.

use std::any::Any;

use super::passes::SLOTS;
use crate::config::{RenderConfig, RenderMethod};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::gpu::frame::FrameInput;
use crate::gpu::layouts::Layouts;
use crate::gpu::method::{Around, CloudMethod, MethodEntry, Needs, Phase, Prepared, Shared};
use crate::gpu::pass::Slots;
use crate::gpu::pipelines::PipelineKey;
use crate::gpu::timing::Recorder;
use crate::gpu::uniform::GridInfo;
use crate::physics::CloudParcel;

/// The registration of the `sprites` method.
pub static ENTRY: MethodEntry = MethodEntry {
    methods: &[RenderMethod::Sprites],
    create: |_, _, _| Ok(Box::new(Sprites)),
    slots: |_| &SLOTS,
    passes: &[],
    files: super::passes::FILES,
    marches_shadow: false,
    pass_names: &[],
    other_passes: |_| Vec::new(),
    unsupported: |_, _| None,
};

/// The `sprites` method; see the module docs.
pub struct Sprites;

impl CloudMethod for Sprites {
    fn slots(&self, _: &RenderConfig) -> &'static Slots {
        &SLOTS
    }

    fn needs(&self, cfg: &RenderConfig, around: Around) -> Needs {
        Needs {
            feeds_layer: cfg.clouds && around.any_clouds,
            ..Needs::default()
        }
    }

    fn pipeline_keys(&self, _: &RenderConfig, _: Around) -> Vec<PipelineKey> {
        Vec::new()
    }

    fn prepare(
        &mut self,
        _: &GpuContext,
        _: &Layouts,
        cfg: &RenderConfig,
        input: &FrameInput<'_>,
    ) -> Result<Prepared> {
        // The drawn spheres are radius_scale × the parcels' (§6.1, as the
        // ray-march draws them): the sprite clouds fill those.
        let layer_parcels = if cfg.clouds {
            input
                .parcels
                .iter()
                .map(|p| CloudParcel {
                    radius_m: p.radius_m * cfg.radius_scale,
                    ..*p
                })
                .collect()
        } else {
            Vec::new()
        };
        Ok(Prepared {
            grid: GridInfo::EMPTY,
            any_clouds: input.parcels.iter().any(|p| p.fill > 0.0),
            layer_parcels,
        })
    }

    fn pass_names(&self, _: &RenderConfig, _: Around, _: Phase) -> Vec<&'static str> {
        Vec::new()
    }

    fn encode(&mut self, _: Phase, _: &mut Recorder<'_>, _: &Shared<'_>) {}

    fn slot_group(&self, _: &RenderConfig) -> Option<&wgpu::BindGroup> {
        None
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
