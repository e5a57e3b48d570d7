//! Animation of the implicit ellipsoids (Schpok et al. 2003 §3.1, §5.4):
//! keyframes of centre, radii and strength, and particle dynamics (a
//! uniform wind every ellipsoid drifts along, plus per-ellipsoid presets
//! for convection, growth, dissipation and the cumulonimbus anvil).

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::ellipsoid::{Ellipsoid, EllipsoidState, validate_shape};
use super::finite_in;
use crate::error::{Error, Result};

/// Most keyframes per ellipsoid.
pub const MAX_KEYFRAMES: usize = 1024;

/// One key of an ellipsoid's animation. A missing value holds the previous
/// key's (the ellipsoid's own `centre_m`, `radii_m` and `strength` are its
/// key at t = 0).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Time of this key, after the previous one. units: s
    pub time_s: f32,
    /// units: m
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_m: Option<[f32; 3]>,
    /// units: m
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radii_m: Option<[f32; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub strength: Option<f32>,
}

/// Particle-dynamics preset of one ellipsoid, applied on top of its
/// keyframes. The rates are the constants below.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Motion {
    /// Only the uniform wind and the keyframes move it.
    #[default]
    Still,
    /// Convection: rises at [`RISE_M_S`].
    Rising,
    /// Growth: all radii grow by [`GROWTH_PER_S`].
    Expanding,
    /// Dissipation: radii shrink by [`GROWTH_PER_S`], strength decays by
    /// [`DECAY_PER_S`].
    Shrinking,
    /// The cumulonimbus anvil (paper §6, Figure 5): a flat ellipsoid whose
    /// horizontal radii spread by [`ANVIL_SPREAD_PER_S`] while its
    /// thickness stays.
    Anvil,
}

/// Rise speed of a `rising` ellipsoid: a typical cumulus updraft (1–5 m/s).
/// units: m/s
pub const RISE_M_S: f32 = 3.0;
/// Relative growth rate of `expanding` radii (and shrink rate of
/// `shrinking` ones): ×2 in about 4 minutes. units: 1/s
pub const GROWTH_PER_S: f32 = 0.003;
/// Relative decay rate of a `shrinking` ellipsoid's strength. units: 1/s
pub const DECAY_PER_S: f32 = 0.004;
/// Relative spreading rate of an `anvil`'s horizontal radii: ×2 in about
/// 12 minutes, so a 2 km anvil reaches ~10 km across in half an hour, as
/// thunderstorm anvils do (a much faster spread makes its bounds swallow
/// every slicing plane). units: 1/s
pub const ANVIL_SPREAD_PER_S: f32 = 0.001;

/// Scene-wide particle dynamics: the `[particles]` table.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ParticleConfig {
    /// Uniform wind every ellipsoid drifts along (paper §5.4). units: m/s
    pub wind_m_s: [f32; 3],
}

impl ParticleConfig {
    /// Checks the wind is finite and below 100 m/s per component.
    pub fn validate(&self) -> Result<()> {
        for (k, v) in self.wind_m_s.iter().enumerate() {
            finite_in(
                &format!("particles.wind_m_s[{k}]"),
                *v,
                -100.0,
                100.0,
                "-100 to 100 m/s",
            )?;
        }
        Ok(())
    }
}

/// (time, centre, radii, strength) of every key, the ellipsoid's own values
/// first, missing values carried forward.
fn keys(e: &Ellipsoid) -> Vec<(f32, Vec3, Vec3, f32)> {
    let mut out = vec![(
        0.0,
        Vec3::from(e.centre_m),
        Vec3::from(e.radii_m),
        e.strength,
    )];
    for k in &e.keyframes {
        let (_, c, r, s) = out[out.len() - 1];
        out.push((
            k.time_s,
            k.centre_m.map_or(c, Vec3::from),
            k.radii_m.map_or(r, Vec3::from),
            k.strength.unwrap_or(s),
        ));
    }
    out
}

