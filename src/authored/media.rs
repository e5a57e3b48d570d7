//! Cloud media filters (Schpok et al. 2003 Table 2, §5.2): named maps of
//! the composited noise, which lies in [0, 1], to the density factor that
//! "subtracts" detail from the implicit field. The slice renderer applies
//! the same filters per fragment; these are their CPU reference.

use serde::{Deserialize, Serialize};

/// One media filter of Table 2. Serialised lower-case in scenes
/// (`media = "wispy"`).
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
