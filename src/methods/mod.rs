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

pub mod standin;

use crate::config::RenderMethod;
use crate::gpu::method::MethodEntry;

/// Declares each method's module and registers its entry in [`METHODS`].
macro_rules! register {
    ($($module:ident => $entry:path,)*) => {
        $(pub mod $module;)*

        /// Every render method, one registration line each: the renderer,
        /// its background pipeline builder, the shader tests and the
        /// bench's tables take the methods from here.
        pub static METHODS: [&MethodEntry; [$(stringify!($module)),*].len()] = [$(&$entry),*];
    };
}

register! {
    raymarch => raymarch::method::ENTRY,
    sprites => sprites::gpu::method::ENTRY,
    slices => slices::gpu::method::ENTRY,
}

/// The index in [`METHODS`] of the entry that draws `method`.
pub fn index_of(method: RenderMethod) -> usize {
    METHODS
        .iter()
        .position(|e| e.methods.contains(&method))
        .unwrap_or_else(|| panic!("no registered method draws {method}"))
}
