//! The atmosphere: thermodynamics, the implicit environment profile, and the
//! readers that build it from real soundings or scene profiles. Nothing here
//! knows about the GPU or a window.

pub mod environment;
pub mod thermo;

pub use environment::{EnvLevel, Environment, PressureModel};

use serde::{Deserialize, Serialize};

/// How a scene profile describes its atmosphere (the `[atmosphere]` table).
/// Placeholder: the atmosphere work extends this with inline points and
/// sounding files.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AtmosphereSpec {}

impl AtmosphereSpec {
    /// Builds the environment; relative sounding paths resolve against `base_dir`.
    /// Placeholder: a fixed fair-weather profile (well-mixed layer to 1.2 km,
    /// inversion to 1.5 km, stable above) until the profile reader lands.
    pub fn build(&self, _base_dir: &std::path::Path) -> crate::Result<Environment> {
        let lv = |z_m: f64, theta_k: f64, qv_g: f64| EnvLevel {
            z_m,
            theta_k,
            qv_kg_per_kg: qv_g / 1000.0,
            pressure_pa: None,
        };
        Environment::new(
            vec![
                lv(0.0, 300.0, 12.0),
                lv(1200.0, 300.5, 10.0),
                lv(1500.0, 305.0, 5.0),
                lv(12_000.0, 340.0, 0.1),
            ],
            100_000.0,
            PressureModel::Hydrostatic,
        )
    }
}
