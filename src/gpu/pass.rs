//! What a pass is, as data its owner declares next to its code: the
//! shader file it starts from, its bind-group layouts, its entry points,
//! vertex buffers, blending and depth ([`PassSpec`]); and which files a
//! render method binds to the shared shaders' slots ([`Slots`]). The
//! pipeline cache ([`crate::gpu::pipelines`]) builds any pipeline from a
//! `PassSpec` and a `Slots` alone, so the core names no method, and a
//! method adds passes without touching it.

use crate::gpu::shaders::{self, Assembly, ImportError};

/// A bind-group layout declared as data (`const`), created once per
/// device by [`crate::gpu::layouts::Layouts`] and shared by every pipeline
/// and bind group that names it.
#[derive(Debug)]
pub struct LayoutSpec {
    /// Unique name (the layout's label and its key in the cache).
    pub label: &'static str,
    pub entries: &'static [wgpu::BindGroupLayoutEntry],
}

/// A vertex buffer of a render pass.
#[derive(Debug, Clone, Copy)]
pub struct VertexLayout {
    /// Bytes per vertex.
    pub stride: u64,
    pub attributes: &'static [wgpu::VertexAttribute],
}

/// How the pipeline runs.
#[derive(Debug, Clone, Copy)]
pub enum PassKind {
    /// A compute pipeline of `entry`.
    Compute { entry: &'static str },
    /// A render pipeline (`vs_main`, `fs_main`) drawing one colour target.
    Render {
        vertex: Option<VertexLayout>,
        /// The colour target's format; None: the key's format.
        target: Option<wgpu::TextureFormat>,
        blend: Option<wgpu::BlendState>,
        /// Depth test and write against [`crate::gpu::layouts::DEPTH_FORMAT`].
        depth: bool,
    },
}

/// One pass (or one variant of a pass: another entry point or target)
/// as the pipeline cache builds it.
#[derive(Debug)]
pub struct PassSpec {
    /// Unique name (the pipeline's label and its key in the cache).
    pub name: &'static str,
    /// The root file in `shaders/`.
    pub root: &'static str,
    /// The owner's files it may import besides the shared ones (a
    /// method's folder; empty for a shared pass).
    pub files: &'static [(&'static str, &'static str)],
    /// Layouts of groups 0, 1, 2 (None: a group the pass leaves unused).
    pub groups: &'static [Option<&'static LayoutSpec>],
    /// The module imports the method's slots: its pipeline is built per
    /// method, with the method's field group ([`Slots::group`]) as group
    /// [`SLOT_GROUP`]. False: one pipeline serves every method.
    pub slotted: bool,
    pub kind: PassKind,
}

/// The bind group of a method's slot files (its field: parcels and grid,
/// baked volumes, or the slices' primitives).
pub const SLOT_GROUP: u32 = 3;

/// The files a render method binds to the shared shaders' slots
/// (`#import <name>`, see [`crate::gpu::shaders`]), the shader files it
/// owns and the layout of their bindings.
#[derive(Debug)]
pub struct Slots {
    /// Unique name (the method's, or "none").
    pub name: &'static str,
    /// (slot, file) pairs.
    pub bind: &'static [(&'static str, &'static str)],
    /// The method's own files under `shaders/` (its folder), embedded.
    pub files: &'static [(&'static str, &'static str)],
    /// Layout of group [`SLOT_GROUP`] of the slotted passes (None: the
    /// slot files bind nothing).
    pub group: Option<&'static LayoutSpec>,
}

impl Slots {
    /// No method: the passes that import no slot (sky, composite, tone
    /// map, the sprites) are built once for all methods with these.
    pub const NONE: Slots = Slots {
        name: "none",
        bind: &[],
        files: &[],
        group: None,
    };
}

