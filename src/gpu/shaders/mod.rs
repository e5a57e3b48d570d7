//! WGSL sources of the passes, embedded at build time ([`FILES`]). Each
//! pass's module is its root file in `shaders/` and the files that file
//! imports (`#import`, resolved by [`imports`], which documents the
//! rules), after a generated [`prelude`] of the array sizes shared with
//! [`crate::methods::raymarch::pack`] and [`crate::sky`] that every module starts
//! with (`common.wgsl` uses them and imports nothing, so the prelude and
//! `common.wgsl` make a module by themselves).
//!
//! `shaders/` by owner:
//! - the top level: what every render method shares. The libraries
//!   `common.wgsl` (uniforms, camera rays, noise, sun, sky, tone curve) and
//!   `air.wgsl` (aerial perspective), and the shared passes `sky`,
//!   `terrain`, `shadow` (the cloud-shadow map), `composite` and `tonemap`;
//! - `raymarch/`: the `baked` and `exact` methods (the march `clouds`, its
//!   `density`, `lighting`, `parcel` and fields, the `bake`, the `temporal`
//!   resolve);
//! - `sprites/`: the sprite clouds;
//! - `slices/`: the `slices` method (the planes, their `implicit` field,
//!   the `vertex_field` compute and the cloud-shadow map's `shadow_field`).
//!
//! Where one file serves several methods with different implementations of
//! the same functions, it imports a slot (`#import <name>`), bound by
//! [`slots`] to one file per method:
//! - `field`, the ray-march's macro field (`field_value`, `field_sample`,
//!   `empty_skip`): `raymarch/field_exact.wgsl` under `exact`,
//!   `raymarch/field_baked.wgsl` otherwise (the methods that do not march
//!   reach it only through the terrain pass, whose in-region sun march they
//!   switch off);
//! - `far_light`, the ray-march's light beyond its short light march
//!   (`far_light_depth`, `far_behind_depth`):
//!   `raymarch/far_light_exact.wgsl` under `exact`, else the baked light
//!   volume of `raymarch/field_baked.wgsl`;
//! - `ground_shadow`, the cloud-shadow map's march (`ground_sun_depth`):
//!   `slices/shadow_field.wgsl` under `slices`, else
//!   `raymarch/density.wgsl`.
//!
//! Variants are WGSL `override` constants set at pipeline creation, so code
//! that a scene does not need (normals, shadow lookups, brute-force loops)
//! is removed then; [`Pass::overrides`] reads which ones a module declares
//! from the module itself (parsed by naga once per pass and method).

pub mod imports;
#[cfg(test)]
pub(crate) mod twins;

use std::collections::HashMap;
use std::sync::{LazyLock, Mutex};

pub use imports::{Assembly, ImportError, ImportErrorKind, assemble};

use crate::config::method::RenderMethod;
use crate::methods::raymarch::pack::{MAX_GRID_CELLS, MAX_GRID_ENTRIES, MAX_PARCELS};
use crate::sky::{AIR_HEIGHTS, AIR_STEPS, AIR_TOP_M, SKY_AZIMUTHS, SKY_ELEVATIONS};

/// A file of `shaders/`, embedded.
macro_rules! shader {
    ($path:literal) => {
        include_str!(concat!("../../../shaders/", $path))
    };
}

