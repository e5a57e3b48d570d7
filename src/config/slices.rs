//! The slice renderer's qualitative controls (Schpok et al. 2003 Table 2,
//! §5.1–5.2): `[render.slices]` in a scene. Each control moves the image
//! along one visual dimension; the derived quantities below compensate for
//! the others (the paper's "qualitatively independent" parameters):
//!   plane opacity    = Opacity ÷ slicing planes
//!   slicing planes   = Quality
//!   lacunarity       = Detail
//!   shadow magnitude = Dirtiness ÷ plane opacity
//!   alpha cutoff     = Sharpness × plane opacity

//!
//! Also the types these controls are made of: the media filters of Table 2
//! ([`MediaFilter`]) and the atmospheric tiers of the noise octaves
//! ([`NoiseTier`], [`NoiseMotion`]), with their checks; the slices method
//! (src/methods/slices/) turns them into its uniforms.

use serde::{Deserialize, Serialize};

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

/// The range of Opacity (validation and the window's slider).
pub const OPACITY_RANGE: (f32, f32) = (0.01, 1000.0);

/// `[render.slices]`: settings of the `slices` render method.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SlicesConfig {
    /// Overall opacity of the cloud, 0.01 to 1000 (the integral of plane
    /// opacities across all planes of a cloud's stack; the renderer scales
    /// it so it acts on one mean primitive of the cloud, see
    /// `methods::slices::model::CloudScale`): the optical depth through a
    /// mean primitive where the field and media are 1. Their product is
    /// mostly 0.05–0.3, so a few is a thin veil and 100–200 the optically
    /// thick body (τ 5–20 across) a real cumulus or cumulonimbus has.
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
    /// Lit cloud colour as painted (sRGB-encoded, shaders/artist.wgsl:
    /// 1 a sunlit white top), in [0, 1].
    pub cloud_colour: [f32; 3],
    /// Colour of fully shadowed cloud as painted, in [0, 1]: lit by the
    /// sky alone.
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
    /// Drop a fragment on its implicit field alone before fetching its
    /// noise where the noise cannot lift it over the cut-off (the same
    /// image either way; off only to check that).
    pub early_discard: bool,
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
            // With the per-cloud scaling of the renderer, τ through a mean
            // primitive's centre is about Opacity × ½ (mean Wyvill field on
            // a diameter) × ½ (mean noise): 6 makes it ~0.8 opaque.
            opacity: 6.0,
            quality: 128,
            detail: 2.0,
            // Dirtiness, Sharpness and the shadow colour: the values
            // nearest the converged path tracer (512–1024 spp) on the
            // parcels of the fair-weather and towering-cumulus frames,
            // kept under 0.08 on a tower and a deck too (docs/rendering.md:
            // mean FLIP 0.074 / 0.078 at 160×120 where 2.5 and
            // [0.45, 0.48, 0.55], chosen against 64-spp references whose
            // noise reads as dark sparkle, give 0.070 / 0.107).
            dirtiness: 3.0,
            sharpness: 0.03,
            cloud_colour: [1.0, 1.0, 1.0],
            shadow_colour: [0.78, 0.8, 0.85],
            background_colour: [0.45, 0.62, 0.85],
            sky: true,
            shadow_octave: true,
            vertex_field: VertexField::Cpu,
            outlines: false,
            early_discard: true,
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
            OPACITY_RANGE.0,
            OPACITY_RANGE.1,
            "0.01 to 1000",
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
        for (key, c, allowed) in [
            (
                "cloud_colour",
                self.cloud_colour,
                "painted (sRGB) RGB, each 0 to 1",
            ),
            (
                "shadow_colour",
                self.shadow_colour,
                "painted (sRGB) RGB, each 0 to 1",
            ),
            (
                "background_colour",
                self.background_colour,
                "linear RGB, each 0 to 1",
            ),
        ] {
            for (k, v) in c.iter().enumerate() {
                finite_in(&format!("{T}.{key}[{k}]"), *v, 0.0, 1.0, allowed)?;
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

/// Most octaves (the paper uses four; more is an advanced setting).
pub const MAX_OCTAVES: usize = 8;
/// Most atmospheric tiers.
pub const MAX_TIERS: usize = 4;
/// Wind and torque of one tier, or of the Base tier.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoiseMotion {
    /// Translation of the first octave's pattern; octave o moves f times
    /// faster. units: m/s
    pub wind_m_s: [f32; 3],
    /// Rotation of the first octave's pattern: the axis, with its length
    /// the turning rate; octave o turns f times faster. units: degrees/s
    pub torque_deg_s: [f32; 3],
}

/// One atmospheric tier: `[[render.slices.tiers]]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoiseTier {
    /// Altitude where this tier starts; it reaches up to the next tier's
    /// bottom (the first tier also covers everything below). units: m
    pub bottom_m: f32,
    /// Media filter of this tier's noise.
    pub media: MediaFilter,
    /// Size of one tile of the first octave ("cloud size is conveyed by
    /// the scale of the first octave", §5.2). units: m
    pub scale_m: f32,
    /// How many times longer the noise features are along the wind than
    /// across it (1 = isotropic; the paper's cirrus, Figure 7, uses > 1).
    pub stretch_along_wind: f32,
    /// This tier's wind: octaves 2 and up drift at f·wind (octave 1 moves
    /// with the Base tier). units: m/s
    pub wind_m_s: [f32; 3],
    /// This tier's torque (axis, length = rate) for octaves 2 and up.
    /// units: degrees/s
    pub torque_deg_s: [f32; 3],
}

