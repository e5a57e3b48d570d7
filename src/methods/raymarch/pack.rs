//! CPU packing of a frame for the GPU (paper §6.2): condensed parcels become
//! fixed-size uniform arrays, and a coarse grid over the cloud layer's
//! bounding box lists, per cell, the parcels whose (shell-padded) sphere
//! touches it, so the ray-marcher evaluates only those at each sample.
//!
//! No wgpu here: everything is plain `#[repr(C)]` Pod data, unit-tested.
//!
//! Limits and fallback (never silent truncation):
//! - more than [`MAX_PARCELS`] condensed parcels → [`Error::InvalidParameter`]
//!   naming the limit (the uniform array is fixed-size; the paper runs ≤ 85).
//!   A GPU limit only: the CPU field (`field`, culled by `parcel_grid`,
//!   which shares this grid's cell test) takes any number;
//! - more cell-list entries than [`MAX_GRID_ENTRIES`] → the grid is coarsened
//!   (each axis halved) until the lists fit; a 1×1×1 grid lists every parcel
//!   once, which always fits because `MAX_PARCELS ≤ MAX_GRID_ENTRIES`.
//!   [`GridInfo::coarsened`] says how often this happened.
//!
//! The structs here are the uniforms of the `exact` field (`Parcel` and
//! `Parcels` of shaders/raymarch/parcel.wgsl, `Grid` of
//! shaders/raymarch/field_exact.wgsl), member for member, and the WGSL
//! array sizes are these constants: tests (src/render/twins.rs)
//! compare names, offsets, sizes and constants with naga's reflection.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::error::{Error, Result};
use crate::gpu::uniform::GridInfo;
use crate::physics::CloudParcel;

/// Most condensed parcels one frame can draw (uniform array length; the
/// physics emits at most `emission.max_parcels`, 1024 by default).
pub const MAX_PARCELS: usize = 1024;
/// Most cells per grid axis (x, y, z).
pub const MAX_GRID_DIMS: [u32; 3] = [16, 16, 8];
/// Most grid cells in all (product of [`MAX_GRID_DIMS`]).
pub const MAX_GRID_CELLS: usize = 16 * 16 * 8;
/// Most parcel indices in all cell lists together.
pub const MAX_GRID_ENTRIES: usize = 8192;
/// Cell side the grid aims for before capping at [`MAX_GRID_DIMS`]. units: m
pub const TARGET_CELL_M: f32 = 250.0;

const _: () = assert!(MAX_PARCELS <= MAX_GRID_ENTRIES);
const _: () =
    assert!(MAX_GRID_CELLS == (MAX_GRID_DIMS[0] * MAX_GRID_DIMS[1] * MAX_GRID_DIMS[2]) as usize);

/// One parcel: `struct Parcel` of shaders/raymarch/parcel.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuParcel {
    /// Centre. units: m
    pub center_m: [f32; 3],
    /// Radius (as drawn, × `render.radius_scale`). units: m
    pub radius_m: f32,
    /// Filling ratio f.
    pub fill: f32,
    /// Height of the condensation plane. units: m
    pub plane_z_m: f32,
    pub _pad: [f32; 2],
}

/// All parcels: `struct Parcels` of shaders/raymarch/parcel.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct ParcelsUniform {
    pub parcels: [GpuParcel; MAX_PARCELS],
}

/// Grid cell lists: `struct Grid` of shaders/raymarch/field_exact.wgsl.
/// `cells[i / 2]` holds (start, count) of cell i in xy (even i) or zw (odd i);
/// `entries[j / 4][j % 4]` is the j-th parcel index.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GridUniform {
    pub cells: [[u32; 4]; MAX_GRID_CELLS / 2],
    pub entries: [[u32; 4]; MAX_GRID_ENTRIES / 4],
}

const _: () = assert!(std::mem::size_of::<GpuParcel>() == 32);
const _: () = assert!(std::mem::size_of::<ParcelsUniform>() == 32 * MAX_PARCELS);
const _: () =
    assert!(std::mem::size_of::<GridUniform>() == 8 * MAX_GRID_CELLS + 4 * MAX_GRID_ENTRIES);

/// A packed frame's cloud data.
#[derive(Debug)]
pub struct Packed {
    pub parcels: Box<ParcelsUniform>,
    pub grid: Box<GridUniform>,
    pub info: GridInfo,
}

