//! Configuration: the `[render]` and `[camera]` tables of a scene, the
//! render method and march path, their defaults and validation. Plain data
//! that imports no renderer, window, bench or CLI code, so every layer above
//! (the scene loader, the renderer, the front ends) reads the same types.
//! The terrain's settings ([`TerrainConfig`]) belong to its CPU model,
//! [`crate::landscape::terrain`], and this module gathers them; the render
//! methods' tables are here ([`slices`], [`SpritesConfig`]), so the
//! methods (above this module) read them without a cycle.

pub mod camera;
pub mod method;
mod render;
pub mod slices;

use crate::error::{Error, Result};

pub use crate::landscape::terrain::TerrainConfig;
pub use camera::{Camera, CameraConfig};
pub use method::{MarchPath, RenderMethod};
pub use render::{DEFAULT_VISIBILITY_KM, RenderConfig, SpritesConfig, TONE_EXPOSURE, TemporalMode};
pub use slices::{SlicesConfig, VertexField};

/// `Ok` when `value` is finite and `ok` holds; else the error naming the
/// setting `name` and what is `allowed`.
pub(crate) fn check(name: &str, value: f32, ok: bool, allowed: &str) -> Result<()> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(name, value, allowed))
    }
}