/// Shared uniforms and bindings (group 0), camera rays, noise, sun, sky and
/// the tone curve.
pub const COMMON_WGSL: &str = shader!("common.wgsl");
/// Aerial perspective (the passes that draw objects: terrain, clouds,
/// sprites, slices).
pub const AIR_WGSL: &str = shader!("air.wgsl");
/// Sky gradient and sun disc.
pub const SKY_WGSL: &str = shader!("sky.wgsl");
/// Terrain mesh.
pub const TERRAIN_WGSL: &str = shader!("terrain.wgsl");
/// Cloud-shadow map.
pub const SHADOW_WGSL: &str = shader!("shadow.wgsl");
/// Composite of a cloud texture over the scene.
pub const COMPOSITE_WGSL: &str = shader!("composite.wgsl");
/// The one tone map of a frame (HDR scene target → output).
pub const TONEMAP_WGSL: &str = shader!("tonemap.wgsl");
/// Cloud ray-march.
pub const CLOUDS_WGSL: &str = shader!("raymarch/clouds.wgsl");
/// One parcel's part of eq. 18 (exact field and bake).
pub const PARCEL_WGSL: &str = shader!("raymarch/parcel.wgsl");
/// Macro field of the `exact` method (per-sample union from the grid lists).
pub const FIELD_EXACT_WGSL: &str = shader!("raymarch/field_exact.wgsl");
/// The `exact` method's far light (marched through its field).
pub const FAR_LIGHT_EXACT_WGSL: &str = shader!("raymarch/far_light_exact.wgsl");
/// Macro field and light volume of the `baked` method (3D textures + occupancy).
pub const FIELD_BAKED_WGSL: &str = shader!("raymarch/field_baked.wgsl");
/// Hypertexture density (paper eq. 18), for clouds and shadows.
pub const DENSITY_WGSL: &str = shader!("raymarch/density.wgsl");
/// Lighting of cloud samples (sun, sky, bounce).
pub const LIGHTING_WGSL: &str = shader!("raymarch/lighting.wgsl");
/// Compute bake of the macro field (`baked` method).
pub const BAKE_WGSL: &str = shader!("raymarch/bake.wgsl");
/// Temporal resolve: reprojection and accumulation of the quarter-rate march.
pub const TEMPORAL_WGSL: &str = shader!("raymarch/temporal.wgsl");
/// The uniform of the quarter-rate march and the temporal resolve.
pub const TEMPORAL_UNIFORM_WGSL: &str = shader!("raymarch/temporal_uniform.wgsl");
/// Wang 2003 sprite clouds (textured, artist-shaded quads).
pub const SPRITES_WGSL: &str = shader!("sprites/sprites.wgsl");
/// Slicing planes of the `slices` method (Schpok 2003).
pub const SLICES_WGSL: &str = shader!("slices/slices.wgsl");
/// The authored field on the GPU (octaves, media, Wyvill sum), for the
/// `slices` method's passes.
pub const IMPLICIT_WGSL: &str = shader!("slices/implicit.wgsl");
/// Compute pass of the slice vertices' field and shadow (`vertex_field = "gpu"`).
pub const SLICES_VERTEX_FIELD_WGSL: &str = shader!("slices/vertex_field.wgsl");
/// `ground_sun_depth` of the `slices` method, for the cloud-shadow map.
pub const SLICES_SHADOW_FIELD_WGSL: &str = shader!("slices/shadow_field.wgsl");

/// Every file in `shaders/`, by its path there (a test checks that none is
/// missing and that every one is in some pass's module).
pub const FILES: &[(&str, &str)] = &[
    ("common.wgsl", COMMON_WGSL),
    ("air.wgsl", AIR_WGSL),
    ("sky.wgsl", SKY_WGSL),
    ("terrain.wgsl", TERRAIN_WGSL),
    ("shadow.wgsl", SHADOW_WGSL),
    ("composite.wgsl", COMPOSITE_WGSL),
    ("tonemap.wgsl", TONEMAP_WGSL),
    ("raymarch/clouds.wgsl", CLOUDS_WGSL),
    ("raymarch/parcel.wgsl", PARCEL_WGSL),
    ("raymarch/field_exact.wgsl", FIELD_EXACT_WGSL),
    ("raymarch/far_light_exact.wgsl", FAR_LIGHT_EXACT_WGSL),
    ("raymarch/field_baked.wgsl", FIELD_BAKED_WGSL),
    ("raymarch/density.wgsl", DENSITY_WGSL),
    ("raymarch/lighting.wgsl", LIGHTING_WGSL),
    ("raymarch/bake.wgsl", BAKE_WGSL),
    ("raymarch/temporal.wgsl", TEMPORAL_WGSL),
    ("raymarch/temporal_uniform.wgsl", TEMPORAL_UNIFORM_WGSL),
    ("sprites/sprites.wgsl", SPRITES_WGSL),
    ("slices/slices.wgsl", SLICES_WGSL),
    ("slices/implicit.wgsl", IMPLICIT_WGSL),
    ("slices/vertex_field.wgsl", SLICES_VERTEX_FIELD_WGSL),
    ("slices/shadow_field.wgsl", SLICES_SHADOW_FIELD_WGSL),
];

