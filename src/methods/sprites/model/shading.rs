//! Artist shading (paper §5), evaluated per sprite vertex on the CPU:
//! ambient = five vertical colour levels (height → RGBA) interpolated at the
//! vertex, times a time-of-day percentage (eq. 1); directional = the sun's
//! colour at this time of day times a biased mapping of the dot product of
//! (vertex − shading group centre) and the sun direction (eq. 2); vertex
//! colour = (ambient + directional) × formation alpha (eq. 3; the GPU
//! multiplies the texture in).

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

/// Ambient percentage over the day: dark at night, full by day, with more
/// samples around dawn (06:00) and dusk (18:00) as the paper advises.
pub fn default_ambient_table() -> TimeTable<f32> {
    TimeTable {
        samples: vec![
            (0.0, 0.08),
            (4.5, 0.08),
            (5.0, 0.15),
            (5.5, 0.3),
            (6.0, 0.5),
            (6.5, 0.7),
            (7.0, 0.85),
            (8.0, 1.0),
            (16.0, 1.0),
            (17.0, 0.85),
            (17.5, 0.7),
            (18.0, 0.5),
            (18.5, 0.3),
            (19.0, 0.15),
            (19.5, 0.08),
        ],
    }
}

/// Maximum directional (sun) colour over the day: none at night, reddish at
/// dawn and dusk, white by day; more samples around dawn and dusk.
pub fn default_sun_table() -> TimeTable<Vec3> {
    TimeTable {
        samples: vec![
            (0.0, Vec3::ZERO),
            (5.0, Vec3::ZERO),
            (5.5, Vec3::new(0.35, 0.12, 0.05)),
            (6.0, Vec3::new(0.7, 0.35, 0.15)),
            (6.5, Vec3::new(0.8, 0.55, 0.35)),
            (7.5, Vec3::new(0.7, 0.65, 0.55)),
            (9.0, Vec3::new(0.6, 0.6, 0.58)),
            (15.0, Vec3::new(0.6, 0.6, 0.58)),
            (16.5, Vec3::new(0.7, 0.65, 0.55)),
            (17.5, Vec3::new(0.8, 0.55, 0.35)),
            (18.0, Vec3::new(0.7, 0.35, 0.15)),
            (18.5, Vec3::new(0.35, 0.12, 0.05)),
            (19.0, Vec3::ZERO),
        ],
    }
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
    pub ambient: TimeTable<f32>,
    pub sun: TimeTable<Vec3>,
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

    /// Ambient colour of a vertex (eq. 1).
    pub fn ambient(&self, levels: &[ColorLevel], z_m: f32) -> Vec4 {
        level_color(levels, z_m) * self.ambient.at(self.hour)
    }

    /// Directional colour of a vertex (eq. 2), from its shading group centre.
    pub fn directional(&self, vertex_m: Vec3, group_center_m: Vec3) -> Vec3 {
        let dot = (vertex_m - group_center_m)
            .normalize_or_zero()
            .dot(self.sun_dir);
        self.sun.at(self.hour) * self.map.map(dot)
    }

    /// Vertex colour (eq. 3 without the texture): (ambient + directional) ×
    /// formation alpha; the alpha channel is the ambient alpha × formation.
    pub fn vertex_color(
        &self,
        levels: &[ColorLevel],
        vertex_m: Vec3,
        group_center_m: Vec3,
        alpha_morph: f32,
    ) -> Vec4 {
        let amb = self.ambient(levels, vertex_m.z);
        let dir = self.directional(vertex_m, group_center_m);
        (amb + dir.extend(0.0)) * alpha_morph
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