impl Packed {
    /// Cell list of cell (ix, iy, iz) as parcel indices (for tests and debugging).
    pub fn cell_list(&self, ix: u32, iy: u32, iz: u32) -> Vec<u32> {
        let [nx, ny, _] = self.info.dims;
        let i = (ix + nx * (iy + ny * iz)) as usize;
        let c = self.grid.cells[i / 2];
        let (start, count) = if i.is_multiple_of(2) {
            (c[0], c[1])
        } else {
            (c[2], c[3])
        };
        (start..start + count)
            .map(|j| self.grid.entries[j as usize / 4][j as usize % 4])
            .collect()
    }
}

fn zeroed_box<T: Zeroable>() -> Box<T> {
    // 48 KiB for the grid: fine on any thread's stack before moving to the heap.
    Box::new(T::zeroed())
}

/// Axis-aligned box a parcel's density can reach: the sphere padded by the
/// shell, cut below at the condensation plane minus the shell.
pub(crate) fn parcel_bounds(p: &GpuParcel, shell_m: f32) -> (Vec3, Vec3) {
    let c = Vec3::from(p.center_m);
    let r = p.radius_m + shell_m;
    let mut lo = c - Vec3::splat(r);
    let hi = c + Vec3::splat(r);
    lo.z = lo.z.max(p.plane_z_m - shell_m).min(hi.z);
    (lo, hi)
}

/// The condensed parcels as drawn: checked (finite fields, else an error
/// naming the parcel), those with f = 0 or r = 0 skipped (eq. 18 gives them
/// no density), radii scaled by `radius_scale`, f capped at 1. No count
/// limit: the exact method's [`pack`] applies its own (the baked method's
/// storage buffer has none).
pub fn gpu_parcels(
    parcels: &[CloudParcel],
    shell_m: f32,
    radius_scale: f32,
) -> Result<Vec<GpuParcel>> {
    if !(shell_m.is_finite() && shell_m >= 0.0) {
        return Err(Error::invalid("render.shell_m", shell_m, "finite, ≥ 0 m"));
    }
    if !(radius_scale.is_finite() && radius_scale > 0.0) {
        return Err(Error::invalid(
            "render.radius_scale",
            radius_scale,
            "finite, > 0",
        ));
    }
    let mut out = Vec::with_capacity(parcels.len());
    for (i, p) in parcels.iter().enumerate() {
        let finite = p.center_m.is_finite()
            && p.radius_m.is_finite()
            && p.fill.is_finite()
            && p.cond_plane_z_m.is_finite();
        if !finite {
            return Err(Error::invalid(
                format!("cloud parcel {i}"),
                format!("{p:?}"),
                "finite centre, radius, fill and condensation plane",
            ));
        }
        if p.fill <= 0.0 || p.radius_m <= 0.0 {
            continue;
        }
        out.push(GpuParcel {
            center_m: p.center_m.to_array(),
            radius_m: p.radius_m * radius_scale,
            fill: p.fill.min(1.0),
            plane_z_m: p.cond_plane_z_m,
            _pad: [0.0; 2],
        });
    }
    Ok(out)
}

/// Packs `parcels` for the GPU. `shell_m` is the hypertexture shell thickness
/// (density reaches that far beyond the sphere and below the plane);
/// `radius_scale` enlarges the rendered spheres over the physical parcels
/// (paper §6.1: "spheres larger than these kernels for nice looking unions").
pub fn pack(parcels: &[CloudParcel], shell_m: f32, radius_scale: f32) -> Result<Packed> {
    let drawn = gpu_parcels(parcels, shell_m, radius_scale)?;
    if drawn.len() > MAX_PARCELS {
        return Err(Error::invalid(
            "condensed parcel count",
            drawn.len(),
            format!(
                "at most {MAX_PARCELS} with render.method = \"exact\" (size of the parcel uniform array in pack.rs and raymarch/parcel.wgsl); the \"baked\" method has no such limit"
            ),
        ));
    }
    let n = drawn.len();
    let mut out_parcels = zeroed_box::<ParcelsUniform>();
    out_parcels.parcels[..n].copy_from_slice(&drawn);
    let live = &out_parcels.parcels[..n];

    let mut grid = zeroed_box::<GridUniform>();
    if n == 0 {
        let info = GridInfo::EMPTY;
        return Ok(Packed {
            parcels: out_parcels,
            grid,
            info,
        });
    }

    let bounds: Vec<(Vec3, Vec3)> = live.iter().map(|p| parcel_bounds(p, shell_m)).collect();
    let (lo, extent) = enclosing(&bounds);
    let mut dims = [0u32; 3];
    for a in 0..3 {
        dims[a] = ((extent[a] / TARGET_CELL_M).ceil() as u32).clamp(1, MAX_GRID_DIMS[a]);
    }

    let mut coarsened = 0;
    loop {
        let cell = extent / Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32);
        if let Some(entries) = fill_grid(live, &bounds, lo, cell, dims, shell_m, &mut grid) {
            let info = GridInfo {
                min: lo,
                cell,
                dims,
                parcel_count: n as u32,
                entry_count: entries,
                coarsened,
            };
            return Ok(Packed {
                parcels: out_parcels,
                grid,
                info,
            });
        }
        debug_assert!(dims != [1, 1, 1], "a 1×1×1 grid always fits");
        dims = dims.map(|d| d.div_ceil(2));
        coarsened += 1;
    }
}

