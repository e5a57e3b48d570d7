//! Reader for radiosonde soundings in the University of Wyoming text format
//! (the `PRES HGHT TEMP DWPT RELH MIXR DRCT SKNT THTA THTE THTV` table served by
//! weather.uwyo.edu), and conversion of a sounding into an [`Environment`].
//!
//! The table has fixed 7-character, right-aligned columns. Around it may be a
//! station header line, dashed rulers, the column-name line and a units line;
//! a file may repeat the header block. Rows whose temperature and dewpoint
//! are both blank (levels below the ground) are skipped; rows with a
//! temperature but no dewpoint (above the top of the humidity sensor, or a
//! gap in it) keep their temperature, their humidity *missing* (see
//! [`Sounding::to_environment`] for what the environment holds there);
//! anything else that is not a clean number where a number belongs is an
//! error naming the file, line and column.

use std::path::Path;

use super::environment::{EnvLevel, Environment, PressureModel};
use super::thermo;
use super::wind::{MAX_WIND_SPEED_M_S, WindLevel, WindProfile, components_from_direction};
use crate::error::{Error, Result};

/// Width of every column of the table. units: characters
const COLUMN_WIDTH: usize = 7;
/// Column names in file order.
const COLUMNS: [&str; 11] = [
    "PRES", "HGHT", "TEMP", "DWPT", "RELH", "MIXR", "DRCT", "SKNT", "THTA", "THTE", "THTV",
];
/// Dewpoint may exceed temperature by this much before the row is rejected.
/// Rounding both to 0.1 °C is monotone, so a saturated level keeps Td = T;
/// but archives that convert from °F or recompute Td from RH round the two
/// separately and can leave Td up to half a digit above T. 0.05 K is half the
/// printed resolution: anything larger is a real inconsistency. Accepted
/// excesses are clamped to Td = T. units: K
pub const DEWPOINT_ABOVE_TEMPERATURE_TOLERANCE_K: f64 = 0.05;
/// Plausible temperature range of a sounding (the coldest tropopause is
/// about −95 °C, the hottest surface about 57 °C). units: °C
const T_RANGE_C: (f64, f64) = (-120.0, 70.0);
/// Highest accepted pressure (the highest sea-level pressure on record is
/// 1084 hPa; 1100 leaves room for stations below sea level). units: hPa
const P_MAX_HPA: f64 = 1100.0;
/// Accepted heights: the Dead Sea shore is at −430 m, balloons burst below
/// 40 km; the bound also keeps tabulated pressure small. units: m
const Z_RANGE_M: (f64, f64) = (-500.0, 60_000.0);
/// Knots to metres per second. units: m s⁻¹ kn⁻¹
const KNOT_M_S: f64 = 0.514_444;

/// One usable level of a sounding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoundingLevel {
    /// Pressure. units: Pa
    pub p_pa: f64,
    /// Geopotential height above mean sea level. units: m
    pub z_msl_m: f64,
    /// Temperature. units: K
    pub t_k: f64,
    /// Dewpoint (never above `t_k`); None where the row has none
    /// (humidity missing, not zero). units: K
    pub td_k: Option<f64>,
    /// Direction the wind blows from, clockwise from north, if given. units: degrees
    pub wind_dir_deg: Option<f64>,
    /// Wind speed, if given. units: m s⁻¹
    pub wind_speed_m_s: Option<f64>,
}

/// A sounding: usable levels from the ground up, and the station line if any.
#[derive(Debug, Clone, PartialEq)]
pub struct Sounding {
    /// Levels with pressure, height and temperature (and mostly a
    /// dewpoint), lowest first; the first has a dewpoint.
    pub levels: Vec<SoundingLevel>,
    /// The station header line (e.g. "72357 OUN Norman Observations at 12Z 22 May 2011").
    pub station: Option<String>,
}

/// One data row split into its fields (None = blank).
struct Row {
    fields: [Option<f64>; 11],
}

