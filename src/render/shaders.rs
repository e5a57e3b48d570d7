//! WGSL sources of the passes, assembled from the files in `shaders/`
//! (naga has no `#include`): a generated prelude with the array sizes from
//! [`crate::render::pack`] and [`crate::sky`], then `common.wgsl`, then, for the passes that
//! evaluate clouds, `parcel.wgsl` (the parcel part of eq. 18), the macro
//! field of the render method (`field_exact.wgsl` or `field_baked.wgsl`,
//! same functions), `density.wgsl` and, for the cloud pass, `lighting.wgsl`;
//! `air.wgsl` for the passes that draw objects (aerial perspective); then
//! the pass's own file. Variants are WGSL `override` constants set at
//! pipeline creation, so code that a scene does not need (normals, shadow
//! lookups, brute-force loops) is removed then.

use crate::config::method::RenderMethod;
use crate::render::pack::{MAX_GRID_CELLS, MAX_GRID_ENTRIES, MAX_PARCELS};
use crate::sky::{AIR_HEIGHTS, AIR_STEPS, AIR_TOP_M, SKY_AZIMUTHS, SKY_ELEVATIONS};

/// Shared uniforms, camera, noise, sun and sky.
pub const COMMON_WGSL: &str = include_str!("../../shaders/common.wgsl");
/// Aerial perspective (the passes that draw objects: terrain, clouds,
/// sprites, slices).
pub const AIR_WGSL: &str = include_str!("../../shaders/air.wgsl");
/// One parcel's part of eq. 18 (exact field and bake).
pub const PARCEL_WGSL: &str = include_str!("../../shaders/parcel.wgsl");
/// Macro field of the `exact` method (per-sample union from the grid lists).
pub const FIELD_EXACT_WGSL: &str = include_str!("../../shaders/field_exact.wgsl");
/// Macro field of the `baked` method (3D texture + occupancy).
pub const FIELD_BAKED_WGSL: &str = include_str!("../../shaders/field_baked.wgsl");
/// Hypertexture density (paper eq. 18), for clouds and shadows.
pub const DENSITY_WGSL: &str = include_str!("../../shaders/density.wgsl");
/// Lighting of cloud samples (sun, sky, bounce).
pub const LIGHTING_WGSL: &str = include_str!("../../shaders/lighting.wgsl");
/// Composite of the compute march path.
pub const COMPOSITE_WGSL: &str = include_str!("../../shaders/composite.wgsl");
/// Compute bake of the macro field (`baked` method).
pub const BAKE_WGSL: &str = include_str!("../../shaders/bake.wgsl");
/// Sky gradient and sun disc.
pub const SKY_WGSL: &str = include_str!("../../shaders/sky.wgsl");
/// Terrain mesh.
pub const TERRAIN_WGSL: &str = include_str!("../../shaders/terrain.wgsl");
/// Cloud-shadow map.
pub const SHADOW_WGSL: &str = include_str!("../../shaders/shadow.wgsl");
/// The one tone map of a frame (HDR scene target → output).
pub const TONEMAP_WGSL: &str = include_str!("../../shaders/tonemap.wgsl");
/// Cloud ray-march.
pub const CLOUDS_WGSL: &str = include_str!("../../shaders/clouds.wgsl");
/// Temporal resolve: reprojection and accumulation of the quarter-rate march.
pub const TEMPORAL_WGSL: &str = include_str!("../../shaders/temporal.wgsl");
/// Wang 2003 sprite clouds (textured, artist-shaded quads).
pub const SPRITES_WGSL: &str = include_str!("../../shaders/sprites.wgsl");
/// Slicing planes of the `slices` method (Schpok 2003).
pub const SLICES_WGSL: &str = include_str!("../../shaders/slices.wgsl");
/// The authored field on the GPU (octaves, media, Wyvill sum), for the
/// `slices` method's passes.
pub const IMPLICIT_WGSL: &str = include_str!("../../shaders/implicit.wgsl");
/// Compute pass of the slice vertices' field and shadow (`vertex_field = "gpu"`).
pub const SLICES_FIELD_WGSL: &str = include_str!("../../shaders/slices_field.wgsl");
/// `cloud_density` of the `slices` method, for the cloud-shadow map.
pub const FIELD_SLICES_WGSL: &str = include_str!("../../shaders/field_slices.wgsl");

