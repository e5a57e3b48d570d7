//! The render methods, each whole in its own folder: its CPU model, its
//! GPU side and (under `shaders/<method>/`) its WGSL.
//!
//! - [`raymarch`]: Goswami & Neyret 2016's hypertextured parcels,
//!   ray-marched (`baked` and `exact`);
//! - [`sprites`]: Wang 2003's textured sprites and impostors;
//! - [`slices`]: Schpok et al. 2003's authored ellipsoids drawn by
//!   light-aligned slicing planes.
//!
//! [`standin`] is a deterministic stand-in cloud field for the tests and
//! the bench (parcels any method draws).

pub mod raymarch;
pub mod slices;
pub mod sprites;
pub mod standin;
