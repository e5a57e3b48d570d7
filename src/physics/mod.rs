//! Parcel physics (paper §3, §5, Algorithm 1): large SPH particles ("parcels")
//! rising through the implicit [`Environment`](crate::atmosphere::Environment).
//! CPU only; never imports wgpu, winit or egui.
//!
//! Coordinates: metres, x and y horizontal, z up, z = 0 at the ground; the
//! domain is centred on x = y = 0.

pub mod config;
pub mod ground;
pub mod parcel;
pub mod rng;
pub mod single;
pub mod sph;
pub mod tessellation;
pub mod world;

pub use config::{EmissionConfig, GroundConfig, PhysicsConfig, WindConfig, WorldConfig};
pub use parcel::{Parcel, ParcelSpec};
pub use world::{
    ClampCounts, Counters, Diagnostics, Fates, ParcelWorld, StepReport, condensation_level_m,
};

/// What the renderer needs of one condensed parcel: the contract between the
/// physics and the renderer. The renderer reads these and nothing else.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudParcel {
    /// Centre of the sphere (x, y horizontal, z up). units: m
    pub center_m: glam::Vec3,
    /// Radius of the rendered sphere. units: m
    pub radius_m: f32,
    /// Filling ratio f ∈ [0, 1]: fraction of the parcel that is opaque (paper §6.1).
    pub fill: f32,
    /// Altitude of the condensation plane that cuts the sphere flat. units: m
    pub cond_plane_z_m: f32,
}
