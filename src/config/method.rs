//! The cloud render method a scene uses (`[render] method`, `--method` on
//! `render`, `watch` and `bench`, the panel's method box). Every method
//! shares the sky, terrain, cloud-shadow and composite passes; what differs
//! is how the cloud field reaches the GPU and how a pixel finds its cloud.
//! `baked` and `exact` ray-march eq. 18 (module [`crate::methods::raymarch`]);
//! `sprites` (Wang 2003) draws the same parcels as textured sprite clouds
//! (module [`crate::methods::sprites::gpu`]); `slices` (Schpok 2003) draws
//! light-aligned slicing planes of an implicit field (module
//! [`crate::methods::slices::gpu`]).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// Declares [`RenderMethod`]: each method once, with its doc, its
/// attributes and its name in scene files (the enum, [`RenderMethod::ALL`]
/// and [`RenderMethod::name`] come from this one list).
macro_rules! render_methods {
    ($($(#[$meta:meta])* $variant:ident = $name:literal,)*) => {
        /// How the clouds are drawn: a method registered in
        /// [`crate::methods::METHODS`].
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
        pub enum RenderMethod {
            $($(#[$meta])* #[serde(rename = $name)] $variant,)*
        }

        impl RenderMethod {
            /// Every method, in the order the panel and the bench list them.
            pub const ALL: [RenderMethod; [$($name),*].len()] = [$(RenderMethod::$variant),*];

            /// Name in scene files, on the command line and in tables.
            pub fn name(self) -> &'static str {
                match self {
                    $(RenderMethod::$variant => $name,)*
                }
            }
        }
    };
}

render_methods! {
    /// The parcels are splatted by compute passes into a 3D texture of the
    /// macro field (re-baked only when they move); the march reads it with
    /// one filtered fetch per sample and skips empty space with a coarse
    /// occupancy grid: cost per pixel independent of the parcel count.
    #[default]
    Baked = "baked",
    /// The paper's path (§6.2): parcels and a culling grid in uniform
    /// buffers, the union of parcels evaluated per sample. The reference the
    /// baked method is measured against; at most
    /// [`crate::methods::raymarch::pack::MAX_PARCELS`] condensed parcels.
    Exact = "exact",
    /// Wang 2003: every condensed parcel becomes a cloud of camera-facing,
    /// textured, artist-shaded sprites drawn back to front (no ray-march,
    /// no field upload). Scene `[[sprite_clouds]]`/`[[layers]]` are drawn
    /// as sprites under every method.
    Sprites = "sprites",
    /// Schpok et al. 2003 (§4): slicing planes aligned with the light,
    /// the implicit field (authored `[[ellipsoids]]` and the parcels as
    /// spheres) and its shadow evaluated at the planes' vertices on the
    /// CPU (or in a compute pass, `vertex_field = "gpu"`), noise octaves
    /// composited per fragment, blended back to front into a float
    /// target. Controlled by `[render.slices]`.
    Slices = "slices",
}

impl RenderMethod {
    /// Whether the method ray-marches a density field (and so needs the
    /// field upload, the cloud and shadow passes).
    pub fn ray_marches(self) -> bool {
        matches!(self, RenderMethod::Baked | RenderMethod::Exact)
    }
}

impl fmt::Display for RenderMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RenderMethod {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self, Error> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<String> = Self::ALL.iter().map(|m| format!("\"{m}\"")).collect();
                Error::invalid("render method", s, format!("one of {}", names.join(", ")))
            })
    }
}

/// Which shader stage runs the ray-march (same WGSL `march` either way).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MarchPath {
    /// A full-screen fragment shader blended over the target.
    Fragment,
    /// A compute shader writing a storage texture, blended over the target
    /// by the composite pass.
    Compute,
    /// Measure both on this adapter during the first frames with clouds
    /// (alternating, no extra work or wait) and keep the faster.
    #[default]
    Auto,
}

impl MarchPath {
    /// Every path, in the order tables list them.
    pub const ALL: [MarchPath; 3] = [MarchPath::Fragment, MarchPath::Compute, MarchPath::Auto];

    /// Name in scene files and tables.
    pub fn name(self) -> &'static str {
        match self {
            MarchPath::Fragment => "fragment",
            MarchPath::Compute => "compute",
            MarchPath::Auto => "auto",
        }
    }
}

impl fmt::Display for MarchPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bad_names_are_explained() {
        for m in RenderMethod::ALL {
            assert_eq!(m.name().parse::<RenderMethod>().unwrap(), m);
        }
        let e = "fast".parse::<RenderMethod>().unwrap_err().to_string();
        assert!(e.contains("fast"), "{e}");
        for m in RenderMethod::ALL {
            assert!(e.contains(m.name()), "{e} lists {m}");
        }
        assert_eq!(RenderMethod::default(), RenderMethod::Baked);
    }
}
