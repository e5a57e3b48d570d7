//! The `[atmosphere]` table of a scene profile: either a sounding file or
//! inline points of temperature and humidity against height, plus how
//! pressure varies with height. [`AtmosphereSpec::build`] turns it into the
//! [`Environment`] the physics reads; the live window calls it every time a
//! point is dragged, so it does no file I/O for inline points and costs a few
//! microseconds per point.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::environment::{EnvLevel, Environment, PressureModel};
use super::sounding::{DEWPOINT_ABOVE_TEMPERATURE_TOLERANCE_K, Sounding};
use super::thermo;
use crate::error::{Error, Result};

/// Allowed surface pressure. units: hPa
const SURFACE_PRESSURE_RANGE_HPA: (f64, f64) = (500.0, 1100.0);
/// Allowed point temperature (and dewpoint). units: °C
const T_RANGE_C: (f64, f64) = (-100.0, 60.0);
/// Highest allowed point. units: m
const Z_MAX_M: f64 = 30_000.0;

/// One inline point of the profile: temperature and humidity at a height.
/// Exactly one of `td_c` and `rh_percent` is given.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AtmospherePoint {
    /// Height above the ground. units: m
    pub z_m: f64,
    /// Temperature. units: °C
    pub t_c: f64,
    /// Dewpoint. units: °C
    #[serde(skip_serializing_if = "Option::is_none")]
    pub td_c: Option<f64>,
    /// Relative humidity over water. units: %
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rh_percent: Option<f64>,
}

/// How a scene profile describes its atmosphere (the `[atmosphere]` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AtmosphereSpec {
    /// A University of Wyoming sounding, relative to the profile's directory.
    /// Excludes `points` and `surface_pressure_hpa` (the sounding has both).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sounding: Option<PathBuf>,
    /// Inline points from the ground (z = 0) up, heights strictly increasing.
    /// A table that is present but has no points has none (it does not get
    /// the default's points, which would clash with a `sounding`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<AtmospherePoint>,
    /// Pressure at the ground for inline points (default 1000). units: hPa
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface_pressure_hpa: Option<f64>,
    /// Pressure model: "hydrostatic" (default for points), "paper_exponential",
    /// or "observed" (default for, and only with, a sounding).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure: Option<PressureModel>,
}

impl Default for AtmosphereSpec {
    /// The fair-weather profile, used when a scene has no `[atmosphere]`
    /// table at all of `profiles/fair_weather.toml`: a warm, moist
    /// well-mixed layer to 1.2 km, a conditionally unstable cloud layer to
    /// 1.9 km and a capping inversion to 2.2 km.
    fn default() -> Self {
        let p = |z_m, t_c, td_c| AtmospherePoint {
            z_m,
            t_c,
            td_c: Some(td_c),
            rh_percent: None,
        };
        AtmosphereSpec {
            sounding: None,
            points: vec![
                p(0.0, 26.0, 16.5),
                p(1200.0, 14.6, 12.0),
                p(1900.0, 9.7, 6.0),
                p(2200.0, 12.5, -2.0),
                p(5000.0, -2.0, -18.0),
                p(10_000.0, -38.0, -50.0),
                p(12_000.0, -52.0, -65.0),
            ],
            surface_pressure_hpa: None,
            pressure: None,
        }
    }
}

impl AtmosphereSpec {
    /// Surface pressure used for inline points. units: Pa
    pub fn surface_pressure_pa(&self) -> f64 {
        self.surface_pressure_hpa.unwrap_or(1000.0) * 100.0
    }

    /// The pressure model in effect.
    pub fn pressure_model(&self) -> PressureModel {
        self.pressure.unwrap_or(if self.sounding.is_some() {
            PressureModel::Observed
        } else {
            PressureModel::Hydrostatic
        })
    }

