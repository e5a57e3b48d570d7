//! Noise-octave animation (Schpok et al. 2003 §3.2, §4.1 eq. 3, §5.3):
//! per octave a texture_from_world transform
//!   transform_octave = scale(f) · rotate(f) · translate(f),
//! driven by a tier's *wind* (translation) and *torque* (rotation), so
//! octave o's pattern drifts at f·wind and turns at f·torque: higher
//! octaves move exponentially faster. Atmospheric tiers (altitude bands)
//! carry their own media, scale and animation; the *Base* tier's animation
//! drives every tier's first octave, so the low frequencies that sculpt the
//! volume move together across tiers. Built on the CPU each frame, handed
//! to the shaders as [`OctaveUniform`].
//!
//! About f: the extracted text reads "f = octave^lacunarity", but the same
//! section says higher octaves move *exponentially* faster and §5.2 calls
//! lacunarity "the fractal step in noise", which is the standard fBm
//! frequency ratio. We take f = lacunarity^o for octave o = 0, 1, 2, …
//! (f = 1 for the first octave), the reading that satisfies both.

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, Vec3};

pub use crate::config::slices::{MAX_OCTAVES, MAX_TIERS, NoiseMotion, NoiseTier, validate_tiers};

/// Fractal persistence: octave o weighs PERSISTENCE^o (paper §4.3).
pub const PERSISTENCE: f32 = 0.5;

/// f of eq. 3 for octave `o` (0-based): lacunarity^o.
pub fn octave_factor(lacunarity: f32, o: usize) -> f32 {
    lacunarity.powi(o as i32)
}

/// Scale by 1/k along the unit `dir` and 1 across it: texture coordinates
/// change k times slower along `dir`, so features are k times longer.
fn stretch(dir: Vec3, k: f32) -> Mat3 {
    Mat3::IDENTITY - (1.0 - 1.0 / k) * Mat3::from_cols(dir * dir.x, dir * dir.y, dir * dir.z)
}

/// texture_from_world of one octave (eq. 3): translate the world so the
/// pattern has drifted by f·wind·t and centre it on `pivot_m`, rotate it by
/// f·|torque|·t about the torque axis (through the pivot), then scale by
/// f / scale_m (one texture tile per scale_m/f metres), stretched along
/// `stretch_dir` by `stretch_k`.
pub fn octave_transform(
    motion: &NoiseMotion,
    f: f32,
    scale_m: f32,
    stretch_dir: Vec3,
    stretch_k: f32,
    pivot_m: Vec3,
    time_s: f32,
) -> Mat4 {
    let torque = Vec3::from(motion.torque_deg_s);
    let rotate = match torque.try_normalize() {
        Some(axis) => Mat3::from_axis_angle(axis, -(f * torque.length() * time_s).to_radians()),
        None => Mat3::IDENTITY,
    };
    let translate = Mat4::from_translation(-(pivot_m + Vec3::from(motion.wind_m_s) * f * time_s));
    let scale = Mat3::from_diagonal(Vec3::splat(f / scale_m)) * stretch(stretch_dir, stretch_k);
    Mat4::from_mat3(scale * rotate) * translate
}

impl NoiseTier {
    /// texture_from_world of every octave at `time_s`: octave 0 moves with
    /// `base`, the others with this tier's own motion.
    pub fn transforms(
        &self,
        base: &NoiseMotion,
        lacunarity: f32,
        octaves: usize,
        pivot_m: Vec3,
        time_s: f32,
    ) -> Vec<Mat4> {
        let own = self.motion();
        let dir = Vec3::from(self.wind_m_s)
            .try_normalize()
            .or_else(|| Vec3::from(base.wind_m_s).try_normalize())
            .unwrap_or(Vec3::X);
        (0..octaves)
            .map(|o| {
                let motion = if o == 0 { base } else { &own };
                let f = octave_factor(lacunarity, o);
                octave_transform(
                    motion,
                    f,
                    self.scale_m,
                    dir,
                    self.stretch_along_wind,
                    pivot_m,
                    time_s,
                )
            })
            .collect()
    }
}

/// The weights of `octaves` octaves, PERSISTENCE^o normalised to sum 1, so
/// the composite of noise in [0, 1] stays in [0, 1] (§4.3: "this harmonic
/// series is bound from 1 to 0").
pub fn octave_weights(octaves: usize) -> Vec<f32> {
    let raw: Vec<f32> = (0..octaves).map(|o| PERSISTENCE.powi(o as i32)).collect();
    let total: f32 = raw.iter().sum();
    raw.into_iter().map(|w| w / total).collect()
}

/// One tier as the shaders take it: WGSL `struct SlicesTier` in
/// shaders/slices/implicit.wgsl (528 bytes; a test compares the layouts).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct TierUniform {
    /// texture_from_world per octave (column-major); unused ones are zero.
    pub texture_from_world: [[[f32; 4]; 4]; MAX_OCTAVES],
    /// Bottom of the tier. units: m
    pub bottom_m: f32,
    /// The first octave's weight.
    pub first_weight: f32,
    /// Media filter id ([`crate::config::slices::MediaFilter::gpu_id`]).
    pub media: u32,
    pub _pad: u32,
}

/// Every tier's octave transforms for one frame: WGSL
/// `struct SlicesOctaves` in shaders/slices/implicit.wgsl (2128 bytes; a
/// test compares the layouts).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct OctaveUniform {
    pub tiers: [TierUniform; MAX_TIERS],
    /// Tiers in use.
    pub tier_count: u32,
    /// Octaves in use.
    pub octave_count: u32,
    pub _pad: [u32; 2],
}

const _: () = assert!(std::mem::size_of::<TierUniform>() == 528);
const _: () = assert!(std::mem::size_of::<OctaveUniform>() == 4 * 528 + 16);

/// Packs the tiers' transforms at `time_s` for the shaders.
pub fn octave_uniform(
    tiers: &[NoiseTier],
    base: &NoiseMotion,
    lacunarity: f32,
    octaves: usize,
    pivot_m: Vec3,
    time_s: f32,
) -> OctaveUniform {
    let mut u = OctaveUniform::zeroed();
    let octaves = octaves.min(MAX_OCTAVES);
    let first_weight = octave_weights(octaves.max(1))[0];
    for (slot, tier) in u.tiers.iter_mut().zip(tiers) {
        for (m, t) in slot
            .texture_from_world
            .iter_mut()
            .zip(tier.transforms(base, lacunarity, octaves, pivot_m, time_s))
        {
            *m = t.to_cols_array_2d();
        }
        slot.bottom_m = tier.bottom_m;
        slot.first_weight = first_weight;
        slot.media = tier.media.gpu_id();
    }
    u.tier_count = tiers.len().min(MAX_TIERS) as u32;
    u.octave_count = octaves as u32;
    u
}