impl Sounding {
    /// Reads a sounding file. Non-UTF-8 or binary content is a parse error.
    pub fn load(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let (line, col) = crate::error::line_col(
                std::str::from_utf8(&e.as_bytes()[..at]).unwrap_or(""),
                at,
            );
            Error::parse(
                path,
                line,
                col,
                format!(
                    "not UTF-8 text (invalid byte at offset {at}): a sounding is a University of Wyoming text table"
                ),
            )
        })?;
        Self::parse(&text, path)
    }

    /// Parses sounding text; `path` is used in error messages only.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        if text.trim().is_empty() {
            return Err(Error::parse(
                path,
                0,
                0,
                "empty file: expected a University of Wyoming sounding table (PRES HGHT TEMP DWPT ...)",
            ));
        }
        if let Some(off) = text.find(|c: char| c == '\0' || (c.is_control() && !c.is_whitespace()))
        {
            let (line, col) = crate::error::line_col(text, off);
            return Err(Error::parse(
                path,
                line,
                col,
                "binary data (control character): a sounding is a plain-text table",
            ));
        }
        let mut station = None;
        let mut seen_table = false;
        let mut levels: Vec<SoundingLevel> = Vec::new();
        // Previous row with pressure and height, for the monotonicity check
        // (incomplete rows take part too: they must also be in order).
        let mut prev: Option<(usize, f64, f64)> = None;
        for (i, raw) in text.lines().enumerate() {
            let lineno = i + 1;
            let line = raw.trim_end();
            let trimmed = line.trim_start();
            if trimmed.is_empty() || trimmed.starts_with('-') && trimmed.chars().all(|c| c == '-') {
                if trimmed.starts_with('-') {
                    seen_table = true;
                }
                continue;
            }
            if trimmed.starts_with("PRES") || trimmed.starts_with("hPa") {
                seen_table = true;
                continue;
            }
            // Before the table, one line with words is the station header
            // (it may start with the station number, so look for letters).
            if !seen_table && trimmed.chars().any(|c| c.is_alphabetic()) {
                if station.is_some() {
                    return Err(Error::parse(
                        path,
                        lineno,
                        line.chars().count() - trimmed.chars().count() + 1,
                        format!(
                            "unexpected text {trimmed:?} before the table: allowed are one station line, dashed rulers, the PRES ... THTV names line and the units line"
                        ),
                    ));
                }
                station = Some(trimmed.to_string());
                continue;
            }
            // The Wyoming service follows the table with a "Station
            // information and sounding indices" section (and, saved from the
            // web page, HTML tags): prose after the data ends the table. A
            // data row never starts with a letter, and a lone word such as
            // `nan` in the PRES column is still reported as a bad number.
            if !levels.is_empty() && ends_table(trimmed) {
                break;
            }
            let row = parse_row(line, path, lineno)?;
            let f = &row.fields;
            let col_of = |k: usize| column_start(line, k);
            let (p_hpa, z) = match (f[0], f[1]) {
                (Some(p), Some(z)) => (p, z),
                (None, _) => {
                    return Err(Error::parse(
                        path,
                        lineno,
                        1,
                        "missing PRES column: every data row needs a pressure in hPa (characters 1-7)",
                    ));
                }
                (Some(_), None) => {
                    return Err(Error::parse(
                        path,
                        lineno,
                        col_of(1),
                        "missing HGHT column: every data row needs a height in m (characters 8-14)",
                    ));
                }
            };
            if !(p_hpa > 0.0 && p_hpa <= P_MAX_HPA) {
                return Err(Error::parse(
                    path,
                    lineno,
                    col_of(0),
                    format!(
                        "pressure {p_hpa} hPa: allowed are positive pressures up to {P_MAX_HPA} hPa"
                    ),
                ));
            }
            if !(Z_RANGE_M.0..=Z_RANGE_M.1).contains(&z) {
                return Err(Error::parse(
                    path,
                    lineno,
                    col_of(1),
                    format!(
                        "height {z} m: allowed are {} to {} m above sea level",
                        Z_RANGE_M.0, Z_RANGE_M.1
                    ),
                ));
            }
            if let Some((pl, pp, pz)) = prev {
                if !(p_hpa < pp) {
                    return Err(Error::parse(
                        path,
                        lineno,
                        col_of(0),
                        format!(
                            "pressure {p_hpa} hPa does not decrease from {pp} hPa on line {pl}: rows must go up, with pressure strictly decreasing"
                        ),
                    ));
                }
                if !(z > pz) {
                    return Err(Error::parse(
                        path,
                        lineno,
                        col_of(1),
                        format!(
                            "height {z} m does not increase from {pz} m on line {pl}: heights must increase strictly with decreasing pressure"
                        ),
                    ));
                }
            }
            prev = Some((lineno, p_hpa, z));
            check_wind(f, path, lineno, &col_of)?;
            let (t_c, td_c) = match (f[2], f[3]) {
                (Some(t), td) => (t, td),
                // Below-ground levels carry no temperature: not usable, skipped.
                (None, None) => continue,
                (None, Some(_)) => {
                    return Err(Error::parse(
                        path,
                        lineno,
                        col_of(2),
                        "missing TEMP column while DWPT is given: a usable row needs both (characters 15-21 and 22-28)",
                    ));
                }
            };
            if levels.is_empty() && td_c.is_none() {
                return Err(Error::parse(
                    path,
                    lineno,
                    col_of(2),
                    "the lowest row with a TEMP (the surface) has no DWPT: the surface needs a dewpoint (higher rows may leave it blank)",
                ));
            }
            for (k, v) in [(2, Some(t_c)), (3, td_c)] {
                let Some(v) = v else { continue };
                if !(T_RANGE_C.0..=T_RANGE_C.1).contains(&v) {
                    return Err(Error::parse(
                        path,
                        lineno,
                        col_of(k),
                        format!(
                            "{} {v} °C: allowed are {} to {} °C",
                            COLUMNS[k], T_RANGE_C.0, T_RANGE_C.1
                        ),
                    ));
                }
            }
            let td_c_or_t = td_c.unwrap_or(t_c);
            if td_c_or_t > t_c + DEWPOINT_ABOVE_TEMPERATURE_TOLERANCE_K {
                return Err(Error::parse(
                    path,
                    lineno,
                    col_of(3),
                    format!(
                        "dewpoint {td_c_or_t} °C above temperature {t_c} °C: allowed is DWPT ≤ TEMP (+{DEWPOINT_ABOVE_TEMPERATURE_TOLERANCE_K} K rounding tolerance)"
                    ),
                ));
            }
            let t_k = t_c + 273.15;
            let td_k = td_c.map(|td| (td + 273.15).min(t_k));
            // The environment accepts q_v ≤ 0.1 kg/kg and θ ≤ 2000 K; check
            // here so that the message can point at the row.
            let qv = td_k.map_or(0.0, |td| {
                thermo::mixing_ratio_from_dewpoint(td, p_hpa * 100.0)
            });
            if qv > 0.1 {
                return Err(Error::parse(
                    path,
                    lineno,
                    col_of(3),
                    format!(
                        "dewpoint {td_c_or_t} °C at {p_hpa} hPa means {:.0} g/kg of vapour: allowed is at most 100 g/kg",
                        qv * 1000.0
                    ),
                ));
            }
            let theta = thermo::potential_temperature_k(t_k, p_hpa * 100.0);
            if theta > 2000.0 {
                return Err(Error::parse(
                    path,
                    lineno,
                    col_of(0),
                    format!(
                        "level at {p_hpa} hPa with {t_c} °C has θ = {theta:.0} K: allowed are levels with θ ≤ 2000 K (pressures above a few hPa)"
                    ),
                ));
            }
            levels.push(SoundingLevel {
                p_pa: p_hpa * 100.0,
                z_msl_m: z,
                t_k,
                td_k,
                wind_dir_deg: f[6],
                wind_speed_m_s: f[7].map(|kn| kn * KNOT_M_S),
            });
        }
        if levels.len() < 2 {
            return Err(Error::parse(
                path,
                0,
                0,
                format!(
                    "{} usable level(s) (rows with PRES, HGHT and TEMP, the lowest with DWPT): at least 2 are needed",
                    levels.len()
                ),
            ));
        }
        Ok(Sounding { levels, station })
    }

    /// The wind profile of the usable levels that give DRCT and SKNT, heights
    /// above the surface; None when no level has wind (the columns are blank
    /// or absent: no wind data, which the callers report as such).
    pub fn wind_profile(&self) -> Result<Option<WindProfile>> {
        let ground = self.levels[0].z_msl_m;
        let levels: Vec<WindLevel> = self
            .levels
            .iter()
            .filter_map(|l| {
                let [u, v] = components_from_direction(l.wind_dir_deg?, l.wind_speed_m_s?);
                Some(WindLevel {
                    z_m: l.z_msl_m - ground,
                    u_m_s: u,
                    v_m_s: v,
                })
            })
            .collect();
        if levels.is_empty() {
            return Ok(None);
        }
        WindProfile::new(levels).map(Some)
    }

    /// The environment this sounding describes, with the simulation's
    /// saturation formula: see [`Sounding::to_environment_with`].
    pub fn to_environment(&self) -> Result<Environment> {
        self.to_environment_with(thermo::Thermo::Model)
    }

    /// The environment this sounding describes: θ and q_v at every usable
    /// level (q_v from the dewpoint with `thermo`'s saturation formula),
    /// observed pressures, heights above the first usable level (the
    /// surface), and the wind of [`Sounding::wind_profile`].
    ///
    /// A level without a dewpoint takes the relative humidity of its
    /// measured neighbours, linear in height between them, and above the
    /// last measured level that level's relative humidity, held: air aloft
    /// stays as far from saturation as the sonde last saw it, where holding
    /// q_v would saturate it as it cools and zero would dry it absolutely.
    /// The environment is told where measured humidity ends
    /// ([`Environment::humidity_top_m`]).
    pub fn to_environment_with(&self, thermo: thermo::Thermo) -> Result<Environment> {
        let ground = self.levels[0].z_msl_m;
        let rh = self.relative_humidities(thermo);
        let levels = self
            .levels
            .iter()
            .zip(&rh)
            .map(|(l, &rh)| EnvLevel {
                z_m: l.z_msl_m - ground,
                theta_k: thermo::potential_temperature_k(l.t_k, l.p_pa),
                qv_kg_per_kg: match l.td_k {
                    Some(td) => thermo.mixing_ratio_from_dewpoint(td, l.p_pa),
                    None => rh * thermo.saturation_mixing_ratio(l.t_k, l.p_pa),
                },
                pressure_pa: Some(l.p_pa),
            })
            .collect();
        Ok(
            Environment::new(levels, self.levels[0].p_pa, PressureModel::Observed)?
                .with_wind(self.wind_profile()?)
                .with_thermo(thermo)
                .with_humidity_top(self.humidity_top_msl_m().map(|z| z - ground)),
        )
    }

    /// Height above sea level of the highest level with a dewpoint, when a
    /// level above it has none (None: humidity measured at every level). units: m
    pub fn humidity_top_msl_m(&self) -> Option<f64> {
        let last = self.levels.iter().rposition(|l| l.td_k.is_some())?;
        (last + 1 < self.levels.len()).then(|| self.levels[last].z_msl_m)
    }

    /// Relative humidity (mixing ratio over its saturation value) of every
    /// level: measured where there is a dewpoint, else interpolated in
    /// height between the measured levels around it or, above the last,
    /// held. units: 1
    fn relative_humidities(&self, thermo: thermo::Thermo) -> Vec<f64> {
        let measured: Vec<(f64, f64)> = self
            .levels
            .iter()
            .filter_map(|l| {
                let td = l.td_k?;
                let rh = thermo.mixing_ratio_from_dewpoint(td, l.p_pa)
                    / thermo.saturation_mixing_ratio(l.t_k, l.p_pa);
                Some((l.z_msl_m, rh))
            })
            .collect();
        self.levels
            .iter()
            .map(|l| {
                let i = measured.partition_point(|m| m.0 <= l.z_msl_m);
                // The parser guarantees a measured surface: i ≥ 1.
                let below = measured[i.max(1) - 1];
                match measured.get(i) {
                    Some(&above) => {
                        let f = (l.z_msl_m - below.0) / (above.0 - below.0);
                        below.1 + (above.1 - below.1) * f
                    }
                    _ => below.1,
                }
            })
            .collect()
    }

    /// Height of the surface (the first usable level) above mean sea level. units: m
    pub fn surface_msl_m(&self) -> f64 {
        self.levels[0].z_msl_m
    }
}

