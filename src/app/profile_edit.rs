//! The profile editor's state and every edit the panel can make (paper §7.2:
//! "alter the temperature profile graphically, select condensation level,
//! choose mixing ratio"). The panel only calls these functions, and so do the
//! tests, so what the tests check is what the user gets.
//!
//! The editor owns the `[atmosphere]` table as inline points (height,
//! temperature, dewpoint). After every successful edit it rebuilds the
//! implicit [`Environment`] with `AtmosphereSpec::build` and lifts the surface
//! parcel with `atmosphere::lifting` (the code behind `cumulus parcel`), so
//! the diagram, the CLI and the simulation agree; the window hands the new
//! environment to the running simulation at once. An
//! edit that would give an invalid profile is refused with an error and
//! leaves the editor unchanged.

use std::path::Path;

use crate::atmosphere::cape::{self, ParcelKind};
use crate::atmosphere::lifting::{self, LiftOptions, ParcelAscent};
use crate::atmosphere::thermo::Thermo;
use crate::atmosphere::{AtmospherePoint, AtmosphereSpec, Environment, WindProfile, thermo};
use crate::error::{Error, Result};

/// 0 °C in kelvin.
const ZERO_C_K: f64 = 273.15;
/// Closest two levels may come while dragging, so heights stay strictly
/// increasing. units: m
pub const MIN_LEVEL_SPACING_M: f64 = 10.0;
/// Height spacing of the drawn parcel curve. Fine enough that the kink at
/// the LCL shows; LCL/LFC/EL themselves are found by bisection in
/// `atmosphere::lifting`, not on this grid. units: m
const CURVE_DZ_M: f64 = 50.0;
/// Points the editor samples from a sounding: enough for the boundary layer
/// and the inversion, few enough to grab each one.
pub const SOUNDING_POINTS: usize = 20;
/// Sampled dewpoints and temperatures are kept above the profile's lower
/// bound (−100 °C): the driest sounding levels have a dewpoint of "no
/// vapour" far below it, which would make the whole profile invalid. units: °C
const MIN_SAMPLED_C: f64 = -99.0;

/// Which curve of the diagram a dragged point belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ProfileCurve {
    Temperature,
    Dewpoint,
}

/// The editor's state: the atmosphere as inline points (every point with a
/// dewpoint), the environment they build and the lifted surface parcel.
/// Fields are private so that every change goes through the edit functions
/// below, which keep the three consistent.
#[derive(Debug, Clone)]
pub struct ProfileEditor {
    spec: AtmosphereSpec,
    env: Environment,
    /// How the surface parcel is lifted (α, condensate loading): set to the
    /// simulation's physics so the diagram shows what the parcels feel.
    lift: LiftOptions,
    curve: ParcelAscent,
    /// CAPE and CIN of the surface-based, mixed-layer and most-unstable
    /// parcels (as `cumulus parcel`, in `ParcelKind::ALL` order),
    /// recomputed with every edit. units: J/kg
    energies: [(f64, f64); 3],
    /// The source's wind profile (a sounding's DRCT/SKNT), kept through
    /// edits: the points edit temperature and humidity only.
    wind: Option<WindProfile>,
    /// Bumped by every successful edit: the window compares it to push the
    /// environment to the simulation once per change.
    revision: u64,
}

/// Dewpoint of an editor point (the editor gives every point one). units: °C
pub fn dewpoint_c(p: &AtmospherePoint) -> f64 {
    p.td_c.unwrap_or(p.t_c)
}

impl ProfileEditor {
    /// An editor on a scene's `[atmosphere]`: inline points are kept (those
    /// given by relative humidity get the equivalent dewpoint); a sounding is
    /// sampled into [`SOUNDING_POINTS`] points, with hydrostatic pressure.
    pub fn from_spec(spec: &AtmosphereSpec, base_dir: &Path) -> Result<Self> {
        Self::from_environment(spec, spec.build(base_dir)?)
    }

    /// [`ProfileEditor::from_spec`] on `spec`'s environment, built already
    /// (`SceneProfile::build_atmosphere`).
    pub fn from_environment(spec: &AtmosphereSpec, env: Environment) -> Result<Self> {
        let mut spec = if spec.sounding.is_some() {
            AtmosphereSpec::inline_points_from(&env, SOUNDING_POINTS)
        } else {
            let mut s = spec.clone();
            for p in &mut s.points {
                if p.td_c.is_none() {
                    p.td_c = Some(env.dewpoint_k(p.z_m) - ZERO_C_K);
                    p.rh_percent = None;
                }
            }
            s
        };
        for p in &mut spec.points {
            p.t_c = p.t_c.max(MIN_SAMPLED_C);
            p.td_c = Some(dewpoint_c(p).clamp(MIN_SAMPLED_C, p.t_c));
        }
        let mut ed = Self::new(spec)?;
        ed.wind = env.wind().cloned();
        ed.env = ed.env.with_wind(ed.wind.clone());
        Ok(ed)
    }

