//! Moist thermodynamics of air in SI units (K, Pa, kg/kg, J).
//!
//! These functions are the one source of thermodynamics for the whole program:
//! the parcel physics, the kinematic parcel lift (`cumulus parcel`) and the
//! panel's parcel curve all call them, so a diagram and a simulation never
//! disagree.
//!
//! Saturation vapour pressure follows the Tetens form printed in the paper
//! (eq. 3), es = 611 Pa · 10^(7.5 (T − 273.15)/(T − 35.45)). Its two
//! singularities are guarded: the denominator vanishes at T = 35.45 K (we
//! treat anything below [`T_MIN_SATURATION_K`] as having no vapour capacity),
//! and ωs = ε·es/(P − es) blows up as es → P (we cap es at
//! [`ES_MAX_FRACTION_OF_P`]·P). Callers that must count clamps use
//! [`saturation_mixing_ratio_checked`].

/// Gas constant of dry air. units: J kg⁻¹ K⁻¹
pub const R_DRY: f64 = 287.04;
/// Gas constant of water vapour. units: J kg⁻¹ K⁻¹
pub const R_VAPOUR: f64 = 461.5;
/// ε = R_d / R_v, ratio of molar masses of water and dry air. units: 1
pub const EPSILON: f64 = R_DRY / R_VAPOUR;
/// Specific heat of dry air at constant pressure. units: J kg⁻¹ K⁻¹
pub const CP_DRY: f64 = 1005.7;
/// κ = R_d / c_p (≈ 0.286, the paper's exponent). units: 1
pub const KAPPA: f64 = R_DRY / CP_DRY;
/// Latent heat of vaporisation at 0 °C. units: J kg⁻¹
pub const LATENT_HEAT_VAPORISATION: f64 = 2.501e6;
/// Standard gravity. units: m s⁻²
pub const GRAVITY: f64 = 9.80665;
/// Reference pressure of potential temperature. units: Pa
pub const P0_PA: f64 = 100_000.0;
/// Dry adiabatic lapse rate g / c_p. units: K m⁻¹
pub const DRY_LAPSE_RATE_K_PER_M: f64 = GRAVITY / CP_DRY;
/// Below this temperature the Tetens formula is not used (its pole is at
/// 35.45 K); saturation vapour pressure is taken as zero. units: K
pub const T_MIN_SATURATION_K: f64 = 100.0;
/// Cap on es / P so that ωs = ε es / (P − es) stays finite (at es = P water
/// boils and the mixing ratio has no bound). units: 1
pub const ES_MAX_FRACTION_OF_P: f64 = 0.5;

/// Which thermodynamics a parcel diagnostic uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Thermo {
    /// The forecasters' (MetPy's): Ambaum saturation pressure, a
    /// pseudo-adiabatic ascent, MetPy's constants ([`super::standard`]).
    Standard,
    /// The simulation's own: Tetens (paper eq. 3) and the reversible
    /// saturation adjustment of this module.
    #[default]
    Model,
}

impl Thermo {
    /// Short name for reports: "standard" or "model".
    pub fn key(self) -> &'static str {
        match self {
            Thermo::Standard => "standard",
            Thermo::Model => "model",
        }
    }

    /// One line saying what it is, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Thermo::Standard => {
                "standard (as MetPy 1.7: pseudo-adiabatic ascent, Ambaum 2020 saturation pressure)"
            }
            Thermo::Model => {
                "model (the simulation's: reversible ascent, Tetens saturation pressure, paper eq. 1-3)"
            }
        }
    }

    /// Saturation mixing ratio. units: K, Pa → kg/kg
    pub fn saturation_mixing_ratio(self, t_k: f64, p_pa: f64) -> f64 {
        match self {
            Thermo::Standard => super::standard::saturation_mixing_ratio(t_k, p_pa),
            Thermo::Model => saturation_mixing_ratio(t_k, p_pa),
        }
    }

    /// Mixing ratio of air with dewpoint `td_k` at `p_pa`. units: K, Pa → kg/kg
    pub fn mixing_ratio_from_dewpoint(self, td_k: f64, p_pa: f64) -> f64 {
        self.saturation_mixing_ratio(td_k, p_pa)
    }

    /// Dewpoint of air with mixing ratio `qv` at `p_pa`. units: kg/kg, Pa → K
    pub fn dewpoint_from_mixing_ratio_k(self, qv: f64, p_pa: f64) -> f64 {
        match self {
            Thermo::Standard => super::standard::dewpoint_k(vapour_pressure_pa(qv, p_pa)),
            Thermo::Model => dewpoint_from_mixing_ratio_k(qv, p_pa),
        }
    }
}

