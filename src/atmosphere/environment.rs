//! The implicit environment (paper §4): clear air is never sampled, it is a
//! piecewise-linear profile of potential temperature θ(z) and vapour mixing
//! ratio q_v(z) above the ground, plus a pressure P(z).
//!
//! Pressure comes from one of three models ([`PressureModel`]): hydrostatic
//! integration of the profile itself (default for scene profiles), the
//! observed pressures of a sounding, or the paper's `P0·exp(−0.143 h[km])`
//! (eq. 2), kept as an option. Hydrostatic pressure is tabulated once on a
//! uniform grid so that a lookup costs O(1) on the physics hot path.
//!
//! Above the top level θ continues with the top segment's gradient (held
//! if that gradient is negative, capped at 2000 K) and q_v is
//! held; below the ground the bottom values are held. Callers that care
//! (stability diagnostics) compare heights with [`Environment::top_m`].

use serde::{Deserialize, Serialize};

use super::thermo;
use super::wind::WindProfile;
use crate::error::{Error, Result};

/// How pressure varies with height.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PressureModel {
    /// Integrate dΠ/dz = −g / (c_p θ_v(z)) from the surface pressure.
    #[default]
    Hydrostatic,
    /// The paper's P = P_surface · exp(−0.143 h), h in km (eq. 2).
    PaperExponential,
    /// Pressures given with the levels (a sounding); ln P is interpolated linearly in z.
    Observed,
}

/// One level of the environment profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EnvLevel {
    /// Height above the ground. units: m
    pub z_m: f64,
    /// Potential temperature. units: K
    pub theta_k: f64,
    /// Vapour mixing ratio. units: kg/kg
    pub qv_kg_per_kg: f64,
    /// Observed pressure, used only with [`PressureModel::Observed`]. units: Pa
    pub pressure_pa: Option<f64>,
}

/// Largest potential temperature of a level; also the cap of θ extrapolated
/// above the top. units: K
const THETA_MAX_K: f64 = 2000.0;
/// Spacing of the tabulated hydrostatic pressure. units: m
const TABLE_DZ_M: f64 = 10.0;
/// The pressure table reaches this far above the top level. units: m
const TABLE_MARGIN_M: f64 = 10_000.0;

/// Piecewise-linear environment θ(z), q_v(z) with pressure P(z).
#[derive(Debug, Clone, PartialEq)]
pub struct Environment {
    levels: Vec<EnvLevel>,
    surface_pressure_pa: f64,
    model: PressureModel,
    /// Exner function Π at z = i·TABLE_DZ_M (hydrostatic model only).
    exner_table: Vec<f64>,
    /// Per table entry: P_i = P0 Π_i^(1/κ) and the cell's relative step
    /// (Π_{i+1} − Π_i)/Π_i. Within cell i at weight w, Π/Π_i = 1 + w·step,
    /// so P = P_i (1 + w·step)^(1/κ), a power near 1 (≈ 3e-4 away). units: Pa, 1
    pressure_table: Vec<(f64, f64)>,
    /// Wind profile (a sounding's DRCT/SKNT), if the source has one.
    wind: Option<WindProfile>,
    /// The saturation formula that turned observed dewpoints into q_v (and
    /// turns q_v back into dewpoints).
    thermo: thermo::Thermo,
    /// Height of the highest level with a measured humidity, when levels
    /// above it have none (their q_v is filled, see
    /// [`Environment::with_humidity_top`]). units: m
    humidity_top_m: Option<f64>,
}