/// The ellipsoid at time `time_s`: keyframes interpolated piecewise
/// linearly in time (held before the first and after the last key; linear
/// never overshoots, so radii stay positive and strength in range), then
/// the uniform `wind_m_s` and the motion preset applied over `time_s`.
pub fn state_at(e: &Ellipsoid, time_s: f32, wind_m_s: Vec3) -> EllipsoidState {
    let keys = keys(e);
    let i = keys.partition_point(|k| k.0 <= time_s);
    let (centre, radii, strength) = if i == 0 {
        (keys[0].1, keys[0].2, keys[0].3)
    } else if i == keys.len() {
        let k = keys[i - 1];
        (k.1, k.2, k.3)
    } else {
        let (a, b) = (keys[i - 1], keys[i]);
        let w = (time_s - a.0) / (b.0 - a.0);
        (a.1.lerp(b.1, w), a.2.lerp(b.2, w), a.3 + (b.3 - a.3) * w)
    };
    let t = time_s.max(0.0);
    let grow = (GROWTH_PER_S * t).exp();
    let spread = (ANVIL_SPREAD_PER_S * t).exp();
    let (velocity, radii_factor, strength_factor) = match e.motion {
        Motion::Still => (Vec3::ZERO, Vec3::ONE, 1.0),
        Motion::Rising => (Vec3::Z * RISE_M_S, Vec3::ONE, 1.0),
        Motion::Expanding => (Vec3::ZERO, Vec3::splat(grow), 1.0),
        Motion::Shrinking => (
            Vec3::ZERO,
            Vec3::splat(1.0 / grow),
            (-DECAY_PER_S * t).exp(),
        ),
        Motion::Anvil => (Vec3::ZERO, Vec3::new(spread, spread, 1.0), 1.0),
    };
    EllipsoidState {
        centre_m: centre + (wind_m_s + velocity) * t,
        radii_m: radii * radii_factor,
        rotation: EllipsoidState::rotation_from_deg(e.rotation_deg),
        strength: strength * strength_factor,
        base_z_m: e.base_m.unwrap_or(f32::NEG_INFINITY),
    }
}

/// Every ellipsoid of a scene at `time_s`.
pub fn states_at(
    ellipsoids: &[Ellipsoid],
    particles: &ParticleConfig,
    time_s: f32,
) -> Vec<EllipsoidState> {
    let wind = Vec3::from(particles.wind_m_s);
    ellipsoids
        .iter()
        .map(|e| state_at(e, time_s, wind))
        .collect()
}

/// Checks an ellipsoid's keyframes: finite values, times after 0 and
/// strictly increasing, shapes as for the ellipsoid itself.
pub(super) fn validate_keyframes(keys: &[Keyframe], name: &str) -> Result<()> {
    if keys.len() > MAX_KEYFRAMES {
        return Err(Error::invalid(
            format!("{name}.keyframes"),
            format!("{} keys", keys.len()),
            format!("at most {MAX_KEYFRAMES} keyframes"),
        ));
    }
    let mut previous = 0.0;
    for (i, k) in keys.iter().enumerate() {
        let place = format!("{name}.keyframes[{i}]");
        finite_in(
            &format!("{place}.time_s"),
            k.time_s,
            0.0,
            1.0e6,
            "0 to 1e6 s",
        )?;
        if k.time_s <= previous {
            return Err(Error::invalid(
                format!("{place}.time_s"),
                k.time_s,
                format!(
                    "later than the previous key ({previous} s; the ellipsoid itself is the key at 0 s)"
                ),
            ));
        }
        previous = k.time_s;
        for (j, v) in k.centre_m.unwrap_or_default().iter().enumerate() {
            finite_in(
                &format!("{place}.centre_m[{j}]"),
                *v,
                -1.0e6,
                1.0e6,
                "-1e6 to 1e6 m",
            )?;
        }
        validate_shape(
            k.radii_m.unwrap_or([1.0; 3]),
            k.strength.unwrap_or(0.0),
            &place,
        )?;
    }
    Ok(())
}

/// The paper's developing cumulonimbus (§6, Figure 5) as ellipsoids: a
/// tower of three rising cells over `base_m` (the cloud base under the
/// tower's axis) and, at `anvil_z_m` (the tropopause the updraft cannot
/// penetrate), a flat anvil that fades in while the tower reaches it and
/// then spreads.
pub fn cumulonimbus(base_m: [f32; 3], anvil_z_m: f32) -> Vec<Ellipsoid> {
    let [x, y, z] = base_m;
    let depth = anvil_z_m - z;
    let cell = |frac: f32, r: f32| Ellipsoid {
        centre_m: [x, y, z + depth * frac],
        radii_m: [r, r, depth * 0.22],
        motion: Motion::Rising,
        ..Ellipsoid::default()
    };
    let mut out = vec![cell(0.15, 1600.0), cell(0.4, 1300.0), cell(0.65, 1000.0)];
    let rise_s = depth * 0.3 / RISE_M_S;
    out.push(Ellipsoid {
        centre_m: [x, y, anvil_z_m],
        radii_m: [2000.0, 2000.0, depth * 0.06],
        strength: 0.0,
        motion: Motion::Anvil,
        keyframes: vec![Keyframe {
            time_s: rise_s,
            centre_m: None,
            radii_m: None,
            strength: Some(1.0),
        }],
        ..Ellipsoid::default()
    });
    out
}
