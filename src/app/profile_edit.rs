//! The profile editor's state and every edit the panel can make (paper §7.2:
//! "alter the temperature profile graphically, select condensation level,
//! choose mixing ratio"). The panel only calls these functions, and so do the
//! tests, so what the tests check is what the user gets.
//!
//! The editor owns the atmosphere as inline points (height, temperature,
//! dewpoint). After every successful edit it rebuilds the implicit
//! [`Environment`] and the lifted surface parcel's curve (LCL, LFC, EL); the
//! window hands the new environment to the running simulation at once. An
//! edit that would give an invalid profile is refused with an error and
//! leaves the editor unchanged.

use crate::atmosphere::{Environment, thermo};
use crate::error::{Error, Result};

/// 0 °C in kelvin.
const ZERO_C_K: f64 = 273.15;
/// Closest two levels may come while dragging, so heights stay strictly
/// increasing. units: m
pub const MIN_LEVEL_SPACING_M: f64 = 10.0;
/// Height step of the drawn parcel curve. Fine enough that the kink at the
/// LCL shows; LCL/LFC/EL themselves are found by bisection, not on this grid.
/// units: m
const CURVE_DZ_M: f64 = 50.0;
/// Most points the editor samples from a sounding: more are hard to grab.
pub const MAX_SAMPLED_POINTS: usize = 16;

/// One editable level of the environment profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfilePoint {
    /// Height above the ground. units: m
    pub z_m: f64,
    /// Air temperature. units: °C
    pub t_c: f64,
    /// Dewpoint, never above the temperature. units: °C
    pub td_c: f64,
}

/// Which curve of the diagram a dragged point belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ProfileCurve {
    Temperature,
    Dewpoint,
}

/// One height of the lifted surface parcel's curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// units: m
    pub z_m: f64,
    /// Parcel temperature. units: K
    pub t_k: f64,
    /// Parcel virtual temperature (condensate loading included). units: K
    pub tv_k: f64,
    /// Environment virtual temperature at the same height. units: K
    pub env_tv_k: f64,
}

/// The surface parcel lifted through the environment conserving θ and total
/// water, with `thermo::saturation_adjust` (α = 1) at every height: the same
/// thermodynamics the simulation uses.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParcelCurve {
    pub points: Vec<CurvePoint>,
    /// Lifting condensation level: where the parcel's vapour first equals ωs.
    /// units: m
    pub lcl_m: Option<f64>,
    /// Level of free convection: lowest height above which the parcel is
    /// warmer (in T_v) than the environment. units: m
    pub lfc_m: Option<f64>,
    /// Equilibrium level: top of the positively buoyant layer above the LFC.
    /// units: m
    pub el_m: Option<f64>,
}

/// The editor's state: the points, the environment they build and the
/// lifted parcel's curve. Fields are private so that every change goes
/// through the edit functions below, which keep the three consistent.
#[derive(Debug, Clone)]
pub struct ProfileEditor {
    points: Vec<ProfilePoint>,
    surface_pressure_pa: f64,
    env: Environment,
    curve: ParcelCurve,
    /// Bumped by every successful edit: the window compares it to push the
    /// environment to the simulation once per change.
    revision: u64,
}

impl ProfileEditor {
    /// An editor on explicit points (lowest first, the first at z = 0).
    pub fn new(points: Vec<ProfilePoint>, surface_pressure_pa: f64) -> Result<Self> {
        let env = build_environment(&points, surface_pressure_pa)?;
        let curve = parcel_curve(&env);
        Ok(Self {
            points,
            surface_pressure_pa,
            env,
            curve,
            revision: 0,
        })
    }