impl PassSpec {
    /// The slots this pass is built with under a method's `slots`.
    pub fn slots_for(&'static self, slots: &'static Slots) -> &'static Slots {
        if self.slotted { slots } else { &Slots::NONE }
    }

    /// The assembled module under `slots` and the files in it.
    pub fn assembly(&self, slots: &Slots) -> Result<Assembly, ImportError> {
        shaders::assemble_with(self.root, self.files, slots)
    }

    /// The assembled WGSL module under `slots`. The files are embedded at
    /// build time and the tests assemble every module, so an
    /// [`ImportError`] here is a bug in `shaders/`: it panics naming the
    /// file and line.
    pub fn source(&self, slots: &Slots) -> String {
        match self.assembly(slots) {
            Ok(a) => a.source,
            Err(e) => panic!("{} ({}): {e}", self.name, slots.name),
        }
    }

    /// The `override` constants this pass's module declares under
    /// `slots` (read from the module, cached).
    pub fn overrides(&self, slots: &Slots) -> &'static [String] {
        shaders::overrides(self.root, self.files, slots)
    }

    /// Whether this pass's module declares the `override` constant `name`.
    pub fn declares(&self, slots: &Slots, name: &str) -> bool {
        self.overrides(slots).iter().any(|n| n == name)
    }

    /// The layouts of the pipeline under `slots`: the pass's groups, then
    /// the slot group when the pass is slotted and the method has one.
    pub fn layout_list(&self, slots: &Slots) -> Vec<Option<&'static LayoutSpec>> {
        let mut groups: Vec<Option<&'static LayoutSpec>> = self.groups.to_vec();
        if self.slotted
            && let Some(g) = slots.group
        {
            groups.resize(SLOT_GROUP as usize, None);
            groups.push(Some(g));
        }
        groups
    }

    /// What this pass needs from the device under `slots`: read from its
    /// kind, layouts and colour target (a target the key chooses is the
    /// scene's float format, or the output's, which every adapter renders
    /// to) and its module.
    pub fn requirement(&self, slots: &Slots) -> crate::gpu::requires::Requirement {
        let slots = if self.slotted { slots } else { &Slots::NONE };
        let groups: Vec<Option<&[wgpu::BindGroupLayoutEntry]>> = self
            .layout_list(slots)
            .iter()
            .map(|g| g.map(|l| l.entries))
            .collect();
        let (compute, target) = match self.kind {
            PassKind::Compute { .. } => (true, None),
            PassKind::Render { target, blend, .. } => (
                false,
                target
                    .or((!std::ptr::eq(self, &crate::gpu::passes::TONEMAP))
                        .then_some(crate::gpu::layouts::SCENE_FORMAT))
                    .map(|t| (t, blend.is_some())),
            ),
        };
        let source = self.assembly(slots).map(|a| a.source).unwrap_or_default();
        crate::gpu::requires::Requirement::of(self.name, compute, target, &groups, &source)
    }
}

impl PassSpec {
    /// The pipeline key of this pass under `slots`, with its own
    /// `override` values `own` and the shared libraries' switches wherever
    /// its module declares them (`AERIAL_PERSPECTIVE` of air.wgsl,
    /// `GRID_CULLING` of raymarch/field_exact.wgsl), into `format`.
    pub fn key(
        &'static self,
        slots: &'static Slots,
        cfg: &crate::config::RenderConfig,
        own: &[(&'static str, f64)],
        format: wgpu::TextureFormat,
    ) -> crate::gpu::pipelines::PipelineKey {
        let mut c = own.to_vec();
        let slots = self.slots_for(slots);
        for (name, on) in [
            ("AERIAL_PERSPECTIVE", cfg.aerial_perspective),
            ("GRID_CULLING", cfg.grid_culling),
        ] {
            if self.declares(slots, name) {
                c.push((name, if on { 1.0 } else { 0.0 }));
            }
        }
        crate::gpu::pipelines::PipelineKey::new(self, slots, &c, format)
    }
}

/// 1.0 for true, 0.0 for false: a boolean `override` value.
pub fn flag(v: bool) -> f64 {
    if v { 1.0 } else { 0.0 }
}
