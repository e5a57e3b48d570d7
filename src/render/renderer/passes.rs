//! Which passes, pipelines and `override` constants a frame needs: the
//! features of a frame with or without clouds and sprites, the pipeline
//! keys of each pass, and the march path (fragment, compute, temporal).

use super::*;
use crate::gpu::pass::{PassSpec, Slots};
use crate::gpu::passes::{COMPOSITE, SHADOW, SKY, TERRAIN, TONEMAP};
use crate::methods::raymarch::passes as raymarch;
use crate::methods::slices::gpu::passes as slices;
use crate::methods::sprites::gpu::passes as sprites;

/// The passes of a frame, in the order they run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pass {
    /// Compute bake of the macro field (`baked` method only).
    Bake,
    /// Compute pass of the slice vertices' field and shadow (`slices`
    /// method with `vertex_field = "gpu"` only).
    SliceField,
    Shadow,
    Sky,
    Terrain,
    Clouds,
    /// Sprite clouds (the `sprites` method's parcels, and a scene's
    /// `[[sprite_clouds]]`/`[[layers]]` under any method). With ray-marched
    /// clouds in the frame, the march (compute) runs first and this pass
    /// draws the sprite fragments behind its cloud depth; the composite
    /// then blends the clouds and draws the fragments in front.
    Sprites,
    /// Temporal resolve of the quarter-rate march (`[render] temporal`,
    /// compute): reprojects and accumulates into the full-size cloud image.
    Temporal,
    /// Slicing planes into the float cloud target (`slices` method only).
    Slices,
    /// Blends the compute march's (or the slices') texture over the target.
    Composite,
    /// The HDR scene target, tone-mapped once into the output.
    Tonemap,
}

impl Pass {
    /// All passes in execution order.
    pub const ALL: [Pass; 11] = [
        Pass::Bake,
        Pass::SliceField,
        Pass::Shadow,
        Pass::Sky,
        Pass::Terrain,
        Pass::Clouds,
        Pass::Sprites,
        Pass::Temporal,
        Pass::Slices,
        Pass::Composite,
        Pass::Tonemap,
    ];

    /// Name used in timings and `Renderer::pass_names`.
    pub fn name(self) -> &'static str {
        match self {
            Pass::Bake => "bake",
            Pass::SliceField => "slice_field",
            Pass::Shadow => "shadow",
            Pass::Sky => "sky",
            Pass::Terrain => "terrain",
            Pass::Sprites => "sprites",
            Pass::Clouds => "clouds",
            Pass::Temporal => "temporal",
            Pass::Slices => "slices",
            Pass::Composite => "composite",
            Pass::Tonemap => "tonemap",
        }
    }
}

/// The files `method` binds to the shared shaders' slots.
pub fn slots(method: RenderMethod) -> &'static Slots {
    match method {
        RenderMethod::Exact => &raymarch::EXACT,
        RenderMethod::Baked => &raymarch::BAKED,
        RenderMethod::Sprites => &sprites::SLOTS,
        RenderMethod::Slices => &slices::SLOTS,
    }
}

/// Every module a pipeline of any method is built from: (pass, slots),
/// each once (the shader tests assemble and validate them all).
pub fn modules() -> Vec<(&'static PassSpec, &'static Slots)> {
    let mut out: Vec<(&'static PassSpec, &'static Slots)> = Vec::new();
    let mut add = |p: &'static PassSpec, s: &'static Slots| {
        let s = p.slots_for(s);
        if !out
            .iter()
            .any(|(q, t)| q.name == p.name && t.name == s.name)
        {
            out.push((p, s));
        }
    };
    for m in RenderMethod::ALL {
        let s = slots(m);
        for p in [&SKY, &TERRAIN, &COMPOSITE, &TONEMAP] {
            add(p, s);
        }
        for p in sprites::ALL {
            add(p, s);
        }
        if m != RenderMethod::Sprites {
            add(&SHADOW, s);
        }
        if m.ray_marches() {
            for p in raymarch::ALL {
                add(p, s);
            }
        }
        if m == RenderMethod::Slices {
            for p in slices::ALL {
                add(p, s);
            }
        }
    }
    out
}

