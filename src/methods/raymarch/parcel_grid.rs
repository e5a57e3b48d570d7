//! The CPU's culling grid of the condensed parcels: per cell of a uniform
//! grid over their box, the parcels that can give density there, as flat
//! lists (one offset table, one index array). The CPU field
//! ([`super::field::CloudField`]) looks up a point's list instead of
//! evaluating every parcel.
//!
//! It lists what the GPU's grid of [`pack`] lists (the same box, the same
//! cell test, [`pack::for_each_touched_cell`]) but has no uniform arrays to
//! fit: any number of parcels, cells of about [`pack::TARGET_CELL_M`] on
//! every axis however large the field, coarsened (each axis halved) only
//! when the lists would pass [`MAX_CPU_ENTRIES`] or the cells
//! [`MAX_CPU_CELLS`]. Since every list holds every parcel that can reach
//! its cell, the union (a max) over a list is the union over all parcels:
//! bit for bit the value the GPU grid gives where both apply.

use glam::Vec3;

use crate::gpu::uniform::GridInfo;
use crate::methods::raymarch::pack::{self, GpuParcel, Packed};

/// Most cells of the CPU grid (4 B each in the offset table).
pub const MAX_CPU_CELLS: u64 = 1 << 22;
/// Most parcel indices in all its lists together (4 B each).
pub const MAX_CPU_ENTRIES: u64 = 1 << 24;

/// Parcel lists per cell of a uniform grid (x fastest).
#[derive(Debug, Clone)]
pub struct ParcelGrid {
    /// Box, cell size and counts (as the GPU's [`GridInfo`]).
    pub info: GridInfo,
    /// Cell i lists `entries[starts[i]..starts[i + 1]]`.
    starts: Vec<u32>,
    entries: Vec<u32>,
}

