//! Parcel physics (paper §3, §5, Algorithm 1): large SPH particles ("parcels")
//! rising through the implicit [`Environment`](crate::atmosphere::Environment).
//! CPU only; never imports wgpu, winit or egui.
//!
//! Coordinates: metres, x and y horizontal, z up, z = 0 at the ground; the
//! domain is centred on x = y = 0.
//!
//! - [`world`]: [`ParcelWorld`], Algorithm 1 and the kick–drift–kick
//!   integrator with adaptive sub-steps, one file per stage, parallel
//!   (rayon) and bit-identical at any thread count;
//! - [`single`]: one parcel released from the ground (`parcel --dynamic`);
//! - [`config`]: the `[physics]`, `[ground]`, `[emission]`, `[wind]` tables;
//! - [`ground`]: heat/humidity maps and the parcel generator;
//! - [`parcel`]: one parcel's state and how to create one;
//! - [`cloud_file`]: the condensed parcels as a CSV file;
//! - [`clusters`]: which spheres touch, through chains (one cloud);
//! - [`sph`], [`tessellation`], [`rng`]: kernels, the 18 × 9 sphere, SplitMix64;
//! - [`scale_bench`]: the lattice worlds of the speed measurements.
//!
//! Where the paper is loose, what we do (details at each function):
//! - SI units throughout; latent-heat factor α = 1 (the paper's 0.3 is
//!   `latent_heat_alpha`).
//! - Kernels of Müller et al. 2003: poly6 density, spiky pressure gradient,
//!   viscosity Laplacian. Rest density ρ0 per parcel = its own isolated
//!   density, so pressure measures overlap only and is never tensile.
//! - Atmospheric pressure on the exposed surface: only the hidden caps'
//!   share, each closed on its contact disk, so an isolated sphere gets
//!   exactly zero and Archimedes (already in eq 5) is not counted twice;
//!   calibrated weight 0.01.
//! - Entrained vapour (eq 12) at the environment's q_v, not ω_s (a typo);
//!   |v + δv_t| as √(|v − w|² + δv_t²); detrainment from the lower of the
//!   parcel's condensation plane and the scene's condensation level.
//! - Exchange of vapour, liquid water and heat (θ, θ_l) through the analytic
//!   contact disk of overlapping spheres, as a symmetric air-mass exchange
//!   (eq 16), conserving each quantity; contacts beyond h are found too.
//! - Filling ratio f = liquid water content / 0.5 g m⁻³ (`opaque_lwc_kg_m3`).
//! - Condensation plane from the parcel's liquid-water potential temperature
//!   θ_l and total water: the LCL of its own air, flat for a cluster.
//! - Death: once cloudy, no liquid left, sinking and `death_depth_m` below
//!   its plane; centre sinking below the ground; older than `max_age_s`.
//!   Leaving the sides or the top (domain or profile) is an escape.

pub mod cloud_file;
pub mod clusters;
pub mod config;
pub mod ground;
pub mod parcel;
pub mod rng;
pub mod scale_bench;
pub mod single;
pub mod sph;
pub mod tessellation;
pub mod world;

pub use config::{
    EmissionConfig, EntrainmentModel, GroundConfig, PhysicsConfig, WindConfig, WorldConfig,
};
pub use parcel::{Parcel, ParcelSpec};
pub use world::{
    ClampCounts, Counters, Diagnostics, Fates, ParcelWorld, StepReport, condensation_level_m,
};

/// What the renderer needs of one condensed parcel: the contract between the
/// physics and the renderer. The renderer reads these and nothing else.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudParcel {
    /// The parcel's stable identity ([`Parcel::id`]); what a renderer
    /// seeds per-cloud randomness with, so a cloud keeps its look when
    /// another parcel condenses or evaporates.
    pub id: u64,
    /// Centre of the sphere (x, y horizontal, z up). units: m
    pub center_m: glam::Vec3,
    /// Radius of the rendered sphere. units: m
    pub radius_m: f32,
    /// Filling ratio f ∈ [0, 1]: fraction of the parcel that is opaque (paper §6.1).
    pub fill: f32,
    /// Altitude of the condensation plane that cuts the sphere flat. units: m
    pub cond_plane_z_m: f32,
}