/// Every shader file of `shaders/`: the shared ones and each method's.
pub fn shader_files() -> Vec<(&'static str, &'static str)> {
    crate::gpu::shaders::FILES
        .iter()
        .chain(raymarch::FILES)
        .chain(sprites::FILES)
        .chain(slices::FILES)
        .copied()
        .collect()
}

impl Renderer {
    /// Features of a frame with or without parcels and sprites: the
    /// method's own, plus the scene's sprite clouds.
    /// Sprites cast shadows on the terrain like the ray-marched clouds
    /// (splatted into the same map).
    pub(super) fn features_for(&self, any_clouds: bool, any_sprites: bool) -> Features {
        let mut f = Features::new(&self.cfg, any_clouds);
        f.sprites = self.cfg.clouds && (f.sprites || any_sprites);
        f.shadows = self.cfg.shadows && f.terrain && (f.clouds || f.sprites || f.slices);
        f.shadow_map = f.shadows && (self.map_marches(f) || f.sprites);
        // Sprites sort against a full-size cloud depth, which the
        // quarter-rate temporal march does not leave: with both, every
        // pixel is marched each frame.
        f.temporal = f.temporal && !f.sprites;
        f
    }

    /// Whether the shadow pass marches a field into the map: the
    /// ray-marched clouds' parcels or the slicing planes' implicit field.
    pub(super) fn map_marches(&self, f: Features) -> bool {
        f.clouds || f.slices
    }

    /// Whether this frame may keep the shadow map of an earlier one: the
    /// `baked` clouds were not re-baked since it was drawn (the bake runs
    /// when the parcels, the shell or the sun moved) and no sprite splats
    /// into it. A paused scene then neither bakes nor marches its shadows.
    pub(super) fn shadow_reusable(&self) -> bool {
        self.shadow_fresh
            && self.cfg.method == RenderMethod::Baked
            && !self.features.sprites
            && !self.baked.dirty()
    }

    /// Whether sprites and ray-marched clouds both draw: the march then
    /// runs in compute (it leaves its cloud depth) and the sprites are
    /// drawn in two halves around its composite (see shaders/sprites/sprites.wgsl).
    pub(super) fn split(&self) -> bool {
        self.features.clouds && self.features.sprites
    }

    /// The sprite pipeline drawing the fragments in front of the clouds
    /// (after their composite; the sprite pass itself draws those behind).
    pub(super) fn sprites_front_key(&self) -> PipelineKey {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        PipelineKey::new(
            &sprites::SPRITES,
            self.slots(),
            &[
                ("HAS_TERRAIN", b(self.features.terrain)),
                ("CLOUD_DEPTH", 2.0),
            ],
            SCENE_FORMAT,
        )
    }

    /// The sprite pipeline splatting their shadows into the shadow map.
    pub(super) fn sprite_shadow_key(&self) -> PipelineKey {
        PipelineKey::new(
            &sprites::SPRITES_SHADOW,
            self.slots(),
            &[("HAS_TERRAIN", 0.0), ("SHADOW_SPLAT", 1.0)],
            crate::gpu::pipelines::SHADOW_FORMAT,
        )
    }

    /// The `override` constants of `pass` under the current features.
    pub(super) fn constants(&self, pass: Pass) -> Vec<(&'static str, f64)> {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let f = self.features;
        let srgb = b(!self.format.is_srgb());
        // Only the tone map depends on the output format; the scene passes
        // are the same pipelines for every target.
        let mut c = match pass {
            Pass::Tonemap => vec![("ENCODE_SRGB", srgb)],
            Pass::Bake
            | Pass::SliceField
            | Pass::Sky
            | Pass::Composite
            | Pass::Shadow
            | Pass::Temporal => vec![],
            Pass::Terrain => vec![
                ("HAS_SHADOWS", b(f.shadows)),
                ("SHADOW_IN_REGION", b(f.shadows && f.clouds)),
                ("HAS_WATER", b(self.cfg.terrain.water_level_m.is_some())),
            ],
            Pass::Sprites => vec![
                ("HAS_TERRAIN", b(f.terrain)),
                ("CLOUD_DEPTH", if self.split() { 1.0 } else { 0.0 }),
            ],
            Pass::Clouds => vec![("USE_NORMALS", b(f.normals)), ("HAS_TERRAIN", b(f.terrain))],
            Pass::Slices => vec![("HAS_TERRAIN", b(f.terrain))],
        };
        // The shared libraries' switches, wherever the pass's module
        // imports them (air.wgsl, raymarch/field_exact.wgsl).
        for (name, v) in [
            ("AERIAL_PERSPECTIVE", b(self.cfg.aerial_perspective)),
            ("GRID_CULLING", b(self.cfg.grid_culling)),
        ] {
            if self
                .spec(pass)
                .declares(self.spec(pass).slots_for(self.slots()), name)
            {
                c.push((name, v));
            }
        }
        c
    }

