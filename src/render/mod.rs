//! GPU renderer (paper §6): packs condensed parcels and a culling grid into
//! uniform buffers and ray-marches hypertextured spheres over a terrain with
//! cloud shadows. One `render` path serves the window, headless commands and tests.

use serde::{Deserialize, Serialize};

/// Render settings and feature switches (the `[render]` table). Placeholder.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderConfig {}

/// Camera placement (the `[camera]` table). Placeholder.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraConfig {}