    /// An editor on an environment (a sounding or a scene's profile): its
    /// levels become points, thinned to at most [`MAX_SAMPLED_POINTS`] so
    /// each stays easy to grab.
    pub fn from_environment(env: &Environment) -> Result<Self> {
        let levels = env.levels();
        let n = levels.len();
        let keep: Vec<usize> = if n <= MAX_SAMPLED_POINTS {
            (0..n).collect()
        } else {
            let mut idx: Vec<usize> = (0..MAX_SAMPLED_POINTS)
                .map(|i| i * (n - 1) / (MAX_SAMPLED_POINTS - 1))
                .collect();
            idx.dedup();
            idx
        };
        let points = keep
            .into_iter()
            .map(|i| {
                let z = levels[i].z_m;
                let t = env.temperature_k(z);
                ProfilePoint {
                    z_m: z,
                    t_c: t - ZERO_C_K,
                    td_c: env.dewpoint_k(z).min(t) - ZERO_C_K,
                }
            })
            .collect();
        Self::new(points, env.surface_pressure_pa())
    }

    /// The points, lowest first.
    pub fn points(&self) -> &[ProfilePoint] {
        &self.points
    }

    /// The environment built from the points.
    pub fn environment(&self) -> &Environment {
        &self.env
    }

    /// The lifted surface parcel's curve.
    pub fn curve(&self) -> &ParcelCurve {
        &self.curve
    }

    /// Pressure at the ground. units: Pa
    pub fn surface_pressure_pa(&self) -> f64 {
        self.surface_pressure_pa
    }

    /// Counts successful edits.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Vapour mixing ratio at the surface. units: kg/kg
    pub fn surface_mixing_ratio(&self) -> f64 {
        self.env.qv(0.0)
    }

    /// Replaces the points if they build a valid environment; otherwise
    /// returns the error and changes nothing.
    fn commit(&mut self, points: Vec<ProfilePoint>) -> Result<()> {
        let env = build_environment(&points, self.surface_pressure_pa)?;
        self.curve = parcel_curve(&env);
        self.env = env;
        self.points = points;
        self.revision += 1;
        Ok(())
    }
}

fn check_index(points: &[ProfilePoint], index: usize) -> Result<()> {
    if index >= points.len() {
        return Err(Error::invalid(
            "profile point",
            index,
            format!("an index below {}", points.len()),
        ));
    }
    Ok(())
}

/// Moves point `index` of `curve` to height `z_m` and temperature `value_c`
/// (what dragging it on the diagram does). The surface point stays at
/// z = 0; other points stay between their neighbours (at least
/// [`MIN_LEVEL_SPACING_M`] apart). A dewpoint cannot exceed its temperature
/// and a temperature cannot drop below its dewpoint: the value is clamped
/// there, as a drag would stop at the other curve.
pub fn move_point(
    ed: &mut ProfileEditor,
    curve: ProfileCurve,
    index: usize,
    z_m: f64,
    value_c: f64,
) -> Result<()> {
    check_index(&ed.points, index)?;
    if !(z_m.is_finite() && value_c.is_finite()) {
        return Err(Error::invalid(
            "profile point",
            format!("z = {z_m} m, {value_c} °C"),
            "finite height and temperature",
        ));
    }
    let mut points = ed.points.clone();
    let z = if index == 0 {
        0.0
    } else {
        let lo = points[index - 1].z_m + MIN_LEVEL_SPACING_M;
        let hi = points
            .get(index + 1)
            .map(|p| p.z_m - MIN_LEVEL_SPACING_M)
            .unwrap_or(f64::INFINITY);
        z_m.clamp(lo, hi.max(lo))
    };
    let p = &mut points[index];
    p.z_m = z;
    match curve {
        ProfileCurve::Temperature => p.t_c = value_c.max(p.td_c),
        ProfileCurve::Dewpoint => p.td_c = value_c.min(p.t_c),
    }
    ed.commit(points)
}

