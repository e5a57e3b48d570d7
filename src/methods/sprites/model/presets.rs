//! The dozen cloud types (paper §3.2, §5.1) as named presets: boxes,
//! textures, colour levels and alpha; and `[[layers]]` of a type over an
//! area, expanded into sprite clouds deterministically. Cirrus is drawn as
//! flat textured rectangles, as in the paper.

use serde::{Deserialize, Serialize};

use super::atlas::{FLAT_BOTTOM_TILE, FOGGY_TILES, PUFFY_TILES, WISPY_TILES};
use super::cloud::{PRUNE_TYPICAL, SpriteBox, SpriteCloud, SpriteCloudSpec};
use super::finite_in;
use super::shading::ColorLevel;
use crate::error::{Error, Result};
use crate::physics::rng::SplitMix64;

/// The cloud types.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CloudType {
    Stratus,
    Nimbostratus,
    Altostratus,
    Stratocumulus,
    Altocumulus,
    CumulusHumilis,
    CumulusCongestus,
    Cumulonimbus,
    Cirrostratus,
    Cirrocumulus,
    Cirrus,
    Fog,
}

/// The look of a type: one cloud's size, its sprites and colours.
struct Look {
    /// Typical cloud base. units: m
    base_m: f32,
    /// Cloud thickness. units: m
    thick_m: f32,
    /// Cloud width (and layer cell size). units: m
    width_m: f32,
    /// Sprite size range (width = height unless `stretch`). units: m
    sprite_m: [f32; 2],
    /// Horizontal stretch of the sprites (hazy and cirrus sprites are wide).
    stretch: f32,
    count: u32,
    textures: &'static [u8],
    /// A flat-bottomed row at the base (cumulus).
    flat_base: bool,
    /// Painted colour (sRGB-encoded, shaders/artist.wgsl) at the bottom
    /// and top levels (RGB) and the alpha.
    bottom: [f32; 3],
    top: [f32; 3],
    alpha: f32,
    /// The boxes the cloud is built from (the paper builds a cloud from
    /// several boxes); None: one box filling the cloud, `count` sprites.
    parts: Option<&'static [Part]>,
    /// A layer of this type is a deck: its clouds overlap their
    /// neighbours and are barely jittered, so it has no gaps.
    deck: bool,
}

/// One box of a type's cloud, each its own shading group: its half-width
/// as a fraction of the cloud's width, its bottom and top as fractions of
/// the thickness above the base, its sprite count, and the size and
/// horizontal stretch of its sprites (× the type's).
#[derive(Debug, Clone, Copy)]
struct Part {
    half_w: f32,
    z: [f32; 2],
    count: u32,
    scale: f32,
    stretch: f32,
}

const fn part(half_w: f32, z0: f32, z1: f32, count: u32, scale: f32, stretch: f32) -> Part {
    Part {
        half_w,
        z: [z0, z1],
        count,
        scale,
        stretch,
    }
}

/// Cumulus humilis: a flat base and a low dome.
const HUMILIS: [Part; 2] = [
    part(0.5, 0.0, 0.6, 20, 1.0, 1.0),
    part(0.32, 0.45, 1.0, 12, 0.85, 1.0),
];
/// Cumulus congestus: a flat base, a body narrowing upward, a domed top.
const CONGESTUS: [Part; 3] = [
    part(0.5, 0.0, 0.4, 45, 1.0, 1.0),
    part(0.38, 0.3, 0.75, 40, 0.9, 1.0),
    part(0.24, 0.65, 1.0, 25, 0.8, 1.0),
];
/// Cumulonimbus: a dark flat base a little wider than the tower, the
/// tower, and the anvil spreading to more than twice the tower's width at
/// the tropopause, with an overshooting top over the updraught.
const CUMULONIMBUS: [Part; 5] = [
    part(0.3, 0.0, 0.3, 70, 1.0, 1.0),
    part(0.22, 0.25, 0.8, 90, 1.0, 1.0),
    part(0.9, 0.8, 0.93, 100, 1.1, 1.8),
    part(0.6, 0.88, 0.97, 70, 1.0, 1.8),
    part(0.14, 0.9, 1.0, 20, 0.8, 1.0),
];
/// A deck: one box reaching past the cloud's cell into its neighbours'.
const DECK: [Part; 1] = [part(0.62, 0.0, 1.0, 0, 1.0, 1.0)];

