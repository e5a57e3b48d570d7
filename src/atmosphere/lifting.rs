//! Parcel theory: lift a parcel kinematically through an [`Environment`]
//! and find its lifting condensation level (LCL), its buoyant layers (the
//! level of free convection, LFC, at the base of each, the equilibrium
//! level, EL, at the top) and its state along the way.
//!
//! Two thermodynamics ([`LiftOptions::thermo`]): the simulation's own
//! ([`Thermo::Model`], the default here, described below) and the
//! forecasters' ([`Thermo::Standard`]: dry adiabat with κ = 2/7 to the LCL,
//! then MetPy's pseudo-adiabat, see [`super::standard`]), which `cumulus
//! parcel` reports by default.
//!
//! The parcel carries θ, q_v and q_l. Each step of at most [`MAX_STEP_M`] it
//! rises to a new height, takes the environment pressure there, converts θ to
//! T with that pressure and calls [`thermo::saturation_adjust`]; the latent
//! heat of what condensed raises θ (θ = T_adjusted / Π). Without phase change θ
//! and q_v are conserved exactly; total water q_v + q_l is conserved always.
//! This is what the particle integrator does per time step, so the diagram
//! and the simulation agree.
//!
//! Because the water stays in the parcel (nothing precipitates), this is a
//! reversible ascent. The *temperature* of the ascent barely depends on that:
//! with c_p of dry air for the whole parcel (no heat capacity of vapour or
//! liquid), reversible and pseudo-adiabatic ascents obey the same dT/dP, so
//! T follows the pseudo-adiabat that MetPy's `parcel_profile` integrates
//! (tests check within 1 K to 300 hPa).
//!
//! LFC and EL are crossings of parcel and environment *virtual* temperature,
//! the buoyancy the simulation uses (paper eq. 4–5). Like the simulation's
//! `PhysicsConfig::condensate_loading`, [`LiftOptions::condensate_loading`]
//! (off by default, as in the paper and the physics) adds the liquid water's
//! weight: T_v = T (1 + q_v/ε)/(1 + q_v + q_l).
//!
//! MetPy's `lfc`/`el` differ: they compare plain temperatures unless given
//! virtual ones, and their parcel drops its condensate. Without loading our
//! crossings differ from MetPy's only by the vapour's virtual correction
//! (≈ 0.6 q_v T, ~1.5 K at the LFC of a moist boundary-layer parcel, ~0 near
//! the tropopause); with loading the parcel is ~0.3 K per g/kg of q_l cooler
//! in T_v, so its EL is lower.

use super::environment::Environment;
use super::standard;
use super::thermo::{self, Thermo};
use crate::error::{Error, Result};

/// Largest height step of the ascent. 10 m keeps the first-order error of
/// evaluating latent heating at the end of each step below 1e-4 of the
/// latent warming (≈ 0.003 K over a 10 km ascent) and costs ~1000 saturation
/// adjustments for a full troposphere (well under a millisecond). units: m
pub const MAX_STEP_M: f64 = 10.0;

/// Options of a parcel ascent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiftOptions {
    /// Latent-heat factor α of the saturation adjustment (1 = physical). units: 1
    pub alpha: f64,
    /// Surface parcel temperature; None = the environment's. units: K
    pub surface_t_k: Option<f64>,
    /// Surface parcel dewpoint; None = the environment's. units: K
    pub surface_td_k: Option<f64>,
    /// Count the liquid water's weight in the parcel's virtual temperature
    /// (the simulation's `condensate_loading`; off by default as there).
    pub condensate_loading: bool,
    /// Which thermodynamics lift the parcel: the simulation's (default here,
    /// so curves drawn over a simulation match it) or the forecasters'.
    pub thermo: Thermo,
    /// Which level of free convection CAPE and CIN use when the parcel has
    /// more than one buoyant layer.
    pub lfc: LfcChoice,
}

/// Which level of free convection (LFC) counts when the parcel becomes
/// buoyant more than once (MetPy's `which_lfc` names).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LfcChoice {
    /// The lowest: the base of the first buoyant layer above the LCL.
    Bottom,
    /// The highest: the base of the last buoyant layer.
    Top,
    /// The base of the buoyant layer whose CAPE (net area from it to the
    /// EL) is largest: above a strong cap, the layer above the cap.
    #[default]
    MostCape,
}