impl Environment {
    /// Builds an environment from levels sorted by strictly increasing height,
    /// the first at the ground (z = 0). `surface_pressure_pa` is the pressure
    /// at z = 0.
    pub fn new(
        levels: Vec<EnvLevel>,
        surface_pressure_pa: f64,
        model: PressureModel,
    ) -> Result<Self> {
        if levels.len() < 2 {
            return Err(Error::invalid(
                "atmosphere levels",
                levels.len(),
                "at least 2 levels are needed for a profile",
            ));
        }
        if !(surface_pressure_pa.is_finite()
            && (10_000.0..=120_000.0).contains(&surface_pressure_pa))
        {
            return Err(Error::invalid(
                "surface pressure (Pa)",
                surface_pressure_pa,
                "between 10000 and 120000 Pa",
            ));
        }
        for (i, l) in levels.iter().enumerate() {
            let ok = l.z_m.is_finite()
                && l.theta_k.is_finite()
                && l.qv_kg_per_kg.is_finite()
                && (150.0..=THETA_MAX_K).contains(&l.theta_k)
                && (0.0..=0.1).contains(&l.qv_kg_per_kg);
            if !ok {
                return Err(Error::invalid(
                    format!("atmosphere level {} (z = {} m)", i + 1, l.z_m),
                    format!("θ = {} K, q_v = {} kg/kg", l.theta_k, l.qv_kg_per_kg),
                    "finite values with 150 K ≤ θ ≤ 2000 K (a sounding to 3 hPa reaches ~1100 K) and 0 ≤ q_v ≤ 0.1 kg/kg",
                ));
            }
            if i > 0 && l.z_m <= levels[i - 1].z_m {
                return Err(Error::invalid(
                    format!("atmosphere level {} height", i + 1),
                    l.z_m,
                    format!(
                        "heights must increase strictly (previous level is at {} m)",
                        levels[i - 1].z_m
                    ),
                ));
            }
            if model == PressureModel::Observed {
                match l.pressure_pa {
                    Some(p) if p.is_finite() && p > 0.0 => {
                        if i > 0 && p >= levels[i - 1].pressure_pa.unwrap_or(f64::INFINITY) {
                            return Err(Error::invalid(
                                format!("atmosphere level {} pressure (Pa)", i + 1),
                                p,
                                "pressure must decrease with height",
                            ));
                        }
                    }
                    other => {
                        return Err(Error::invalid(
                            format!("atmosphere level {} pressure (Pa)", i + 1),
                            format!("{other:?}"),
                            "a positive observed pressure at every level",
                        ));
                    }
                }
            }
        }
        if levels[0].z_m != 0.0 {
            return Err(Error::invalid(
                "first atmosphere level height (m)",
                levels[0].z_m,
                "the first level must be at the ground, z = 0",
            ));
        }
        let mut env = Environment {
            levels,
            surface_pressure_pa,
            model,
            exner_table: Vec::new(),
            pressure_table: Vec::new(),
            wind: None,
            thermo: thermo::Thermo::Model,
            humidity_top_m: None,
        };
        if model == PressureModel::Hydrostatic {
            env.exner_table = env.integrate_exner()?;
            let t = &env.exner_table;
            env.pressure_table = (0..t.len())
                .map(|i| {
                    let next = t.get(i + 1).unwrap_or(&t[i]);
                    (
                        thermo::P0_PA * t[i].powf(1.0 / thermo::KAPPA),
                        (next - t[i]) / t[i],
                    )
                })
                .collect();
        }
        Ok(env)
    }

    /// Hydrostatic Exner function on a uniform grid, by the trapezoid rule
    /// on dΠ/dz = −g/(c_p θ_v). θ_v is linear within a 10 m cell to far below
    /// the trapezoid error, so the table is accurate to ~1e-6 in Π. Π must
    /// stay positive: a profile too cold for its height (Π ≤ 0, zero pressure,
    /// below its top) is an error; above the top the table stops before Π
    /// would reach 0 and `pressure_pa` continues it isothermally (no floor).
    fn integrate_exner(&self) -> Result<Vec<f64>> {
        let n = ((self.top_m() + TABLE_MARGIN_M) / TABLE_DZ_M).ceil() as usize + 1;
        let mut table = Vec::with_capacity(n);
        let mut pi = thermo::exner(self.surface_pressure_pa);
        table.push(pi);
        let mut prev = self.theta_v_k(0.0);
        for i in 1..n {
            let z = i as f64 * TABLE_DZ_M;
            let next = self.theta_v_k(z);
            let mean_inv = 0.5 * (1.0 / prev + 1.0 / next);
            pi -= thermo::GRAVITY / thermo::CP_DRY * mean_inv * TABLE_DZ_M;
            // Above the top, stop where the air would fall below 150 K (the
            // coldest θ at 1000 hPa): the continuation is then at least as
            // warm and its pressure decays too slowly to underflow.
            if pi <= 0.0 || (z > self.top_m() && next * pi < 150.0) {
                if pi <= 0.0 && z - TABLE_DZ_M < self.top_m() {
                    return Err(Error::invalid(
                        "atmosphere profile (hydrostatic pressure)",
                        format!(
                            "zero pressure at z = {z} m, below the top at {} m",
                            self.top_m()
                        ),
                        "a profile warm enough (θ) for its height that the hydrostatic pressure stays positive to its top",
                    ));
                }
                break;
            }
            table.push(pi);
            prev = next;
        }
        Ok(table)
    }

    /// The same environment with this wind profile (None: no wind data).
    pub fn with_wind(mut self, wind: Option<WindProfile>) -> Self {
        self.wind = wind;
        self
    }

    /// The same environment, its q_v derived from dewpoints with `thermo`.
    pub fn with_thermo(mut self, thermo: thermo::Thermo) -> Self {
        self.thermo = thermo;
        self
    }

