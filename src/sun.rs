//! The sun from the clock: where the sun stands (azimuth, elevation) for a
//! place, a date and a local clock time, and the scene's `[sun]` table that
//! holds them. Pure astronomy: no GPU, no physics; the renderer, the window
//! and the emission clock all read the sun from here.
//!
//! Formula: the NOAA Solar Calculator's equations (NOAA Global Monitoring
//! Laboratory, "NOAA_Solar_Calculations_day.xls"), which take the solar
//! coordinates and the equation of time from J. Meeus, *Astronomical
//! Algorithms* (2nd ed., 1998), ch. 25 and 28, and add NOAA's fit of
//! atmospheric refraction. NOAA quotes them as good to about a minute of time
//! for 1800–2100 within ±72° latitude; tests/cumulus/sky/sun.rs checks them against
//! NREL's Solar Position Algorithm (Reda & Andreas 2004) to 0.5°. Universal
//! time stands in for terrestrial time (ΔT ≈ 70 s moves the sun < 0.005°).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Where the sun stands, seen from the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolarPosition {
    /// Clockwise from north (+y) toward east (+x). units: degrees, [0, 360)
    pub azimuth_deg: f64,
    /// Apparent elevation above the horizon, refraction included. units: degrees
    pub elevation_deg: f64,
}

impl SolarPosition {
    /// Unit vector toward the sun (x east, y north, z up).
    pub fn direction(&self) -> glam::Vec3 {
        direction(self.azimuth_deg, self.elevation_deg)
    }
}

/// Unit vector toward a sun at `azimuth_deg` (clockwise from +y, north) and
/// `elevation_deg` (x east, y north, z up).
pub fn direction(azimuth_deg: f64, elevation_deg: f64) -> glam::Vec3 {
    let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    glam::DVec3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin()).as_vec3()
}

/// Days from 2000-01-01 to a proleptic-Gregorian date (H. Hinnant's
/// `days_from_civil`).
pub fn days_from_civil(year: i64, month: u32, day: u32) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = month as i64;
    let doy = (153 * (m + if m > 2 { -3 } else { 9 }) + 2) / 5 + day as i64 - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468 - 10_957
}

/// The date `days` after 2000-01-01: (year, month, day).
pub fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 10_957 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(month <= 2), month, day)
}

/// Parses "YYYY-MM-DD" (a real calendar day between 1800 and 2100, the
/// formula's range) into days from 2000-01-01; `key` names the field in errors.
pub fn parse_date(text: &str, key: &str) -> Result<i64> {
    let bad = || {
        Error::invalid(
            key,
            format!("\"{text}\""),
            "a date written YYYY-MM-DD between 1800-01-01 and 2100-12-31",
        )
    };
    let parts: Vec<&str> = text.trim().split('-').collect();
    let [y, m, d] = parts[..] else {
        return Err(bad());
    };
    if y.len() != 4 || m.len() != 2 || d.len() != 2 {
        return Err(bad());
    }
    let (Ok(y), Ok(m), Ok(d)) = (y.parse::<i64>(), m.parse::<u32>(), d.parse::<u32>()) else {
        return Err(bad());
    };
    if !(1800..=2100).contains(&y) || !(1..=12).contains(&m) || d == 0 {
        return Err(bad());
    }
    let days = days_from_civil(y, m, d);
    // 2023-02-30 would roll over into March: reject what does not round-trip.
    if civil_from_days(days) != (y, m, d) {
        return Err(bad());
    }
    Ok(days)
}

/// The sun at a moment of universal time, `jd_ut` as a Julian day, seen from
/// `latitude_deg` (north +) and `longitude_deg` (east +). Also returns the
/// equation of time (apparent − mean solar time). units: degrees, minutes
pub fn solar_position(jd_ut: f64, latitude_deg: f64, longitude_deg: f64) -> (SolarPosition, f64) {
    let (sin, cos) = (|d: f64| d.to_radians().sin(), |d: f64| d.to_radians().cos());
    // Julian centuries from J2000.0.
    let t = (jd_ut - 2_451_545.0) / 36_525.0;
    let l0 = (280.46646 + t * (36_000.769_83 + t * 0.000_303_2)).rem_euclid(360.0);
    let m = 357.52911 + t * (35_999.050_29 - 0.000_153_7 * t);
    let e = 0.016_708_634 - t * (0.000_042_037 + 0.000_000_126_7 * t);
    let centre = sin(m) * (1.914_602 - t * (0.004_817 + 0.000_014 * t))
        + sin(2.0 * m) * (0.019_993 - 0.000_101 * t)
        + sin(3.0 * m) * 0.000_289;
    let omega = 125.04 - 1934.136 * t;
    let apparent_long = l0 + centre - 0.005_69 - 0.004_78 * sin(omega);
    let mean_obliquity =
        23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.000_59 - t * 0.001_813))) / 60.0) / 60.0;
    let obliquity = mean_obliquity + 0.002_56 * cos(omega);
    let declination = (sin(obliquity) * sin(apparent_long)).asin().to_degrees();
    let y = (0.5 * obliquity).to_radians().tan().powi(2);
    let eot_min = 4.0
        * (y * sin(2.0 * l0) - 2.0 * e * sin(m) + 4.0 * e * y * sin(m) * cos(2.0 * l0)
            - 0.5 * y * y * sin(4.0 * l0)
            - 1.25 * e * e * sin(2.0 * m))
        .to_degrees();
    // True solar time at the place, then the hour angle (0 at solar noon).
    let ut_min = (jd_ut + 0.5).rem_euclid(1.0) * 1440.0;
    let solar_min = (ut_min + eot_min + 4.0 * longitude_deg).rem_euclid(1440.0);
    let hour_angle = solar_min / 4.0 - 180.0;
    let cos_zenith = (sin(latitude_deg) * sin(declination)
        + cos(latitude_deg) * cos(declination) * cos(hour_angle))
    .clamp(-1.0, 1.0);
    let elevation = 90.0 - cos_zenith.acos().to_degrees();
    // Meeus eq. 13.5 (azimuth from south, westward) turned to from north, eastward.
    let azimuth = (sin(hour_angle)
        .atan2(
            cos(hour_angle) * sin(latitude_deg)
                - declination.to_radians().tan() * cos(latitude_deg),
        )
        .to_degrees()
        + 180.0)
        .rem_euclid(360.0);
    let position = SolarPosition {
        azimuth_deg: azimuth,
        elevation_deg: elevation + refraction_deg(elevation),
    };
    (position, eot_min)
}