    pub(super) fn needed(&self, pass: Pass) -> bool {
        match pass {
            Pass::Bake => self.features.clouds && self.cfg.method == RenderMethod::Baked,
            Pass::SliceField => self.features.slices && self.slices.field_pending(),
            Pass::Shadow => self.features.shadow_map,
            Pass::Sky => true,
            Pass::Terrain => self.features.terrain,
            Pass::Sprites => self.features.sprites,
            Pass::Clouds => self.features.clouds,
            Pass::Temporal => self.features.temporal,
            Pass::Slices => self.features.slices,
            Pass::Composite => {
                (self.features.clouds && self.compute_path()) || self.features.slices
            }
            Pass::Tonemap => true,
        }
    }

    /// Whether the next frame marches in a compute shader: always on the
    /// temporal path, and when sprites draw too (it leaves the cloud depth
    /// they sort against).
    pub(super) fn compute_path(&self) -> bool {
        self.features.temporal
            || self.auto_march.path(self.cfg.march) == MarchPath::Compute
            || self.split()
    }

    /// Frames drawn on the temporal path since its history began (0 when
    /// it is off or has just restarted).
    pub fn temporal_frames(&self) -> u32 {
        self.temporal
            .as_ref()
            .filter(|t| t.history_valid)
            .map_or(0, |t| t.frame_index)
    }

    /// The march path in use: the configured one, or what `auto` chose
    /// (None while it is still measuring).
    pub fn march_path(&self) -> Option<MarchPath> {
        if self.features.temporal {
            return Some(MarchPath::Compute);
        }
        match self.cfg.march {
            MarchPath::Auto => self.auto_march.chosen(),
            p => Some(p),
        }
    }

    /// The method's slots.
    pub(super) fn slots(&self) -> &'static Slots {
        slots(self.cfg.method)
    }

    /// The pass spec `pass` is drawn with this frame (the cloud pass's:
    /// fragment, compute or temporal).
    pub(super) fn spec(&self, pass: Pass) -> &'static PassSpec {
        match pass {
            Pass::Sky => &SKY,
            Pass::Terrain => &TERRAIN,
            Pass::Shadow => &SHADOW,
            Pass::Composite => &COMPOSITE,
            Pass::Tonemap => &TONEMAP,
            Pass::Sprites => &sprites::SPRITES,
            Pass::Slices => &slices::SLICES,
            Pass::Temporal => &raymarch::TEMPORAL,
            Pass::Clouds if self.features.temporal => &raymarch::CLOUDS_TEMPORAL,
            Pass::Clouds if self.compute_path() => &raymarch::CLOUDS_COMPUTE,
            Pass::Clouds => &raymarch::CLOUDS,
            Pass::Bake | Pass::SliceField => {
                unreachable!("{} makes its own pipelines", pass.name())
            }
        }
    }

    pub(super) fn key(&self, pass: Pass) -> PipelineKey {
        let format = if pass == Pass::Tonemap {
            self.format
        } else {
            SCENE_FORMAT
        };
        PipelineKey::new(self.spec(pass), self.slots(), &self.constants(pass), format)
    }

    /// Both cloud-pass pipelines when `auto` is still measuring (it
    /// alternates), else the one in use.
    pub(super) fn cloud_keys(&self) -> Vec<PipelineKey> {
        let mut keys = vec![self.key(Pass::Clouds)];
        if self.cfg.march == MarchPath::Auto
            && self.auto_march.chosen().is_none()
            && !self.features.temporal
        {
            let mut other = keys[0].clone();
            other.pass = if self.compute_path() {
                &raymarch::CLOUDS
            } else {
                &raymarch::CLOUDS_COMPUTE
            };
            keys.push(other);
            keys.push(self.key(Pass::Composite));
        }
        keys
    }
}
