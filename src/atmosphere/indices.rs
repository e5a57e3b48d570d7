//! The sounding indices a forecaster reads first, beside CAPE and CIN:
//! lifted index, K-index, precipitable water, the 0–3 km and 700–500 hPa
//! lapse rates, and from the wind the 0–1 and 0–6 km bulk shear, the
//! Bunkers storm motions and the 0–1 and 0–3 km storm-relative helicity.
//! Definitions are MetPy 1.7's (`lifted_index`, `k_index`,
//! `precipitable_water`, `bulk_shear`, `bunkers_storm_motion`,
//! `storm_relative_helicity`), evaluated on the piecewise-linear
//! [`Environment`].
//!
//! An index whose layer the data do not cover is None (a surface above
//! 850 hPa has no K-index; a sounding whose winds end below 6 km has no 0–6
//! km shear, Bunkers motion or helicity); a sounding without wind columns
//! has no wind indices at all ([`Indices::wind`] is None), never zeros.

use super::environment::Environment;
use super::lifting::ParcelLevel;
use super::thermo;
use super::wind::WindProfile;

/// Density of liquid water (MetPy's `rho_l`). units: kg m⁻³
const WATER_DENSITY_KG_M3: f64 = 999.974_95;
/// Deviation of the Bunkers storm motions from the mean wind (Bunkers et
/// al. 2000). units: m s⁻¹
const BUNKERS_DEVIATION_M_S: f64 = 7.5;

/// The thermodynamic indices and, where the sounding has wind, the wind ones.
#[derive(Debug, Clone, PartialEq)]
pub struct Indices {
    /// Environment minus surface-based parcel temperature at 500 hPa (not
    /// virtual); negative is unstable. None if the data end below 500 hPa. units: K
    pub lifted_index_k: Option<f64>,
    /// K = (T850 − T500) + Td850 − (T700 − Td700). None if the surface is
    /// above 850 hPa or the data end below 500 hPa. units: °C
    pub k_index_c: Option<f64>,
    /// Column water vapour ∫ q_v dp / (g ρ_w) over the levels with a
    /// measured humidity. units: mm
    pub precipitable_water_mm: f64,
    /// Mean temperature lapse rate from the ground to 3 km above it; None
    /// if the data end below. units: K km⁻¹
    pub lapse_0_3km_k_per_km: Option<f64>,
    /// Mean lapse rate between 700 and 500 hPa; None if the data do not
    /// span them. units: K km⁻¹
    pub lapse_700_500_k_per_km: Option<f64>,
    /// Wind indices; None without wind data.
    pub wind: Option<WindIndices>,
}

/// Indices of the wind profile (heights above the ground).
#[derive(Debug, Clone, PartialEq)]
pub struct WindIndices {
    /// Height of the highest wind. units: m
    pub top_m: f64,
    /// |V(1 km) − V(0)|. units: m s⁻¹
    pub shear_0_1km_m_s: Option<f64>,
    /// |V(6 km) − V(0)|. units: m s⁻¹
    pub shear_0_6km_m_s: Option<f64>,
    /// Bunkers right-moving storm motion (u, v). units: m s⁻¹
    pub bunkers_right_m_s: Option<[f64; 2]>,
    /// Bunkers left-moving storm motion (u, v). units: m s⁻¹
    pub bunkers_left_m_s: Option<[f64; 2]>,
    /// 0–1 km storm-relative helicity for the right mover. units: m² s⁻²
    pub srh_0_1km_m2_s2: Option<f64>,
    /// 0–3 km storm-relative helicity for the right mover. units: m² s⁻²
    pub srh_0_3km_m2_s2: Option<f64>,
}

/// The indices of `env`, the lifted index from the surface-based parcel's
/// `sb_levels` (its ascent, lowest first).
pub fn indices(env: &Environment, sb_levels: &[ParcelLevel]) -> Indices {
    let at = |p_hpa: f64| env.height_at_pressure_m(p_hpa * 100.0);
    let t = |z: f64| env.temperature_k(z);
    let td = |z: f64| env.dewpoint_k(z);
    let lifted_index_k =
        at(500.0).and_then(|z5| parcel_t_at(sb_levels, 50_000.0).map(|tp| t(z5) - tp));
    let k_index_c = match (at(850.0), at(700.0), at(500.0)) {
        (Some(z8), Some(z7), Some(z5)) => {
            Some((t(z8) - t(z5)) + (td(z8) - 273.15) - (t(z7) - td(z7)))
        }
        _ => None,
    };
    let lapse = |z0: f64, z1: f64| (t(z0) - t(z1)) / ((z1 - z0) / 1000.0);
    Indices {
        lifted_index_k,
        k_index_c,
        precipitable_water_mm: precipitable_water_mm(env),
        lapse_0_3km_k_per_km: (env.top_m() >= 3000.0).then(|| lapse(0.0, 3000.0)),
        lapse_700_500_k_per_km: at(700.0).zip(at(500.0)).map(|(z7, z5)| lapse(z7, z5)),
        wind: env.wind().map(|w| wind_indices(env, w)),
    }
}

/// Parcel temperature at `p_pa`, linear in ln p between recorded levels.
fn parcel_t_at(levels: &[ParcelLevel], p_pa: f64) -> Option<f64> {
    levels.windows(2).find_map(|w| {
        let (a, b) = (&w[0], &w[1]);
        (a.p_pa >= p_pa && b.p_pa <= p_pa && a.p_pa > b.p_pa).then(|| {
            let f = (a.p_pa / p_pa).ln() / (a.p_pa / b.p_pa).ln();
            a.t_k + (b.t_k - a.t_k) * f
        })
    })
}

