//! Artist shading (paper §5), evaluated per sprite vertex on the CPU, and
//! the colour contract that turns it into light ([`artist_light`], the
//! twin of shaders/artist.wgsl, which the GPU runs per vertex).
//!
//! Per vertex: the painted colour = the five vertical colour levels
//! (height → RGBA) interpolated at the vertex (eq. 1's first factor), as
//! the artist sees it (sRGB-encoded: 0.2 a dark base, 1.0 a sunlit top);
//! the share of the sky's light = a time-of-day percentage (eq. 1); the
//! share of the sun's = a time-of-day percentage times a biased mapping of
//! the dot product of (vertex − shading group centre) and the sun direction
//! (eq. 2); alpha = the level's alpha × formation alpha (eq. 3; the GPU
//! multiplies the texture in). The light itself is the frame's: the sun
//! and the sky's irradiance from the atmosphere model, reddened and dimmed
//! at a low sun as for the ray-marched clouds, so the paper's hand-painted
//! dawn and dusk colours are the model's and the default tables are
//! neutral (1 all day); an artist's table still scales them.

use glam::{Vec3, Vec4};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Colour levels per cloud (§5.1: "5 color levels").
pub const LEVELS: usize = 5;

/// One vertical colour level.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorLevel {
    /// Height of the level (relative to the cloud centre in a scene; world
    /// height once the cloud is built). units: m
    pub height_m: f32,
    /// Linear RGBA in [0, 1].
    pub rgba: [f32; 4],
}

/// Checks that `levels` are five, with finite increasing heights and RGBA in [0, 1].
pub fn validate_levels(key: &str, levels: &[ColorLevel]) -> Result<()> {
    if levels.len() != LEVELS {
        return Err(Error::invalid(
            key,
            format!("{} levels", levels.len()),
            "exactly 5 colour levels (§5.1)",
        ));
    }
    for (i, l) in levels.iter().enumerate() {
        if !l.height_m.is_finite() || (i > 0 && l.height_m <= levels[i - 1].height_m) {
            return Err(Error::invalid(
                key,
                format!("level {i} height_m = {}", l.height_m),
                "finite heights, strictly increasing",
            ));
        }
        if !l
            .rgba
            .iter()
            .all(|c| c.is_finite() && (0.0..=1.0).contains(c))
        {
            return Err(Error::invalid(
                key,
                format!("level {i} rgba = {:?}", l.rgba),
                "RGBA components in [0, 1]",
            ));
        }
    }
    Ok(())
}

/// The colour levels interpolated at height `z_m` (eq. 1's first factor).
/// Below the lowest level the lowest colour holds, above the highest the
/// highest (the artist's levels bound the cloud).
pub fn level_color(levels: &[ColorLevel], z_m: f32) -> Vec4 {
    let first = levels[0];
    let last = levels[levels.len() - 1];
    if z_m <= first.height_m {
        return Vec4::from(first.rgba);
    }
    if z_m >= last.height_m {
        return Vec4::from(last.rgba);
    }
    let i = levels
        .windows(2)
        .position(|w| z_m <= w[1].height_m)
        .unwrap_or(0);
    let (l0, l1) = (levels[i], levels[i + 1]);
    // A_V = (V1 − Vy) / (V1 − V0): weight of the lower level.
    let a = (l1.height_m - z_m) / (l1.height_m - l0.height_m);
    a * Vec4::from(l0.rgba) + (1.0 - a) * Vec4::from(l1.rgba)
}

/// A table of samples over the day (hour → value), interpolated linearly
/// with wrap-around at midnight.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeTable<T> {
    /// (hour in [0, 24), value), sorted by hour.
    pub samples: Vec<(f32, T)>,
}

impl<T> TimeTable<T>
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    /// The value at `hour` (wrapped into [0, 24)): A_T = (T1 − T)/(T1 − T0),
    /// value = A_T·C(T0) + (1 − A_T)·C(T1).
    pub fn at(&self, hour: f32) -> T {
        let h = hour.rem_euclid(24.0);
        let s = &self.samples;
        let next = s.iter().position(|(t, _)| *t > h).unwrap_or(s.len());
        let (t0, c0) = if next == 0 {
            (s[s.len() - 1].0 - 24.0, s[s.len() - 1].1)
        } else {
            s[next - 1]
        };
        let (t1, c1) = if next == s.len() {
            (s[0].0 + 24.0, s[0].1)
        } else {
            s[next]
        };
        if t1 <= t0 {
            return c0;
        }
        let a = (t1 - h) / (t1 - t0);
        c0 * a + c1 * (1.0 - a)
    }
}