const FOG_WISP: [u8; 5] = [0, 1, 2, 4, 5];
const PUFF_WISP: [u8; 8] = [10, 11, 12, 13, 14, 15, 6, 7];

impl CloudType {
    /// All twelve, in the order of `profiles/cloud_types.toml`.
    pub const ALL: [CloudType; 12] = [
        CloudType::Stratus,
        CloudType::Nimbostratus,
        CloudType::Altostratus,
        CloudType::Stratocumulus,
        CloudType::Altocumulus,
        CloudType::CumulusHumilis,
        CloudType::CumulusCongestus,
        CloudType::Cumulonimbus,
        CloudType::Cirrostratus,
        CloudType::Cirrocumulus,
        CloudType::Cirrus,
        CloudType::Fog,
    ];

    /// Cirrus sprites are flat horizontal rectangles, not camera-facing.
    pub fn is_flat(self) -> bool {
        self == CloudType::Cirrus
    }

    fn look(self) -> Look {
        use CloudType::*;
        let l = |base_m, thick_m, width_m, sprite_m, count, textures, bottom, top, alpha| Look {
            base_m,
            thick_m,
            width_m,
            sprite_m,
            stretch: 1.0,
            count,
            textures,
            flat_base: false,
            bottom,
            top,
            alpha,
            parts: None,
            deck: false,
        };
        match self {
            // §5.1: stratus light grey and partly transparent, nimbostratus darker.
            Stratus => Look {
                stretch: 1.5,
                parts: Some(&DECK),
                deck: true,
                ..l(
                    500.0,
                    300.0,
                    4000.0,
                    [500.0, 800.0],
                    60,
                    &FOGGY_TILES,
                    [0.62; 3],
                    [0.8; 3],
                    0.7,
                )
            },
            // A thick deck: dark grey underneath, a little lighter above.
            Nimbostratus => Look {
                stretch: 1.5,
                parts: Some(&DECK),
                deck: true,
                ..l(
                    700.0,
                    1500.0,
                    4000.0,
                    [1100.0, 1600.0],
                    90,
                    &FOGGY_TILES,
                    [0.36, 0.37, 0.4],
                    [0.66, 0.67, 0.7],
                    0.95,
                )
            },
            Altostratus => Look {
                stretch: 1.5,
                parts: Some(&DECK),
                deck: true,
                ..l(
                    3000.0,
                    500.0,
                    4000.0,
                    [600.0, 900.0],
                    50,
                    &FOG_WISP,
                    [0.68, 0.7, 0.75],
                    [0.82, 0.84, 0.88],
                    0.6,
                )
            },
            Stratocumulus => l(
                900.0,
                400.0,
                2000.0,
                [300.0, 500.0],
                50,
                &PUFF_WISP,
                [0.62; 3],
                [0.88; 3],
                0.85,
            ),
            Altocumulus => l(
                3500.0,
                250.0,
                1200.0,
                [150.0, 250.0],
                40,
                &PUFFY_TILES,
                [0.78; 3],
                [0.96; 3],
                0.85,
            ),
            // Humilis puffs are nearly uniformly white.
            CumulusHumilis => Look {
                flat_base: true,
                parts: Some(&HUMILIS),
                ..l(
                    1000.0,
                    500.0,
                    800.0,
                    [200.0, 300.0],
                    30,
                    &PUFFY_TILES,
                    [0.92; 3],
                    [1.0; 3],
                    1.0,
                )
            },
            CumulusCongestus => Look {
                flat_base: true,
                parts: Some(&CONGESTUS),
                ..l(
                    1000.0,
                    2500.0,
                    2000.0,
                    [400.0, 700.0],
                    100,
                    &PUFF_WISP,
                    [0.6; 3],
                    [1.0; 3],
                    1.0,
                )
            },
            // §5.1: "a black look from top to bottom" seen from below it;
            // its sunlit anvil is lighter.
            Cumulonimbus => Look {
                flat_base: true,
                parts: Some(&CUMULONIMBUS),
                ..l(
                    900.0,
                    9000.0,
                    6000.0,
                    [900.0, 1500.0],
                    100,
                    &PUFFY_TILES,
                    [0.3; 3],
                    [0.85; 3],
                    1.0,
                )
            },
            Cirrostratus => Look {
                stretch: 2.0,
                parts: Some(&DECK),
                deck: true,
                ..l(
                    7500.0,
                    200.0,
                    5000.0,
                    [1000.0, 1500.0],
                    30,
                    &WISPY_TILES,
                    [0.9, 0.92, 0.96],
                    [0.95, 0.96, 1.0],
                    0.35,
                )
            },
            Cirrocumulus => l(
                6500.0,
                150.0,
                1500.0,
                [100.0, 200.0],
                50,
                &PUFF_WISP,
                [0.9; 3],
                [0.98; 3],
                0.6,
            ),
            Cirrus => Look {
                stretch: 3.0,
                ..l(
                    8000.0,
                    50.0,
                    3000.0,
                    [600.0, 900.0],
                    12,
                    &WISPY_TILES,
                    [0.95; 3],
                    [1.0; 3],
                    0.5,
                )
            },
            Fog => Look {
                stretch: 1.5,
                parts: Some(&DECK),
                deck: true,
                ..l(
                    0.0,
                    150.0,
                    3000.0,
                    [400.0, 600.0],
                    60,
                    &FOGGY_TILES,
                    [0.78, 0.8, 0.86],
                    [0.85, 0.87, 0.92],
                    0.6,
                )
            },
        }
    }

