//! The entrainment models (`physics.entrainment_model`) against the
//! fractional rates they are defined by: an isolated parcel at rest in
//! calm, neutral air entrains through its whole surface at the turbulent
//! speed δv_t, so its fractional rate per metre, ṁ_e / (m δv_t), must be
//! 3ε (paper: the same at every radius), c/R (plume theory: three times
//! faster for a parcel a third the size) or μ (observed: the same at every
//! radius).

use cumulus::physics::{EntrainmentModel, ParcelSpec, PhysicsConfig};
use glam::DVec3;

use crate::common::physics::{neutral, world};

/// Fractional entrainment per metre of an isolated parcel of radius `r_m`.
/// units: m⁻¹
fn fractional_rate(model: EntrainmentModel, r_m: f64) -> f64 {
    let physics = PhysicsConfig {
        sph: false,
        viscosity: false,
        atmospheric_pressure: false,
        exchange: false,
        condensation: false,
        buoyancy: false,
        drag: false,
        mixing: true,
        entrainment_model: model,
        ..PhysicsConfig::default()
    };
    let turbulence = physics.turbulence_m_s;
    let mut w = world(neutral(), physics, false, 1);
    let s =
        ParcelSpec::from_environment(w.environment(), DVec3::new(0.0, 0.0, 2000.0), 0.0, 0.0, r_m);
    w.spawn_parcel(s).unwrap();
    w.step(0.1);
    let p = &w.parcels()[0];
    p.entrain_rate_kg_s / (p.total_mass_kg() * turbulence)
}

/// Within 0.5 %: the rate is 3ε'/R times ρ_env/ρ_parcel (1 for a parcel of
/// environment air, up to the 0.1 s step's change of volume) times the
/// exposed share of the sphere (1 when isolated; the 18 × 9 tessellation's
/// area is the sphere's within a fraction of a per cent).
const REL_TOL: f64 = 5e-3;

fn close(a: f64, b: f64) -> bool {
    (a / b - 1.0).abs() < REL_TOL
}

#[test]
fn each_entrainment_model_gives_its_fractional_rate() {
    let d = PhysicsConfig::default();
    assert_eq!(
        d.entrainment_model,
        EntrainmentModel::Paper,
        "the paper's stays the default"
    );
    for r in [100.0, 300.0] {
        let paper = fractional_rate(EntrainmentModel::Paper, r);
        assert!(
            close(paper, 3.0 * d.entrainment_rate_per_m),
            "paper, R = {r}: {paper}"
        );
        let plume = fractional_rate(EntrainmentModel::Plume, r);
        assert!(
            close(plume, d.entrainment_plume_coefficient / r),
            "plume, R = {r}: {plume}"
        );
        let observed = fractional_rate(EntrainmentModel::Observed, r);
        assert!(
            close(observed, d.entrainment_observed_per_m),
            "observed, R = {r}: {observed}"
        );
    }
}