impl Default for NoiseTier {
    fn default() -> Self {
        Self {
            bottom_m: 0.0,
            media: MediaFilter::Cumulus,
            scale_m: 1200.0,
            stretch_along_wind: 1.0,
            wind_m_s: [0.0; 3],
            torque_deg_s: [0.0; 3],
        }
    }
}

impl NoiseTier {
    /// This tier's own wind and torque.
    pub fn motion(&self) -> NoiseMotion {
        NoiseMotion {
            wind_m_s: self.wind_m_s,
            torque_deg_s: self.torque_deg_s,
        }
    }

    /// Checks one tier; `name` is its place (`"render.slices.tiers[1]"`).
    pub fn validate(&self, name: &str) -> Result<()> {
        finite_in(
            &format!("{name}.bottom_m"),
            self.bottom_m,
            -1.0e4,
            1.0e5,
            "-1e4 to 1e5 m",
        )?;
        finite_in(
            &format!("{name}.scale_m"),
            self.scale_m,
            1.0,
            1.0e5,
            "1 to 1e5 m",
        )?;
        finite_in(
            &format!("{name}.stretch_along_wind"),
            self.stretch_along_wind,
            1.0,
            100.0,
            "1 to 100",
        )?;
        self.motion().validate(name)
    }
}

impl NoiseMotion {
    /// Checks wind (≤ 100 m/s per component) and torque (≤ 360 °/s).
    pub fn validate(&self, name: &str) -> Result<()> {
        for (k, v) in self.wind_m_s.iter().enumerate() {
            finite_in(
                &format!("{name}.wind_m_s[{k}]"),
                *v,
                -100.0,
                100.0,
                "-100 to 100 m/s",
            )?;
        }
        for (k, v) in self.torque_deg_s.iter().enumerate() {
            finite_in(
                &format!("{name}.torque_deg_s[{k}]"),
                *v,
                -360.0,
                360.0,
                "-360 to 360 degrees/s",
            )?;
        }
        Ok(())
    }
}

/// Checks the tier list: 1 to [`MAX_TIERS`] tiers with strictly increasing
/// bottoms.
pub fn validate_tiers(tiers: &[NoiseTier], name: &str) -> Result<()> {
    if tiers.is_empty() || tiers.len() > MAX_TIERS {
        return Err(Error::invalid(
            name,
            format!("{} tiers", tiers.len()),
            format!("1 to {MAX_TIERS} [[{name}]] tables"),
        ));
    }
    for (i, t) in tiers.iter().enumerate() {
        let place = format!("{name}[{i}]");
        t.validate(&place)?;
        if i > 0 && t.bottom_m <= tiers[i - 1].bottom_m {
            return Err(Error::invalid(
                format!("{place}.bottom_m"),
                t.bottom_m,
                format!(
                    "above the previous tier's bottom ({} m)",
                    tiers[i - 1].bottom_m
                ),
            ));
        }
    }
    Ok(())
}

/// `value` must be finite and within [lo, hi]; the error names `name` and
/// says `allowed`.
pub(crate) fn finite_in(name: &str, value: f32, lo: f32, hi: f32, allowed: &str) -> Result<()> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(Error::invalid(name, value, allowed))
    }
}

/// One cloud media filter of Schpok et al. 2003 Table 2 (§5.2): a named
/// map of the composited noise, which lies in [0, 1], to the density
/// factor that "subtracts" detail from the implicit field. Serialised
/// lower-case in scenes (`media = "wispy"`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MediaFilter {
    /// Table 2: cumulus = noise. Billowy, the noise as it is.
    #[default]
    Cumulus,
    /// Table 2: stratus = noise. The table gives the same filter as
    /// cumulus; stratus differs by its flat primitives and a larger
    /// first-octave scale, which the tier sets.
    Stratus,
    /// Table 2: wispy = 1 − 2·|noise|, where |noise| is taken of the noise
    /// centred on zero (noise − ½), so the result stays in [0, 1]: bright
    /// thin ridges where the noise crosses its middle.
    Wispy,
    /// Table 2's last row, (1 + 10·noise)⁻¹, the "specially filtered
    /// cirrus noise" of Figure 7: dense where the noise is low, a long
    /// thin tail elsewhere. Its tier also stretches the noise along the
    /// wind (see `octaves`).
    Cirrus,
}

impl MediaFilter {
    /// Every filter, in the order of their GPU ids.
    pub const ALL: [MediaFilter; 4] = [Self::Cumulus, Self::Stratus, Self::Wispy, Self::Cirrus];

    /// The filter's value for noise `n` in [0, 1]; the result is in [0, 1].
    pub fn apply(self, n: f32) -> f32 {
        match self {
            Self::Cumulus | Self::Stratus => n,
            Self::Wispy => 1.0 - 2.0 * (n - 0.5).abs(),
            Self::Cirrus => 1.0 / (1.0 + 10.0 * n),
        }
    }

    /// The id the shaders switch on: the slices pass's WGSL filter numbers
    /// them the same (tests/cumulus/render/slices.rs checks it).
    pub fn gpu_id(self) -> u32 {
        self as u32
    }

    /// The filter's name as written in a scene.
    pub fn name(self) -> &'static str {
        match self {
            Self::Cumulus => "cumulus",
            Self::Stratus => "stratus",
            Self::Wispy => "wispy",
            Self::Cirrus => "cirrus",
        }
    }
}