/// Every file in `shaders/`, by name (the shader test checks none is missing).
pub const FILES: &[(&str, &str)] = &[
    ("common.wgsl", COMMON_WGSL),
    ("air.wgsl", AIR_WGSL),
    ("parcel.wgsl", PARCEL_WGSL),
    ("field_exact.wgsl", FIELD_EXACT_WGSL),
    ("field_baked.wgsl", FIELD_BAKED_WGSL),
    ("density.wgsl", DENSITY_WGSL),
    ("lighting.wgsl", LIGHTING_WGSL),
    ("bake.wgsl", BAKE_WGSL),
    ("composite.wgsl", COMPOSITE_WGSL),
    ("sky.wgsl", SKY_WGSL),
    ("terrain.wgsl", TERRAIN_WGSL),
    ("shadow.wgsl", SHADOW_WGSL),
    ("clouds.wgsl", CLOUDS_WGSL),
    ("temporal.wgsl", TEMPORAL_WGSL),
    ("tonemap.wgsl", TONEMAP_WGSL),
    ("sprites.wgsl", SPRITES_WGSL),
    ("slices.wgsl", SLICES_WGSL),
    ("implicit.wgsl", IMPLICIT_WGSL),
    ("slices_field.wgsl", SLICES_FIELD_WGSL),
    ("field_slices.wgsl", FIELD_SLICES_WGSL),
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

    fn file(self) -> &'static str {
        match self {
            Pass::Bake => BAKE_WGSL,
            Pass::SliceField => SLICES_FIELD_WGSL,
            Pass::Shadow => SHADOW_WGSL,
            Pass::Sky => SKY_WGSL,
            Pass::Terrain => TERRAIN_WGSL,
            Pass::Sprites => SPRITES_WGSL,
            Pass::Clouds => CLOUDS_WGSL,
            Pass::Temporal => TEMPORAL_WGSL,
            Pass::Slices => SLICES_WGSL,
            Pass::Composite => COMPOSITE_WGSL,
            Pass::Tonemap => TONEMAP_WGSL,
        }
    }

    /// Whether the pass draws objects seen through the air (air.wgsl).
    fn sees_air(self) -> bool {
        matches!(
            self,
            Pass::Terrain | Pass::Clouds | Pass::Sprites | Pass::Slices
        )
    }

    fn needs_density(self) -> bool {
        matches!(self, Pass::Shadow | Pass::Clouds | Pass::Terrain)
    }

    /// Whether the pass exists for `method`: the bake only for `baked`;
    /// the cloud march only for the ray-marching methods; the shadow map
    /// for those (density.wgsl `ground_sun_depth`) and for `slices` (from
    /// its implicit field, see field_slices.wgsl); the
    /// slicing planes and their vertex-field compute only for `slices`;
    /// the composite for the
    /// compute march and the slices' target; sprites (scene layers) for
    /// every method.
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

    /// The `override` constants this pass's module declares under `method`
    /// (every one must be given a value or keep its default; naming an
    /// absent one is an error).
    pub fn overrides(self, method: RenderMethod) -> &'static [&'static str] {
        let exact = method == RenderMethod::Exact;
        match self {
            Pass::Bake | Pass::SliceField | Pass::Composite | Pass::Tonemap | Pass::Temporal => {
                &["ENCODE_SRGB"]
            }
            Pass::Shadow if exact => &["ENCODE_SRGB", "GRID_CULLING"],
            Pass::Shadow => &["ENCODE_SRGB"],
            Pass::Sky => &["ENCODE_SRGB"],
            Pass::Terrain if exact => &[
                "ENCODE_SRGB",
                "AERIAL_PERSPECTIVE",
                "HAS_SHADOWS",
                "SHADOW_IN_REGION",
                "HAS_WATER",
                "GRID_CULLING",
            ],
            Pass::Terrain => &[
                "ENCODE_SRGB",
                "AERIAL_PERSPECTIVE",
                "HAS_SHADOWS",
                "SHADOW_IN_REGION",
                "HAS_WATER",
            ],
            Pass::Sprites => &[
                "ENCODE_SRGB",
                "AERIAL_PERSPECTIVE",
                "HAS_TERRAIN",
                "IMPOSTOR_QUAD",
                "CLOUD_DEPTH",
                "SHADOW_SPLAT",
            ],
            Pass::Clouds if exact => &[
                "ENCODE_SRGB",
                "GRID_CULLING",
                "USE_NORMALS",
                "AERIAL_PERSPECTIVE",
                "HAS_TERRAIN",
            ],
            Pass::Clouds => &[
                "ENCODE_SRGB",
                "USE_NORMALS",
                "AERIAL_PERSPECTIVE",
                "HAS_TERRAIN",
            ],
            Pass::Slices => &["ENCODE_SRGB", "AERIAL_PERSPECTIVE", "HAS_TERRAIN"],
        }
    }

    /// The assembled WGSL module of this pass for `method`.
    pub fn source(self, method: RenderMethod) -> String {
        let mut s = prelude();
        s.push_str(COMMON_WGSL);
        if method == RenderMethod::Slices
            && matches!(self, Pass::Shadow | Pass::Slices | Pass::SliceField)
        {
            // The implicit field instead of the parcels' hypertexture.
            s.push_str(IMPLICIT_WGSL);
            if self == Pass::Shadow {
                s.push_str(FIELD_SLICES_WGSL);
            }
            if self.sees_air() {
                s.push_str(AIR_WGSL);
            }
            s.push_str(self.file());
            return s;
        }
        if self.needs_density() || self == Pass::Bake {
            s.push_str(PARCEL_WGSL);
        }
        if self.needs_density() {
            s.push_str(match method {
                RenderMethod::Exact => FIELD_EXACT_WGSL,
                // `used_by` gives sprites and slices no density pass; their
                // arm only keeps `source` total.
                RenderMethod::Baked | RenderMethod::Sprites | RenderMethod::Slices => {
                    FIELD_BAKED_WGSL
                }
            });
            s.push_str(DENSITY_WGSL);
        }
        if self == Pass::Clouds {
            s.push_str(LIGHTING_WGSL);
        }
        if self.sees_air() {
            s.push_str(AIR_WGSL);
        }
        s.push_str(self.file());
        s
    }
}

/// Array sizes shared with [`crate::render::pack`], as WGSL constants.
pub fn prelude() -> String {
    format!(
        "// Generated by src/render/shaders.rs from src/render/pack.rs.\n\
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