/// Adds a level at height `z_m` with temperature and dewpoint interpolated
/// from the current profile (so the environment does not change until the
/// new point is dragged). Returns the new point's index.
pub fn add_point(ed: &mut ProfileEditor, z_m: f64) -> Result<usize> {
    let top = ed.points.last().map(|p| p.z_m).unwrap_or(0.0);
    if !(z_m.is_finite() && z_m > 0.0) {
        return Err(Error::invalid(
            "new profile point height (m)",
            z_m,
            "above the ground (z > 0)",
        ));
    }
    let mut points = ed.points.clone();
    let index = points.partition_point(|p| p.z_m < z_m);
    let too_close = |i: usize| {
        points
            .get(i)
            .is_some_and(|p| (p.z_m - z_m).abs() < MIN_LEVEL_SPACING_M)
    };
    if too_close(index) || (index > 0 && too_close(index - 1)) {
        return Err(Error::invalid(
            "new profile point height (m)",
            z_m,
            format!("at least {MIN_LEVEL_SPACING_M} m from existing points"),
        ));
    }
    let (t_c, td_c) = if z_m <= top {
        let t = ed.env.temperature_k(z_m) - ZERO_C_K;
        (t, (ed.env.dewpoint_k(z_m) - ZERO_C_K).min(t))
    } else {
        // Above the top: extend the top segment's lapse rates.
        let n = points.len();
        let (a, b) = (points[n - 2], points[n - 1]);
        let w = (z_m - b.z_m) / (b.z_m - a.z_m);
        let t = b.t_c + (b.t_c - a.t_c) * w;
        (t, (b.td_c + (b.td_c - a.td_c) * w).min(t))
    };
    points.insert(index, ProfilePoint { z_m, t_c, td_c });
    ed.commit(points)?;
    Ok(index)
}

/// Removes level `index`. The surface level stays, and a profile keeps at
/// least two levels.
pub fn remove_point(ed: &mut ProfileEditor, index: usize) -> Result<()> {
    check_index(&ed.points, index)?;
    if index == 0 {
        return Err(Error::invalid(
            "profile point to remove",
            0,
            "any level but the surface (index 0)",
        ));
    }
    if ed.points.len() <= 2 {
        return Err(Error::invalid(
            "profile point to remove",
            index,
            "nothing: a profile needs at least 2 levels",
        ));
    }
    let mut points = ed.points.clone();
    points.remove(index);
    ed.commit(points)
}

/// Sets the surface vapour mixing ratio by moving the surface dewpoint.
/// units: kg/kg. It must be positive and at most saturation at the surface.
pub fn set_surface_mixing_ratio(ed: &mut ProfileEditor, qv_kg_per_kg: f64) -> Result<()> {
    let p = ed.surface_pressure_pa;
    let t_k = ed.points[0].t_c + ZERO_C_K;
    let qs = thermo::saturation_mixing_ratio(t_k, p);
    if !(qv_kg_per_kg.is_finite() && qv_kg_per_kg > 0.0 && qv_kg_per_kg <= qs * (1.0 + 1e-9)) {
        return Err(Error::invalid(
            "surface mixing ratio (g/kg)",
            qv_kg_per_kg * 1000.0,
            format!(
                "above 0 and at most saturation at the surface temperature, {:.2} g/kg",
                qs * 1000.0
            ),
        ));
    }
    let td_c = thermo::dewpoint_from_mixing_ratio_k(qv_kg_per_kg, p) - ZERO_C_K;
    let mut points = ed.points.clone();
    points[0].td_c = td_c.min(points[0].t_c);
    ed.commit(points)
}