    /// Typical cloud base of the type. units: m
    pub fn base_m(self) -> f32 {
        self.look().base_m
    }

    /// Width of one cloud of the type. units: m
    pub fn width_m(self) -> f32 {
        self.look().width_m
    }

    /// The type's five colour levels, heights relative to the cloud centre.
    pub fn levels(self) -> Vec<ColorLevel> {
        let k = self.look();
        (0..5)
            .map(|i| {
                let t = i as f32 / 4.0;
                let c = |a: usize| k.bottom[a] + (k.top[a] - k.bottom[a]) * t;
                ColorLevel {
                    height_m: (t - 0.5) * k.thick_m,
                    rgba: [c(0), c(1), c(2), k.alpha],
                }
            })
            .collect()
    }

    /// One cloud of the type with its base at `base_m` above (x, y), from `seed`.
    pub fn spec(self, name: &str, x_m: f32, y_m: f32, base_m: f32, seed: u64) -> SpriteCloudSpec {
        let k = self.look();
        let ht = 0.5 * k.thick_m;
        let s = k.sprite_m;
        let whole = [part(0.5, 0.0, 1.0, k.count, 1.0, 1.0)];
        let parts = k.parts.unwrap_or(&whole);
        let mut boxes: Vec<SpriteBox> = parts
            .iter()
            .enumerate()
            .map(|(g, p)| {
                let size = [s[0] * p.scale, s[1] * p.scale];
                let stretch = k.stretch * p.stretch;
                // A box reaching past the cloud (a deck) keeps its sprites'
                // centres at its edge; otherwise they stay inside the cloud.
                let half = p.half_w * k.width_m;
                let inset = if p.half_w > 0.5 { 0.0 } else { 0.5 * size[1] };
                let xy = (half - inset).max(0.0);
                let lo = -ht + (p.z[0] * k.thick_m + 0.5 * size[0]).min(k.thick_m * p.z[1]);
                let hi = (-ht + p.z[1] * k.thick_m - 0.5 * size[0]).max(lo);
                SpriteBox {
                    min_m: [-xy, -xy, lo],
                    max_m: [xy, xy, hi],
                    count: Some(if p.count == 0 { k.count } else { p.count }.min(100)),
                    density_per_km3: None,
                    width_m: [size[0] * stretch, size[1] * stretch],
                    height_m: size,
                    // The atlas's puffs and fog are lit from above: turned
                    // at most 30° either way; flat cirrus turns freely.
                    rotation_deg: if self.is_flat() {
                        [0.0, 360.0]
                    } else {
                        [-30.0, 30.0]
                    },
                    textures: k.textures.to_vec(),
                    group: g as u32,
                }
            })
            .collect();
        if k.flat_base {
            // §3.2: flat bottoms from the flat-bottomed tile, rotation ±5°,
            // under the lowest box.
            let z = -ht + 0.3 * s[0];
            let xy = 0.8 * parts[0].half_w * k.width_m;
            boxes.push(SpriteBox {
                min_m: [-xy, -xy, z],
                max_m: [xy, xy, z],
                count: Some((boxes[0].count.unwrap_or(1) / 4).max(1)),
                rotation_deg: [-5.0, 5.0],
                textures: vec![FLAT_BOTTOM_TILE],
                group: parts.len() as u32,
                ..boxes[0].clone()
            });
        }
        SpriteCloudSpec {
            name: name.to_string(),
            kind: self,
            center_m: [x_m, y_m, base_m + ht],
            seed,
            prune_fraction: PRUNE_TYPICAL,
            levels: None,
            boxes,
        }
    }
}