impl LfcChoice {
    /// MetPy's name: "bottom", "top" or "most_cape".
    pub fn key(self) -> &'static str {
        match self {
            LfcChoice::Bottom => "bottom",
            LfcChoice::Top => "top",
            LfcChoice::MostCape => "most_cape",
        }
    }
}

/// One layer in which the lifted parcel is buoyant (above its LCL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuoyantLayer {
    /// Where it becomes buoyant (a candidate LFC; the LCL if it is buoyant there).
    pub lfc: LevelMark,
    /// Where it stops being buoyant; None if it is still buoyant at the top.
    pub el: Option<LevelMark>,
}

impl Default for LiftOptions {
    fn default() -> Self {
        LiftOptions {
            alpha: 1.0,
            surface_t_k: None,
            surface_td_k: None,
            condensate_loading: false,
            thermo: Thermo::Model,
            lfc: LfcChoice::MostCape,
        }
    }
}

/// A height of interest (LCL, LFC, EL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelMark {
    /// Environment pressure there. units: Pa
    pub p_pa: f64,
    /// Height above the ground. units: m
    pub z_m: f64,
}

/// Parcel and environment at one height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParcelLevel {
    /// units: Pa
    pub p_pa: f64,
    /// Height above the ground. units: m
    pub z_m: f64,
    /// Parcel temperature. units: K
    pub t_k: f64,
    /// Parcel virtual temperature (with condensate loading if
    /// [`LiftOptions::condensate_loading`]). units: K
    pub tv_k: f64,
    /// Environment temperature. units: K
    pub env_t_k: f64,
    /// Environment virtual temperature. units: K
    pub env_tv_k: f64,
    /// Parcel vapour mixing ratio. units: kg/kg
    pub qv: f64,
    /// Parcel liquid water mixing ratio. units: kg/kg
    pub ql: f64,
    /// Parcel potential temperature. units: K
    pub theta_k: f64,
}

/// Result of lifting the surface parcel. The LFC is the lowest level at or
/// above the LCL where the parcel becomes buoyant; the EL is the highest
/// level above it where it stops being buoyant (MetPy's defaults are
/// `which="top"` for both).
#[derive(Debug, Clone, PartialEq)]
pub struct ParcelAscent {
    /// Lifting condensation level, None if the parcel never saturates.
    pub lcl: Option<LevelMark>,
    /// Level of free convection, None if the parcel is never buoyant above the LCL.
    pub lfc: Option<LevelMark>,
    /// Equilibrium level, None without LFC or if still buoyant at the top.
    pub el: Option<LevelMark>,
    /// Every buoyant layer above the LCL, lowest first: `lfc` is the first's
    /// base, `el` the last's top.
    pub layers: Vec<BuoyantLayer>,
    /// Parcel and environment at the requested heights, lowest first.
    pub levels: Vec<ParcelLevel>,
}

/// Lifts the surface parcel and reports it at every environment level.
pub fn lift_surface_parcel(env: &Environment, opts: &LiftOptions) -> Result<ParcelAscent> {
    let heights: Vec<f64> = env.levels().iter().map(|l| l.z_m).collect();
    lift_at(env, opts, &heights)
}

/// Lifts the surface parcel and reports it at `n` (≥ 2) evenly spaced
/// heights from the ground to the environment's top: the curve the window
/// redraws while a profile point is dragged.
pub fn surface_parcel_curve(
    env: &Environment,
    opts: &LiftOptions,
    n: usize,
) -> Result<ParcelAscent> {
    let n = n.max(2);
    let top = env.top_m();
    let heights: Vec<f64> = (0..n).map(|i| top * i as f64 / (n - 1) as f64).collect();
    lift_at(env, opts, &heights)
}

/// Where a lifted parcel starts: its height, temperature and dewpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParcelStart {
    /// Starting height above the ground. units: m
    pub z_m: f64,
    /// Starting temperature. units: K
    pub t_k: f64,
    /// Starting dewpoint (at most `t_k`). units: K
    pub td_k: f64,
}

impl ParcelStart {
    /// The surface parcel of `env`, or the temperature and dewpoint that
    /// `opts` sets for it.
    pub fn surface(env: &Environment, opts: &LiftOptions) -> Self {
        ParcelStart {
            z_m: 0.0,
            t_k: opts.surface_t_k.unwrap_or_else(|| env.temperature_k(0.0)),
            td_k: opts.surface_td_k.unwrap_or_else(|| env.dewpoint_k(0.0)),
        }
    }
}