/// Saturation vapour pressure over liquid water (Tetens, paper eq. 3).
/// units: T in K, result in Pa. Zero below [`T_MIN_SATURATION_K`].
pub fn saturation_vapour_pressure_pa(t_k: f64) -> f64 {
    if !(t_k > T_MIN_SATURATION_K) {
        return 0.0;
    }
    // 10^y as e^(y ln 10): one exp, cheaper than a general power.
    611.0 * (7.5 * std::f64::consts::LN_10 * (t_k - 273.15) / (t_k - 35.45)).exp()
}

/// Saturation mixing ratio ωs = ε es / (P − es) and whether es had to be
/// capped at [`ES_MAX_FRACTION_OF_P`]·P. units: K, Pa → kg/kg.
pub fn saturation_mixing_ratio_checked(t_k: f64, p_pa: f64) -> (f64, bool) {
    mixing_ratio_of_es(saturation_vapour_pressure_pa(t_k), p_pa)
}

/// ωs = ε es / (P − es) from a saturation vapour pressure `es`, capped as
/// in [`saturation_mixing_ratio_checked`] (which is this of es(T)).
fn mixing_ratio_of_es(es: f64, p_pa: f64) -> (f64, bool) {
    let cap = ES_MAX_FRACTION_OF_P * p_pa;
    let (es, clamped) = if es > cap { (cap, true) } else { (es, false) };
    (EPSILON * es / (p_pa - es), clamped)
}

/// Saturation mixing ratio ωs (kg/kg) at temperature `t_k` (K), pressure `p_pa` (Pa).
pub fn saturation_mixing_ratio(t_k: f64, p_pa: f64) -> f64 {
    saturation_mixing_ratio_checked(t_k, p_pa).0
}

/// Exner function Π = (P/P0)^κ. units: Pa → 1
pub fn exner(p_pa: f64) -> f64 {
    (p_pa / P0_PA).powf(KAPPA)
}

/// Largest |t| for which [`pow_1p`] sums its series: past it, `powf`.
const NEAR_ONE: f64 = 1.0 / 128.0;

/// (1 + t)^a for small t and |a| ≤ 4: a power whose base is near 1 (the
/// Exner function's 1/κ within one table cell, eq 6's 1/γ over one
/// sub-step, both within 1e-3 of 1). The binomial series 1 + a t (1 +
/// (a−1)/2 t (1 + (a−2)/3 t (…))) to the t⁷ term: for |t| ≤ 1/128 the first
/// omitted term is below |C(a, 8)| 2⁻⁵⁶ < 1e-16 of the result, so it agrees
/// with `powf` to a few ulps (tested) at a fraction of the cost. Taking t
/// rather than 1 + t keeps the small difference exact where the caller
/// has it (a table's relative step, a pressure difference). Farther from
/// 1, or for larger |a|, it is `powf`.
pub fn pow_1p(t: f64, a: f64) -> f64 {
    if !(t.abs() <= NEAR_ONE) || a.abs() > 4.0 {
        return (1.0 + t).powf(a);
    }
    // The coefficients C(a, k) = C(a, k−1) (a − k + 1)/k (constants when a
    // is), then Estrin's scheme: three levels of independent products
    // instead of Horner's chain of seven.
    let mut c = [1.0; 8];
    for k in 1..8 {
        c[k] = c[k - 1] * (a - (k - 1) as f64) * (1.0 / k as f64);
    }
    let (t2, t4) = (t * t, t * t * t * t);
    let (p01, p23, p45, p67) = (
        c[0] + c[1] * t,
        c[2] + c[3] * t,
        c[4] + c[5] * t,
        c[6] + c[7] * t,
    );
    (p01 + p23 * t2) + (p45 + p67 * t2) * t4
}

/// Potential temperature θ = T (P0/P)^κ. units: K, Pa → K
pub fn potential_temperature_k(t_k: f64, p_pa: f64) -> f64 {
    t_k / exner(p_pa)
}

/// Temperature from potential temperature and pressure. units: K, Pa → K
pub fn temperature_from_theta_k(theta_k: f64, p_pa: f64) -> f64 {
    theta_k * exner(p_pa)
}

/// Virtual temperature factor (1 + q_v/ε)/(1 + q_v + q_l): the ratio of the
/// density temperature to the temperature. With `q_l = 0` it is the usual
/// virtual temperature T_v = T (1 + q_v/ε)/(1 + q_v) ≈ T (1 + 0.61 q_v) of
/// paper eq. 4; a non-zero `q_l` adds condensate loading. units: kg/kg → 1
pub fn virtual_factor(qv: f64, ql: f64) -> f64 {
    (1.0 + qv / EPSILON) / (1.0 + qv + ql)
}

/// Virtual temperature. units: K, kg/kg, kg/kg → K
pub fn virtual_temperature_k(t_k: f64, qv: f64, ql: f64) -> f64 {
    t_k * virtual_factor(qv, ql)
}