    /// The saturation formula of its q_v (the model's unless a sounding was
    /// read for the standard one).
    pub fn thermo(&self) -> thermo::Thermo {
        self.thermo
    }

    /// The same environment, marked as having measured humidity only up to
    /// `z_m` (None: everywhere). Above it the q_v of the levels is a fill
    /// (a sounding holds the last measured relative humidity), which
    /// diagnostics that need a measured humidity (the most-unstable parcel,
    /// precipitable water) leave out.
    pub fn with_humidity_top(mut self, z_m: Option<f64>) -> Self {
        self.humidity_top_m = z_m;
        self
    }

    /// Height of the highest measured humidity, when levels above it have
    /// none. units: m
    pub fn humidity_top_m(&self) -> Option<f64> {
        self.humidity_top_m
    }

    /// The wind profile, if the source gave one.
    pub fn wind(&self) -> Option<&WindProfile> {
        self.wind.as_ref()
    }

    /// Horizontal wind (u east, v north) at `z_m`, if the environment has a
    /// wind profile. units: m → m s⁻¹
    pub fn wind_m_s(&self, z_m: f64) -> Option<[f64; 2]> {
        self.wind.as_ref().map(|w| w.at(z_m))
    }

    /// The profile levels, lowest first.
    pub fn levels(&self) -> &[EnvLevel] {
        &self.levels
    }

    /// The pressure model in use.
    pub fn pressure_model(&self) -> PressureModel {
        self.model
    }

    /// Pressure at the ground. units: Pa
    pub fn surface_pressure_pa(&self) -> f64 {
        self.surface_pressure_pa
    }

    /// Height of the top level. units: m
    pub fn top_m(&self) -> f64 {
        self.levels.last().map(|l| l.z_m).unwrap_or(0.0)
    }

    /// Index of the segment [i, i+1] holding z, and the weight of level i+1.
    fn segment(&self, z_m: f64) -> (usize, f64) {
        let n = self.levels.len();
        let i = match self.levels.binary_search_by(|l| l.z_m.total_cmp(&z_m)) {
            Ok(i) => i.min(n - 2),
            Err(0) => 0,
            Err(i) => (i - 1).min(n - 2),
        };
        let (a, b) = (&self.levels[i], &self.levels[i + 1]);
        (i, (z_m - a.z_m) / (b.z_m - a.z_m))
    }

    /// Environment potential temperature θ(z). units: m → K
    pub fn theta_k(&self, z_m: f64) -> f64 {
        let (i, w) = self.segment(z_m);
        let (a, b) = (&self.levels[i], &self.levels[i + 1]);
        // Below ground: hold the surface value. Above the top: keep the top
        // gradient, but only a stable one, up to the largest θ a level may
        // have: a superadiabatic top segment extrapolated without end reaches
        // 0 K (a sounding whose last two levels are 9 m apart with 49 K of θ
        // between them would give T = −825 K 1.6 km above its top).
        if w > 1.0 && b.theta_k < a.theta_k {
            return b.theta_k;
        }
        let w = w.max(0.0);
        (a.theta_k + (b.theta_k - a.theta_k) * w).min(THETA_MAX_K.max(b.theta_k))
    }

    /// Environment vapour mixing ratio q_v(z), held constant outside the
    /// profile. units: m → kg/kg
    pub fn qv(&self, z_m: f64) -> f64 {
        let (i, w) = self.segment(z_m);
        let (a, b) = (&self.levels[i], &self.levels[i + 1]);
        let w = w.clamp(0.0, 1.0);
        a.qv_kg_per_kg + (b.qv_kg_per_kg - a.qv_kg_per_kg) * w
    }

    /// Environment pressure P(z). units: m → Pa
    pub fn pressure_pa(&self, z_m: f64) -> f64 {
        self.pressure_exner(z_m).0
    }

