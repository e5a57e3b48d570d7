//! Textured-sprite clouds after Wang, "Realistic and Fast Cloud Rendering"
//! (J. Graphics Tools 2003; papers 000, 002, 003): the CPU side of the
//! `sprites` render method. Like the atmosphere and the physics, this layer
//! imports no GPU or window code; the sprite renderer draws what it builds.
//!
//! - [`cloud`]: `[[sprite_clouds]]` boxes, seeded filling and pruning (§3.1);
//! - [`parcels`]: physics parcels as sprite clouds, touching parcels shaded
//!   as one cloud;
//! - [`atlas`]: the 16-tile texture sheet from our own noise (§3.2);
//! - [`shading`]: colour levels, time-of-day tables, biased sun mapping (§5);
//! - [`formation`]: formation and dissipation alpha (§4, Listing 1);
//! - [`presets`]: the dozen cloud types and `[[layers]]`;
//! - [`impostor`]: the ring of 8 impostors and the vertex-shading cache (§6);
//! - [`facing`]: locked facing inside a sprite (§3.3);
//! - [`vertices`]: a cloud's camera-facing quads, shaded per corner;
//! - [`order`]: back-to-front sorting and the paper's "cloud block overdraw".

pub mod atlas;
pub mod cloud;
pub mod facing;
pub mod formation;
pub mod impostor;
pub mod order;
pub mod parcels;
pub mod presets;
pub mod shading;
pub mod vertices;

pub use atlas::{Atlas, TileKind};
pub use cloud::{Sprite, SpriteBox, SpriteCloud, SpriteCloudSpec};
pub use parcels::{parcel_cloud, parcel_clouds};
pub use presets::{CloudType, LayerSpec};
pub use shading::{ColorLevel, TimeTable};

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

/// A `[lo, hi]` range must be finite, ordered and within [min, max].
fn range_in(name: &str, r: [f32; 2], min: f32, max: f32, unit: &str) -> Result<()> {
    if r.iter().all(|v| v.is_finite() && (min..=max).contains(v)) && r[0] <= r[1] {
        Ok(())
    } else {
        Err(Error::invalid(
            name,
            format!("[{}, {}]", r[0], r[1]),
            format!("a range [lo, hi] with {min} ≤ lo ≤ hi ≤ {max} {unit}"),
        ))
    }
}

/// Checks a scene's `[[sprite_clouds]]` and `[[layers]]`; errors name the
/// key (`"sprite_clouds[1].boxes"`, `"layers[0].coverage"`).
pub fn validate_scene(clouds: &[SpriteCloudSpec], layers: &[LayerSpec]) -> Result<()> {
    for (i, c) in clouds.iter().enumerate() {
        c.validate(&format!("sprite_clouds[{i}]"))?;
    }
    for (i, l) in layers.iter().enumerate() {
        l.validate(&format!("layers[{i}]"))?;
    }
    Ok(())
}

/// The sprite clouds of a scene's `[[sprite_clouds]]`, then its
/// `[[layers]]` expanded, in that order (deterministic).
pub fn build_clouds(clouds: &[SpriteCloudSpec], layers: &[LayerSpec]) -> Vec<SpriteCloud> {
    let authored = clouds.iter().map(SpriteCloudSpec::build);
    authored
        .chain(layers.iter().flat_map(LayerSpec::build))
        .collect()
}

/// Sprites built and dropped over a set of clouds, for the panel and the
/// render log (every dropped sprite is counted and shown).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FillCounts {
    pub clouds: usize,
    pub sprites: usize,
    /// Dropped by the pruning distance (§3.1).
    pub pruned: usize,
    /// Dropped beyond [`cloud::MAX_SPRITES_PER_CLOUD`].
    pub capped: usize,
}

impl FillCounts {
    /// The counts over `clouds`.
    pub fn of(clouds: &[SpriteCloud]) -> Self {
        clouds
            .iter()
            .fold(FillCounts::default(), |c, k| FillCounts {
                clouds: c.clouds + 1,
                sprites: c.sprites + k.sprites.len(),
                pruned: c.pruned + k.pruned,
                capped: c.capped + k.capped,
            })
    }
}

impl std::fmt::Display for FillCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} sprite clouds, {} sprites ({} pruned as too close, {} over the {}-sprite cap)",
            self.clouds,
            self.sprites,
            self.pruned,
            self.capped,
            cloud::MAX_SPRITES_PER_CLOUD
        )
    }
}
