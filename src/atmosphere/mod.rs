//! The atmosphere: thermodynamics, the implicit environment profile and its
//! wind, the readers that build it from real soundings or scene profiles,
//! and parcel theory on it (lifted parcels, CAPE and CIN). Nothing here
//! knows about the GPU or a window.

pub mod cape;
pub mod environment;
pub mod indices;
pub mod lifting;
pub mod sounding;
mod spec;
pub mod standard;
pub mod thermo;
pub mod wind;

pub use environment::{EnvLevel, Environment, PressureModel};
pub use sounding::{Sounding, SoundingLevel};
pub use spec::{AtmospherePoint, AtmosphereSpec};
pub use wind::{WindLevel, WindProfile};