    /// Environment pressure P(z) and its Exner function Π = (P/P0)^κ
    /// together: the hydrostatic model holds Π and takes P from the table's
    /// pressure by a power near 1 (`thermo::pow_1p`), so Π costs nothing
    /// more (the physics needs both at every parcel every sub-step, and a
    /// general power would be a large part of its cost). units: m → (Pa, 1)
    pub fn pressure_exner(&self, z_m: f64) -> (f64, f64) {
        match self.model {
            PressureModel::Hydrostatic => {
                let x = (z_m / TABLE_DZ_M).max(0.0);
                let last = self.exner_table.len() - 1;
                if x <= last as f64 {
                    let i = (x as usize).min(last - 1);
                    let w = x - i as f64;
                    let (pi_a, pi_b) = (self.exner_table[i], self.exner_table[i + 1]);
                    let pi = pi_a + (pi_b - pi_a) * w;
                    let (p_a, step) = self.pressure_table[i];
                    (p_a * thermo::pow_1p(w * step, 1.0 / thermo::KAPPA), pi)
                } else {
                    // Above the table, an isothermal layer at the table top's
                    // T_v: dΠ/dz = −g/(c_p θ_v) with θ_v = T_v/Π, so Π decays
                    // exponentially and stays positive (a linear extrapolation
                    // would reach Π = 0).
                    let (z_top, pi_top) = (last as f64 * TABLE_DZ_M, self.exner_table[last]);
                    let tv_top = self.theta_v_k(z_top) * pi_top;
                    let pi = pi_top
                        * (-thermo::GRAVITY / (thermo::CP_DRY * tv_top) * (z_m - z_top)).exp();
                    (thermo::P0_PA * pi.powf(1.0 / thermo::KAPPA), pi)
                }
            }
            PressureModel::PaperExponential => {
                let p = self.surface_pressure_pa * (-0.143 * z_m / 1000.0).exp();
                (p, thermo::exner(p))
            }
            PressureModel::Observed => {
                let (i, w) = self.segment(z_m);
                let pa = self.levels[i]
                    .pressure_pa
                    .unwrap_or(self.surface_pressure_pa)
                    .ln();
                let pb = self.levels[i + 1]
                    .pressure_pa
                    .unwrap_or(self.surface_pressure_pa)
                    .ln();
                let p = (pa + (pb - pa) * w).exp();
                (p, thermo::exner(p))
            }
        }
    }

    /// Environment temperature T(z) = θ(z) Π(P(z)). units: m → K
    pub fn temperature_k(&self, z_m: f64) -> f64 {
        let (_, pi) = self.pressure_exner(z_m);
        self.theta_k(z_m) * pi
    }

    /// Environment virtual potential temperature θ_v(z). units: m → K
    pub fn theta_v_k(&self, z_m: f64) -> f64 {
        thermo::virtual_potential_temperature_k(self.theta_k(z_m), self.qv(z_m), 0.0)
    }

    /// Environment air density. units: m → kg m⁻³
    pub fn density_kg_m3(&self, z_m: f64) -> f64 {
        // One pressure lookup for both uses (temperature_k's own is the same value).
        let (p, pi) = self.pressure_exner(z_m);
        thermo::air_density_kg_m3(p, self.theta_k(z_m) * pi, self.qv(z_m))
    }

    /// Environment dewpoint. units: m → K
    pub fn dewpoint_k(&self, z_m: f64) -> f64 {
        self.thermo
            .dewpoint_from_mixing_ratio_k(self.qv(z_m), self.pressure_pa(z_m))
    }

    /// Height at which the environment pressure equals `p_pa` (bisection on
    /// the monotone P(z)), or None outside [top of table, ground]. units: Pa → m
    pub fn height_at_pressure_m(&self, p_pa: f64) -> Option<f64> {
        let (mut lo, mut hi) = (0.0, self.top_m());
        if p_pa > self.pressure_pa(lo) || p_pa < self.pressure_pa(hi) {
            return None;
        }
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.pressure_pa(mid) > p_pa {
                lo = mid
            } else {
                hi = mid
            }
        }
        Some(0.5 * (lo + hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn isentropic() -> Environment {
        let lv = |z_m| EnvLevel {
            z_m,
            theta_k: 300.0,
            qv_kg_per_kg: 0.0,
            pressure_pa: None,
        };
        Environment::new(
            vec![lv(0.0), lv(10_000.0)],
            100_000.0,
            PressureModel::Hydrostatic,
        )
        .unwrap()
    }

    #[test]
    fn isentropic_dry_atmosphere_has_dry_lapse_rate() {
        // With θ constant and dry air, T(z) = θ − g z / c_p exactly.
        let env = isentropic();
        for z in [500.0, 2000.0, 8000.0] {
            let expect = 300.0 - thermo::DRY_LAPSE_RATE_K_PER_M * z;
            assert!((env.temperature_k(z) - expect).abs() < 1e-3, "z = {z}");
        }
    }

    #[test]
    fn rejects_unsorted_levels() {
        let lv = |z_m| EnvLevel {
            z_m,
            theta_k: 300.0,
            qv_kg_per_kg: 0.0,
            pressure_pa: None,
        };
        let err = Environment::new(
            vec![lv(0.0), lv(500.0), lv(400.0)],
            1e5,
            PressureModel::Hydrostatic,
        );
        assert!(err.is_err());
    }
}