/// NOAA's fit of atmospheric refraction at a true elevation (standard
/// atmosphere: 1010 hPa, 10 °C). units: degrees → degrees
pub fn refraction_deg(elevation_deg: f64) -> f64 {
    let e = elevation_deg;
    let tan = e.to_radians().tan();
    let arcsec = if e > 85.0 {
        0.0
    } else if e > 5.0 {
        58.1 / tan - 0.07 / tan.powi(3) + 0.000_086 / tan.powi(5)
    } else if e > -0.575 {
        1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)))
    } else {
        -20.772 / tan
    };
    arcsec / 3600.0
}

/// The `[sun]` table: the place and the clock the sun is computed from. A
/// scene without it pins the sun with `[render] sun_azimuth_deg` and
/// `sun_elevation_deg`; with it, those two are unused and the sun, the sky,
/// the shadows and the ground heating (`[emission]`'s solar hour) all follow
/// this one clock as the simulation runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunConfig {
    /// Latitude of the domain's centre, north positive. units: degrees
    pub latitude_deg: f64,
    /// Longitude of the domain's centre, east positive. units: degrees
    pub longitude_deg: f64,
    /// Time zone of the clock: local time minus UTC (daylight saving
    /// included); omitted = the whole hour nearest longitude/15. units: h
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub utc_offset_h: Option<f64>,
    /// Local date at simulated time 0, "YYYY-MM-DD".
    pub date: String,
    /// Local clock time at simulated time 0. units: h, [0, 24)
    pub time_h: f64,
}

impl Default for SunConfig {
    /// A midsummer morning at 47° N, 8° E (the Swiss plateau), summer time.
    fn default() -> Self {
        Self {
            latitude_deg: 47.0,
            longitude_deg: 8.0,
            utc_offset_h: Some(2.0),
            date: "2025-06-21".into(),
            time_h: 10.0,
        }
    }
}

/// Checks that `value` is finite and in `[lo, hi]`; the error names `key`.
fn check(key: &str, value: f64, lo: f64, hi: f64, allowed: &str) -> Result<()> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(Error::invalid(key, value, allowed))
    }
}

impl SunConfig {
    /// Checks every field; the error names the key and what is allowed.
    pub fn validate(&self) -> Result<()> {
        self.clock().map(|_| ())
    }

    /// The clock this table describes (validated).
    pub fn clock(&self) -> Result<SolarClock> {
        check(
            "sun.latitude_deg",
            self.latitude_deg,
            -90.0,
            90.0,
            "-90 to 90 degrees (north positive)",
        )?;
        check(
            "sun.longitude_deg",
            self.longitude_deg,
            -180.0,
            180.0,
            "-180 to 180 degrees (east positive)",
        )?;
        if let Some(z) = self.utc_offset_h {
            check(
                "sun.utc_offset_h",
                z,
                -12.0,
                14.0,
                "-12 to 14 hours (local time minus UTC)",
            )?;
        }
        if !(self.time_h.is_finite() && (0.0..24.0).contains(&self.time_h)) {
            return Err(Error::invalid(
                "sun.time_h",
                self.time_h,
                "a local clock time from 0 up to (not including) 24 hours",
            ));
        }
        Ok(SolarClock {
            latitude_deg: self.latitude_deg,
            longitude_deg: self.longitude_deg,
            utc_offset_h: self
                .utc_offset_h
                .unwrap_or_else(|| (self.longitude_deg / 15.0).round()),
            start_day: parse_date(&self.date, "sun.date")?,
            start_time_h: self.time_h,
        })
    }
}

