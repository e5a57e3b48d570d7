//! Sprite clouds (paper §3.1): an artist's boxes, each filled with randomly
//! placed sprites at load (seeded, so the same scene gives the same sprites),
//! then pruned of sprites too close to another to be worth their overdraw.
//! Physics parcels become sprite clouds in [`super::parcels`].

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::presets::CloudType;
use super::parcels::PARCEL_MAP;
use super::shading::{ColorLevel, Lighting, VertexShade};
use super::{finite_in, range_in};
use crate::error::{Error, Result};
use crate::physics::rng::SplitMix64;

/// Pruning distance as a fraction of the sprite height for typical clouds.
/// The paper's number (§3.1, "a radius of ⅕ of the sprite height works well
/// for typical clouds") is garbled in our text extract; ⅕ is its reading.
pub const PRUNE_TYPICAL: f32 = 0.2;
/// Pruning fraction that "yields dense clouds" (§3.1, read as ⅒).
pub const PRUNE_DENSE: f32 = 0.1;
/// Most sprites in one cloud: the paper's clouds hold 5–400 sprites.
pub const MAX_SPRITES_PER_CLOUD: usize = 400;
/// Most sprites one box may ask for: the paper uses 1–100 per box.
pub const MAX_SPRITES_PER_BOX: u32 = 100;
/// Textures on the atlas (§3.2).
pub const TEXTURES: u8 = 16;

/// One box of a sprite cloud, as written in `boxes = [{ ... }]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpriteBox {
    /// Lower corner relative to the cloud centre (z up). units: m
    pub min_m: [f32; 3],
    /// Upper corner relative to the cloud centre. units: m
    pub max_m: [f32; 3],
    /// Sprites to place; give this or `density_per_km3`.
    #[serde(default)]
    pub count: Option<u32>,
    /// Sprites per cubic kilometre of box; the count is rounded, at least 1.
    #[serde(default)]
    pub density_per_km3: Option<f32>,
    /// Sprite width range. units: m
    pub width_m: [f32; 2],
    /// Sprite height range. units: m
    pub height_m: [f32; 2],
    /// Rotation range in the sprite plane (narrow for flat bottoms). units: degrees
    #[serde(default = "full_turn")]
    pub rotation_deg: [f32; 2],
    /// Atlas tiles to choose from (0–15).
    pub textures: Vec<u8>,
    /// Shading group the box's sprites belong to (§5.2).
    #[serde(default)]
    pub group: u32,
}

pub(super) fn full_turn() -> [f32; 2] {
    [0.0, 360.0]
}

/// A `[[sprite_clouds]]` table: boxes around a centre, a type for colours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpriteCloudSpec {
    /// Label shown next to the cloud.
    #[serde(default)]
    pub name: String,
    /// Cloud type: its colour levels and alpha (§5.1).
    #[serde(rename = "type")]
    pub kind: CloudType,
    /// Cloud centre (x, y horizontal, z up). units: m
    pub center_m: [f32; 3],
    /// Seed of the sprite placement.
    #[serde(default)]
    pub seed: u64,
    /// Pruning distance as a fraction of the sprite height.
    #[serde(default = "prune_typical")]
    pub prune_fraction: f32,
    /// Five colour levels overriding the type's (heights relative to the centre).
    #[serde(default)]
    pub levels: Option<Vec<ColorLevel>>,
    /// The boxes; when empty, the type's preset boxes around `center_m`.
    #[serde(default)]
    pub boxes: Vec<SpriteBox>,
}

fn prune_typical() -> f32 {
    PRUNE_TYPICAL
}

/// One sprite, ready for shading and drawing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sprite {
    /// Centre in the world. units: m
    pub center_m: Vec3,
    /// units: m
    pub width_m: f32,
    /// units: m
    pub height_m: f32,
    /// Rotation in the sprite plane. units: radians
    pub rotation_rad: f32,
    /// Atlas tile (0–15).
    pub texture: u8,
    /// Shading group index within its cloud.
    pub group: u32,
    /// Share of the sun's light that reaches it past the cloud between it
    /// and the sun, in (0, 1]: 1 for an authored cloud (its painter
    /// shades it); for a physics parcel's,
    /// [`super::parcels::sunlit_shares`].
    pub sunlit: f32,
}

/// A filled sprite cloud.
#[derive(Debug, Clone, PartialEq)]
pub struct SpriteCloud {
    pub name: String,
    pub kind: CloudType,
    /// units: m
    pub center_m: Vec3,
    /// Radius of the cloud's bounding box around its centre (Listing 1). units: m
    pub radius_m: f32,
    /// Colour levels with world heights.
    pub levels: Vec<ColorLevel>,
    pub sprites: Vec<Sprite>,
    /// Sprites the pruning removed (shown, like every clamp).
    pub pruned: usize,
    /// Sprites dropped beyond [`MAX_SPRITES_PER_CLOUD`] (shown).
    pub capped: usize,
    /// Centres for the directional shading of every sprite (None: each
    /// shading group's own centre, the paper's): a physics parcel's
    /// sprites are shaded as part of the cloud and the billow the parcel
    /// belongs to.
    pub shade_center_m: Option<ShadeCenters>,
}

