//! Authored clouds after Schpok, Simons, Ebert & Hansen, "A Real-Time Cloud
//! Modeling, Rendering, and Animation System" (SCA 2003; paper 001): the
//! CPU side of the `slices` render method. Like the atmosphere and the
//! physics, this layer imports no GPU or window code; the renderer reads
//! what it builds.
//!
//! - [`ellipsoid`]: `[[ellipsoids]]` in a scene, Wyvill blending, the field;
//! - [`animation`]: keyframes, particle dynamics, the cumulonimbus preset;
//! - [`octaves`]: per-octave noise transforms (eq. 3), tiers, the Base tier;
//! - the media filters and the qualitative controls of Table 2
//!   (`[render.slices]`) are configuration: [`crate::config::slices`];
//! - [`pick`]: picking, moving and resizing ellipsoids with the mouse;
//! - [`slicing`]: light-aligned slicing planes, vertex field and shadows;
//! - [`clouds`]: the primitives grouped into clouds, a stack each;
//! - [`frame`]: all of it for one frame, as the slice renderer takes it.

pub mod animation;
pub mod clouds;
pub mod ellipsoid;
pub mod frame;
pub mod octaves;
pub mod pick;
pub mod slicing;

pub use crate::config::slices::{MediaFilter, SlicesConfig, VertexField};
pub use animation::{Keyframe, Motion, ParticleConfig, cumulonimbus, state_at, states_at};
pub use ellipsoid::{Ellipsoid, EllipsoidState, field_at, wyvill};
pub use frame::{AuthoredFrame, authored_frame};
pub use octaves::{NoiseMotion, NoiseTier, OctaveUniform, octave_uniform};
/// The media filters and the qualitative controls (`[render.slices]`) are
/// configuration: [`crate::config::slices`].
pub mod media {
    pub use crate::config::slices::MediaFilter;
}
pub use clouds::{CloudSlices, CloudStack, MAX_STACKS, PLANE_VERTEX_BUDGET, cloud_groups};
pub use slicing::{
    CloudScale, ShadowRays, SliceGeometry, SliceOrientation, SliceVertex, build_slices,
    slice_grid, slice_normal,
};

use crate::error::{Error, Result};

/// `value` must be finite and within [lo, hi]; the error names `name` and
/// says `allowed`.
fn finite_in(name: &str, value: f32, lo: f32, hi: f32, allowed: &str) -> Result<()> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(Error::invalid(name, value, allowed))
    }
}