/// Lifts the surface parcel to the environment's top, recording it at
/// `heights` (non-decreasing, ≥ 0); heights above the top are not reported.
pub fn lift_at(env: &Environment, opts: &LiftOptions, heights: &[f64]) -> Result<ParcelAscent> {
    lift_from(env, opts, &ParcelStart::surface(env, opts), heights)
}

/// Height in [`lo_m`, `hi_m`] at which air of potential temperature
/// `theta_k` and total water `qt` (kg/kg), lifted dry-adiabatically through
/// `env`, reaches saturation (ω_s(θ Π(P(z)), P(z)) = q_t; ω_s falls with
/// height): `Some(lo_m)` if it is saturated there already, None if it is
/// still unsaturated at `hi_m`. Its bisection is
/// [`saturation_level_between`], the one saturation-level search of the
/// program (the physics' condensation planes use it too). units: m
pub fn lcl_height_m(env: &Environment, theta_k: f64, qt: f64, lo_m: f64, hi_m: f64) -> Option<f64> {
    if !(saturation_excess(env, theta_k, qt, lo_m) > 0.0) {
        return Some(lo_m);
    }
    if saturation_excess(env, theta_k, qt, hi_m) > 0.0 {
        return None;
    }
    // 60 halvings: far below a millimetre for any bracket in the atmosphere.
    Some(saturation_level_between(env, theta_k, qt, lo_m, hi_m, 60))
}

