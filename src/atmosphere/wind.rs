//! The environment's wind profile u(z), v(z): from a sounding's DRCT/SKNT
//! columns, piecewise linear in height, held constant below the lowest and
//! above the highest level with wind. x (u) points east and y (v) north, as
//! in the scene's `[wind]` table; the sounding gives the direction the wind
//! blows *from*, clockwise from north.

use crate::error::{Error, Result};

/// Largest accepted wind speed (the strongest jet streams reach ~110 m/s;
/// the scene's `[wind]` allows components up to 100 m/s). units: m s⁻¹
pub const MAX_WIND_SPEED_M_S: f64 = 150.0;

/// Wind at one height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindLevel {
    /// Height above the ground. units: m
    pub z_m: f64,
    /// Eastward component. units: m s⁻¹
    pub u_m_s: f64,
    /// Northward component. units: m s⁻¹
    pub v_m_s: f64,
}

/// (u, v) of a wind blowing from `from_deg` (clockwise from north) at
/// `speed_m_s`. units: deg, m s⁻¹ → m s⁻¹
pub fn components_from_direction(from_deg: f64, speed_m_s: f64) -> [f64; 2] {
    let (s, c) = from_deg.to_radians().sin_cos();
    [-s * speed_m_s, -c * speed_m_s]
}

/// The direction a wind (u, v) blows from, clockwise from north in
/// [0, 360), and its speed: the inverse of [`components_from_direction`].
/// units: m s⁻¹ → (deg, m s⁻¹)
pub fn direction_from_components(u_m_s: f64, v_m_s: f64) -> (f64, f64) {
    let from = (-u_m_s).atan2(-v_m_s).to_degrees().rem_euclid(360.0);
    (from, u_m_s.hypot(v_m_s))
}

/// Piecewise-linear wind profile, at least one level, heights increasing.
#[derive(Debug, Clone, PartialEq)]
pub struct WindProfile {
    levels: Vec<WindLevel>,
}

impl WindProfile {
    /// A profile from levels with strictly increasing heights and finite
    /// components of at most [`MAX_WIND_SPEED_M_S`].
    pub fn new(levels: Vec<WindLevel>) -> Result<Self> {
        if levels.is_empty() {
            return Err(Error::invalid(
                "wind profile levels",
                0,
                "at least one level with a wind",
            ));
        }
        for (i, l) in levels.iter().enumerate() {
            let speed = l.u_m_s.hypot(l.v_m_s);
            if !(l.z_m.is_finite() && speed.is_finite() && speed <= MAX_WIND_SPEED_M_S) {
                return Err(Error::invalid(
                    format!("wind level {} (z = {} m)", i + 1, l.z_m),
                    format!("u = {} m/s, v = {} m/s", l.u_m_s, l.v_m_s),
                    format!("a finite height and a speed of at most {MAX_WIND_SPEED_M_S} m/s"),
                ));
            }
            if i > 0 && l.z_m <= levels[i - 1].z_m {
                return Err(Error::invalid(
                    format!("wind level {} height (m)", i + 1),
                    l.z_m,
                    format!(
                        "heights must increase strictly (previous: {} m)",
                        levels[i - 1].z_m
                    ),
                ));
            }
        }
        Ok(WindProfile { levels })
    }

    /// The levels, lowest first.
    pub fn levels(&self) -> &[WindLevel] {
        &self.levels
    }

    /// Wind (u, v) at height `z_m`, linear between levels and held outside
    /// them. units: m → m s⁻¹
    pub fn at(&self, z_m: f64) -> [f64; 2] {
        let l = &self.levels;
        let i = l.partition_point(|w| w.z_m <= z_m);
        if i == 0 {
            return [l[0].u_m_s, l[0].v_m_s];
        }
        if i == l.len() {
            let w = l[l.len() - 1];
            return [w.u_m_s, w.v_m_s];
        }
        let (a, b) = (&l[i - 1], &l[i]);
        let f = (z_m - a.z_m) / (b.z_m - a.z_m);
        [
            a.u_m_s + (b.u_m_s - a.u_m_s) * f,
            a.v_m_s + (b.v_m_s - a.v_m_s) * f,
        ]
    }

    /// Magnitude of the vector wind difference between two heights (bulk
    /// shear), the number forecasters quote for 0–6 km. units: m, m → m s⁻¹
    pub fn bulk_shear_m_s(&self, z0_m: f64, z1_m: f64) -> f64 {
        let (a, b) = (self.at(z0_m), self.at(z1_m));
        (b[0] - a[0]).hypot(b[1] - a[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_is_where_the_wind_comes_from() {
        // A south wind (from 180°) blows north: v > 0.
        let [u, v] = components_from_direction(180.0, 10.0);
        assert!(u.abs() < 1e-12 && (v - 10.0).abs() < 1e-12);
        // A west wind (from 270°) blows east: u > 0.
        let [u, v] = components_from_direction(270.0, 10.0);
        assert!((u - 10.0).abs() < 1e-12 && v.abs() < 1e-12);
        for from in [0.0, 45.0, 180.0, 270.0, 359.0] {
            let [u, v] = components_from_direction(from, 7.0);
            let (back, speed) = direction_from_components(u, v);
            // 1e-9: rounding of sin/cos/atan2 only.
            let d = (back - from + 180.0).rem_euclid(360.0) - 180.0;
            assert!(
                d.abs() < 1e-9 && (speed - 7.0).abs() < 1e-9,
                "{from} -> {back}"
            );
        }
    }

    #[test]
    fn interpolates_and_holds() {
        let lv = |z_m, u_m_s| WindLevel {
            z_m,
            u_m_s,
            v_m_s: 0.0,
        };
        let w = WindProfile::new(vec![lv(100.0, 2.0), lv(1100.0, 12.0)]).unwrap();
        assert_eq!(w.at(0.0), [2.0, 0.0]);
        assert_eq!(w.at(600.0), [7.0, 0.0]);
        assert_eq!(w.at(5000.0), [12.0, 0.0]);
        assert!(WindProfile::new(vec![lv(0.0, 1.0), lv(0.0, 2.0)]).is_err());
        assert!(WindProfile::new(vec![lv(0.0, f64::NAN)]).is_err());
    }
}