    /// Checks the table without reading files; names the bad field and what
    /// is allowed.
    pub fn validate(&self) -> Result<()> {
        if self.sounding.is_some() {
            if !self.points.is_empty() {
                return Err(Error::invalid(
                    "atmosphere.points",
                    format!("{} points", self.points.len()),
                    "give either `sounding` or `points`, not both",
                ));
            }
            if let Some(p) = self.surface_pressure_hpa {
                return Err(Error::invalid(
                    "atmosphere.surface_pressure_hpa",
                    p,
                    "with a sounding the surface pressure is the sounding's first level: remove it",
                ));
            }
            return Ok(());
        }
        if self.pressure == Some(PressureModel::Observed) {
            return Err(Error::invalid(
                "atmosphere.pressure",
                "\"observed\"",
                "\"observed\" needs a sounding; inline points allow \"hydrostatic\" or \"paper_exponential\"",
            ));
        }
        let ps = self.surface_pressure_hpa.unwrap_or(1000.0);
        if !(SURFACE_PRESSURE_RANGE_HPA.0..=SURFACE_PRESSURE_RANGE_HPA.1).contains(&ps) {
            return Err(Error::invalid(
                "atmosphere.surface_pressure_hpa",
                ps,
                format!(
                    "between {} and {} hPa",
                    SURFACE_PRESSURE_RANGE_HPA.0, SURFACE_PRESSURE_RANGE_HPA.1
                ),
            ));
        }
        if self.points.len() < 2 {
            return Err(Error::invalid(
                "atmosphere.points",
                format!("{} points", self.points.len()),
                "at least 2 points ([[atmosphere.points]] with z_m, t_c and td_c or rh_percent), or a `sounding`",
            ));
        }
        for (i, pt) in self.points.iter().enumerate() {
            let name = |f: &str| format!("atmosphere.points[{i}].{f}");
            if i == 0 && pt.z_m != 0.0 {
                return Err(Error::invalid(
                    name("z_m"),
                    pt.z_m,
                    "the first point is at the ground: z_m = 0",
                ));
            }
            if !(pt.z_m.is_finite() && pt.z_m <= Z_MAX_M) {
                return Err(Error::invalid(
                    name("z_m"),
                    pt.z_m,
                    format!("a height from 0 to {Z_MAX_M} m"),
                ));
            }
            if i > 0 && !(pt.z_m > self.points[i - 1].z_m) {
                return Err(Error::invalid(
                    name("z_m"),
                    pt.z_m,
                    format!(
                        "heights must increase strictly (the previous point is at {} m)",
                        self.points[i - 1].z_m
                    ),
                ));
            }
            if !(T_RANGE_C.0..=T_RANGE_C.1).contains(&pt.t_c) {
                return Err(Error::invalid(
                    name("t_c"),
                    pt.t_c,
                    format!("between {} and {} °C", T_RANGE_C.0, T_RANGE_C.1),
                ));
            }
            match (pt.td_c, pt.rh_percent) {
                (Some(td), None) => {
                    if !(td >= T_RANGE_C.0 && td <= pt.t_c + DEWPOINT_ABOVE_TEMPERATURE_TOLERANCE_K)
                    {
                        return Err(Error::invalid(
                            name("td_c"),
                            td,
                            format!(
                                "a dewpoint from {} °C up to the temperature t_c = {} °C",
                                T_RANGE_C.0, pt.t_c
                            ),
                        ));
                    }
                }
                (None, Some(rh)) => {
                    if !(0.0..=100.0).contains(&rh) {
                        return Err(Error::invalid(name("rh_percent"), rh, "0 to 100 %"));
                    }
                }
                (Some(_), Some(_)) => {
                    return Err(Error::invalid(
                        name("td_c"),
                        "both td_c and rh_percent",
                        "give exactly one of td_c and rh_percent",
                    ));
                }
                (None, None) => {
                    return Err(Error::invalid(
                        name("td_c"),
                        "neither td_c nor rh_percent",
                        "give exactly one of td_c and rh_percent",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Builds the environment; a relative sounding path resolves against
    /// `base_dir` (the profile's directory).
    pub fn build(&self, base_dir: &Path) -> Result<Environment> {
        self.validate()?;
        if let Some(rel) = &self.sounding {
            let path = if rel.is_absolute() {
                rel.clone()
            } else {
                base_dir.join(rel)
            };
            let env = Sounding::load(&path)?.to_environment()?;
            return match self.pressure_model() {
                PressureModel::Observed => Ok(env),
                // Keep the sounding's θ and q_v, recompute pressure from them.
                model => {
                    let levels = env
                        .levels()
                        .iter()
                        .map(|l| EnvLevel {
                            pressure_pa: None,
                            ..*l
                        })
                        .collect();
                    Ok(Environment::new(levels, env.surface_pressure_pa(), model)?
                        .with_wind(env.wind().cloned()))
                }
            };
        }
        let model = self.pressure_model();
        let ps = self.surface_pressure_pa();
        let mut levels = Vec::with_capacity(self.points.len());
        let mut pressure = ps;
        for (i, pt) in self.points.iter().enumerate() {
            let t_k = pt.t_c + 273.15;
            if i > 0 {
                pressure = match model {
                    PressureModel::PaperExponential => ps * (-0.143 * pt.z_m / 1000.0).exp(),
                    _ => hydrostatic_step(&levels[i - 1], pressure, pt, t_k),
                };
            }
            let (theta, qv) = theta_qv(pt, t_k, pressure);
            levels.push(EnvLevel {
                z_m: pt.z_m,
                theta_k: theta,
                qv_kg_per_kg: qv,
                pressure_pa: None,
            });
        }
        Environment::new(levels, ps, model)
    }

    /// Samples an environment (typically from a sounding) into `n` (≥ 2)
    /// editable points, with dewpoints, hydrostatic pressure and the
    /// environment's surface pressure. The points are the environment's most
    /// significant levels: starting from the ground and the top, the level
    /// worst reproduced by linear interpolation between the points so far
    /// (in temperature, or half-weighted dewpoint) is added until there are
    /// `n`, so inversions and dry layers survive where even spacing would
    /// step over them. An environment with fewer than `n` levels is padded
    /// by halving its widest gaps.
    pub fn inline_points_from(env: &Environment, n: usize) -> AtmosphereSpec {
        let n = n.max(2);
        let levels = env.levels();
        let zs: Vec<f64> = levels.iter().map(|l| l.z_m.round()).collect();
        let t: Vec<f64> = levels.iter().map(|l| env.temperature_k(l.z_m)).collect();
        let td: Vec<f64> = levels.iter().map(|l| env.dewpoint_k(l.z_m)).collect();
        let mut chosen = vec![0, levels.len() - 1];
        while chosen.len() < n {
            let mut best: Option<(f64, usize)> = None;
            for w in chosen.windows(2) {
                let (a, b) = (w[0], w[1]);
                for k in a + 1..b {
                    let f = (zs[k] - zs[a]) / (zs[b] - zs[a]);
                    let et = (t[k] - (t[a] + (t[b] - t[a]) * f)).abs();
                    let ed = (td[k] - (td[a] + (td[b] - td[a]) * f)).abs();
                    let err = et.max(0.5 * ed);
                    if best.is_none_or(|(e, _)| err > e) {
                        best = Some((err, k));
                    }
                }
            }
            let Some((_, k)) = best else { break };
            let at = chosen.partition_point(|&c| c < k);
            chosen.insert(at, k);
        }
        let mut heights: Vec<f64> = chosen.iter().map(|&i| zs[i]).collect();
        while heights.len() < n {
            let (i, gap) = heights
                .windows(2)
                .map(|w| w[1] - w[0])
                .enumerate()
                .fold((0, 0.0), |acc, (i, g)| if g > acc.1 { (i, g) } else { acc });
            if gap < 2.0 {
                break;
            }
            heights.insert(i + 1, (heights[i] + 0.5 * gap).round());
        }
        let round1 = |x: f64| (x * 10.0).round() / 10.0;
        let points = heights
            .iter()
            .map(|&z| {
                let t_c = round1(env.temperature_k(z) - 273.15);
                AtmospherePoint {
                    z_m: z,
                    t_c,
                    td_c: Some(round1(env.dewpoint_k(z) - 273.15).min(t_c)),
                    rh_percent: None,
                }
            })
            .collect();
        AtmosphereSpec {
            sounding: None,
            points,
            surface_pressure_hpa: Some(round1(env.surface_pressure_pa() / 100.0)),
            pressure: None,
        }
    }
}

/// θ and q_v of a point at pressure `p_pa`. units: K, kg/kg
fn theta_qv(pt: &AtmospherePoint, t_k: f64, p_pa: f64) -> (f64, f64) {
    let qv = match (pt.td_c, pt.rh_percent) {
        (Some(td), _) => thermo::mixing_ratio_from_dewpoint((td + 273.15).min(t_k), p_pa),
        (None, Some(rh)) => thermo::mixing_ratio_from_relative_humidity(rh / 100.0, t_k, p_pa),
        (None, None) => 0.0,
    };
    (thermo::potential_temperature_k(t_k, p_pa), qv)
}

/// Pressure at `pt` given the level below and its pressure, by the same
/// hydrostatic law the environment integrates (dΠ/dz = −g/(c_p θ_v) with θ_v
/// linear in z), so that the built environment gives back the point's
/// temperature. θ_v at the top depends on the unknown pressure, so Π₁ solves
/// Π₁ = Π₀ − (g/c_p) Δz · mean(1/θ_v)(Π₁). The residual falls strictly as Π₁
/// rises (a lower Π₁ means a warmer, moister θ_v₁), from Π₀ > 0 at Π₁ → 0 to
/// below 0 at Π₁ = Π₀: bisection always finds the root, where a fixed-point
/// iteration does not converge for deep layers (docs/notes.md,
/// "Atmosphere").
fn hydrostatic_step(below: &EnvLevel, p_below: f64, pt: &AtmospherePoint, t_k: f64) -> f64 {
    let pi0 = thermo::exner(p_below);
    let thv0 = thermo::virtual_potential_temperature_k(below.theta_k, below.qv_kg_per_kg, 0.0);
    let dz = pt.z_m - below.z_m;
    let residual = |pi1: f64| {
        let p1 = thermo::P0_PA * pi1.powf(1.0 / thermo::KAPPA);
        let (theta, qv) = theta_qv(pt, t_k, p1);
        let thv1 = thermo::virtual_potential_temperature_k(theta, qv, 0.0);
        // ∫ dz/θ_v for θ_v linear in z.
        let mean_inv = if (thv1 - thv0).abs() > 1e-9 * thv0 {
            (thv1 / thv0).ln() / (thv1 - thv0)
        } else {
            1.0 / thv0
        };
        pi0 - thermo::GRAVITY / thermo::CP_DRY * dz * mean_inv - pi1
    };
    let (mut lo, mut hi) = (1e-6_f64, pi0);
    // 60 halvings of Π₀ < 1.3: far below a rounding error of Π.
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        // A non-finite residual only arises at absurdly low pressure: move up.
        if !(residual(mid) <= 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    thermo::P0_PA * (0.5 * (lo + hi)).powf(1.0 / thermo::KAPPA)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_environment_returns_the_points() {
        // Hydrostatic pressure here and in the environment's table agree to
        // the table's trapezoid error (~1e-6 in Π ≈ 1e-3 K in T).
        let spec = AtmosphereSpec::default();
        let env = spec.build(Path::new(".")).unwrap();
        for pt in &spec.points {
            let t = env.temperature_k(pt.z_m) - 273.15;
            assert!(
                (t - pt.t_c).abs() < 0.01,
                "z = {}: {t} vs {}",
                pt.z_m,
                pt.t_c
            );
            let td = env.dewpoint_k(pt.z_m) - 273.15;
            assert!((td - pt.td_c.unwrap()).abs() < 0.01, "z = {}: {td}", pt.z_m);
        }
    }
}