/// The lowest corner and the extent (at least 1 m a side) of the boxes
/// `bounds` of [`parcel_bounds`] (not empty): the culling grid's box.
/// units: m
pub(crate) fn enclosing(bounds: &[(Vec3, Vec3)]) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for (a, b) in bounds {
        lo = lo.min(*a);
        hi = hi.max(*b);
    }
    (lo, (hi - lo).max(Vec3::splat(1.0)))
}

/// Calls `visit` with the index (x fastest) of every cell of the grid of
/// `dims` cells of side `cell` from `lo` that parcel `p`, of box `bound`
/// ([`parcel_bounds`]), can give density: its shell-padded sphere touches
/// the cell and the cell reaches above the plane cut. The one cell test of
/// both culling grids (the GPU's here, the CPU's in `parcel_grid`).
pub(crate) fn for_each_touched_cell(
    p: &GpuParcel,
    bound: (Vec3, Vec3),
    shell_m: f32,
    (lo, cell, dims): (Vec3, Vec3, [u32; 3]),
    mut visit: impl FnMut(usize),
) {
    let (a, b) = bound;
    let c = Vec3::from(p.center_m);
    let r = p.radius_m + shell_m;
    let first = ((a - lo) / cell).floor();
    let last = ((b - lo) / cell).floor();
    let range = |ax: usize| {
        let f = first[ax].max(0.0) as u32;
        let l = (last[ax].max(0.0) as u32).min(dims[ax] - 1);
        f..=l
    };
    for iz in range(2) {
        for iy in range(1) {
            for ix in range(0) {
                let cmin = lo + cell * Vec3::new(ix as f32, iy as f32, iz as f32);
                let cmax = cmin + cell;
                // Sphere–box test, and the box must reach above the cut.
                let q = c.clamp(cmin, cmax);
                if q.distance_squared(c) <= r * r && cmax.z >= a.z {
                    visit((ix + dims[0] * (iy + dims[1] * iz)) as usize);
                }
            }
        }
    }
}