/// Most cloud cells one layer may hold.
pub const MAX_LAYER_CELLS: usize = 20_000;

/// A `[[layers]]` table: a type spread over an area with a coverage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerSpec {
    #[serde(rename = "type")]
    pub kind: CloudType,
    /// Cloud base; the type's typical base when absent. units: m
    #[serde(default)]
    pub altitude_m: Option<f32>,
    /// Fraction of the layer's cells holding a cloud, in [0, 1].
    pub coverage: f32,
    /// Side of the square the layer covers, centred on `center_m`. units: m
    pub extent_m: f32,
    /// Centre of the layer (x, y). units: m
    #[serde(default)]
    pub center_m: [f32; 2],
    #[serde(default)]
    pub seed: u64,
}

impl LayerSpec {
    /// Checks the layer; `key` is `"layers[i]"`.
    pub fn validate(&self, key: &str) -> Result<()> {
        if let Some(a) = self.altitude_m {
            finite_in(
                &format!("{key}.altitude_m"),
                a,
                0.0,
                20_000.0,
                "a cloud base in [0, 20000] m",
            )?;
        }
        finite_in(
            &format!("{key}.coverage"),
            self.coverage,
            0.0,
            1.0,
            "a fraction in [0, 1]",
        )?;
        finite_in(
            &format!("{key}.extent_m"),
            self.extent_m,
            1.0,
            400_000.0,
            "a side in [1, 400000] m",
        )?;
        for c in self.center_m {
            finite_in(
                &format!("{key}.center_m"),
                c,
                -1.0e6,
                1.0e6,
                "finite, within ±1000 km",
            )?;
        }
        let n = self.cells_per_side();
        if n * n > MAX_LAYER_CELLS {
            return Err(Error::invalid(
                format!("{key}.extent_m"),
                self.extent_m,
                format!(
                    "at most {MAX_LAYER_CELLS} clouds of {} m per layer",
                    self.kind.width_m()
                ),
            ));
        }
        Ok(())
    }

    fn cells_per_side(&self) -> usize {
        (self.extent_m / self.kind.width_m()).ceil().max(1.0) as usize
    }

    /// The layer's cloud specs: one cell per cloud width, a cloud where a
    /// seeded draw falls under the coverage, jittered by a quarter cell (a
    /// deck's by 8 %).
    pub fn specs(&self) -> Vec<SpriteCloudSpec> {
        let n = self.cells_per_side();
        let cell = self.extent_m / n as f32;
        let base = self.altitude_m.unwrap_or(self.kind.base_m());
        let mut rng = SplitMix64::new(self.seed ^ 0x1a7e_55ed);
        // A deck is barely jittered: its clouds overlap into one sheet.
        let jitter = if self.kind.look().deck { 0.08 } else { 0.25 };
        let mut out = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (draw, jx, jy, seed) = (
                    rng.next_f64() as f32,
                    rng.range(-jitter, jitter) as f32,
                    rng.range(-jitter, jitter) as f32,
                    rng.next_u64(),
                );
                if draw >= self.coverage {
                    continue;
                }
                let x = self.center_m[0] + (i as f32 + 0.5 + jx) * cell - 0.5 * self.extent_m;
                let y = self.center_m[1] + (j as f32 + 0.5 + jy) * cell - 0.5 * self.extent_m;
                out.push(self.kind.spec("", x, y, base, seed));
            }
        }
        out
    }

    /// The layer's clouds, filled.
    pub fn build(&self) -> Vec<SpriteCloud> {
        self.specs().iter().map(SpriteCloudSpec::build).collect()
    }
}