/// ∫ q_v dp / (g ρ_w) by trapezoids over the environment's levels up to
/// the highest measured humidity. units: mm
fn precipitable_water_mm(env: &Environment) -> f64 {
    let top = env.humidity_top_m().unwrap_or(env.top_m());
    let zs: Vec<f64> = env
        .levels()
        .iter()
        .map(|l| l.z_m)
        .filter(|&z| z <= top)
        .collect();
    let kg_m2: f64 = zs
        .windows(2)
        .map(|w| {
            let dp = env.pressure_pa(w[0]) - env.pressure_pa(w[1]);
            0.5 * (env.qv(w[0]) + env.qv(w[1])) * dp
        })
        .sum::<f64>()
        / thermo::GRAVITY;
    kg_m2 / WATER_DENSITY_KG_M3 * 1000.0
}

fn wind_indices(env: &Environment, wind: &WindProfile) -> WindIndices {
    let top = wind.levels().last().map_or(0.0, |l| l.z_m);
    let covers = |z: f64| top >= z;
    let shear = |z: f64| covers(z).then(|| wind.bulk_shear_m_s(0.0, z));
    let bunkers = covers(6000.0).then(|| bunkers_m_s(env, wind)).flatten();
    let srh = |z: f64| {
        bunkers
            .filter(|_| covers(z))
            .map(|(right, _)| storm_relative_helicity(wind, z, right))
    };
    WindIndices {
        top_m: top,
        shear_0_1km_m_s: shear(1000.0),
        shear_0_6km_m_s: shear(6000.0),
        bunkers_right_m_s: bunkers.map(|b| b.0),
        bunkers_left_m_s: bunkers.map(|b| b.1),
        srh_0_1km_m2_s2: srh(1000.0),
        srh_0_3km_m2_s2: srh(3000.0),
    }
}

/// The wind's levels inside (lo, hi) with the interpolated ends: the
/// points of the piecewise-linear hodograph over that layer. units: m
fn layer_heights(wind: &WindProfile, lo: f64, hi: f64) -> Vec<f64> {
    let mut zs = vec![lo];
    zs.extend(
        wind.levels()
            .iter()
            .map(|l| l.z_m)
            .filter(|&z| z > lo && z < hi),
    );
    zs.push(hi);
    zs
}

/// Pressure-weighted mean wind ∫ V dp / ∫ dp over heights [lo, hi]
/// (trapezoids over the wind's levels, as MetPy's
/// `weighted_continuous_average`). units: m s⁻¹
fn mean_wind(env: &Environment, wind: &WindProfile, lo: f64, hi: f64) -> [f64; 2] {
    let zs = layer_heights(wind, lo, hi);
    let mut sum = [0.0; 2];
    for w in zs.windows(2) {
        let dp = env.pressure_pa(w[0]) - env.pressure_pa(w[1]);
        let (a, b) = (wind.at(w[0]), wind.at(w[1]));
        sum[0] += 0.5 * (a[0] + b[0]) * dp;
        sum[1] += 0.5 * (a[1] + b[1]) * dp;
    }
    let dp = env.pressure_pa(lo) - env.pressure_pa(hi);
    [sum[0] / dp, sum[1] / dp]
}

/// Bunkers (2000) right and left storm motions: the 0–6 km mean wind ±
/// 7.5 m/s across the shear from the 0–0.5 km to the 5.5–6 km mean wind
/// (right of it for the right mover). None if that shear is zero. units: m s⁻¹
fn bunkers_m_s(env: &Environment, wind: &WindProfile) -> Option<([f64; 2], [f64; 2])> {
    let mean = mean_wind(env, wind, 0.0, 6000.0);
    let low = mean_wind(env, wind, 0.0, 500.0);
    let high = mean_wind(env, wind, 5500.0, 6000.0);
    let shear = [high[0] - low[0], high[1] - low[1]];
    let mag = shear[0].hypot(shear[1]);
    if !(mag > 0.0) {
        return None;
    }
    let dev = [
        BUNKERS_DEVIATION_M_S * shear[1] / mag,
        -BUNKERS_DEVIATION_M_S * shear[0] / mag,
    ];
    Some((
        [mean[0] + dev[0], mean[1] + dev[1]],
        [mean[0] - dev[0], mean[1] - dev[1]],
    ))
}

/// Storm-relative helicity from the ground to `depth_m` for a storm moving
/// at `storm`: −∫ k·(V − c) × dV/dz dz, exact for the piecewise-linear
/// hodograph as Σ (u_{k+1} − c_u)(v_k − c_v) − (u_k − c_u)(v_{k+1} − c_v).
/// units: m, m s⁻¹ → m² s⁻²
fn storm_relative_helicity(wind: &WindProfile, depth_m: f64, storm: [f64; 2]) -> f64 {
    layer_heights(wind, 0.0, depth_m)
        .windows(2)
        .map(|w| {
            let (a, b) = (wind.at(w[0]), wind.at(w[1]));
            let (ua, va) = (a[0] - storm[0], a[1] - storm[1]);
            let (ub, vb) = (b[0] - storm[0], b[1] - storm[1]);
            ub * va - ua * vb
        })
        .sum()
}
