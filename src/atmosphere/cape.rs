//! Convective available potential energy (CAPE) and convective inhibition
//! (CIN) of the three parcels forecasters lift, defined as MetPy 1.7.1's
//! `surface_based_cape_cin`, `mixed_layer_cape_cin` and
//! `most_unstable_cape_cin`:
//!
//! - surface-based (SB): the air at the ground;
//! - mixed-layer (ML): the pressure-weighted mean θ and q_v of the lowest
//!   [`MIXED_LAYER_DEPTH_PA`], started at the ground. The layer is taken as
//!   mixed, so within it the environment *is* the mixed parcel (MetPy replaces
//!   those levels the same way; SHARPpy keeps the observed layer and so
//!   reports more CIN);
//! - most-unstable (MU): the environment level of highest equivalent
//!   potential temperature θ_e in the lowest [`MOST_UNSTABLE_DEPTH_PA`],
//!   started there.
//!
//! Each is lifted with [`lifting::lift_from`] (the thermodynamics of
//! [`LiftOptions::thermo`]: the forecasters' standard for `cumulus parcel`,
//! the simulation's own for the window's curve) and compared in virtual
//! temperature, the vapour's correction included in both parcel and
//! environment, as MetPy's `cape_cin` does:
//!
//!   CAPE = R_d ∫_{EL}^{LFC} (T_v,parcel − T_v,env) d ln p, 0 if negative,
//!   CIN  = R_d ∫_{LFC}^{p_start} min(T_v,parcel − T_v,env, 0) d ln p.
//!
//! The LFC is the base of one of the parcel's buoyant layers, chosen by
//! [`LiftOptions::lfc`] with MetPy's `which_lfc` names: the lowest
//! (`bottom`, MetPy's `cape_cin` default), the highest (`top`) or, the
//! default here, the base of the layer with the most CAPE (`most_cape`).
//! With `bottom` and `top` the EL is the top of the highest buoyant layer
//! (MetPy's `which_el="top"`), or the top of the data for a parcel still
//! buoyant there; with `most_cape` it is the top of the same layer or of a
//! higher one, whichever pair encloses the largest net area (see
//! `choose_lfc_el`). CAPE is the *net* area from LFC to EL, as MetPy's: a
//! cap between two buoyant layers is never subtracted from the upper one
//! under `most_cape`, because that layer's own base is then the LFC. CIN is
//! all the *negative* area from the parcel's start to the LFC, the
//! forecasters' definition: a buoyant superadiabatic surface layer under a
//! cap does not cancel the cap (MetPy nets the two and clips at 0, so it
//! differs by that layer's positive area).
//!
//! The integrals are trapezoids over the ascent's own ≤ 10 m steps, cut at
//! the LFC and EL. Without an LFC both are 0.

use super::environment::{EnvLevel, Environment};
use super::lifting::{self, LevelMark, LfcChoice, LiftOptions, ParcelAscent, ParcelStart};
use super::thermo;
use crate::error::{Error, Result};

/// Depth of the mixed layer averaged into the ML parcel (MetPy's default). units: Pa
pub const MIXED_LAYER_DEPTH_PA: f64 = 10_000.0;
/// Depth searched for the most unstable parcel (MetPy's default). units: Pa
pub const MOST_UNSTABLE_DEPTH_PA: f64 = 30_000.0;

/// Which parcel is lifted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParcelKind {
    /// Surface-based.
    Surface,
    /// Mean of the lowest 100 hPa.
    MixedLayer,
    /// Highest θ_e of the lowest 300 hPa.
    MostUnstable,
}

impl ParcelKind {
    /// All three, in the order reports list them.
    pub const ALL: [ParcelKind; 3] = [
        ParcelKind::Surface,
        ParcelKind::MixedLayer,
        ParcelKind::MostUnstable,
    ];

    /// Short key: "sb", "ml" or "mu".
    pub fn key(self) -> &'static str {
        match self {
            ParcelKind::Surface => "sb",
            ParcelKind::MixedLayer => "ml",
            ParcelKind::MostUnstable => "mu",
        }
    }

    /// Name for reports.
    pub fn name(self) -> &'static str {
        match self {
            ParcelKind::Surface => "surface-based",
            ParcelKind::MixedLayer => "mixed-layer (lowest 100 hPa)",
            ParcelKind::MostUnstable => "most-unstable (lowest 300 hPa)",
        }
    }
}

/// A lifted parcel with its levels and energies.
#[derive(Debug, Clone, PartialEq)]
pub struct ParcelReport {
    pub kind: ParcelKind,
    /// Where it started.
    pub start: ParcelStart,
    /// Pressure at the start. units: Pa
    pub start_p_pa: f64,
    /// LCL, the buoyant layers and the parcel at every ≤ 10 m step from
    /// the start.
    pub ascent: ParcelAscent,
    /// The LFC the energies use (chosen by [`LiftOptions::lfc`]); None if
    /// the parcel is never buoyant above its LCL.
    pub lfc: Option<LevelMark>,
    /// The EL the energies use; None without an LFC or if the parcel is
    /// still buoyant at the top.
    pub el: Option<LevelMark>,
    /// units: J/kg (≥ 0)
    pub cape_j_per_kg: f64,
    /// units: J/kg (≤ 0)
    pub cin_j_per_kg: f64,
}

