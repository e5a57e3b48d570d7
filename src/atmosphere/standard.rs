//! The forecasters' parcel thermodynamics, as MetPy 1.7 (and, up to
//! constants, SHARPpy) computes it: what `cumulus parcel` reports by default
//! so that its CAPE and CIN are the numbers a forecaster compares.
//!
//! It differs from the simulation's own ([`super::thermo`], paper eq. 1–5)
//! in three ways, which together make the model's moist ascent 0.26–0.37 K
//! warmer up to 300 hPa and its CAPE 3–16 % higher:
//! - saturation vapour pressure over liquid water by Ambaum (2020, eq. 13),
//!   with a latent heat that falls with temperature, instead of Tetens;
//! - a *pseudo-adiabatic* ascent above the LCL (condensate falls out at
//!   once), dT/dp = (R_d T + L_v r_s) / (p (c_pd + L_v² r_s ε / (R_d T²))),
//!   MetPy's `moist_lapse`, instead of the model's reversible saturation
//!   adjustment;
//! - MetPy's constants (R_d = R/M_d, c_pd = 7/2 R_d, L_v = 2.50084e6 J/kg).
//!
//! Dewpoints invert this es exactly (MetPy's `dewpoint` uses Bolton's fit,
//! which differs by up to 0.1 K; a sounding's dewpoints pass through
//! unchanged here).

/// Gas constant of dry air (MetPy's R/M_d). units: J kg⁻¹ K⁻¹
pub const R_DRY: f64 = 287.047_490_977_184_57;
/// Specific heat of dry air at constant pressure, 7/2 R_d. units: J kg⁻¹ K⁻¹
pub const CP_DRY: f64 = 1_004.666_218_420_146_2;
/// κ = R_d / c_pd = 2/7. units: 1
pub const KAPPA: f64 = R_DRY / CP_DRY;
/// ε = M_w / M_d. units: 1
pub const EPSILON: f64 = 0.621_956_910_057_703_3;
/// Latent heat of vaporisation at the triple point. units: J kg⁻¹
pub const LATENT_HEAT: f64 = 2.500_84e6;
/// Gas constant of water vapour. units: J kg⁻¹ K⁻¹
const R_VAPOUR: f64 = 461.523_115_726_060_84;
/// Specific heat of liquid water. units: J kg⁻¹ K⁻¹
const CP_LIQUID: f64 = 4219.4;
/// Specific heat of water vapour at constant pressure (γ = 1.33). units: J kg⁻¹ K⁻¹
const CP_VAPOUR: f64 = 1_860.078_011_865_639;
/// Triple point of water. units: K
const T_TRIPLE_K: f64 = 273.16;
/// Saturation vapour pressure at the triple point. units: Pa
const ES_TRIPLE_PA: f64 = 611.2;
/// Below this the formula is not used (no vapour capacity), as the model's
/// [`super::thermo::T_MIN_SATURATION_K`]. units: K
const T_MIN_K: f64 = 100.0;

/// Saturation vapour pressure over liquid water (Ambaum 2020 eq. 13, with
/// L(T) = L_v − (c_pl − c_pv)(T − T_0)). units: K → Pa; 0 below 100 K.
pub fn saturation_vapour_pressure_pa(t_k: f64) -> f64 {
    if !(t_k > T_MIN_K) {
        return 0.0;
    }
    let latent = LATENT_HEAT - (CP_LIQUID - CP_VAPOUR) * (t_k - T_TRIPLE_K);
    let power = (CP_LIQUID - CP_VAPOUR) / R_VAPOUR;
    ES_TRIPLE_PA
        * (T_TRIPLE_K / t_k).powf(power)
        * ((LATENT_HEAT / T_TRIPLE_K - latent / t_k) / R_VAPOUR).exp()
}

/// Dewpoint of vapour pressure `e_pa`: the inverse of
/// [`saturation_vapour_pressure_pa`], so that a sounding's dewpoint comes
/// back unchanged from the mixing ratio it was turned into. Bolton's
/// (1980) inverse, MetPy's `dewpoint`, is the first guess (within 0.1 K
/// of it between −40 and 40 °C); Newton steps on ln e_s, whose slope is
/// (L_v + (c_pl − c_pv) T_0)/(R_v T²) − (c_pl − c_pv)/(R_v T), finish it.
/// [`T_MIN_K`] for (next to) no vapour. units: Pa → K
pub fn dewpoint_k(e_pa: f64) -> f64 {
    if !(e_pa > saturation_vapour_pressure_pa(T_MIN_K + 1.0)) {
        return T_MIN_K;
    }
    let l = (e_pa / ES_TRIPLE_PA).ln();
    let mut t = 273.15 + 243.5 * l / (17.67 - l);
    let dc = CP_LIQUID - CP_VAPOUR;
    // Quadratic convergence from within a few K: 4 steps reach rounding.
    for _ in 0..4 {
        let f = saturation_vapour_pressure_pa(t).ln() - e_pa.ln();
        let slope = (LATENT_HEAT + dc * T_TRIPLE_K) / (R_VAPOUR * t * t) - dc / (R_VAPOUR * t);
        t -= f / slope;
    }
    t
}