/// Checks a row's DRCT (0–360°) and SKNT (≥ 0, at most the largest speed a
/// wind profile accepts); one without the other is an error too.
fn check_wind(
    f: &[Option<f64>; 11],
    path: &Path,
    lineno: usize,
    col_of: &dyn Fn(usize) -> usize,
) -> Result<()> {
    let max_kn = MAX_WIND_SPEED_M_S / KNOT_M_S;
    match (f[6], f[7]) {
        (Some(d), _) if !(0.0..=360.0).contains(&d) => Err(Error::parse(
            path,
            lineno,
            col_of(6),
            format!("wind direction DRCT {d}°: allowed are 0 to 360° (where the wind blows from)"),
        )),
        (_, Some(kn)) if !(0.0..=max_kn).contains(&kn) => Err(Error::parse(
            path,
            lineno,
            col_of(7),
            format!("wind speed SKNT {kn} knots: allowed are 0 to {max_kn:.0} knots"),
        )),
        (Some(_), None) => Err(Error::parse(
            path,
            lineno,
            col_of(7),
            "DRCT without SKNT: give both wind columns or leave both blank (characters 50-56)",
        )),
        (None, Some(_)) => Err(Error::parse(
            path,
            lineno,
            col_of(6),
            "SKNT without DRCT: give both wind columns or leave both blank (characters 43-49)",
        )),
        _ => Ok(()),
    }
}

