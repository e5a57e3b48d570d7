//! Which passes, pipelines and `override` constants a frame needs: the
//! features of a frame with or without clouds and sprites, the pipeline
//! keys of the shared passes and of the sprite layer, the pass names in
//! order; and, from the method registry, every method's slots, modules
//! and shader files.

use super::*;
use crate::gpu::method::Phase;
use crate::gpu::pass::{PassSpec, Slots, flag};
use crate::gpu::passes::{COMPOSITE, SHADOW, SHADOW_COMPUTE, SKY, TERRAIN, TONEMAP};
use crate::gpu::pipelines::{PipelineKey, SHADOW_FORMAT};
use crate::gpu::requires::Requirement;
use crate::methods::sprites::gpu::passes::{SPRITES, SPRITES_SHADOW};
use std::sync::LazyLock;

/// The files `method` binds to the shared shaders' slots.
pub fn slots(method: RenderMethod) -> &'static Slots {
    (METHODS[crate::methods::index_of(method)].slots)(method)
}

/// Every module a pipeline of any method is built from: (pass, slots),
/// each once (the shader tests assemble and validate them all).
pub fn modules() -> Vec<(&'static PassSpec, &'static Slots)> {
    let mut out: Vec<(&'static PassSpec, &'static Slots)> = Vec::new();
    for m in RenderMethod::ALL {
        for (p, s) in method_modules(m) {
            if !out
                .iter()
                .any(|(q, t)| q.name == p.name && t.name == s.name)
            {
                out.push((p, s));
            }
        }
    }
    out
}

/// The passes a renderer may build for `method`, each with the slots it
/// is built with: the shared passes and the method's own.
fn method_modules(m: RenderMethod) -> Vec<(&'static PassSpec, &'static Slots)> {
    let entry = METHODS[crate::methods::index_of(m)];
    let s = (entry.slots)(m);
    let mut passes: Vec<&'static PassSpec> = vec![
        &SKY,
        &TERRAIN,
        &COMPOSITE,
        &TONEMAP,
        &SPRITES,
        &SPRITES_SHADOW,
    ];
    if entry.marches_shadow {
        passes.push(&SHADOW);
    }
    passes.extend(entry.passes);
    passes.into_iter().map(|p| (p, p.slots_for(s))).collect()
}

/// Everything a renderer drawing `method` needs from the device: every
/// pass it may build (read from the passes' declarations and modules once
/// per process), then the method's pipelines built outside the cache.
pub fn requirements(method: RenderMethod) -> &'static [Requirement] {
    static ALL: LazyLock<Vec<Vec<Requirement>>> = LazyLock::new(|| {
        RenderMethod::ALL
            .into_iter()
            .map(|m| {
                let entry = METHODS[crate::methods::index_of(m)];
                let mut r: Vec<Requirement> = method_modules(m)
                    .into_iter()
                    .map(|(p, s)| p.requirement(s))
                    .collect();
                r.extend((entry.other_passes)(m));
                r
            })
            .collect()
    });
    let i = RenderMethod::ALL
        .iter()
        .position(|m| *m == method)
        .expect("every method is in RenderMethod::ALL");
    &ALL[i]
}

/// Whether an adapter of capabilities `caps` runs the compute shadow
/// march under a method's `slots` ([`SHADOW_COMPUTE`]'s requirement).
pub(super) fn compute_shadow(
    caps: &crate::gpu::requires::Capabilities,
    slots: &'static Slots,
) -> bool {
    SHADOW_COMPUTE.requirement(slots).check(caps).is_ok()
}

/// Every shader file of `shaders/`: the shared ones and each method's.
pub fn shader_files() -> Vec<(&'static str, &'static str)> {
    let mut files: Vec<(&'static str, &'static str)> = crate::gpu::shaders::FILES.to_vec();
    for e in METHODS {
        files.extend(
            e.files
                .iter()
                .filter(|f| !files.contains(f))
                .copied()
                .collect::<Vec<_>>(),
        );
    }
    files
}