/// Lifts the parcel `kind` of `env` and integrates its CAPE and CIN.
/// `opts.surface_t_k`/`surface_td_k` change only the surface-based parcel.
pub fn parcel_report(
    env: &Environment,
    kind: ParcelKind,
    opts: &LiftOptions,
) -> Result<ParcelReport> {
    let (start, env_used) = match kind {
        ParcelKind::Surface => (ParcelStart::surface(env, opts), None),
        ParcelKind::MixedLayer => {
            let (start, mixed_env) = mixed_layer(env)?;
            (start, Some(mixed_env))
        }
        ParcelKind::MostUnstable => (most_unstable_start(env), None),
    };
    let env = env_used.as_ref().unwrap_or(env);
    let top = env.top_m();
    let n = ((top - start.z_m) / lifting::MAX_STEP_M).ceil() as usize;
    let heights: Vec<f64> = (0..=n)
        .map(|i| (start.z_m + i as f64 * lifting::MAX_STEP_M).min(top))
        .collect();
    let ascent = lifting::lift_from(env, opts, &start, &heights)?;
    let chosen = choose_lfc_el(&ascent, opts.lfc, top);
    let (cape, cin) = match chosen {
        None => (0.0, 0.0),
        Some((lfc, el)) => (
            buoyancy_integral(&ascent, lfc.z_m, el.map_or(top, |m| m.z_m), Area::Net).max(0.0),
            buoyancy_integral(&ascent, start.z_m, lfc.z_m, Area::Negative),
        ),
    };
    Ok(ParcelReport {
        kind,
        start,
        start_p_pa: env.pressure_pa(start.z_m),
        lfc: chosen.map(|c| c.0),
        el: chosen.and_then(|c| c.1),
        ascent,
        cape_j_per_kg: cape,
        cin_j_per_kg: cin,
    })
}

/// The LFC and EL `choice` picks among the ascent's buoyant layers (the EL
/// None where the parcel is still buoyant at the top). `bottom` and `top`
/// take the lowest or highest layer's base with the highest layer's top
/// (MetPy's `which_el="top"`); `most_cape` the base of one layer and the
/// top of the same or a higher one whose net area between is largest (the
/// lowest on ties). Letting the EL be chosen too keeps a layer cut off at
/// the top of the data above a cap from lowering CAPE: with the EL fixed at
/// the top, a moister surface that makes that thin layer buoyant would move
/// the LFC above the cap and cut CAPE from the layer below it to the thin
/// one's.
fn choose_lfc_el(
    a: &ParcelAscent,
    choice: LfcChoice,
    top: f64,
) -> Option<(LevelMark, Option<LevelMark>)> {
    let (first, last) = (a.layers.first()?, a.layers.last()?);
    match choice {
        LfcChoice::Bottom => Some((first.lfc, last.el)),
        LfcChoice::Top => Some((last.lfc, last.el)),
        LfcChoice::MostCape => {
            let mut best: Option<(f64, (LevelMark, Option<LevelMark>))> = None;
            for (i, base) in a.layers.iter().enumerate() {
                for upper in &a.layers[i..] {
                    let el = upper.el.map_or(top, |m| m.z_m);
                    let cape = buoyancy_integral(a, base.lfc.z_m, el, Area::Net);
                    if best.is_none_or(|(b, _)| cape > b) {
                        best = Some((cape, (base.lfc, upper.el)));
                    }
                }
            }
            best.map(|(_, pair)| pair)
        }
    }
}

/// Which part of the area between the parcel and environment curves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Area {
    /// Positive and negative parts summed.
    Net,
    /// Only where the parcel is colder (CIN).
    Negative,
}

/// R_d ∫ (T_v,parcel − T_v,env) d(−ln p) over heights [z_lo, z_hi]:
/// trapezoids over the recorded steps, the end segments cut by linear
/// interpolation in z; with [`Area::Negative`] just the area where the
/// parcel is colder (the buoyancy linear within each step). units: J/kg
fn buoyancy_integral(a: &ParcelAscent, z_lo: f64, z_hi: f64, area: Area) -> f64 {
    let mut sum = 0.0;
    for w in a.levels.windows(2) {
        let (l0, l1) = (&w[0], &w[1]);
        let (za, zb) = (l0.z_m.max(z_lo), l1.z_m.min(z_hi));
        if zb <= za || l1.z_m <= l0.z_m {
            continue;
        }
        let at = |z: f64| {
            let f = (z - l0.z_m) / (l1.z_m - l0.z_m);
            let b0 = l0.tv_k - l0.env_tv_k;
            let b1 = l1.tv_k - l1.env_tv_k;
            let lnp = l0.p_pa.ln() + (l1.p_pa.ln() - l0.p_pa.ln()) * f;
            (b0 + (b1 - b0) * f, lnp)
        };
        let ((ba, xa), (bb, xb)) = (at(za), at(zb));
        sum += if area == Area::Net || (ba <= 0.0 && bb <= 0.0) {
            0.5 * (ba + bb) * (xa - xb)
        } else if ba >= 0.0 && bb >= 0.0 {
            0.0
        } else {
            // The negative triangle of a step that changes sign.
            let neg = ba.min(bb);
            -(0.5 * neg * neg / (ba - bb).abs() * (xa - xb))
        };
    }
    thermo::R_DRY * sum
}