    /// An editor on inline points, each with `td_c`.
    pub fn new(spec: AtmosphereSpec) -> Result<Self> {
        if spec.sounding.is_some() || spec.points.iter().any(|p| p.td_c.is_none()) {
            return Err(Error::invalid(
                "profile editor atmosphere",
                "a sounding or points without td_c",
                "inline points with a dewpoint each (use ProfileEditor::from_spec)",
            ));
        }
        let lift = LiftOptions::default();
        let (env, curve, energies) = build(&spec, &lift, None)?;
        Ok(Self {
            spec,
            env,
            lift,
            curve,
            energies,
            wind: None,
            revision: 0,
        })
    }

    /// Lifts the parcel with these options from now on (the simulation's
    /// latent-heat factor and condensate loading).
    pub fn set_lift_options(&mut self, lift: LiftOptions) -> Result<()> {
        self.curve = lift_curve(&self.env, &lift)?;
        self.energies = parcel_energies(&self.env, &lift)?;
        self.lift = lift;
        Ok(())
    }

    /// The points, lowest first.
    pub fn points(&self) -> &[AtmospherePoint] {
        &self.spec.points
    }

    /// The edited `[atmosphere]` table (what "save" writes).
    pub fn spec(&self) -> &AtmosphereSpec {
        &self.spec
    }

    /// The environment built from the points.
    pub fn environment(&self) -> &Environment {
        &self.env
    }

    /// The lifted surface parcel: its curve and LCL, LFC, EL.
    pub fn curve(&self) -> &ParcelAscent {
        &self.curve
    }

    /// CAPE (≥ 0) and CIN (≤ 0) of the surface-based parcel. units: J/kg
    pub fn cape_cin_j_per_kg(&self) -> (f64, f64) {
        self.energies[0]
    }

    /// CAPE (≥ 0) and CIN (≤ 0) of each parcel: surface-based, mixed-layer
    /// and most-unstable (`ParcelKind::ALL`). units: J/kg
    pub fn parcel_energies(&self) -> [(ParcelKind, f64, f64); 3] {
        let e = &self.energies;
        let k = ParcelKind::ALL;
        [
            (k[0], e[0].0, e[0].1),
            (k[1], e[1].0, e[1].1),
            (k[2], e[2].0, e[2].1),
        ]
    }

    /// Lifting condensation level. units: m
    pub fn lcl_m(&self) -> Option<f64> {
        self.curve.lcl.map(|l| l.z_m)
    }

    /// Level of free convection. units: m
    pub fn lfc_m(&self) -> Option<f64> {
        self.curve.lfc.map(|l| l.z_m)
    }

    /// Equilibrium level. units: m
    pub fn el_m(&self) -> Option<f64> {
        self.curve.el.map(|l| l.z_m)
    }