/// Lifts a parcel from `start` to the environment's top, recording it at
/// `heights` (non-decreasing, ≥ 0); heights below the start or above the top
/// are not reported.
pub fn lift_from(
    env: &Environment,
    opts: &LiftOptions,
    start: &ParcelStart,
    heights: &[f64],
) -> Result<ParcelAscent> {
    if let Some(i) = (0..heights.len()).find(|&i| {
        !(heights[i] >= 0.0 && heights[i].is_finite() && (i == 0 || heights[i] >= heights[i - 1]))
    }) {
        return Err(Error::invalid(
            format!("parcel output height [{i}] (m)"),
            heights[i],
            "finite heights ≥ 0 in non-decreasing order",
        ));
    }
    if !(opts.alpha.is_finite() && (0.0..=2.0).contains(&opts.alpha)) {
        return Err(Error::invalid(
            "latent-heat factor alpha",
            opts.alpha,
            "between 0 and 2 (1 is physical)",
        ));
    }
    let top = env.top_m();
    let z_start = start.z_m;
    if !(z_start.is_finite() && (0.0..top).contains(&z_start)) {
        return Err(Error::invalid(
            "parcel starting height (m)",
            z_start,
            format!("from the ground up to below the profile top, {top} m"),
        ));
    }
    // The surface parcel keeps its established wording in messages.
    let at = if z_start == 0.0 {
        "surface".to_string()
    } else {
        format!("parcel (starting at {z_start:.0} m)")
    };
    let p0 = env.pressure_pa(z_start);
    let (t0, td0) = (start.t_k, start.td_k);
    if !(t0.is_finite() && (173.15..=343.15).contains(&t0)) {
        return Err(Error::invalid(
            format!("{at} temperature (°C)"),
            t0 - 273.15,
            "between -100 and 70 °C",
        ));
    }
    if !(td0.is_finite() && td0 >= thermo::T_MIN_SATURATION_K && td0 <= t0 + 1e-9) {
        return Err(Error::invalid(
            format!("{at} dewpoint (°C)"),
            td0 - 273.15,
            format!(
                "a dewpoint from {:.2} °C up to the {at} temperature {:.2} °C",
                thermo::T_MIN_SATURATION_K - 273.15,
                t0 - 273.15
            ),
        ));
    }
    let qt = opts.thermo.mixing_ratio_from_dewpoint(td0, p0);
    let theta_s = thermo::potential_temperature_k(t0, p0);

    let loading = opts.condensate_loading;
    let record = |z: f64, t: f64, qv: f64, ql: f64| {
        let p = env.pressure_pa(z);
        let env_t = env.temperature_k(z);
        ParcelLevel {
            p_pa: p,
            z_m: z,
            t_k: t,
            tv_k: thermo::virtual_temperature_k(t, qv, if loading { ql } else { 0.0 }),
            env_t_k: env_t,
            env_tv_k: thermo::virtual_temperature_k(env_t, env.qv(z), 0.0),
            qv,
            ql,
            theta_k: t / thermo::exner(p),
        }
    };

    let mut parcel = Parcel {
        thermo: opts.thermo,
        alpha: opts.alpha,
        start: (t0, p0, theta_s, qt),
        t: t0,
        theta: theta_s,
        qv: qt,
        ql: 0.0,
        saturated: false,
    };
    let mut z = z_start;
    let mut lcl = parcel.saturation_height(env, z_start, z_start);
    parcel.saturated = lcl.is_some();
    let mut out = Vec::with_capacity(heights.len());
    let mut next = heights.partition_point(|&h| h < z_start);
    let first = record(z_start, t0, qt, 0.0);
    let mut prev_b = first.tv_k - first.env_tv_k;
    let mut layers: Vec<(f64, Option<f64>)> = Vec::new();
    // Crossings are only sought at or above the LCL: a superadiabatic surface
    // layer makes the dry parcel buoyant, but that is not free convection.
    let mut buoyant_above_lcl = lcl.is_some() && prev_b > 0.0;
    if buoyant_above_lcl {
        layers.push((z_start, None));
    }
    while next < heights.len() && heights[next] <= z_start {
        out.push(first);
        next += 1;
    }
    while z < top {
        let target = if next < heights.len() {
            heights[next].min(top)
        } else {
            top
        };
        let z1 = (z + MAX_STEP_M).min(target.max(z + 1e-9)).min(top);
        if let Some(zl) = parcel.advance(env, z, z1) {
            lcl.get_or_insert(zl);
        }
        let lvl = record(z1, parcel.t, parcel.qv, parcel.ql);
        let b = lvl.tv_k - lvl.env_tv_k;
        if let Some(zl) = lcl {
            // Linear interpolation of buoyancy within one ≤10 m step.
            let cross = || z + (z1 - z) * prev_b / (prev_b - b);
            if !buoyant_above_lcl && b > 0.0 {
                buoyant_above_lcl = true;
                let base = if prev_b < 0.0 {
                    cross().max(zl)
                } else {
                    zl.max(z)
                };
                layers.push((base, None));
            } else if buoyant_above_lcl && b <= 0.0 {
                buoyant_above_lcl = false;
                if let Some(layer) = layers.last_mut() {
                    layer.1 = Some(cross());
                }
            }
        }
        prev_b = b;
        z = z1;
        while next < heights.len() && heights[next] <= z + 1e-9 {
            out.push(lvl);
            next += 1;
        }
    }
    let mark = |z: f64| LevelMark {
        p_pa: env.pressure_pa(z),
        z_m: z,
    };
    let layers: Vec<BuoyantLayer> = layers
        .into_iter()
        .map(|(lfc, el)| BuoyantLayer {
            lfc: mark(lfc),
            el: el.map(mark),
        })
        .collect();
    Ok(ParcelAscent {
        lcl: lcl.map(mark),
        lfc: layers.first().map(|l| l.lfc),
        // A parcel still buoyant at the top has no equilibrium level in the data.
        el: layers.last().and_then(|l| l.el),
        layers,
        levels: out,
    })
}

/// A lifted parcel between steps.
struct Parcel {
    thermo: Thermo,
    /// Latent-heat factor of the model's saturation adjustment.
    alpha: f64,
    /// At the start: T (K), p (Pa), θ (K), total water (kg/kg).
    start: (f64, f64, f64, f64),
    /// Temperature. units: K
    t: f64,
    /// Potential temperature (the model's state variable). units: K
    theta: f64,
    /// Vapour and liquid mixing ratios. units: kg/kg
    qv: f64,
    ql: f64,
    /// Whether it has reached its LCL.
    saturated: bool,
}

impl Parcel {
    /// Height in [lo, hi] at which the parcel, lifted dry from its start,
    /// saturates (`Some(lo)` if it already is there, None if not by `hi`).
    fn saturation_height(&self, env: &Environment, lo: f64, hi: f64) -> Option<f64> {
        let (t0, p0, theta_s, qt) = self.start;
        match self.thermo {
            Thermo::Model => lcl_height_m(env, theta_s, qt, lo, hi),
            Thermo::Standard => {
                let excess = |z: f64| {
                    let p = env.pressure_pa(z);
                    standard::saturation_mixing_ratio(standard::dry_adiabat_k(t0, p0, p), p) - qt
                };
                if !(excess(lo) > 0.0) {
                    Some(lo)
                } else if excess(hi) > 0.0 {
                    None
                } else {
                    // 60 halvings: far below a millimetre.
                    Some(bisect(lo, hi, 60, excess))
                }
            }
        }
    }