/// Fills the cell lists; None when they exceed [`MAX_GRID_ENTRIES`].
fn fill_grid(
    live: &[GpuParcel],
    bounds: &[(Vec3, Vec3)],
    lo: Vec3,
    cell: Vec3,
    dims: [u32; 3],
    shell_m: f32,
    grid: &mut GridUniform,
) -> Option<u32> {
    let ncells = (dims[0] * dims[1] * dims[2]) as usize;
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); ncells];
    for (i, (p, bound)) in live.iter().zip(bounds).enumerate() {
        for_each_touched_cell(p, *bound, shell_m, (lo, cell, dims), |ci| {
            lists[ci].push(i as u32)
        });
    }
    let total: usize = lists.iter().map(Vec::len).sum();
    if total > MAX_GRID_ENTRIES {
        return None;
    }
    *grid = GridUniform::zeroed();
    let mut j = 0u32;
    for (ci, list) in lists.iter().enumerate() {
        let slot = &mut grid.cells[ci / 2];
        let o = (ci % 2) * 2;
        slot[o] = j;
        slot[o + 1] = list.len() as u32;
        for &p in list {
            grid.entries[j as usize / 4][j as usize % 4] = p;
            j += 1;
        }
    }
    Some(j)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A condensed parcel at (x, y, z) of radius r, its plane half a radius
    /// under its centre.
    pub(crate) fn parcel(x: f32, y: f32, z: f32, r: f32) -> CloudParcel {
        CloudParcel {
            id: 0,
            center_m: Vec3::new(x, y, z),
            radius_m: r,
            fill: 0.8,
            cond_plane_z_m: z - 0.5 * r,
        }
    }

    #[test]
    fn sizes_and_alignment_match_wgsl() {
        assert_eq!(std::mem::size_of::<GridUniform>() % 16, 0);
    }

    #[test]
    fn empty_packs_to_zero_parcels() {
        let p = pack(&[], 100.0, 1.0).unwrap();
        assert_eq!(p.info.parcel_count, 0);
        assert_eq!(p.info.entry_count, 0);
    }

    #[test]
    fn parcel_fields_land_in_place() {
        let p = pack(&[parcel(10.0, 20.0, 1500.0, 300.0)], 50.0, 1.0).unwrap();
        let g = p.parcels.parcels[0];
        assert_eq!((g.center_m, g.radius_m), ([10.0, 20.0, 1500.0], 300.0));
        assert_eq!(g.fill, 0.8);
        assert_eq!(g.plane_z_m, 1350.0);
        // Grid bottom is the plane minus the shell, not the sphere bottom.
        assert!((p.info.min.z - 1300.0).abs() < 1e-3, "{:?}", p.info);
    }

    #[test]
    fn every_cell_the_sphere_touches_lists_it_and_no_other() {
        let parcels: Vec<_> = (0..12)
            .map(|i| {
                parcel(
                    i as f32 * 700.0 - 4000.0,
                    (i % 3) as f32 * 900.0,
                    1800.0,
                    400.0,
                )
            })
            .collect();
        let shell = 100.0;
        let p = pack(&parcels, shell, 1.0).unwrap();
        let info = p.info;
        assert_eq!(info.coarsened, 0);
        let mut total = 0;
        for iz in 0..info.dims[2] {
            for iy in 0..info.dims[1] {
                for ix in 0..info.dims[0] {
                    let list = p.cell_list(ix, iy, iz);
                    total += list.len();
                    let cmin = info.min + info.cell * Vec3::new(ix as f32, iy as f32, iz as f32);
                    let cmax = cmin + info.cell;
                    for (i, q) in parcels.iter().enumerate() {
                        let r = q.radius_m + shell;
                        let d = q.center_m.clamp(cmin, cmax).distance(q.center_m);
                        let above = cmax.z >= q.cond_plane_z_m - shell;
                        // Compare away from the exact boundary (float rounding).
                        if d < r - 1.0 && above {
                            assert!(list.contains(&(i as u32)), "cell {ix},{iy},{iz} misses {i}");
                        }
                        if d > r + 1.0 {
                            assert!(!list.contains(&(i as u32)), "cell {ix},{iy},{iz} lists {i}");
                        }
                    }
                }
            }
        }
        assert_eq!(total as u32, info.entry_count);
        assert!(info.dims.iter().product::<u32>() > 1);
    }

    #[test]
    fn too_many_parcels_is_an_error_not_truncation() {
        let parcels: Vec<_> = (0..MAX_PARCELS + 1)
            .map(|i| parcel(i as f32 * 10.0, 0.0, 1500.0, 50.0))
            .collect();
        let e = pack(&parcels, 10.0, 1.0).unwrap_err().to_string();
        assert!(e.contains(&format!("at most {MAX_PARCELS}")), "{e}");
    }

    #[test]
    fn overflowing_lists_coarsen_the_grid() {
        // Many large overlapping spheres touch most cells of a fine grid.
        let parcels: Vec<_> = (0..MAX_PARCELS)
            .map(|i| {
                parcel(
                    (i % 23) as f32 * 400.0,
                    (i / 23) as f32 * 400.0,
                    2000.0,
                    1500.0,
                )
            })
            .collect();
        let p = pack(&parcels, 200.0, 1.0).unwrap();
        assert!(p.info.coarsened > 0, "{:?}", p.info);
        assert!(p.info.entry_count as usize <= MAX_GRID_ENTRIES);
        assert_eq!(p.info.parcel_count as usize, MAX_PARCELS);
    }

    #[test]
    fn empty_and_nan_parcels() {
        let mut q = parcel(0.0, 0.0, 1000.0, 100.0);
        q.fill = 0.0;
        assert_eq!(pack(&[q], 10.0, 1.0).unwrap().info.parcel_count, 0);
        q.center_m.x = f32::NAN;
        assert!(pack(&[q], 10.0, 1.0).is_err());
    }
}