/// Share of the sky's light over the day (eq. 1's percentage): 1, the
/// frame's own sky (dark at night, reddened at dusk by the atmosphere
/// model), which the paper's artist had to paint in by hand.
pub fn default_ambient_table() -> TimeTable<f32> {
    TimeTable {
        samples: vec![(0.0, 1.0)],
    }
}

/// Share of the sun's light over the day (eq. 2's maximum): 1, the frame's
/// own sun, as for [`default_ambient_table`].
pub fn default_sun_table() -> TimeTable<f32> {
    TimeTable {
        samples: vec![(0.0, 1.0)],
    }
}

/// A thick cloud's sunlit side reflects about like a white Lambertian
/// surface of albedo 0.75 facing the sun: the sun's irradiance is
/// 4π·sun_color, so its radiance is 0.75·4π·sun_color/π
/// (shaders/artist.wgsl `ARTIST_SUN_GAIN`).
pub const ARTIST_SUN_GAIN: f32 = 3.0;
/// Its shaded side sees the sky like a white Lambertian surface
/// (`ARTIST_SKY_GAIN`).
pub const ARTIST_SKY_GAIN: f32 = 1.0;

/// The sRGB decoding (IEC 61966-2-1), encoded [0, 1] to linear.
pub fn srgb_decode(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c.max(0.0) + 0.055) / 1.055).powf(2.4)
    }
}

/// Luminance of the full light a painted colour is meant at
/// (`ARTIST_WHITE`).
pub const ARTIST_WHITE: f32 = 6.5;
/// The light is adapted to [`ARTIST_WHITE`] from this fraction of it up
/// (`ARTIST_ADAPT_FLOOR`).
pub const ARTIST_ADAPT_FLOOR: f32 = 0.3;

/// Linear radiance of a painted colour (sRGB-encoded) receiving the share
/// `sky` of the sky's light (`sky_ambient`: its irradiance on an up-facing
/// surface / π) and `sun` of the sun's (`sun_color`: the renderer's sun
/// colour, irradiance / 4π), adapted to [`ARTIST_WHITE`]. CPU twin of
/// shaders/artist.wgsl `artist_light`.
pub fn artist_light(painted: Vec3, sky: f32, sun: f32, sky_ambient: Vec3, sun_color: Vec3) -> Vec3 {
    let (sky_light, sun_light) = (ARTIST_SKY_GAIN * sky_ambient, ARTIST_SUN_GAIN * sun_color);
    let full = (sky_light + sun_light).dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let adapt = ARTIST_WHITE / full.max(ARTIST_ADAPT_FLOOR * ARTIST_WHITE);
    Vec3::new(
        srgb_decode(painted.x),
        srgb_decode(painted.y),
        srgb_decode(painted.z),
    ) * (sky * sky_light + sun * sun_light)
        * adapt
}

/// One corner's shading, as the GPU turns it into light
/// ([`artist_light`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexShade {
    /// The painted colour (sRGB-encoded RGB) and alpha × formation alpha.
    pub painted: Vec4,
    /// Share of the sky's light.
    pub sky: f32,
    /// Share of the sun's light.
    pub sun: f32,
}

impl VertexShade {
    /// Nothing drawn.
    pub const CLEAR: VertexShade = VertexShade {
        painted: Vec4::ZERO,
        sky: 0.0,
        sun: 0.0,
    };
}

/// The artist's percentages of the maximum directional colour (§5.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionalMap {
    pub min: f32,
    pub median: f32,
    pub max: f32,
}

impl Default for DirectionalMap {
    fn default() -> Self {
        DirectionalMap {
            min: 0.0,
            median: 0.45,
            max: 1.0,
        }
    }
}

