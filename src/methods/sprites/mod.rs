//! Wang 2003's sprite clouds (papers 000, 002, 003): [`model`] is the CPU
//! side (cloud boxes, atlas, shading, formation, impostors), [`gpu`] the
//! atlas upload, the per-frame instances and the impostor ring.

pub mod gpu;
pub mod model;
