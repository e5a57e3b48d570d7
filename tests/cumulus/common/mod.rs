//! Helpers shared by the integration tests: the GPU adapter of the render
//! tests and the environments of the physics tests.

#![allow(dead_code)] // each test binary uses its own subset

use cumulus::atmosphere::{EnvLevel, Environment, PressureModel};
use cumulus::render::GpuContext;

pub mod flip;
pub mod hdr;
pub mod physics;
pub mod render;

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

/// The CPU Vulkan adapter (lavapipe "llvmpipe"), or any adapter when that is
/// absent. With none: a notice naming `what` and `None`, or a panic when
/// CI=true (CI must not silently skip the GPU tests).
pub fn context(what: &str) -> Option<GpuContext> {
    let ctx =
        GpuContext::new_headless(Some("llvmpipe")).or_else(|_| GpuContext::new_headless(None));
    match ctx {
        Ok(c) => Some(c),
        Err(e) => {
            if std::env::var("CI").as_deref() == Ok("true") {
                panic!("CI=true needs a GPU adapter (lavapipe): {e}");
            }
            eprintln!("NOTICE: skipping {what}, no adapter: {e}");
            None
        }
    }
}

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