/// Saturation mixing ratio ε e_s/(p − e_s), e_s capped at half of p as the
/// model's (`thermo::ES_MAX_FRACTION_OF_P`). units: K, Pa → kg/kg
pub fn saturation_mixing_ratio(t_k: f64, p_pa: f64) -> f64 {
    let es = saturation_vapour_pressure_pa(t_k).min(super::thermo::ES_MAX_FRACTION_OF_P * p_pa);
    EPSILON * es / (p_pa - es)
}

/// Temperature of a dry parcel lifted adiabatically from (t0_k, p0_pa) to
/// p_pa (Poisson's equation with κ = 2/7). units: K, Pa, Pa → K
pub fn dry_adiabat_k(t0_k: f64, p0_pa: f64, p_pa: f64) -> f64 {
    t0_k * (p_pa / p0_pa).powf(KAPPA)
}

/// dT/d ln p along the pseudo-adiabat at (T, p): MetPy's `moist_lapse`
/// right-hand side times p. units: K, Pa → K
fn moist_lapse_dlnp(t_k: f64, p_pa: f64) -> f64 {
    let rs = saturation_mixing_ratio(t_k, p_pa);
    (R_DRY * t_k + LATENT_HEAT * rs)
        / (CP_DRY + LATENT_HEAT * LATENT_HEAT * rs * EPSILON / (R_DRY * t_k * t_k))
}

/// Temperature of a saturated parcel at `t0_k`, `p0_pa` carried along the
/// pseudo-adiabat to `p1_pa`: classical Runge–Kutta in ln p, in steps of at
/// most 0.002 in ln p (≈ 20 m): its error, O(h⁵) a step, is far below 1e-6
/// K over a troposphere (MetPy's adaptive solver is set to 1e-7 relative).
/// units: K, Pa, Pa → K
pub fn pseudo_adiabat_k(t0_k: f64, p0_pa: f64, p1_pa: f64) -> f64 {
    let (x0, x1) = (p0_pa.ln(), p1_pa.ln());
    let n = ((x1 - x0).abs() / 0.002).ceil().max(1.0);
    let h = (x1 - x0) / n;
    let (mut t, mut x) = (t0_k, x0);
    for _ in 0..n as usize {
        let f = |t: f64, x: f64| moist_lapse_dlnp(t, x.exp());
        let k1 = f(t, x);
        let k2 = f(t + 0.5 * h * k1, x + 0.5 * h);
        let k3 = f(t + 0.5 * h * k2, x + 0.5 * h);
        let k4 = f(t + h * k3, x + h);
        t += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        x += h;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ambaum_matches_metpy_docstring() {
        // MetPy 1.7.1's own example: saturation_vapor_pressure(25 °C) =
        // 31.623456 hPa; 1e-6 relative is the printed precision.
        let es = saturation_vapour_pressure_pa(298.15);
        assert!((es / 3162.3456 - 1.0).abs() < 1e-6, "{es}");
        assert!((saturation_vapour_pressure_pa(T_TRIPLE_K) - ES_TRIPLE_PA).abs() < 1e-9);
    }

    #[test]
    fn dewpoint_inverts_saturation_pressure() {
        // 1e-9 K: Newton converged to rounding.
        for t in [200.0, 240.0, 273.16, 300.0, 320.0] {
            let back = dewpoint_k(saturation_vapour_pressure_pa(t));
            assert!((back - t).abs() < 1e-9, "{t} -> {back}");
        }
    }

    #[test]
    fn dry_pseudo_adiabat_is_poisson() {
        // At 150 K there is no vapour: the pseudo-adiabat is the dry one,
        // d ln T / d ln p = κ, to the solver's error (1e-9 relative).
        let t = pseudo_adiabat_k(150.0, 50_000.0, 20_000.0);
        let dry = dry_adiabat_k(150.0, 50_000.0, 20_000.0);
        assert!((t / dry - 1.0).abs() < 1e-6, "{t} vs {dry}");
    }
}
