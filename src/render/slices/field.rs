//! The CPU twin of the slices pass's density: the implicit field of every
//! primitive times the tier's media filter of the composited noise octaves,
//! exactly the product `shaders/slices.wgsl` multiplies the plane opacity
//! by (keep in sync with `tier_at`, `composite_noise` and `media_filter`
//! there). `cumulus export` samples it for authored scenes, so an
//! animation's frames leave for offline renderers with the detail the
//! window shows.

use glam::{Mat4, Vec3};

use crate::authored::MediaFilter;
use crate::authored::ellipsoid::{EllipsoidState, bounds_m, field_at};
use crate::authored::octaves::OctaveUniform;
use crate::render::noise::NoiseVolume;

/// The noise-detailed implicit field of one frame.
pub struct AuthoredField {
    states: Vec<EllipsoidState>,
    octaves: OctaveUniform,
    noise: NoiseVolume,
}

impl AuthoredField {
    /// The field of `frame` (see [`super::slices_frame`]) with the noise
    /// volume of `noise_texels` (`render.noise_texels`).
    pub fn new(frame: &super::SlicesFrame, noise_texels: u32) -> Self {
        Self {
            states: frame.states.clone(),
            octaves: frame.octaves,
            noise: NoiseVolume::new(noise_texels),
        }
    }

    /// Bounds (min, max) of every primitive with strength, or None. units: m
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds_m(&self.states)
    }

    /// The tier holding altitude `z_m`: the highest whose bottom is at or
    /// below it (the first covers everything below).
    fn tier_at(&self, z_m: f32) -> usize {
        let count = self.octaves.counts[0] as usize;
        (1..count)
            .filter(|&i| z_m >= self.octaves.tiers[i].bottom_m[0])
            .last()
            .unwrap_or(0)
    }

    /// Octaves of tier `tier` composited at `p` (weights first × ½^o).
    pub fn composite_noise(&self, tier: usize, p: Vec3) -> f32 {
        let t = &self.octaves.tiers[tier];
        let mut w = t.bottom_m[1];
        let mut sum = 0.0;
        for m in t
            .texture_from_world
            .iter()
            .take(self.octaves.counts[1] as usize)
        {
            let q = Mat4::from_cols_array_2d(m).transform_point3(p);
            sum += w * self.noise.sample(q.to_array(), 0.0)[0];
            w *= 0.5;
        }
        sum
    }

    /// Field × media filter at `p`: the density the slices pass draws.
    pub fn density(&self, p: Vec3) -> f32 {
        let field = field_at(&self.states, p);
        if field <= 0.0 {
            return 0.0;
        }
        let tier = self.tier_at(p.z);
        let media = MediaFilter::ALL
            .into_iter()
            .find(|f| f.gpu_id() == self.octaves.tiers[tier].media[0])
            .unwrap_or_default();
        field * media.apply(self.composite_noise(tier, p))
    }
}
