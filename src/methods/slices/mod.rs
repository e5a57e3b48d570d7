//! Schpok et al. 2003's authored clouds (paper 001): [`model`] is the CPU
//! side (ellipsoids, keyframes, noise octaves, slicing), [`gpu`] the
//! buffers, the vertex-field compute pass and the slicing planes' draw.

pub mod gpu;
pub mod model;