/// Virtual potential temperature θ_v = θ (1 + q_v/ε)/(1 + q_v + q_l)
/// (paper eq. 4; `ql` > 0 includes condensate loading). units: K, kg/kg → K
pub fn virtual_potential_temperature_k(theta_k: f64, qv: f64, ql: f64) -> f64 {
    theta_k * virtual_factor(qv, ql)
}

/// Vapour pressure of air with mixing ratio `qv` at pressure `p_pa`.
/// units: kg/kg, Pa → Pa
pub fn vapour_pressure_pa(qv: f64, p_pa: f64) -> f64 {
    let qv = qv.max(0.0);
    qv * p_pa / (EPSILON + qv)
}

/// Mixing ratio of air whose dewpoint is `td_k` at pressure `p_pa`.
/// units: K, Pa → kg/kg
pub fn mixing_ratio_from_dewpoint(td_k: f64, p_pa: f64) -> f64 {
    saturation_mixing_ratio(td_k, p_pa)
}

/// Dewpoint of air with mixing ratio `qv` at pressure `p_pa` (inverse Tetens).
/// Returns [`T_MIN_SATURATION_K`] for dry air. units: kg/kg, Pa → K
pub fn dewpoint_from_mixing_ratio_k(qv: f64, p_pa: f64) -> f64 {
    let e = vapour_pressure_pa(qv, p_pa);
    if e <= saturation_vapour_pressure_pa(T_MIN_SATURATION_K) {
        return T_MIN_SATURATION_K;
    }
    // es = 611·10^(7.5 Tc/(Tc + 237.7)) solved for Tc.
    let l = (e / 611.0).log10();
    let tc = 237.7 * l / (7.5 - l);
    tc + 273.15
}

/// Equivalent potential temperature θ_e of air at `t_k`, dewpoint `td_k` and
/// pressure `p_pa` (Bolton 1980 eq. 39 with the LCL temperature of his eq.
/// 15, the form MetPy's `equivalent_potential_temperature` uses): the θ a
/// parcel reaches when all its vapour condenses. Used to pick the most
/// unstable parcel. units: K, K, Pa → K
pub fn equivalent_potential_temperature_k(t_k: f64, td_k: f64, p_pa: f64) -> f64 {
    let r = mixing_ratio_from_dewpoint(td_k, p_pa);
    let e = vapour_pressure_pa(r, p_pa);
    let t_lcl = 56.0 + 1.0 / (1.0 / (td_k - 56.0) + (t_k / td_k).ln() / 800.0);
    let theta_dry = t_k * (P0_PA / (p_pa - e)).powf(KAPPA) * (t_k / t_lcl).powf(0.28 * r);
    theta_dry * (r * (1.0 + 0.448 * r) * (3036.0 / t_lcl - 1.78)).exp()
}

/// Mixing ratio from relative humidity (0–1) at temperature and pressure.
/// units: 1, K, Pa → kg/kg
pub fn mixing_ratio_from_relative_humidity(rh: f64, t_k: f64, p_pa: f64) -> f64 {
    let e = rh.clamp(0.0, 1.0) * saturation_vapour_pressure_pa(t_k);
    let e = e.min(ES_MAX_FRACTION_OF_P * p_pa);
    EPSILON * e / (p_pa - e)
}

/// Density of moist air from the ideal gas law ρ = P / (R_d T_v).
/// units: Pa, K, kg/kg → kg m⁻³
pub fn air_density_kg_m3(p_pa: f64, t_k: f64, qv: f64) -> f64 {
    p_pa / (R_DRY * virtual_temperature_k(t_k, qv, 0.0))
}

/// Result of bringing a parcel to saturation equilibrium at fixed pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adjusted {
    /// Temperature after condensation/evaporation. units: K
    pub t_k: f64,
    /// Vapour mixing ratio after adjustment. units: kg/kg
    pub qv: f64,
    /// Liquid water mixing ratio after adjustment. units: kg/kg
    pub ql: f64,
    /// Vapour condensed (positive) or liquid evaporated (negative). units: kg/kg
    pub condensed: f64,
    /// Whether the ωs cap near es → P was hit.
    pub clamped: bool,
}