/// Whether a line after the data is prose that ends the table: it starts
/// with a letter or `<` and has at least two words of letters.
fn ends_table(trimmed: &str) -> bool {
    let first = trimmed.chars().next().unwrap_or(' ');
    let words = trimmed
        .split(|c: char| !c.is_alphabetic())
        .filter(|w| w.len() >= 2)
        .count();
    (first.is_alphabetic() || first == '<') && words >= 2
}

/// 1-based column of field `k` (the first non-blank character, else the
/// field start).
fn column_start(line: &str, k: usize) -> usize {
    let start = k * COLUMN_WIDTH;
    let chars: Vec<char> = line.chars().collect();
    (start..(start + COLUMN_WIDTH).min(chars.len()))
        .find(|&c| chars[c] != ' ')
        .unwrap_or(start)
        + 1
}

/// Splits a data row into 11 fixed-width fields.
fn parse_row(line: &str, path: &Path, lineno: usize) -> Result<Row> {
    let chars: Vec<char> = line.chars().collect();
    if let Some(c) = chars.iter().position(|&c| c == '\t') {
        return Err(Error::parse(
            path,
            lineno,
            c + 1,
            "tab character in a data row: the table has fixed 7-character columns padded with spaces",
        ));
    }
    let width = COLUMN_WIDTH * COLUMNS.len();
    if chars.len() > width {
        return Err(Error::parse(
            path,
            lineno,
            width + 1,
            format!(
                "text after the last column (THTV ends at character {width}): found {:?}",
                chars[width..].iter().collect::<String>()
            ),
        ));
    }
    let mut fields = [None; 11];
    for (k, field) in fields.iter_mut().enumerate() {
        let start = k * COLUMN_WIDTH;
        if start >= chars.len() {
            break;
        }
        let end = (start + COLUMN_WIDTH).min(chars.len());
        let s: String = chars[start..end].iter().collect();
        let tok = s.trim();
        if tok.is_empty() {
            continue;
        }
        let col = start + s.find(|c: char| c != ' ').unwrap_or(0) + 1;
        // Right alignment is how the format marks where a number belongs: a
        // token that does not end on the column edge straddles two columns.
        if end - start < COLUMN_WIDTH || s.ends_with(' ') || tok.contains(' ') {
            return Err(Error::parse(
                path,
                lineno,
                col,
                format!(
                    "{:?} is not aligned to the {} column (characters {}-{}): numbers are right-aligned in fixed 7-character columns",
                    tok,
                    COLUMNS[k],
                    start + 1,
                    start + COLUMN_WIDTH
                ),
            ));
        }
        let v: f64 = tok
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                Error::parse(
                    path,
                    lineno,
                    col,
                    format!(
                        "found {:?} in the {} column: allowed is a finite number or a blank",
                        tok, COLUMNS[k]
                    ),
                )
            })?;
        *field = Some(v);
    }
    Ok(Row { fields })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_a_minimal_table() {
        let text = "\
   PRES   HGHT   TEMP   DWPT
 1000.0     36
  966.0    345   22.2   21.0
  900.0    950   18.0   10.0
";
        let s = Sounding::parse(text, Path::new("t.txt")).unwrap();
        assert_eq!(s.levels.len(), 2);
        assert_eq!(s.levels[0].p_pa, 96_600.0);
        let env = s.to_environment().unwrap();
        assert_eq!(env.levels()[1].z_m, 605.0);
    }
}