/// The render passes, in the order they run.
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
    /// Blends the compute march's (or the slices') texture over the target (compute path).
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

    /// The pass's root file in `shaders/`.
    pub fn root(self) -> &'static str {
        match self {
            Pass::Bake => "raymarch/bake.wgsl",
            Pass::SliceField => "slices/vertex_field.wgsl",
            Pass::Shadow => "shadow.wgsl",
            Pass::Sky => "sky.wgsl",
            Pass::Terrain => "terrain.wgsl",
            Pass::Sprites => "sprites/sprites.wgsl",
            Pass::Clouds => "raymarch/clouds.wgsl",
            Pass::Temporal => "raymarch/temporal.wgsl",
            Pass::Slices => "slices/slices.wgsl",
            Pass::Composite => "composite.wgsl",
            Pass::Tonemap => "tonemap.wgsl",
        }
    }

    /// Whether the pass exists for `method`: the bake only for `baked`;
    /// the cloud march only for the ray-marching methods; the shadow map
    /// for those and for `slices` (the `ground_shadow` slot); the slicing
    /// planes and their vertex-field compute only for `slices`; the
    /// composite for the compute march and the slices' target; sprites
    /// (scene layers) for every method.
    pub fn used_by(self, method: RenderMethod) -> bool {
        let slices = method == RenderMethod::Slices;
        match self {
            Pass::Bake => method == RenderMethod::Baked,
            Pass::Shadow => method.ray_marches() || slices,
            Pass::Clouds | Pass::Temporal => method.ray_marches(),
            Pass::Slices | Pass::SliceField => slices,
            Pass::Composite => method.ray_marches() || slices,
            Pass::Sky | Pass::Terrain | Pass::Sprites | Pass::Tonemap => true,
        }
    }

    /// The assembled module of this pass for `method` and the files in it.
    pub fn assembly(self, method: RenderMethod) -> Result<Assembly, ImportError> {
        assemble(FILES, self.root(), &slots(method), &prelude())
    }

    /// The assembled WGSL module of this pass for `method`. The files are
    /// embedded at build time and the tests assemble every module, so an
    /// [`ImportError`] here is a bug in `shaders/`: it panics naming the
    /// file and line.
    pub fn source(self, method: RenderMethod) -> String {
        match self.assembly(method) {
            Ok(a) => a.source,
            Err(e) => panic!("{} ({method}): {e}", self.name()),
        }
    }

    /// The `override` constants this pass's module declares under `method`,
    /// read from the module (parsed once, then cached). A pipeline may set
    /// any of them and no other (wgpu refuses an undeclared constant, and
    /// [`crate::gpu::pipelines::PipelineKey::new`] panics on one).
    /// Empty for a module that does not parse; building its pipeline
    /// reports why.
    pub fn overrides(self, method: RenderMethod) -> &'static [String] {
        static CACHE: LazyLock<Mutex<HashMap<(Pass, RenderMethod), &'static [String]>>> =
            LazyLock::new(Default::default);
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        cache.entry((self, method)).or_insert_with(|| {
            let names: Vec<String> = match naga::front::wgsl::parse_str(&self.source(method)) {
                Ok(module) => module
                    .overrides
                    .iter()
                    .filter_map(|(_, o)| o.name.clone())
                    .collect(),
                Err(_) => Vec::new(),
            };
            // One leak per pass and method, for the program's lifetime.
            Box::leak(names.into_boxed_slice())
        })
    }

    /// Whether this pass's module declares the `override` constant `name`
    /// under `method`.
    pub fn declares(self, method: RenderMethod, name: &str) -> bool {
        self.overrides(method).iter().any(|n| n == name)
    }
}

/// The files bound to the slots under `method` (see the module docs), for
/// every pass: each module uses those it imports.
pub fn slots(method: RenderMethod) -> [(&'static str, &'static str); 3] {
    let exact = method == RenderMethod::Exact;
    let field = if exact {
        "raymarch/field_exact.wgsl"
    } else {
        "raymarch/field_baked.wgsl"
    };
    let far_light = if exact {
        "raymarch/far_light_exact.wgsl"
    } else {
        "raymarch/field_baked.wgsl"
    };
    let ground_shadow = if method == RenderMethod::Slices {
        "slices/shadow_field.wgsl"
    } else {
        "raymarch/density.wgsl"
    };
    [
        ("field", field),
        ("far_light", far_light),
        ("ground_shadow", ground_shadow),
    ]
}