impl ParcelGrid {
    /// The grid of `live` parcels (as drawn, [`pack::gpu_parcels`]) with
    /// hypertexture shell `shell_m` (units: m). No limit on their number.
    pub fn new(live: &[GpuParcel], shell_m: f32) -> Self {
        if live.is_empty() {
            return Self {
                // EMPTY is one cell: one empty list.
                info: GridInfo::EMPTY,
                starts: vec![0, 0],
                entries: Vec::new(),
            };
        }
        let bounds: Vec<(Vec3, Vec3)> = live
            .iter()
            .map(|p| pack::parcel_bounds(p, shell_m))
            .collect();
        let (lo, extent) = pack::enclosing(&bounds);
        let mut dims = [0, 1, 2].map(|a| ((extent[a] / pack::TARGET_CELL_M).ceil() as u32).max(1));
        let mut coarsened = 0;
        loop {
            let cell = extent / Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32);
            let ncells: u64 = dims.iter().map(|&d| d as u64).product();
            if ncells <= MAX_CPU_CELLS {
                // Counting first: the lists are allocated once, at their size.
                let mut counts = vec![0u32; ncells as usize];
                let mut total = 0u64;
                for (p, b) in live.iter().zip(&bounds) {
                    pack::for_each_touched_cell(p, *b, shell_m, (lo, cell, dims), |c| {
                        counts[c] += 1;
                        total += 1;
                    });
                }
                if total <= MAX_CPU_ENTRIES || dims == [1, 1, 1] {
                    let info = GridInfo {
                        min: lo,
                        cell,
                        dims,
                        parcel_count: live.len() as u32,
                        entry_count: total as u32,
                        coarsened,
                    };
                    return Self::fill(live, &bounds, shell_m, info, counts);
                }
            }
            dims = dims.map(|d| d.div_ceil(2));
            coarsened += 1;
        }
    }

    fn fill(
        live: &[GpuParcel],
        bounds: &[(Vec3, Vec3)],
        shell_m: f32,
        info: GridInfo,
        counts: Vec<u32>,
    ) -> Self {
        let mut starts = Vec::with_capacity(counts.len() + 1);
        let mut next = counts;
        let mut at = 0u32;
        starts.push(0);
        for n in next.iter_mut() {
            let start = at;
            at += *n;
            starts.push(at);
            *n = start;
        }
        let mut entries = vec![0u32; at as usize];
        let grid = (info.min, info.cell, info.dims);
        for (i, (p, b)) in live.iter().zip(bounds).enumerate() {
            pack::for_each_touched_cell(p, *b, shell_m, grid, |c| {
                entries[next[c] as usize] = i as u32;
                next[c] += 1;
            });
        }
        Self {
            info,
            starts,
            entries,
        }
    }

    /// The GPU's (capped) grid of a packed frame, as CPU lists: the
    /// reference the uncapped grid is tested against.
    pub fn from_packed(packed: &Packed) -> Self {
        let info = packed.info;
        let [nx, ny, nz] = info.dims;
        let mut starts = vec![0];
        let mut entries = Vec::with_capacity(info.entry_count as usize);
        for iz in 0..nz {
            for iy in 0..ny {
                for ix in 0..nx {
                    entries.extend(packed.cell_list(ix, iy, iz));
                    starts.push(entries.len() as u32);
                }
            }
        }
        Self {
            info,
            starts,
            entries,
        }
    }

    /// `cell_list` of field_exact.wgsl: the parcels listed in p's cell (none
    /// outside the grid).
    pub fn list(&self, p: Vec3) -> &[u32] {
        let rel = (p - self.info.min) / self.info.cell;
        let [nx, ny, nz] = self.info.dims;
        let dims = Vec3::new(nx as f32, ny as f32, nz as f32);
        if rel.cmplt(Vec3::ZERO).any() || rel.cmpge(dims).any() {
            return &[];
        }
        let (x, y, z) = (rel.x as u32, rel.y as u32, rel.z as u32);
        let i = (x + nx * (y + ny * z)) as usize;
        &self.entries[self.starts[i] as usize..self.starts[i + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::raymarch::pack::tests::parcel;

    #[test]
    fn lists_hold_what_the_gpu_grid_lists_without_its_caps() {
        let parcels: Vec<_> = (0..40)
            .map(|i| parcel(i as f32 * 350.0, (i % 5) as f32 * 600.0, 1500.0, 300.0))
            .collect();
        let shell = 100.0;
        let live = pack::gpu_parcels(&parcels, shell, 1.0).unwrap();
        let ours = ParcelGrid::new(&live, shell);
        let gpu = ParcelGrid::from_packed(&pack::pack(&parcels, shell, 1.0).unwrap());
        // The same box (both from pack::enclosing); the GPU's is capped at
        // 16 cells in x, ours is not.
        assert_eq!(ours.info.min, gpu.info.min);
        assert!(ours.info.dims[0] > gpu.info.dims[0], "{:?}", ours.info);
        // At any point in the box, a parcel reaching it is in both lists.
        for k in 0..2000 {
            let t = Vec3::new(
                (k as f32 * 0.618).fract(),
                (k as f32 * 0.414).fract(),
                (k as f32 * 0.732).fract(),
            );
            let p = ours.info.min + t * (ours.info.max() - ours.info.min);
            for (i, q) in live.iter().enumerate() {
                let reach = q.radius_m + shell;
                let near = p.distance(Vec3::from(q.center_m)) < reach && p.z > q.plane_z_m - shell;
                if near {
                    let i = i as u32;
                    assert!(ours.list(p).contains(&i) && gpu.list(p).contains(&i));
                }
            }
        }
    }

    #[test]
    fn many_parcels_are_listed_and_empty_is_empty() {
        let parcels: Vec<_> = (0..3000)
            .map(|i| parcel((i % 60) as f32 * 700.0, (i / 60) as f32 * 700.0, 1500.0, 200.0))
            .collect();
        let live = pack::gpu_parcels(&parcels, 100.0, 1.0).unwrap();
        let g = ParcelGrid::new(&live, 100.0);
        assert_eq!(g.info.parcel_count, 3000);
        assert_eq!(g.info.coarsened, 0);
        let c = Vec3::from(live[2999].center_m);
        assert!(g.list(c).contains(&2999));
        let e = ParcelGrid::new(&[], 100.0);
        assert!(e.list(Vec3::ZERO).is_empty());
    }
}