    /// Pressure at the ground. units: Pa
    pub fn surface_pressure_pa(&self) -> f64 {
        self.env.surface_pressure_pa()
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
    fn commit(&mut self, points: Vec<AtmospherePoint>) -> Result<()> {
        let spec = AtmosphereSpec {
            points,
            ..self.spec.clone()
        };
        let (env, curve, energies) = build(&spec, &self.lift, self.wind.clone())?;
        self.spec = spec;
        self.env = env;
        self.curve = curve;
        self.energies = energies;
        self.revision += 1;
        Ok(())
    }
}

/// The thermodynamics of the panel's CAPE and CIN: MetPy's standard, so
/// they read as a forecaster's tools give them (docs/aerology.md).
pub const ENERGY_THERMO: Thermo = Thermo::Standard;

/// What [`build`] makes of a profile: the environment of its inline points
/// (with `wind`), the surface parcel's ascent and the three (CAPE, CIN)
/// pairs.
type Built = (Environment, ParcelAscent, [(f64, f64); 3]);

fn build(spec: &AtmosphereSpec, lift: &LiftOptions, wind: Option<WindProfile>) -> Result<Built> {
    // Inline points read no file, so the base directory does not matter.
    let env = spec.build(Path::new("."))?.with_wind(wind);
    let curve = lift_curve(&env, lift)?;
    let energies = parcel_energies(&env, lift)?;
    Ok((env, curve, energies))
}

/// CAPE and CIN of the surface-based, mixed-layer and most-unstable
/// parcels, in `ParcelKind::ALL` order, with the forecasters' standard
/// thermodynamics ([`ENERGY_THERMO`], as `cumulus parcel` by default; the
/// drawn ascent keeps `lift`'s, the simulation's). units: J/kg
fn parcel_energies(env: &Environment, lift: &LiftOptions) -> Result<[(f64, f64); 3]> {
    let lift = LiftOptions {
        thermo: ENERGY_THERMO,
        ..*lift
    };
    let mut out = [(0.0, 0.0); 3];
    for (o, kind) in out.iter_mut().zip(ParcelKind::ALL) {
        let r = cape::parcel_report(env, kind, &lift)?;
        *o = (r.cape_j_per_kg, r.cin_j_per_kg);
    }
    Ok(out)
}

fn lift_curve(env: &Environment, lift: &LiftOptions) -> Result<ParcelAscent> {
    let n = (env.top_m() / CURVE_DZ_M).ceil() as usize + 1;
    lifting::surface_parcel_curve(env, lift, n)
}

fn check_index(points: &[AtmospherePoint], index: usize) -> Result<()> {
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
    check_index(&ed.spec.points, index)?;
    if !(z_m.is_finite() && value_c.is_finite()) {
        return Err(Error::invalid(
            "profile point",
            format!("z = {z_m} m, {value_c} °C"),
            "finite height and temperature",
        ));
    }
    let mut points = ed.spec.points.clone();
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
    let td = dewpoint_c(p);
    match curve {
        ProfileCurve::Temperature => p.t_c = value_c.max(td),
        ProfileCurve::Dewpoint => p.td_c = Some(value_c.min(p.t_c)),
    }
    ed.commit(points)
}

/// Adds a level at height `z_m` with temperature and dewpoint interpolated
/// from the current profile (so the environment does not change until the
/// new point is dragged). Returns the new point's index.
pub fn add_point(ed: &mut ProfileEditor, z_m: f64) -> Result<usize> {
    let top = ed.env.top_m();
    if !(z_m.is_finite() && z_m > 0.0) {
        return Err(Error::invalid(
            "new profile point height (m)",
            z_m,
            "above the ground (z > 0)",
        ));
    }
    let mut points = ed.spec.points.clone();
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
        let (tda, tdb) = (dewpoint_c(&a), dewpoint_c(&b));
        (t, (tdb + (tdb - tda) * w).min(t))
    };
    points.insert(
        index,
        AtmospherePoint {
            z_m,
            t_c,
            td_c: Some(td_c),
            rh_percent: None,
        },
    );
    ed.commit(points)?;
    Ok(index)
}

/// Removes level `index`. The surface level stays, and a profile keeps at
/// least two levels.
pub fn remove_point(ed: &mut ProfileEditor, index: usize) -> Result<()> {
    check_index(&ed.spec.points, index)?;
    if index == 0 {
        return Err(Error::invalid(
            "profile point to remove",
            0,
            "any level but the surface (index 0)",
        ));
    }
    if ed.spec.points.len() <= 2 {
        return Err(Error::invalid(
            "profile point to remove",
            index,
            "nothing: a profile needs at least 2 levels",
        ));
    }
    let mut points = ed.spec.points.clone();
    points.remove(index);
    ed.commit(points)
}

/// Sets the surface vapour mixing ratio by moving the surface dewpoint.
/// units: kg/kg. It must be positive and at most saturation at the surface.
pub fn set_surface_mixing_ratio(ed: &mut ProfileEditor, qv_kg_per_kg: f64) -> Result<()> {
    let p = ed.surface_pressure_pa();
    let t_k = ed.spec.points[0].t_c + ZERO_C_K;
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
    let mut points = ed.spec.points.clone();
    points[0].td_c = Some(td_c.min(points[0].t_c));
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
    let top = ed.env.top_m();
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
        let t_k = trial.spec.points[0].t_c + ZERO_C_K;
        let q = q.min(thermo::saturation_mixing_ratio(
            t_k,
            trial.surface_pressure_pa(),
        ));
        set_surface_mixing_ratio(&mut trial, q)?;
    }
    ed.commit(trial.spec.points)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fair() -> ProfileEditor {
        let pt = |z_m, t_c, td_c| AtmospherePoint {
            z_m,
            t_c,
            td_c: Some(td_c),
            rh_percent: None,
        };
        ProfileEditor::new(AtmosphereSpec {
            points: vec![
                pt(0.0, 25.0, 16.0),
                pt(1500.0, 10.0, 8.0),
                pt(1800.0, 12.0, -5.0),
                pt(8000.0, -30.0, -45.0),
            ],
            ..AtmosphereSpec::default()
        })
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
        assert_eq!(Some(p.t_c), p.td_c);
        move_point(&mut ed, ProfileCurve::Dewpoint, 0, 300.0, 40.0).unwrap();
        assert_eq!(ed.points()[0].z_m, 0.0);
        assert_eq!(ed.points()[0].td_c, Some(ed.points()[0].t_c));
    }
}