/// Sets the condensation level (paper §7.2): moves the surface dewpoint so
/// that the lifted surface parcel saturates at `z_m`. The surface θ stays;
/// the parcel keeps its mixing ratio q while rising dry-adiabatically, so it
/// saturates where q = ωs(θ_s Π(P(z)), P(z)): that q becomes the surface
/// mixing ratio. P(z) itself depends slightly on the humidity (virtual
/// temperature in the hydrostatic pressure), so this is iterated; three
/// rounds settle it far below a metre.
pub fn set_condensation_level(ed: &mut ProfileEditor, z_m: f64) -> Result<()> {
    let top = ed.points.last().map(|p| p.z_m).unwrap_or(0.0);
    if !(z_m.is_finite() && z_m > 0.0 && z_m < top) {
        return Err(Error::invalid(
            "condensation level (m)",
            z_m,
            format!("above the ground and below the profile top, {top} m"),
        ));
    }
    let mut trial = ed.clone();
    for _ in 0..3 {
        let env = trial.environment();
        let theta_s = env.theta_k(0.0);
        let p = env.pressure_pa(z_m);
        let q = thermo::saturation_mixing_ratio(thermo::temperature_from_theta_k(theta_s, p), p);
        let t_k = trial.points[0].t_c + ZERO_C_K;
        let q = q.min(thermo::saturation_mixing_ratio(
            t_k,
            trial.surface_pressure_pa,
        ));
        set_surface_mixing_ratio(&mut trial, q)?;
    }
    let points = trial.points;
    ed.commit(points)
}

/// Builds the implicit environment from points: T/Td → θ/q_v needs the
/// pressure, so it is integrated upward level by level with the hypsometric
/// equation over each layer's mean virtual temperature. The environment then
/// integrates its own hydrostatic pressure from the same surface pressure.
pub fn build_environment(points: &[ProfilePoint], surface_pressure_pa: f64) -> Result<Environment> {
    use crate::atmosphere::{EnvLevel, PressureModel};
    for (i, p) in points.iter().enumerate() {
        if p.td_c > p.t_c + 1e-9 {
            return Err(Error::invalid(
                format!("profile point {} dewpoint (°C)", i + 1),
                p.td_c,
                format!("at most the temperature, {} °C", p.t_c),
            ));
        }
    }
    let mut levels = Vec::with_capacity(points.len());
    let mut p_pa = surface_pressure_pa;
    let mut prev: Option<(f64, f64)> = None; // (z, Tv)
    for pt in points {
        let t_k = pt.t_c + ZERO_C_K;
        // Vapour barely changes the layer's virtual temperature, so two
        // rounds (the first without it) settle the pressure.
        let mut p_here = p_pa;
        let mut qv = 0.0;
        for _ in 0..2 {
            if let Some((z0, tv0)) = prev {
                let tv = thermo::virtual_temperature_k(t_k, qv, 0.0);
                let tv_mean = 0.5 * (tv0 + tv);
                p_here =
                    p_pa * (-thermo::GRAVITY * (pt.z_m - z0) / (thermo::R_DRY * tv_mean)).exp();
            }
            qv = thermo::mixing_ratio_from_dewpoint(pt.td_c + ZERO_C_K, p_here);
        }
        levels.push(EnvLevel {
            z_m: pt.z_m,
            theta_k: thermo::potential_temperature_k(t_k, p_here),
            qv_kg_per_kg: qv,
            pressure_pa: None,
        });
        prev = Some((pt.z_m, thermo::virtual_temperature_k(t_k, qv, 0.0)));
        p_pa = p_here;
    }
    Environment::new(levels, surface_pressure_pa, PressureModel::Hydrostatic)
}