/// Saturation adjustment at constant pressure: condense vapour above
/// saturation, or evaporate liquid into sub-saturated air, releasing or
/// absorbing latent heat ΔT = α (L/c_p) Δq (paper eq. 1; α = 1 is the physical
/// value, the paper's 0.3 is a calibration). Solved by Newton's method on
/// q_v − ωs(T + α L/c_p (q_v0 − q_v), P) = 0, which converges in 2–4 steps.
pub fn saturation_adjust(t_k: f64, qv: f64, ql: f64, p_pa: f64, alpha: f64) -> Adjusted {
    let qv0 = qv.max(0.0);
    let ql0 = ql.max(0.0);
    let lc = alpha * LATENT_HEAT_VAPORISATION / CP_DRY;
    let (qs0, mut clamped) = saturation_mixing_ratio_checked(t_k, p_pa);
    if qv0 <= qs0 && ql0 <= 0.0 {
        return Adjusted {
            t_k,
            qv: qv0,
            ql: 0.0,
            condensed: 0.0,
            clamped,
        };
    }
    // Unknown: condensed amount c (negative = evaporation), bounded by -ql0 ≤ c ≤ qv0.
    let mut c = 0.0_f64;
    for _ in 0..20 {
        let t = t_k + lc * c;
        // es once per iteration: ωs and its derivative both need it.
        let es = saturation_vapour_pressure_pa(t);
        let (qs, cl) = mixing_ratio_of_es(es, p_pa);
        clamped |= cl;
        let f = qv0 - c - qs;
        // dqs/dT by the Clausius–Clapeyron-like derivative of Tetens:
        // d ln es / dT = 7.5 ln10 (273.15 − 35.45) / (T − 35.45)².
        let dlnes = 7.5 * std::f64::consts::LN_10 * (273.15 - 35.45) / ((t - 35.45) * (t - 35.45));
        let dqs_dt = if es > 0.0 && !cl {
            qs * dlnes * p_pa / (p_pa - es)
        } else {
            0.0
        };
        let df = -1.0 - dqs_dt * lc;
        let step = f / df;
        let next = (c - step).clamp(-ql0, qv0);
        let done = (next - c).abs() < 1e-12;
        c = next;
        if done {
            break;
        }
    }
    Adjusted {
        t_k: t_k + lc * c,
        qv: qv0 - c,
        ql: ql0 + c,
        condensed: c,
        clamped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetens_matches_known_values() {
        // 611 Pa at 0 °C by construction; 2339 Pa at 20 °C in standard tables
        // (Tetens is within 0.5 % of Goff–Gratch between 0 and 35 °C).
        assert!((saturation_vapour_pressure_pa(273.15) - 611.0).abs() < 1e-9);
        let e20 = saturation_vapour_pressure_pa(293.15);
        assert!((e20 - 2339.0).abs() / 2339.0 < 0.005, "{e20}");
    }

    #[test]
    fn pow_1p_matches_powf() {
        // Relative 4e-16 (≈ 2 ulp): the omitted series terms are far below
        // an ulp, what remains is the rounding of the 7 Horner steps and of
        // powf itself. Exponents: κ, 1/κ, eq 6's 1/γ for γ = 1.4, and others.
        for a in [KAPPA, 1.0 / KAPPA, 1.0 / 1.4, -1.0, 0.5, 3.9] {
            // t = k 2⁻¹⁷ up to ±1/128: 1 + t is exact, so powf's answer
            // is not off by the rounding of its base.
            for k in -1024..=1024 {
                let t = k as f64 * (NEAR_ONE / 1024.0);
                let (got, want) = (pow_1p(t, a), (1.0 + t).powf(a));
                assert!(
                    (got - want).abs() <= 4e-16 * want,
                    "(1+{t})^{a}: {got} vs {want}"
                );
            }
        }
        // Far from 1 it is powf itself.
        assert_eq!(pow_1p(-0.5, KAPPA), 0.5f64.powf(KAPPA));
        assert_eq!(pow_1p(0.001, 5.0), 1.001f64.powf(5.0));
    }

    #[test]
    fn poles_are_guarded() {
        assert_eq!(saturation_vapour_pressure_pa(35.45), 0.0);
        assert_eq!(saturation_vapour_pressure_pa(f64::NAN), 0.0);
        let (q, clamped) = saturation_mixing_ratio_checked(400.0, 10_000.0);
        assert!(q.is_finite() && clamped);
    }

    #[test]
    fn dewpoint_round_trips() {
        for td in [230.0, 260.0, 280.0, 300.0] {
            let q = mixing_ratio_from_dewpoint(td, 85_000.0);
            let back = dewpoint_from_mixing_ratio_k(q, 85_000.0);
            assert!((back - td).abs() < 1e-6, "{td} -> {back}");
        }
    }

    #[test]
    fn adjustment_reaches_saturation_and_conserves_water() {
        let a = saturation_adjust(290.0, 0.02, 0.0, 90_000.0, 1.0);
        let qs = saturation_mixing_ratio(a.t_k, 90_000.0);
        assert!((a.qv - qs).abs() < 1e-9);
        assert!((a.qv + a.ql - 0.02).abs() < 1e-15);
        // Condensation warms: moist static energy c_p T + L q_v is conserved.
        let before = CP_DRY * 290.0 + LATENT_HEAT_VAPORISATION * 0.02;
        let after = CP_DRY * a.t_k + LATENT_HEAT_VAPORISATION * a.qv;
        assert!((before - after).abs() < 1e-6 * before);
    }
}
