//! Helpers shared by the integration tests: the `cumulus` binary (`cli`),
//! the GPU adapter and what a GPU test does without one (`gpu`), image
//! comparison (`flip`, `hdr`), one-frame renders (`render`), and the
//! environments of the physics tests (here and `physics`).

use cumulus::atmosphere::{EnvLevel, Environment, PressureModel};

pub mod cli;
pub mod flip;
pub mod gpu;
pub mod hdr;
pub mod physics;
pub mod points;
pub mod render;

pub use gpu::context;

/// A minimal `[atmosphere]` table (two levels) for test profiles: a profile
/// file must say what its atmosphere is. Append it after the lines a test
/// pins error positions on.
pub const ATMOSPHERE_TOML: &str = "
[[atmosphere.points]]
z_m = 0.0
t_c = 20.0
td_c = 10.0

[[atmosphere.points]]
z_m = 10000.0
t_c = -45.0
td_c = -60.0
";

pub fn level(z_m: f64, theta_k: f64, qv_g: f64) -> EnvLevel {
    EnvLevel {
        z_m,
        theta_k,
        qv_kg_per_kg: qv_g / 1000.0,
        pressure_pa: None,
    }
}

/// Fair weather: well-mixed layer to 1.2 km, inversion to 1.5 km, stable above.
pub fn fair_weather() -> Environment {
    Environment::new(
        vec![
            level(0.0, 300.0, 12.0),
            level(1200.0, 300.5, 10.0),
            level(1500.0, 306.0, 5.0),
            level(12_000.0, 345.0, 0.1),
        ],
        100_000.0,
        PressureModel::Hydrostatic,
    )
    .unwrap()
}
