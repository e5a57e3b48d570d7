//! cumulus grows cumulus clouds from atmospheric parcel physics (Goswami &
//! Neyret 2016) and renders them on the GPU.
//!
//! Layers, bottom up (each only reads the ones below it):
//! - [`atmosphere`]: thermodynamics, environment profiles, sounding reader;
//! - [`physics`]: parcels, SPH, mixing, condensation, emission, integrator;
//! - [`landscape`] (ground height), [`sun`] (solar position from the
//!   clock) and [`sky`] (sun and sky colours from an atmosphere model):
//!   pure CPU, read by the physics and the renderer alike;
//! - [`scene`]: a scene profile (TOML) → validated configuration;
//! - [`sprites_model`]: Wang 2003's sprite clouds, CPU side (reads the physics);
//! - [`render`]: wgpu renderer (headless or to a window surface);
//! - front ends: [`app`] (window), [`bench`], [`stability`], and `cli` in the binary.

// Input checks are written `!(x > 0.0)` on purpose: the negated comparison
// is also true for NaN, which must be an error, never a silent pass.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod app;
pub mod atmosphere;
pub mod authored;
pub mod bench;
pub mod error;
pub mod export;
pub mod landscape;
pub mod output;
pub mod physics;
pub mod plots;
pub mod render;
pub mod scene;
pub mod scene_set;
pub mod sky;
pub mod sprites_model;
pub mod stability;
pub mod sun;

pub use error::{Error, Result};