impl DirectionalMap {
    /// The paper's biased mapping: dot ∈ [−1, 0] → [min, median], [0, 1] →
    /// [median, max] (so the cloud has no sharp light/dark line in its middle).
    pub fn map(&self, dot: f32) -> f32 {
        let d = dot.clamp(-1.0, 1.0);
        if d < 0.0 {
            self.median + d * (self.median - self.min)
        } else {
            self.median + d * (self.max - self.median)
        }
    }
}

/// The sun and the clock, as the shading sees them.
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    /// Unit vector towards the sun (z up).
    pub sun_dir: Vec3,
    /// Local solar time. units: hours
    pub hour: f32,
    /// Share of the sky's light over the day.
    pub ambient: TimeTable<f32>,
    /// Share of the sun's light over the day.
    pub sun: TimeTable<f32>,
    pub map: DirectionalMap,
}

impl Lighting {
    /// The default tables with the sun direction and hour given; a sun
    /// direction that is not a finite non-zero vector, or an hour that is
    /// not finite, is an error (never a silent default).
    pub fn new(sun_dir: Vec3, hour: f32) -> Result<Self> {
        let Some(sun_dir) = sun_dir.try_normalize() else {
            return Err(Error::invalid(
                "sun direction",
                sun_dir,
                "a finite, non-zero vector",
            ));
        };
        if !hour.is_finite() {
            return Err(Error::invalid(
                "time of day",
                hour,
                "a finite hour (wrapped into [0, 24))",
            ));
        }
        Ok(Lighting {
            sun_dir,
            hour,
            ambient: default_ambient_table(),
            sun: default_sun_table(),
            map: DirectionalMap::default(),
        })
    }

    /// Share of the sky's light at this hour (eq. 1's percentage).
    pub fn sky_share(&self) -> f32 {
        self.ambient.at(self.hour)
    }

    /// Share of the sun's light of a vertex (eq. 2), from its shading
    /// group centre.
    pub fn sun_share(&self, vertex_m: Vec3, group_center_m: Vec3) -> f32 {
        self.sun_share_mapped(&self.map, vertex_m, group_center_m)
    }

    /// [`Self::sun_share`] through the directional mapping `map` instead
    /// of the frame's.
    pub fn sun_share_mapped(&self, map: &DirectionalMap, vertex_m: Vec3, group_center_m: Vec3) -> f32 {
        let dot = (vertex_m - group_center_m)
            .normalize_or_zero()
            .dot(self.sun_dir);
        self.sun.at(self.hour) * map.map(dot)
    }

    /// A vertex's shading (eq. 3 without the texture): the painted level at
    /// its height, its alpha × formation alpha, and its shares of the light.
    pub fn vertex_shade(
        &self,
        levels: &[ColorLevel],
        vertex_m: Vec3,
        group_center_m: Vec3,
        alpha_morph: f32,
    ) -> VertexShade {
        self.vertex_shade_mapped(&self.map, levels, vertex_m, group_center_m, alpha_morph)
    }

    /// [`Self::vertex_shade`] through the directional mapping `map`.
    pub fn vertex_shade_mapped(
        &self,
        map: &DirectionalMap,
        levels: &[ColorLevel],
        vertex_m: Vec3,
        group_center_m: Vec3,
        alpha_morph: f32,
    ) -> VertexShade {
        let level = level_color(levels, vertex_m.z);
        VertexShade {
            painted: level.truncate().extend(level.w * alpha_morph),
            sky: self.sky_share(),
            sun: self.sun_share_mapped(map, vertex_m, group_center_m),
        }
    }
}

/// Centre of each shading group of a cloud's sprites (mean sprite centre).
pub fn group_centers(sprites: &[super::Sprite]) -> Vec<Vec3> {
    let n = sprites
        .iter()
        .map(|s| s.group as usize + 1)
        .max()
        .unwrap_or(0);
    let mut sum = vec![(Vec3::ZERO, 0u32); n];
    for s in sprites {
        let e = &mut sum[s.group as usize];
        e.0 += s.center_m;
        e.1 += 1;
    }
    sum.into_iter()
        .map(|(p, k)| if k == 0 { Vec3::ZERO } else { p / k as f32 })
        .collect()
}