/// The name of every pass a frame may time, in the order they run (the
/// bench's table columns).
pub fn all_pass_names() -> Vec<&'static str> {
    let of = |phase: Phase| -> Vec<&'static str> {
        METHODS
            .iter()
            .flat_map(|e| e.pass_names.iter())
            .filter(|(p, _)| *p == phase)
            .map(|(_, n)| *n)
            .collect()
    };
    let mut names = of(Phase::Prepare);
    names.extend(["shadow", "sky", "terrain"]);
    names.extend(of(Phase::Clouds));
    names.push("sprites");
    names.extend(of(Phase::Resolve));
    names.extend(["composite", "tonemap"]);
    names
}

impl Renderer {
    /// Features under `cfg` of a frame with or without clouds for the
    /// method, with or without sprites of the scene's layer (`layer_sprites`:
    /// its sprite clouds, or this frame's instances and the impostor
    /// ring). The method's parcels may feed the layer too. Sprites cast
    /// shadows on the terrain like the method's clouds (splatted into the
    /// same map).
    pub(super) fn features_for(
        &self,
        cfg: &RenderConfig,
        any_clouds: bool,
        layer_sprites: bool,
    ) -> Features {
        let method = self.methods[crate::methods::index_of(cfg.method)].as_ref();
        let terrain = cfg.terrain.enabled;
        let mut around = Around {
            any_clouds,
            terrain,
            layers: cfg.clouds && layer_sprites,
            shadows: false,
        };
        around.layers |= cfg.clouds && method.needs(cfg, around).feeds_layer;
        let draws = method.needs(cfg, around).draws;
        around.shadows = cfg.shadows && terrain && (draws || around.layers);
        let needs = method.needs(cfg, around);
        Features {
            around,
            method: needs,
            shadow_map: around.shadows && (needs.marches_shadow || around.layers),
        }
    }

