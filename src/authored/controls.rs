//! The slice renderer's qualitative controls (Schpok et al. 2003 Table 2,
//! §5.1–5.2): `[render.slices]` in a scene. Each control moves the image
//! along one visual dimension; the derived quantities below compensate for
//! the others (the paper's "qualitatively independent" parameters):
//!   plane opacity    = Opacity ÷ slicing planes
//!   slicing planes   = Quality
//!   lacunarity       = Detail
//!   shadow magnitude = Dirtiness ÷ plane opacity
//!   alpha cutoff     = Sharpness × plane opacity

use serde::{Deserialize, Serialize};

use super::finite_in;
use super::octaves::{MAX_OCTAVES, NoiseMotion, NoiseTier, validate_tiers};
use crate::error::{Error, Result};

/// Where the slice vertices' field and shadow are evaluated (paper §4.1:
/// "on the CPU (or a compute pass: measure both)").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexField {
    /// On the CPU, with a uniform-grid index of the primitives (the reference).
    #[default]
    Cpu,
    /// In a WGSL compute pass over the vertex buffer, with the same index.
    Gpu,
}

impl VertexField {
    /// The name as written in a scene.
    pub fn name(self) -> &'static str {
        match self {
            Self::Cpu => "cpu",
            Self::Gpu => "gpu",
        }
    }
}

/// `[render.slices]`: settings of the `slices` render method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SlicesConfig {
    /// Overall opacity of the cloud, 0.01 to 16 (the integral of plane
    /// opacities across all planes; the renderer scales it so it acts on
    /// one mean primitive, see `render::slices::CloudscapeScale`).
    pub opacity: f32,
    /// Number of slicing planes, 8 to 1024.
    pub quality: u32,
    /// Lacunarity: the frequency ratio of successive noise octaves, 1.1 to 4.
    pub detail: f32,
    /// How fast the cloud darkens with depth toward the light, 0 to 16.
    pub dirtiness: f32,
    /// Alpha cutoff in units of the plane opacity, 0 to 1: the fraction of
    /// the (field × noise) below which a fragment is dropped.
    pub sharpness: f32,
    /// Lit cloud colour, linear RGB in [0, 1].
    pub cloud_colour: [f32; 3],
    /// Colour of fully shadowed cloud, linear RGB in [0, 1].
    pub shadow_colour: [f32; 3],
    /// The paper's Background control: with `sky = false`, the scene's
    /// background (everything no terrain covers) is this flat colour
    /// instead of the sky gradient, as linear radiance in the sky's units
    /// (the sky's zenith is about [0.16, 0.34, 0.85]). Linear RGB in [0, 1].
    pub background_colour: [f32; 3],
    /// Draw the sky behind the clouds (true) or `background_colour` (false).
    pub sky: bool,
    /// Include the first noise octave in the vertex shadow (paper §4:
    /// "optionally with the first noise octave"): the shadow sums field ×
    /// media(first octave) instead of the field alone, so the noise's large
    /// lumps shade what lies behind them.
    pub shadow_octave: bool,
    /// Where the field and shadow at the slice vertices are evaluated:
    /// "cpu" (the reference) or "gpu" (a compute pass, the same formulas).
    pub vertex_field: VertexField,
    /// Outline the ellipsoids in the window (`cumulus watch` only).
    pub outlines: bool,
    /// Noise octaves composited per fragment (advanced), 1 to 8.
    pub octaves: u32,
    /// Vertices along each side of a slicing plane minus one (advanced):
    /// the resolution of the vertex field and shadows, 1 to 512.
    pub tessellation: u32,
    /// The Base tier: moves every tier's first octave.
    pub base: NoiseMotion,
    /// Atmospheric tiers, bottom up.
    pub tiers: Vec<NoiseTier>,
}