/// The centres a physics parcel's directional term looks from besides its
/// own (model::parcels). units: m
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadeCenters {
    /// The whole cloud's (its parcels' mean centre).
    pub cloud_m: Vec3,
    /// The parcel's billow's (the parcels around it).
    pub billow_m: Vec3,
}

/// Weights of the directions from the cloud's, the billow's and the
/// parcel's centre in [`SpriteCloud::shading_from`]: the cloud gives a
/// little of its sunlit and shaded sides, the parcel its own roundness,
/// the billow a little of its lit rim. Chosen against the path tracer
/// (issue 32) together with the sprites' sunlit shares
/// ([`super::parcels::sunlit_shares`]), which now carry the shade behind
/// and under the cloud's other parts, so the billows count for a
/// twenty-fifth of what they did before them (3 : 2 for billow : parcel).
pub const SHADE_WEIGHTS: [f32; 3] = [0.55, 0.12, 0.8];

impl SpriteCloud {
    /// The point the directional term (eq. 2) of `vertex_m` looks from:
    /// its shading group's centre `group_m` (the paper's), or, for a
    /// physics parcel's cloud, a point from which the vertex lies in the
    /// [`SHADE_WEIGHTS`] mean of the directions from the cloud's, its
    /// billow's and its parcel's (`group_m`) centres.
    pub fn shading_from(&self, group_m: Vec3, vertex_m: Vec3) -> Vec3 {
        match self.shade_center_m {
            None => group_m,
            Some(c) => {
                let d = [c.cloud_m, c.billow_m, group_m]
                    .iter()
                    .zip(SHADE_WEIGHTS)
                    .map(|(&from, w)| w * (vertex_m - from).normalize_or_zero())
                    .sum::<Vec3>();
                vertex_m - d.normalize_or_zero()
            }
        }
    }

    /// The shading of a corner at `vertex_m` of `sprite` (shading group
    /// centre `group_m`, formation alpha `alpha`; eq. 3 without the
    /// texture): the paper's for an authored cloud; for a physics parcel's,
    /// looking from [`Self::shading_from`] through
    /// [`super::parcels::PARCEL_MAP`]. Its share of the sun is then ×
    /// the sprite's sunlit share.
    pub fn vertex_shade(
        &self,
        lighting: &Lighting,
        sprite: &Sprite,
        group_m: Vec3,
        vertex_m: Vec3,
        alpha: f32,
    ) -> VertexShade {
        let mut v = match self.shade_center_m {
            None => lighting.vertex_shade(&self.levels, vertex_m, group_m, alpha),
            Some(_) => {
                let from = self.shading_from(group_m, vertex_m);
                lighting.vertex_shade_mapped(&PARCEL_MAP, &self.levels, vertex_m, from, alpha)
            }
        };
        v.sun *= sprite.sunlit;
        v
    }
}

impl SpriteBox {
    /// Checks the box; errors name `key` (`"sprite_clouds[0].boxes"`) and the box.
    pub fn validate(&self, key: &str, i: usize) -> Result<()> {
        let bad = |what: &str, allowed: &str| {
            Err(Error::invalid(key, format!("box {i}: {what}"), allowed))
        };
        let corners = self.min_m.iter().chain(&self.max_m);
        if !corners.clone().all(|v| v.is_finite() && v.abs() <= 1.0e6) {
            return bad("min_m/max_m", "finite corners within ±1000 km");
        }
        if (0..3).any(|a| self.min_m[a] > self.max_m[a]) {
            return bad("min_m > max_m", "min_m ≤ max_m on every axis");
        }
        match (self.count, self.density_per_km3) {
            (Some(n), None) if (1..=MAX_SPRITES_PER_BOX).contains(&n) => {}
            (None, Some(d)) if d.is_finite() && d > 0.0 => {}
            _ => {
                return bad(
                    "count/density_per_km3",
                    "exactly one of count (1–100) or density_per_km3 (> 0)",
                );
            }
        }
        range_in(
            &format!("{key}[{i}].width_m"),
            self.width_m,
            1.0,
            1.0e5,
            "m",
        )
        .and(range_in(
            &format!("{key}[{i}].height_m"),
            self.height_m,
            1.0,
            1.0e5,
            "m",
        ))
        .and(range_in(
            &format!("{key}[{i}].rotation_deg"),
            self.rotation_deg,
            -360.0,
            720.0,
            "degrees",
        ))
        .map_err(|e| Error::invalid(key, format!("box {i}"), e.to_string()))?;
        if self.textures.is_empty() || self.textures.iter().any(|&t| t >= TEXTURES) {
            return bad("textures", "a non-empty list of atlas tiles 0–15");
        }
        Ok(())
    }

