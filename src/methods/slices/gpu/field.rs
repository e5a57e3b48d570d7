//! The CPU twin of the slices pass's density: the implicit field of every
//! primitive times the tier's media filter of the composited noise octaves,
//! exactly the product `shaders/slices/slices.wgsl` multiplies the plane opacity
//! by (`implicit_field` × `media_at` of shaders/slices/implicit.wgsl; the
//! test `render::slices_twin::gpu_slices_density_matches_its_cpu_twin`
//! compares them). `cumulus export` samples it for authored scenes, so an
//! animation's frames leave for offline renderers with the detail the
//! window shows.

use glam::{Mat4, Vec3};

use crate::methods::slices::model::MediaFilter;
use crate::methods::slices::model::ellipsoid::{EllipsoidState, bounds_m, field_at};
use crate::methods::slices::model::octaves::OctaveUniform;
use crate::noise::NoiseVolume;

/// The noise-detailed implicit field of one frame.
pub struct AuthoredField {
    states: Vec<EllipsoidState>,
    octaves: OctaveUniform,
    noise: NoiseVolume,
    /// Each cloud's primitives (a range of `states`) and the extinction
    /// its stack draws per unit of density: its planes' opacity over their
    /// spacing. units: 1/m
    clouds: Vec<(std::ops::Range<usize>, f32)>,
    /// `[render.slices] sharpness`: the density at or under which the
    /// pass discards a fragment.
    sharpness: f32,
}

impl AuthoredField {
    /// The field of `frame` (see [`super::slices_frame`]) with the noise
    /// volume of `noise_texels` (`render.noise_texels`).
    pub fn new(frame: &super::SlicesFrame, noise_texels: u32) -> Self {
        let clouds = frame
            .slices
            .stacks
            .iter()
            .filter_map(|s| Some((s.primitives.clone(), stack_extinction_per_m(&s.geometry)?)))
            .collect();
        Self {
            states: frame.slices.states.clone(),
            octaves: frame.octaves,
            noise: NoiseVolume::new(noise_texels),
            clouds,
            sharpness: frame.cfg.sharpness,
        }
    }

    /// The largest extinction per unit density of any cloud, or None
    /// without a cloud. units: 1/m
    pub fn max_extinction_per_m(&self) -> Option<f32> {
        self.clouds.iter().map(|c| c.1).reduce(f32::max)
    }

    /// The extinction the slices pass draws at `p`: each cloud's stack
    /// composites planes of opacity τ = plane opacity × field × media
    /// (1 − e^−τ each, so e^−Στ through the stack, the Beer–Lambert law of
    /// the extinction τ / plane spacing), discarding where field × media
    /// is at or under Sharpness; clouds whose stacks overlap add. The
    /// field is the exact implicit field where the pass interpolates it
    /// between its vertices. units: 1/m
    pub fn extinction_per_m(&self, p: Vec3) -> f32 {
        let mut media = None;
        let mut sigma = 0.0;
        for (range, per_density) in &self.clouds {
            let field = field_at(&self.states[range.clone()], p);
            // The media filters are at most 1: no noise lifts this cloud over.
            if field <= self.sharpness {
                continue;
            }
            let m = *media.get_or_insert_with(|| {
                let tier = tier_at(&self.octaves, p.z);
                media_of(&self.octaves, tier).apply(self.composite_noise(tier, p))
            });
            let density = field * m;
            if density > self.sharpness {
                sigma += per_density * density;
            }
        }
        sigma
    }

    /// Bounds (min, max) of every primitive with strength, or None. units: m
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        bounds_m(&self.states)
    }

    /// Octaves of tier `tier` composited at `p` (weights first × ½^o).
    pub fn composite_noise(&self, tier: usize, p: Vec3) -> f32 {
        let t = &self.octaves.tiers[tier];
        let mut w = t.first_weight;
        let mut sum = 0.0;
        for o in 0..self.octaves.octave_count as usize {
            sum += w * octave_noise(&self.octaves, &self.noise, tier, o, p);
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
        let tier = tier_at(&self.octaves, p.z);
        field * media_of(&self.octaves, tier).apply(self.composite_noise(tier, p))
    }
}

/// A stack's extinction per unit density: its planes' opacity (which
/// carries the cloud's compensation) over their spacing, or None for a
/// stack without planes. units: 1/m
fn stack_extinction_per_m(g: &crate::methods::slices::model::slicing::SliceGeometry) -> Option<f32> {
    let planes = g.plane_offsets_m.len();
    let plane_opacity = g.vertices.first()?.plane_opacity;
    let spacing = if planes > 1 {
        (g.plane_offsets_m[0] - g.plane_offsets_m[planes - 1]).abs() / (planes - 1) as f32
    } else {
        return None;
    };
    (spacing > 0.0).then(|| plane_opacity / spacing)
}

/// The tier holding altitude `z_m`: the highest whose bottom is at or
/// below it (the first covers everything below).
pub fn tier_at(octaves: &OctaveUniform, z_m: f32) -> usize {
    let count = octaves.tier_count as usize;
    (1..count)
        .rfind(|&i| z_m >= octaves.tiers[i].bottom_m)
        .unwrap_or(0)
}

fn media_of(octaves: &OctaveUniform, tier: usize) -> MediaFilter {
    MediaFilter::ALL
        .into_iter()
        .find(|f| f.gpu_id() == octaves.tiers[tier].media)
        .unwrap_or_default()
}

/// Octave `o` of tier `tier`'s noise at `p` (red channel, mip 0, as the
/// shaders' `octave_noise`).
fn octave_noise(
    octaves: &OctaveUniform,
    noise: &NoiseVolume,
    tier: usize,
    o: usize,
    p: Vec3,
) -> f32 {
    let m = &octaves.tiers[tier].texture_from_world[o];
    let q = Mat4::from_cols_array_2d(m).transform_point3(p);
    noise.sample(q.to_array(), 0.0)[0]
}

/// The weight of a vertex's density in its shadow with the first noise
/// octave (paper §4, `[render.slices] shadow_octave`): the tier's media
/// filter of the composite with octaves 2 and up replaced by their mean ½,
/// w₀·n₀ + (1 − w₀)·½, divided by the filter at ½, so the weight is 1 on
/// average and Dirtiness keeps its calibration while the first octave's
/// lumps shade what lies behind them. `first_octave_weight` in
/// shaders/slices/implicit.wgsl is the GPU twin.
pub fn first_octave_weight(octaves: &OctaveUniform, noise: &NoiseVolume, p: Vec3) -> f32 {
    let tier = tier_at(octaves, p.z);
    let w0 = octaves.tiers[tier].first_weight;
    let media = media_of(octaves, tier);
    let n = w0 * octave_noise(octaves, noise, tier, 0, p) + (1.0 - w0) * 0.5;
    media.apply(n) / media.apply(0.5)
}