/// The prelude of every module: the array sizes shared with
/// [`crate::methods::raymarch::pack`] and [`crate::sky`], as WGSL constants.
pub fn prelude() -> String {
    format!(
        "// Generated by src/render/shaders.rs from src/render/pack.rs and src/sky.\n\
         const MAX_PARCELS: u32 = {MAX_PARCELS}u;\n\
         const GRID_CELL_PAIRS: u32 = {}u;\n\
         const GRID_ENTRY_QUADS: u32 = {}u;\n\
         const SKY_AZIMUTHS: u32 = {SKY_AZIMUTHS}u;\n\
         const SKY_ELEVATIONS: u32 = {SKY_ELEVATIONS}u;\n\
         const AIR_HEIGHTS: u32 = {AIR_HEIGHTS}u;\n\
         const AIR_TOP_M: f32 = {AIR_TOP_M:.1};\n\
         const AIR_STEPS: u32 = {AIR_STEPS}u;\n\n",
        MAX_GRID_CELLS / 2,
        MAX_GRID_ENTRIES / 4
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_module_assembles_with_its_root_last() {
        for pass in Pass::ALL {
            for method in RenderMethod::ALL.into_iter().filter(|m| pass.used_by(*m)) {
                let a = pass.assembly(method).unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(a.files.last().map(String::as_str), Some(pass.root()));
            }
        }
    }

    /// Each file names what it uses: assembled with only its own imports
    /// (under the slots of every method whose passes use it), it parses
    /// and validates.
    #[test]
    fn every_file_stands_on_its_own_imports() {
        let mut failures = Vec::new();
        for (path, _) in FILES {
            for method in RenderMethod::ALL {
                let used = Pass::ALL.iter().any(|p| {
                    p.used_by(method) && p.assembly(method).unwrap().files.iter().any(|f| f == path)
                });
                if !used {
                    continue;
                }
                let src = assemble(FILES, path, &slots(method), &prelude())
                    .unwrap()
                    .source;
                let checked = naga::front::wgsl::parse_str(&src)
                    .map_err(|e| e.emit_to_string(&src))
                    .and_then(|m| {
                        naga::valid::Validator::new(
                            naga::valid::ValidationFlags::all(),
                            naga::valid::Capabilities::default(),
                        )
                        .validate(&m)
                        .map(|_| ())
                        .map_err(|e| e.emit_to_string(&src))
                    });
                if let Err(e) = checked {
                    failures.push(format!("{path} ({method}): {e}"));
                }
            }
        }
        assert!(failures.is_empty(), "{}", failures.join("\n"));
    }

    #[test]
    fn slots_pick_each_method_s_files() {
        let files = |pass: Pass, m| pass.assembly(m).unwrap().files;
        let exact = files(Pass::Clouds, RenderMethod::Exact);
        let baked = files(Pass::Clouds, RenderMethod::Baked);
        assert!(exact.iter().any(|f| f == "raymarch/field_exact.wgsl"));
        assert!(exact.iter().any(|f| f == "raymarch/far_light_exact.wgsl"));
        assert!(!exact.iter().any(|f| f == "raymarch/field_baked.wgsl"));
        assert!(baked.iter().any(|f| f == "raymarch/field_baked.wgsl"));
        assert!(!baked.iter().any(|f| f.contains("exact")));
        let shadow = files(Pass::Shadow, RenderMethod::Slices);
        assert!(shadow.iter().any(|f| f == "slices/shadow_field.wgsl"));
        assert!(!shadow.iter().any(|f| f.starts_with("raymarch/")));
        // Every module starts with the prelude, then common.wgsl.
        for pass in Pass::ALL {
            let a = pass.assembly(RenderMethod::Baked).unwrap();
            assert!(a.source.starts_with(&prelude()));
            assert_eq!(a.files[0], "common.wgsl");
        }
    }

    #[test]
    fn overrides_come_from_the_modules() {
        let mut clouds = Pass::Clouds.overrides(RenderMethod::Exact).to_vec();
        clouds.sort();
        assert_eq!(
            clouds,
            [
                "AERIAL_PERSPECTIVE",
                "ENCODE_SRGB",
                "GRID_CULLING",
                "HAS_TERRAIN",
                "USE_NORMALS"
            ]
        );
        assert!(!Pass::Clouds.declares(RenderMethod::Baked, "GRID_CULLING"));
        assert!(Pass::Shadow.declares(RenderMethod::Exact, "GRID_CULLING"));
        assert!(Pass::Terrain.declares(RenderMethod::Slices, "HAS_WATER"));
        assert!(!Pass::Sky.declares(RenderMethod::Baked, "AERIAL_PERSPECTIVE"));
        // Cached: the same slice each time.
        assert!(std::ptr::eq(
            Pass::Sprites.overrides(RenderMethod::Baked),
            Pass::Sprites.overrides(RenderMethod::Baked)
        ));
    }

    #[test]
    #[should_panic(expected = "sky (baked) declares no override HAS_TERRAIN")]
    fn a_pipeline_key_takes_only_declared_constants() {
        use crate::gpu::pipelines::PipelineKey;
        let format = wgpu::TextureFormat::Rgba16Float;
        PipelineKey::new(Pass::Sky, RenderMethod::Baked, &[], format, false);
        PipelineKey::new(
            Pass::Sky,
            RenderMethod::Baked,
            &[("HAS_TERRAIN", 1.0)],
            format,
            false,
        );
    }
}