/// A running clock at a place: local time `start_time_h` on local day
/// `start_day` at simulated time 0, advancing with the simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolarClock {
    /// units: degrees, north positive
    pub latitude_deg: f64,
    /// units: degrees, east positive
    pub longitude_deg: f64,
    /// Local clock minus UTC. units: h
    pub utc_offset_h: f64,
    /// Local date at t = 0, as days from 2000-01-01.
    pub start_day: i64,
    /// Local clock time at t = 0 (may run past 24 after edits). units: h
    pub start_time_h: f64,
}

impl SolarClock {
    /// Julian day (universal time) at simulated time `t_s`.
    pub fn julian_day_ut(&self, t_s: f64) -> f64 {
        // 2000-01-01 00:00 UT is JD 2451544.5.
        2_451_544.5
            + self.start_day as f64
            + (self.start_time_h + t_s / 3600.0 - self.utc_offset_h) / 24.0
    }

    /// Where the sun stands at simulated time `t_s`.
    pub fn position(&self, t_s: f64) -> SolarPosition {
        solar_position(
            self.julian_day_ut(t_s),
            self.latitude_deg,
            self.longitude_deg,
        )
        .0
    }

    /// Local clock time at `t_s`, in [0, 24). units: h
    pub fn local_time_h(&self, t_s: f64) -> f64 {
        (self.start_time_h + t_s / 3600.0).rem_euclid(24.0)
    }

    /// Local date at `t_s`, "YYYY-MM-DD".
    pub fn local_date(&self, t_s: f64) -> String {
        let days = self.start_day + (self.start_time_h + t_s / 3600.0).div_euclid(24.0) as i64;
        let (y, m, d) = civil_from_days(days);
        format!("{y:04}-{m:02}-{d:02}")
    }

    /// Apparent (true) solar time at `t_s`: 12 when the sun crosses the
    /// meridian. The ground's heating follows it. units: h, [0, 24)
    pub fn solar_time_h(&self, t_s: f64) -> f64 {
        let jd = self.julian_day_ut(t_s);
        let (_, eot_min) = solar_position(jd, self.latitude_deg, self.longitude_deg);
        let ut_h = (jd + 0.5).rem_euclid(1.0) * 24.0;
        (ut_h + (eot_min + 4.0 * self.longitude_deg) / 60.0).rem_euclid(24.0)
    }

    /// The same clock reading `hour` (local) at simulated time `t_s`, on the
    /// same local day (moving the clock by less than a day).
    pub fn with_local_time_at(&self, hour: f64, t_s: f64) -> Self {
        let now = self.start_time_h + t_s / 3600.0;
        let day_start = now.div_euclid(24.0) * 24.0;
        Self {
            start_time_h: self.start_time_h + (day_start + hour - now),
            ..*self
        }
    }

    /// The same clock on local date `days` (from 2000-01-01) at `t_s`,
    /// keeping the time of day.
    pub fn with_date_at(&self, days: i64, t_s: f64) -> Self {
        let now = self.start_time_h + t_s / 3600.0;
        let today = self.start_day + now.div_euclid(24.0) as i64;
        Self {
            start_day: self.start_day + (days - today),
            ..*self
        }
    }

    /// The `[sun]` table of this clock (date and time at t = 0).
    pub fn to_config(&self) -> SunConfig {
        SunConfig {
            latitude_deg: self.latitude_deg,
            longitude_deg: self.longitude_deg,
            utc_offset_h: Some(self.utc_offset_h),
            date: self.local_date(0.0),
            time_h: self.local_time_h(0.0),
        }
    }
}

/// Elevation below which the light is held (the shadow pass needs the sun
/// above the horizon). units: degrees
pub const MIN_LIGHT_ELEVATION_DEG: f64 = 2.0;

/// The light the renderer gets for a sun position: the direction, held at
/// [`MIN_LIGHT_ELEVATION_DEG`] when the sun is lower, and a strength that
/// fades from 1 at 4° to 0 at −2° (dusk to night). `held` says whether the
/// direction was clamped, so front ends can show it.
pub fn light(position: SolarPosition) -> (glam::Vec3, f32, bool) {
    let el = position.elevation_deg;
    let held = el < MIN_LIGHT_ELEVATION_DEG;
    let dir = direction(position.azimuth_deg, el.max(MIN_LIGHT_ELEVATION_DEG));
    let strength = ((el + 2.0) / 6.0).clamp(0.0, 1.0) as f32;
    (dir, strength, held)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calendar_round_trips() {
        assert_eq!(days_from_civil(2000, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 60);
        for d in [-80_000, -1, 0, 59, 60, 365, 9_000, 36_000] {
            let (y, m, dd) = civil_from_days(d);
            assert_eq!(days_from_civil(y, m, dd), d);
        }
    }

    #[test]
    fn dates_are_checked() {
        assert_eq!(parse_date("2000-01-02", "k").unwrap(), 1);
        for bad in [
            "2023-02-29",
            "2024-13-01",
            "24-01-01",
            "2024/01/01",
            "1700-01-01",
            "",
        ] {
            let e = parse_date(bad, "sun.date").unwrap_err().to_string();
            assert!(e.contains("sun.date") && e.contains("YYYY-MM-DD"), "{e}");
        }
        assert!(parse_date("2024-02-29", "k").is_ok());
    }
}