    /// Names of the passes that exist for the current features, in
    /// execution order (the bake, and under `baked` the shadow map, run
    /// only in frames whose parcels or sun moved).
    pub fn pass_names(&self) -> Vec<&'static str> {
        let (f, m, cfg) = (self.features, self.method(), &self.cfg);
        let mut names = m.pass_names(cfg, f.around, Phase::Prepare);
        if f.shadow_map {
            names.push("shadow");
        }
        names.push("sky");
        if f.around.terrain {
            names.push("terrain");
        }
        names.extend(m.pass_names(cfg, f.around, Phase::Clouds));
        if f.around.layers {
            names.push("sprites");
        }
        names.extend(m.pass_names(cfg, f.around, Phase::Resolve));
        if f.method.composite && !self.folds(f) {
            names.push("composite");
        }
        names.push("tonemap");
        names
    }

    /// The shadow march under `cfg`: in compute where the adapter runs it
    /// for the method, else the full-screen fragment pass.
    pub(super) fn shadow_spec(&self, cfg: &RenderConfig) -> &'static PassSpec {
        if self.shadow_compute[crate::methods::index_of(cfg.method)] {
            &SHADOW_COMPUTE
        } else {
            &SHADOW
        }
    }

    /// Whether a frame of features `f` leaves the method's cloud image to
    /// the tone map instead of a composite pass: when the image is the
    /// last thing drawn into the scene target (no sprite in front of the
    /// clouds, which the composite pass draws after it) and the target is
    /// not read back ([`Renderer::set_scene_whole`]). The blend is the
    /// same, in the tone map's registers instead of the scene target: one
    /// full-screen pass and one write and read of the target less.
    pub(super) fn folds(&self, f: Features) -> bool {
        f.method.composite
            && !(f.method.cloud_depth && f.around.layers)
            && !self.scene_whole
            && self.method().composite_foldable(&self.cfg, f.around)
    }

    /// The tone map's key, blending the cloud image (`fold`) or not.
    pub(super) fn tonemap_key(&self, cfg: &RenderConfig, fold: bool) -> PipelineKey {
        // Only the tone map depends on the output format; the scene
        // passes are the same pipelines for every target.
        let own = [
            ("ENCODE_SRGB", flag(!self.format.is_srgb())),
            ("WITH_CLOUDS", flag(fold)),
        ];
        TONEMAP.key(slots(cfg.method), cfg, &own, self.format)
    }

    /// The key of shared pass `spec` under `cfg` and features `f` (the
    /// tone map's: [`Renderer::tonemap_key`]).
    pub(super) fn shared_key(
        &self,
        spec: &'static PassSpec,
        cfg: &RenderConfig,
        f: Features,
    ) -> PipelineKey {
        let slots = slots(cfg.method);
        let (own, format): (Vec<(&'static str, f64)>, _) = if std::ptr::eq(spec, &TERRAIN) {
            let shadows = f.around.shadows;
            (
                vec![
                    ("HAS_SHADOWS", flag(shadows)),
                    (
                        "SHADOW_IN_REGION",
                        flag(shadows && f.method.shadow_in_region),
                    ),
                    ("HAS_WATER", flag(cfg.terrain.water_level_m.is_some())),
                ],
                SCENE_FORMAT,
            )
        } else {
            debug_assert!(
                !std::ptr::eq(spec, &TONEMAP),
                "the tone map has tonemap_key"
            );
            (Vec::new(), SCENE_FORMAT)
        };
        spec.key(slots, cfg, &own, format)
    }

    /// The sprite pipeline: `depth_test` 0 (none), 1 (fragments behind the
    /// method's cloud depth) or 2 (in front).
    pub(super) fn sprites_key(
        &self,
        cfg: &RenderConfig,
        f: Features,
        depth_test: f64,
    ) -> PipelineKey {
        SPRITES.key(
            slots(cfg.method),
            cfg,
            &[
                ("HAS_TERRAIN", flag(f.around.terrain)),
                ("CLOUD_DEPTH", depth_test),
            ],
            SCENE_FORMAT,
        )
    }

    /// The sprite pipeline splatting their shadows into the shadow map.
    pub(super) fn sprite_shadow_key(&self, cfg: &RenderConfig) -> PipelineKey {
        SPRITES_SHADOW.key(
            slots(cfg.method),
            cfg,
            &[("HAS_TERRAIN", 0.0), ("SHADOW_SPLAT", 1.0)],
            SHADOW_FORMAT,
        )
    }

    /// The pipelines of one frame's features `f` under `cfg`: the shared
    /// passes', the sprite layer's and the method's.
    pub(super) fn frame_keys(&self, cfg: &RenderConfig, f: Features) -> Vec<PipelineKey> {
        let mut keys = vec![self.shared_key(&SKY, cfg, f), self.tonemap_key(cfg, false)];
        if f.around.terrain {
            keys.push(self.shared_key(&TERRAIN, cfg, f));
        }
        // The shadow pass marches only the method's field; the sprites
        // splat into it with a pipeline of their own.
        if f.shadow_map && f.method.marches_shadow {
            keys.push(self.shared_key(self.shadow_spec(cfg), cfg, f));
        }
        if f.method.composite {
            keys.push(self.shared_key(&COMPOSITE, cfg, f));
        }
        if f.around.layers {
            keys.push(self.sprites_key(cfg, f, flag(f.method.cloud_depth)));
            if f.method.cloud_depth {
                keys.push(self.sprites_key(cfg, f, 2.0));
            }
            if f.around.shadows {
                keys.push(self.sprite_shadow_key(cfg));
            }
        }
        let method = self.methods[crate::methods::index_of(cfg.method)].as_ref();
        keys.extend(method.pipeline_keys(cfg, f.around));
        // Wherever a composite may run, the tone map that blends the
        // clouds instead, so that neither keeping the scene target whole
        // nor `auto` deciding waits for a build.
        if keys.iter().any(|k| std::ptr::eq(k.pass, &COMPOSITE)) {
            keys.push(self.tonemap_key(cfg, true));
        }
        keys
    }

    /// The pipelines the settings `cfg` use: the frame with clouds, the
    /// one without, and `current`.
    pub(super) fn settings_keys(&self, cfg: &RenderConfig, current: Features) -> Vec<PipelineKey> {
        let scene_sprites = !self.sprite_scene.is_empty();
        let mut keys = Vec::new();
        for f in [
            self.features_for(cfg, true, scene_sprites),
            self.features_for(cfg, false, scene_sprites),
            current,
        ] {
            keys.extend(self.frame_keys(cfg, f));
        }
        keys
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bench's columns: every pass a frame may time, in order, from
    /// the shared passes and each registered method's names.
    #[test]
    fn every_pass_name_in_frame_order() {
        assert_eq!(
            all_pass_names(),
            [
                "bake",
                "slice_field",
                "shadow",
                "sky",
                "terrain",
                "clouds",
                "sprites",
                "temporal",
                "slices",
                "composite",
                "tonemap"
            ]
        );
    }

    /// Each method's registration names its own slots and files.
    #[test]
    fn every_method_is_registered_once() {
        for m in RenderMethod::ALL {
            let n = METHODS.iter().filter(|e| e.methods.contains(&m)).count();
            assert_eq!(n, 1, "{m}");
        }
        assert_eq!(slots(RenderMethod::Exact).name, "exact");
        assert_eq!(slots(RenderMethod::Slices).name, "slices");
        let files = shader_files();
        let mut names: Vec<_> = files.iter().map(|(n, _)| *n).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), files.len(), "a file listed twice");
    }

    fn caps(limits: wgpu::Limits, compute: bool) -> crate::gpu::requires::Capabilities {
        crate::gpu::requires::Capabilities {
            limits,
            compute,
            formats: Box::new(|_| wgpu::TextureFormatFeatures {
                allowed_usages: wgpu::TextureUsages::all(),
                flags: wgpu::TextureFormatFeatureFlags::all(),
            }),
        }
    }

    fn first_missing(m: RenderMethod, c: &crate::gpu::requires::Capabilities) -> Option<String> {
        requirements(m)
            .iter()
            .find_map(|r| r.check(c).err())
            .map(|e| e.to_string())
    }

    /// wgpu's default limits (what every Vulkan, Metal and DirectX 12
    /// adapter offers) run every pass of every method.
    #[test]
    fn every_method_runs_on_wgpu_s_default_limits() {
        for m in RenderMethod::ALL {
            assert_eq!(
                first_missing(m, &caps(wgpu::Limits::default(), true)),
                None,
                "{m}"
            );
            assert!(requirements(m).len() >= 6, "{m}: {:?}", requirements(m));
        }
    }

    /// Limits below ours are caught before anything is built, naming the
    /// pass and the limit: one storage texture per stage is too few for the
    /// bake (field and light) and the compute march (image and depth).
    #[test]
    fn a_device_below_our_limits_is_named_up_front() {
        let low = wgpu::Limits {
            max_storage_textures_per_shader_stage: 1,
            ..wgpu::Limits::default()
        };
        let e = first_missing(RenderMethod::Baked, &caps(low.clone(), true)).unwrap();
        assert!(
            e.contains("max_storage_textures_per_shader_stage ≥ 2"),
            "{e}"
        );
        assert!(e.contains("= 1"), "{e}");
        assert_eq!(first_missing(RenderMethod::Sprites, &caps(low, true)), None);
        // The exact method's grid index is a 48 KiB uniform (that its
        // terrain reads too, for the shadows in the clouds' region); 16 KiB
        // is OpenGL ES's minimum.
        let low = wgpu::Limits {
            max_uniform_buffer_binding_size: 16 << 10,
            ..wgpu::Limits::default()
        };
        let e = first_missing(RenderMethod::Exact, &caps(low, true)).unwrap();
        assert!(e.contains("max_uniform_buffer_binding_size ≥ 49152"), "{e}");
    }

    /// Without compute shaders the sprites still draw; the ray-march and
    /// the slices' vertex field name their compute pass.
    #[test]
    fn without_compute_only_the_sprites_draw() {
        let c = caps(wgpu::Limits::default(), false);
        assert_eq!(first_missing(RenderMethod::Sprites, &c), None);
        let e = first_missing(RenderMethod::Baked, &c).unwrap();
        assert!(
            e.contains("clouds (compute) pass needs compute shaders"),
            "{e}"
        );
        let e = first_missing(RenderMethod::Slices, &c).unwrap();
        assert!(e.contains("slice_field pass needs compute shaders"), "{e}");
    }
}