/// Lifts the surface parcel through `env` (θ and total water conserved,
/// saturation adjustment at α = 1) and finds its LCL, LFC and EL.
pub fn parcel_curve(env: &Environment) -> ParcelCurve {
    let theta = env.theta_k(0.0);
    let qt = env.qv(0.0);
    let parcel_at = |z: f64| {
        let p = env.pressure_pa(z);
        let t = thermo::temperature_from_theta_k(theta, p);
        let a = thermo::saturation_adjust(t, qt, 0.0, p, 1.0);
        let tv = thermo::virtual_temperature_k(a.t_k, a.qv, a.ql);
        let env_tv = thermo::virtual_temperature_k(env.temperature_k(z), env.qv(z), 0.0);
        CurvePoint {
            z_m: z,
            t_k: a.t_k,
            tv_k: tv,
            env_tv_k: env_tv,
        }
    };
    let top = env.top_m();
    let n = (top / CURVE_DZ_M).ceil().max(1.0) as usize;
    let points: Vec<CurvePoint> = (0..=n)
        .map(|i| parcel_at((i as f64 * CURVE_DZ_M).min(top)))
        .collect();

    let bisect = |mut lo: f64, mut hi: f64, f: &dyn Fn(f64) -> bool| {
        // f(lo) is false, f(hi) true; 40 halvings of ≤ 50 m is far below 1 mm.
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if f(mid) { hi = mid } else { lo = mid }
        }
        0.5 * (lo + hi)
    };
    let saturated = |z: f64| {
        let p = env.pressure_pa(z);
        qt >= thermo::saturation_mixing_ratio(thermo::temperature_from_theta_k(theta, p), p)
    };
    let buoyant = |z: f64| {
        let c = parcel_at(z);
        c.tv_k > c.env_tv_k
    };

    let mut lcl = None;
    for w in points.windows(2) {
        if saturated(w[1].z_m) && !saturated(w[0].z_m) {
            lcl = Some(bisect(w[0].z_m, w[1].z_m, &saturated));
            break;
        }
    }
    if lcl.is_none() && saturated(0.0) {
        lcl = Some(0.0);
    }
    // LFC: first rise into positive buoyancy at or above the LCL; EL: the
    // next fall out of it (the parcel stops accelerating upward there).
    let (mut lfc, mut el) = (None, None);
    if let Some(l) = lcl {
        for w in points.windows(2).filter(|w| w[1].z_m >= l) {
            let (b0, b1) = (w[0].tv_k > w[0].env_tv_k, w[1].tv_k > w[1].env_tv_k);
            if lfc.is_none() {
                if b1 && !b0 {
                    lfc = Some(bisect(w[0].z_m, w[1].z_m, &buoyant).max(l));
                } else if b0 && b1 && w[0].z_m <= l {
                    lfc = Some(l);
                }
            } else if b0 && !b1 {
                el = Some(bisect(w[0].z_m, w[1].z_m, &|z| !buoyant(z)));
                break;
            }
        }
    }
    ParcelCurve {
        points,
        lcl_m: lcl,
        lfc_m: lfc,
        el_m: el,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fair() -> ProfileEditor {
        let pt = |z_m, t_c, td_c| ProfilePoint { z_m, t_c, td_c };
        ProfileEditor::new(
            vec![
                pt(0.0, 25.0, 16.0),
                pt(1500.0, 10.0, 8.0),
                pt(1800.0, 12.0, -5.0),
                pt(8000.0, -30.0, -45.0),
            ],
            100_000.0,
        )
        .unwrap()
    }

    #[test]
    fn refused_edits_leave_the_editor_unchanged() {
        let mut ed = fair();
        let before = ed.points().to_vec();
        assert!(remove_point(&mut ed, 0).is_err());
        assert!(add_point(&mut ed, 1500.0 + 1.0).is_err());
        assert!(set_condensation_level(&mut ed, -5.0).is_err());
        assert_eq!(ed.points(), &before[..]);
        assert_eq!(ed.revision(), 0);
    }

    #[test]
    fn dragging_keeps_order_and_dewpoint_below_temperature() {
        let mut ed = fair();
        move_point(&mut ed, ProfileCurve::Temperature, 1, 5000.0, -50.0).unwrap();
        let p = ed.points()[1];
        assert_eq!(p.z_m, 1800.0 - MIN_LEVEL_SPACING_M);
        assert_eq!(p.t_c, p.td_c);
        move_point(&mut ed, ProfileCurve::Dewpoint, 0, 300.0, 40.0).unwrap();
        assert_eq!(ed.points()[0].z_m, 0.0);
        assert_eq!(ed.points()[0].td_c, ed.points()[0].t_c);
    }
}
