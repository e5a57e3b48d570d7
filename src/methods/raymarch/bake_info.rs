//! What the `baked` method's last bake covered ([`BakeInfo`]) and what
//! the front ends say about it.

use crate::methods::raymarch::clipmap::MAX_BAKE_VOXELS;

/// What the last bake covered.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BakeInfo {
    /// Voxel side of the finest level. units: m
    pub voxel_m: f32,
    /// Clipmap levels (1: the parcels' whole box).
    pub levels: u32,
    /// Voxel side the radii asked for, before the memory cap. units: m
    pub wanted_voxel_m: f32,
    /// How many times the voxel was enlarged to fit [`MAX_BAKE_VOXELS`].
    pub coarsened: u32,
    /// Voxels per axis of the stacked field texture.
    pub dims: [u32; 3],
    /// GPU memory of the field. units: bytes
    pub bytes: u64,
    /// Bakes run so far (a bake runs only when parcels moved).
    pub bakes: u64,
}

impl BakeInfo {
    /// What to tell the user when the memory cap made the voxels coarser
    /// than the parcel radii asked for (the CLI prints it, the window's
    /// panel shows it); None when it did not.
    pub fn coarsening_note(&self) -> Option<String> {
        (self.coarsened > 0).then(|| {
            format!(
                "the baked cloud field uses {:.0} m voxels instead of {:.0} m to stay within {} voxels (clouds cover a large region)",
                self.voxel_m, self.wanted_voxel_m, MAX_BAKE_VOXELS
            )
        })
    }
}

impl BakeInfo {
    /// The clipmap's levels and their voxels, when there are several (the
    /// CLI prints it): e.g. "3 camera-centred levels of 45, 90, 181 m
    /// voxels".
    pub fn levels_note(&self) -> Option<String> {
        (self.levels > 1).then(|| {
            let sides: Vec<String> = (0..self.levels)
                .map(|k| format!("{:.0}", self.voxel_m * (1u32 << k) as f32))
                .collect();
            format!(
                "the baked cloud field has {} camera-centred levels of {} m voxels",
                self.levels,
                sides.join(", ")
            )
        })
    }
}