    /// Lifts the parcel from `z` to `z1`; returns the LCL if it saturated
    /// on the way.
    fn advance(&mut self, env: &Environment, z: f64, z1: f64) -> Option<f64> {
        let p1 = env.pressure_pa(z1);
        match self.thermo {
            Thermo::Model => {
                let (theta_s, qt) = (self.start.2, self.start.3);
                let pi1 = thermo::exner(p1);
                let adj =
                    thermo::saturation_adjust(self.theta * pi1, self.qv, self.ql, p1, self.alpha);
                let lcl = (!self.saturated && adj.condensed > 0.0).then(|| {
                    // q_v = ωs along the dry adiabat somewhere between z and z1.
                    lcl_height_m(env, theta_s, qt, z, z1).unwrap_or(z1)
                });
                self.saturated |= lcl.is_some();
                self.theta = adj.t_k / pi1;
                (self.t, self.qv, self.ql) = (adj.t_k, adj.qv, adj.ql);
                lcl
            }
            Thermo::Standard => {
                let (t0, p0, _, _) = self.start;
                if self.saturated {
                    let p = env.pressure_pa(z);
                    self.t = standard::pseudo_adiabat_k(self.t, p, p1);
                    self.qv = standard::saturation_mixing_ratio(self.t, p1);
                    return None;
                }
                let lcl = self
                    .saturation_height(env, z1, z1)
                    .and_then(|_| self.saturation_height(env, z, z1));
                match lcl {
                    None => self.t = standard::dry_adiabat_k(t0, p0, p1),
                    Some(zl) => {
                        // Dry to the LCL, then along the pseudo-adiabat; the
                        // condensate falls out.
                        let pl = env.pressure_pa(zl);
                        let tl = standard::dry_adiabat_k(t0, p0, pl);
                        self.t = standard::pseudo_adiabat_k(tl, pl, p1);
                        self.qv = standard::saturation_mixing_ratio(self.t, p1);
                        self.saturated = true;
                    }
                }
                lcl
            }
        }
    }
}

/// Bisection for the root of a decreasing `excess` inside [lo, hi]
/// (positive at lo): `n` halvings.
fn bisect(lo: f64, hi: f64, n: u32, excess: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..n {
        let mid = 0.5 * (lo + hi);
        if excess(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Height at which air of liquid-water potential temperature `theta_l_k` and
/// total water `qt` becomes saturated when lifted through `env` (bisection on
/// ω_s(θ_l Π(P(z)), P(z)) = q_t, which decreases with height). 0 if it is
/// saturated at the ground, `z_max_m` if it never saturates below it. units: m
pub fn condensation_level_m(env: &Environment, theta_l_k: f64, qt: f64, z_max_m: f64) -> f64 {
    if !(saturation_excess(env, theta_l_k, qt, 0.0) > 0.0) {
        return 0.0;
    }
    if saturation_excess(env, theta_l_k, qt, z_max_m) > 0.0 {
        return z_max_m;
    }
    // 40 halvings of ≤ 100 km: below a millimetre.
    saturation_level_between(env, theta_l_k, qt, 0.0, z_max_m, 40)
}

/// ω_s − q_t of air with liquid-water potential temperature θ_l lifted to z.
pub fn saturation_excess(env: &Environment, theta_l_k: f64, qt: f64, z_m: f64) -> f64 {
    let (p, pi) = env.pressure_exner(z_m);
    thermo::saturation_mixing_ratio(theta_l_k * pi, p) - qt
}

/// Bisection for the saturation level inside [lo, hi] (unsaturated at lo):
/// `n` halvings of the bracket. The one LCL search of the crate: the
/// surface parcel's lifting and the physics' condensation planes use it.
pub fn saturation_level_between(
    env: &Environment,
    theta_l_k: f64,
    qt: f64,
    lo: f64,
    hi: f64,
    n: u32,
) -> f64 {
    bisect(lo, hi, n, |z| saturation_excess(env, theta_l_k, qt, z))
}