    /// Sprites this box asks for.
    pub fn sprite_count(&self) -> u32 {
        match (self.count, self.density_per_km3) {
            (Some(n), _) => n,
            (None, Some(d)) => {
                let km3 = (0..3)
                    .map(|a| (self.max_m[a] - self.min_m[a]) / 1000.0)
                    .product::<f32>();
                ((d * km3).round() as u32).clamp(1, MAX_SPRITES_PER_BOX)
            }
            (None, None) => 0,
        }
    }
}

impl SpriteCloudSpec {
    /// Checks the cloud; `key` is `"sprite_clouds[i]"`.
    pub fn validate(&self, key: &str) -> Result<()> {
        for (a, v) in self.center_m.iter().enumerate() {
            finite_in(
                &format!("{key}.center_m"),
                *v,
                -1.0e6,
                1.0e6,
                &format!("finite, within ±1000 km (component {a})"),
            )?;
        }
        finite_in(
            &format!("{key}.prune_fraction"),
            self.prune_fraction,
            0.0,
            1.0,
            "a fraction of the sprite height in [0, 1] (paper: 0.2 typical, 0.1 dense)",
        )?;
        for (i, b) in self.boxes.iter().enumerate() {
            b.validate(&format!("{key}.boxes"), i)?;
        }
        if let Some(levels) = &self.levels {
            super::shading::validate_levels(&format!("{key}.levels"), levels)?;
        }
        Ok(())
    }

    /// Fills the boxes with seeded random sprites and prunes them.
    pub fn build(&self) -> SpriteCloud {
        let center = Vec3::from(self.center_m);
        let mut rng = SplitMix64::new(self.seed);
        let mut sprites = Vec::new();
        let preset;
        let boxes = if self.boxes.is_empty() {
            let [x, y, z] = self.center_m;
            preset = self.kind.spec("", x, y, z, self.seed).boxes;
            &preset
        } else {
            &self.boxes
        };
        for b in boxes {
            fill_box(&mut rng, center, b, &mut sprites);
        }
        let levels = self.levels.clone().unwrap_or_else(|| self.kind.levels());
        finish(
            self.name.clone(),
            self.kind,
            center,
            levels,
            sprites,
            self.prune_fraction,
        )
    }
}

fn fill_box(rng: &mut SplitMix64, center: Vec3, b: &SpriteBox, out: &mut Vec<Sprite>) {
    let mut r = |lo: f32, hi: f32| rng.range(lo as f64, hi as f64) as f32;
    for _ in 0..b.sprite_count() {
        let p = Vec3::new(
            r(b.min_m[0], b.max_m[0]),
            r(b.min_m[1], b.max_m[1]),
            r(b.min_m[2], b.max_m[2]),
        );
        let width_m = r(b.width_m[0], b.width_m[1]);
        let height_m = r(b.height_m[0], b.height_m[1]);
        let rot = r(b.rotation_deg[0], b.rotation_deg[1]);
        // §3.2: non-square sprites are not rotated (their stretch is horizontal).
        let square = (width_m - height_m).abs() <= 0.05 * height_m.max(width_m);
        let pick = (r(0.0, 1.0) * b.textures.len() as f32) as usize;
        out.push(Sprite {
            center_m: center + p,
            width_m,
            height_m,
            rotation_rad: if square { rot.to_radians() } else { 0.0 },
            texture: b.textures[pick.min(b.textures.len() - 1)],
            group: b.group,
            sunlit: 1.0,
        });
    }
}

/// Prunes (§3.1: walk the list, drop a sprite closer than `fraction` × its
/// height to one already kept), caps the count and measures the radius.
fn finish(
    name: String,
    kind: CloudType,
    center: Vec3,
    mut levels: Vec<ColorLevel>,
    all: Vec<Sprite>,
    fraction: f32,
) -> SpriteCloud {
    let (mut sprites, pruned) = prune(all, fraction);
    let capped = sprites.len().saturating_sub(MAX_SPRITES_PER_CLOUD);
    sprites.truncate(MAX_SPRITES_PER_CLOUD);
    let radius_m = sprites
        .iter()
        .map(|s| (s.center_m - center).length() + 0.5 * s.height_m.max(s.width_m))
        .fold(0.0, f32::max);
    for l in &mut levels {
        l.height_m += center.z;
    }
    SpriteCloud {
        name,
        kind,
        center_m: center,
        radius_m,
        levels,
        sprites,
        pruned,
        capped,
        shade_center_m: None,
    }
}

/// Keeps a sprite only when no kept sprite lies within `fraction` × its
/// height (3-D distance). Returns the kept sprites and how many were dropped.
pub fn prune(all: Vec<Sprite>, fraction: f32) -> (Vec<Sprite>, usize) {
    let n = all.len();
    let mut kept: Vec<Sprite> = Vec::with_capacity(n);
    for s in all {
        let min_d = fraction * s.height_m;
        if kept
            .iter()
            .all(|k| k.center_m.distance_squared(s.center_m) >= min_d * min_d)
        {
            kept.push(s);
        }
    }
    let dropped = n - kept.len();
    (kept, dropped)
}