impl Default for SlicesConfig {
    fn default() -> Self {
        Self {
            // With the cloudscape scaling of the renderer, τ through a mean
            // primitive's centre is about Opacity × ½ (mean Wyvill field on
            // a diameter) × ½ (mean noise): 6 makes it ~0.8 opaque.
            opacity: 6.0,
            quality: 128,
            detail: 2.0,
            dirtiness: 0.5,
            sharpness: 0.1,
            cloud_colour: [1.0, 1.0, 1.0],
            shadow_colour: [0.35, 0.38, 0.45],
            background_colour: [0.45, 0.62, 0.85],
            sky: true,
            shadow_octave: true,
            vertex_field: VertexField::Cpu,
            outlines: false,
            octaves: 4,
            tessellation: 32,
            base: NoiseMotion::default(),
            tiers: vec![NoiseTier::default()],
        }
    }
}

impl SlicesConfig {
    /// Opacity of one slicing plane: Opacity ÷ planes, so adding planes
    /// does not thicken the cloud.
    pub fn plane_opacity(&self) -> f32 {
        self.opacity / self.planes() as f32
    }

    /// Number of slicing planes (= Quality).
    pub fn planes(&self) -> u32 {
        self.quality
    }

    /// Lacunarity of the noise octaves (= Detail).
    pub fn lacunarity(&self) -> f32 {
        self.detail
    }

    /// Shadow added per unit of vertex opacity in eq. 2: Dirtiness ÷ plane
    /// opacity (Table 2), so a vertex's shadow step is Dirtiness × field
    /// whatever the Opacity (the slicing also divides it by the vertices
    /// along the light ray, §5.2: see `SliceGeometry::shadow_rays`).
    pub fn shadow_magnitude(&self) -> f32 {
        self.dirtiness / self.plane_opacity()
    }

    /// Fragment alpha below which nothing is drawn: Sharpness × plane
    /// opacity, so changing Opacity does not grow or shrink the cloud.
    pub fn alpha_cutoff(&self) -> f32 {
        self.sharpness * self.plane_opacity()
    }

    /// Checks every key; errors name `render.slices.KEY` and the range.
    pub fn validate(&self) -> Result<()> {
        const T: &str = "render.slices";
        finite_in(
            &format!("{T}.opacity"),
            self.opacity,
            0.01,
            16.0,
            "0.01 to 16",
        )?;
        if !(8..=1024).contains(&self.quality) {
            return Err(Error::invalid(
                format!("{T}.quality"),
                self.quality,
                "8 to 1024 slicing planes",
            ));
        }
        finite_in(
            &format!("{T}.detail"),
            self.detail,
            1.1,
            4.0,
            "1.1 to 4 (lacunarity)",
        )?;
        finite_in(
            &format!("{T}.dirtiness"),
            self.dirtiness,
            0.0,
            16.0,
            "0 to 16",
        )?;
        finite_in(
            &format!("{T}.sharpness"),
            self.sharpness,
            0.0,
            1.0,
            "0 to 1",
        )?;
        for (key, c) in [
            ("cloud_colour", self.cloud_colour),
            ("shadow_colour", self.shadow_colour),
            ("background_colour", self.background_colour),
        ] {
            for (k, v) in c.iter().enumerate() {
                finite_in(
                    &format!("{T}.{key}[{k}]"),
                    *v,
                    0.0,
                    1.0,
                    "linear RGB, each 0 to 1",
                )?;
            }
        }
        if !(1..=MAX_OCTAVES as u32).contains(&self.octaves) {
            return Err(Error::invalid(
                format!("{T}.octaves"),
                self.octaves,
                format!("1 to {MAX_OCTAVES}"),
            ));
        }
        if !(1..=512).contains(&self.tessellation) {
            return Err(Error::invalid(
                format!("{T}.tessellation"),
                self.tessellation,
                "1 to 512",
            ));
        }
        self.base.validate(&format!("{T}.base"))?;
        validate_tiers(&self.tiers, &format!("{T}.tiers"))
    }
}