/// The mixed-layer parcel (pressure-weighted means of θ and q_v over the
/// lowest [`MIXED_LAYER_DEPTH_PA`], by trapezoids over the environment's
/// levels and the interpolated layer top, as MetPy's `mixed_layer`) and the
/// environment with that layer replaced by the parcel.
fn mixed_layer(env: &Environment) -> Result<(ParcelStart, Environment)> {
    let ps = env.surface_pressure_pa();
    let p_top = ps - MIXED_LAYER_DEPTH_PA;
    let Some(z_top) = env.height_at_pressure_m(p_top) else {
        return Err(Error::invalid(
            "atmosphere depth for the mixed-layer parcel (hPa)",
            (ps - env.pressure_pa(env.top_m())) / 100.0,
            "a profile at least 100 hPa deep",
        ));
    };
    let mut zs: Vec<f64> = env
        .levels()
        .iter()
        .map(|l| l.z_m)
        .filter(|&z| z < z_top)
        .collect();
    zs.push(z_top);
    let (mut theta_sum, mut qv_sum) = (0.0, 0.0);
    for w in zs.windows(2) {
        let dp = env.pressure_pa(w[0]) - env.pressure_pa(w[1]);
        theta_sum += 0.5 * (env.theta_k(w[0]) + env.theta_k(w[1])) * dp;
        qv_sum += 0.5 * (env.qv(w[0]) + env.qv(w[1])) * dp;
    }
    let dp_total = ps - env.pressure_pa(z_top);
    let (theta, qv) = (theta_sum / dp_total, qv_sum / dp_total);
    let t_k = thermo::temperature_from_theta_k(theta, ps);
    let start = ParcelStart {
        z_m: 0.0,
        t_k,
        td_k: thermo::dewpoint_from_mixing_ratio_k(qv, ps).min(t_k),
    };
    // Levels strictly above the layer top stay; the ground level becomes the
    // mixed parcel, so the environment runs from it straight to them.
    let mut levels = vec![EnvLevel {
        z_m: 0.0,
        theta_k: theta,
        qv_kg_per_kg: qv,
        pressure_pa: Some(ps),
    }];
    // Strictly above by pressure, as MetPy (`pressure < p_start − depth`):
    // a level exactly at the layer top belongs to the layer, and the
    // bisected z_top can fall a rounding error below it. 1e-9 relative is
    // far above that error and far below any two distinct levels.
    levels.extend(
        env.levels()
            .iter()
            .copied()
            .filter(|l| env.pressure_pa(l.z_m) < p_top * (1.0 - 1e-9)),
    );
    if levels.len() < 2 {
        levels.push(EnvLevel {
            z_m: env.top_m(),
            ..*env.levels().last().expect("an environment has ≥ 2 levels")
        });
    }
    let mixed = Environment::new(levels, ps, env.pressure_model())?
        .with_thermo(env.thermo())
        .with_humidity_top(env.humidity_top_m());
    Ok((start, mixed))
}

/// The environment level of highest θ_e within the lowest
/// [`MOST_UNSTABLE_DEPTH_PA`] (the lowest such level on ties, as numpy's
/// `argmax`), among levels with a measured humidity.
fn most_unstable_start(env: &Environment) -> ParcelStart {
    let p_min = env.surface_pressure_pa() - MOST_UNSTABLE_DEPTH_PA;
    let mut best = (f64::NEG_INFINITY, 0.0);
    for l in env.levels() {
        let p = env.pressure_pa(l.z_m);
        if p < p_min || l.z_m >= env.top_m() || env.humidity_top_m().is_some_and(|z| l.z_m > z) {
            break;
        }
        let theta_e = thermo::equivalent_potential_temperature_k(
            env.temperature_k(l.z_m),
            env.dewpoint_k(l.z_m),
            p,
        );
        if theta_e > best.0 {
            best = (theta_e, l.z_m);
        }
    }
    let z = best.1;
    ParcelStart {
        z_m: z,
        t_k: env.temperature_k(z),
        td_k: env.dewpoint_k(z).min(env.temperature_k(z)),
    }
}
