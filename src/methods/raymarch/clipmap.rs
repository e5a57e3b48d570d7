//! How the `baked` method divides the clouds' box into levels: a
//! camera-centred clipmap. When the whole box fits [`MAX_BAKE_VOXELS`] at
//! the voxel the radii ask for ([`wanted_voxel_m`]) it is one level, the
//! box itself (padded by one empty voxel). Otherwise it is 2 to
//! [`MAX_CLIP_LEVELS`] nested levels at 2× voxel steps: level k has voxels
//! of `h0·2^k`, covers a square of the same number of voxels across
//! centred on the camera (snapped to a world grid of [`RECENTRE_CELLS`]
//! level-0 cells, so a small camera move neither re-bakes nor shifts the
//! voxels), cut to the box and spanning the box's whole height; the last
//! level is the whole box. The level side is the largest the budget
//! allows; the finest voxel `h0` is enlarged (by 2^¼ steps, counted in
//! `coarsened`) only when no level count fits, so no box is refused for
//! its shape. The march samples the finest level whose texels surround the
//! sample ([`Clipmap::level_at`], shaders/raymarch/clipmap.wgsl
//! `clip_level`).
//!
//! On the GPU the levels sit one above the other along z in one field
//! texture, one light volume and one key buffer, and their occupancy
//! pyramids one after the other in one buffer; [`ClipUniform`] says where.

use glam::Vec3;

use crate::methods::raymarch::baked::{BAKE_BLOCK, occupancy_cells};
use crate::methods::raymarch::pack::GpuParcel;
use crate::methods::raymarch::region::{parcel_box, wanted_voxel_m};

/// Most voxels of the baked field, all levels together (12 B a voxel:
/// 768 MiB). A cloud layer 2 km deep (the 100 km landscape's, drawn
/// spheres included) at 45 m voxels over the 41 km square that keeps them
/// within 20 km of the camera is 3.7·10⁷ voxels in level 0 alone; 2²⁵
/// would leave 19 km.
pub const MAX_BAKE_VOXELS: u64 = 1 << 26;
// The splat's keys fit its two key buffers (baked.rs).
const _: () = assert!(MAX_BAKE_VOXELS <= 2 * crate::methods::raymarch::baked::KEY_SPLIT);
/// Most levels: MAX_CLIP_LEVELS of shaders/raymarch/clipmap.wgsl (a test
/// compares them). Five levels at 2× steps take a 40 km level-0 square to
/// 640 km, more than any scene holds.
pub const MAX_CLIP_LEVELS: usize = 5;
/// Most voxels along one side of the stacked texture (WebGPU's default
/// `max_texture_dimension_3d`).
pub const MAX_SIDE: u32 = 2048;
/// The camera is snapped to a world grid of this many level-0 cells: the
/// levels move (and the field re-bakes) only when it crosses a grid line.
/// 8 cells (32 voxels, 1.4 km at 45 m) shorten the fine level's reach on
/// one side of the camera by at most 4 cells.
pub const RECENTRE_CELLS: f32 = 8.0;

/// One level: a box of cubic voxels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClipLevel {
    /// Lowest corner (of voxel 0's cube). units: m
    pub min: Vec3,
    /// Voxel side. units: m
    pub voxel_m: f32,
    /// Coarse occupancy cells per axis (voxels = cells × BAKE_BLOCK).
    pub cells: [u32; 3],
}

impl ClipLevel {
    /// Voxels per axis.
    pub fn voxel_dims(&self) -> [u32; 3] {
        self.cells.map(|c| c * BAKE_BLOCK)
    }

    /// Voxels in all.
    pub fn voxels(&self) -> u64 {
        self.voxel_dims().iter().map(|&d| d as u64).product()
    }

    /// Coarse cell side. units: m
    pub fn cell_m(&self) -> f32 {
        self.voxel_m * BAKE_BLOCK as f32
    }

    /// Highest corner. units: m
    pub fn max(&self) -> Vec3 {
        self.min + Vec3::from(self.cells.map(|c| c as f32)) * self.cell_m()
    }

    /// Whether a trilinear fetch at `p` reads only this level's texels
    /// (p at least half a voxel inside): clipmap.wgsl `clip_inside`.
    pub fn surrounds(&self, p: Vec3) -> bool {
        let rel = (p - self.min) / self.voxel_m;
        let dims = Vec3::from(self.voxel_dims().map(|d| d as f32));
        rel.cmpge(Vec3::splat(0.5)).all() && rel.cmple(dims - 0.5).all()
    }
}

/// The levels of one bake, finest first; see the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct Clipmap {
    pub levels: Vec<ClipLevel>,
    /// Voxel side the radii asked for. units: m
    pub wanted_voxel_m: f32,
    /// How many 2^¼ steps the finest voxel was enlarged to fit the budget.
    pub coarsened: u32,
}

impl Clipmap {
    /// The finest level whose texels surround `p`; None outside the field
    /// (no cloud there).
    pub fn level_at(&self, p: Vec3) -> Option<usize> {
        self.levels.iter().position(|l| l.surrounds(p))
    }

    /// The voxel side the march samples at `p`; None outside the field.
    /// units: m
    pub fn voxel_at(&self, p: Vec3) -> Option<f32> {
        self.level_at(p).map(|l| self.levels[l].voxel_m)
    }

    /// The outermost level: the whole box (the frame's grid).
    pub fn top(&self) -> &ClipLevel {
        self.levels.last().expect("a clipmap has a level")
    }

    /// Voxels of every level.
    pub fn voxels(&self) -> u64 {
        self.levels.iter().map(ClipLevel::voxels).sum()
    }

    /// Coarse cells of the stacked light volume: the widest level across,
    /// the levels one above the other.
    pub fn stacked_cells(&self) -> [u32; 3] {
        let m = |a: usize| self.levels.iter().map(|l| l.cells[a]).max().unwrap_or(1);
        [m(0), m(1), self.levels.iter().map(|l| l.cells[2]).sum()]
    }

    /// Voxels of the stacked field texture.
    pub fn stacked_dims(&self) -> [u32; 3] {
        self.stacked_cells().map(|c| c * BAKE_BLOCK)
    }

    /// The levels as the shaders read them.
    pub fn uniform(&self) -> ClipUniform {
        let mut u = ClipUniform::zeroed();
        u.count = [self.levels.len() as u32, 0, 0, 0];
        let (mut occupancy, mut keys, mut z) = (0u64, 0u64, 0u32);
        for (g, l) in u.levels.iter_mut().zip(&self.levels) {
            g.min_voxel = [l.min.x, l.min.y, l.min.z, l.voxel_m];
            g.cells = [l.cells[0], l.cells[1], l.cells[2], z];
            g.offsets = [occupancy as u32, keys as u32, 0, 0];
            occupancy += occupancy_cells(l.cells);
            keys += l.voxels();
            z += l.cells[2];
        }
        u
    }

    /// Entries of all the occupancy pyramids.
    pub fn occupancy_cells(&self) -> u64 {
        self.levels.iter().map(|l| occupancy_cells(l.cells)).sum()
    }
}

/// One level of a clipmap: `ClipLevel` of shaders/raymarch/clipmap.wgsl
/// (a test checks the layout against naga's).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuClipLevel {
    /// xyz: lowest corner (m), w: voxel side (m).
    pub min_voxel: [f32; 4],
    /// xyz: coarse cells per axis, w: the level's first cell along z in
    /// the stacked volumes.
    pub cells: [u32; 4],
    /// x: first occupancy entry, y: first voxel key; z, w unused.
    pub offsets: [u32; 4],
}

/// The clipmap's uniform: `Clipmap` of shaders/raymarch/clipmap.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ClipUniform {
    /// x: levels in use.
    pub count: [u32; 4],
    pub levels: [GpuClipLevel; MAX_CLIP_LEVELS],
}

const _: () = assert!(std::mem::size_of::<ClipUniform>() == 16 + 48 * MAX_CLIP_LEVELS);

impl ClipUniform {
    fn zeroed() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

/// The whole padded box at voxel `h` (one empty voxel all round: outside
/// it the field reads v = −1, as far from every parcel).
fn whole(lo: Vec3, hi: Vec3, h: f32) -> ClipLevel {
    let min = lo - Vec3::splat(h);
    let ext = hi - lo + Vec3::splat(2.0 * h);
    let cell = h * BAKE_BLOCK as f32;
    ClipLevel {
        min,
        voxel_m: h,
        cells: [0, 1, 2].map(|a| ((ext[a] / cell).ceil() as u32).max(1)),
    }
}

/// A square of `side` cells at voxel `h` around `centre` (its corner on
/// the world's cell grid), cut to the padded box.
fn square(lo: Vec3, hi: Vec3, h: f32, centre: Vec3, side: u32) -> ClipLevel {
    let box_ = whole(lo, hi, h);
    let cell = box_.cell_m();
    let (bmin, bmax) = (box_.min, box_.max());
    let mut min = box_.min;
    let mut cells = box_.cells;
    for a in 0..2 {
        let start = ((centre[a] / cell).floor() - (side / 2) as f32) * cell;
        let end = start + side as f32 * cell;
        // Clamped into the box, so a camera far outside still gives a
        // level (at the box's near edge) and the levels stay nested.
        let a0 = start.min(bmax[a] - cell).max(bmin[a]);
        let a1 = end.min(bmax[a]).max(a0 + cell);
        min[a] = a0;
        cells[a] = (((a1 - a0) / cell).ceil() as u32).max(1);
    }
    ClipLevel {
        min,
        voxel_m: h,
        cells,
    }
}

/// Whether the levels fit the budget and the stacked texture's sides.
fn fits(levels: &[ClipLevel]) -> bool {
    let m = Clipmap {
        levels: levels.to_vec(),
        wanted_voxel_m: 0.0,
        coarsened: 0,
    };
    m.voxels() <= MAX_BAKE_VOXELS && m.stacked_dims().iter().all(|&d| d <= MAX_SIDE)
}

/// `count` levels from voxel `h0` with fine squares of `side` cells.
fn levels(lo: Vec3, hi: Vec3, h0: f32, centre: Vec3, count: usize, side: u32) -> Vec<ClipLevel> {
    let h = |k: usize| h0 * (1u32 << k) as f32;
    let mut v: Vec<ClipLevel> = (0..count - 1)
        .map(|k| square(lo, hi, h(k), centre, side))
        .collect();
    v.push(whole(lo, hi, h(count - 1)));
    v
}

/// The clipmap of `live` parcels (not empty) seen from `camera`; see the
/// module docs.
pub fn clipmap(live: &[GpuParcel], shell_m: f32, camera: Vec3) -> Clipmap {
    let wanted = wanted_voxel_m(live, shell_m);
    let (lo, hi) = parcel_box(live, shell_m);
    let mut h0 = wanted;
    let mut coarsened = 0;
    loop {
        if let Some(levels) = fit(lo, hi, h0, camera) {
            return Clipmap {
                levels,
                wanted_voxel_m: wanted,
                coarsened,
            };
        }
        h0 *= 2f32.powf(0.25);
        coarsened += 1;
    }
}

/// The levels at finest voxel `h0`, or None when no level count fits.
fn fit(lo: Vec3, hi: Vec3, h0: f32, camera: Vec3) -> Option<Vec<ClipLevel>> {
    let one = [whole(lo, hi, h0)];
    if fits(&one) {
        return Some(one.to_vec());
    }
    let grid = RECENTRE_CELLS * h0 * BAKE_BLOCK as f32;
    let centre = ((camera / grid).round()) * grid;
    // For each level count, the widest fine squares that fit; the count
    // whose level 0 reaches furthest wins (the fewest levels on a tie).
    let mut best: Option<(u32, Vec<ClipLevel>)> = None;
    for count in 2..=MAX_CLIP_LEVELS {
        let at = |side| levels(lo, hi, h0, centre, count, side);
        if !fits(&at(1)) {
            continue;
        }
        let (mut ok, mut too_big) = (1u32, MAX_SIDE / BAKE_BLOCK + 1);
        while too_big - ok > 1 {
            let mid = (ok + too_big) / 2;
            if fits(&at(mid)) {
                ok = mid;
            } else {
                too_big = mid;
            }
        }
        if best.as_ref().is_none_or(|(s, _)| ok > *s) {
            best = Some((ok, at(ok)));
        }
    }
    best.map(|(_, v)| v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parcel(x: f32, y: f32, z: f32, r: f32) -> GpuParcel {
        GpuParcel {
            center_m: [x, y, z],
            radius_m: r,
            fill: 1.0,
            plane_z_m: z - 0.5 * r,
            _pad: [0.0; 2],
        }
    }

    #[test]
    fn a_small_scene_is_one_level_the_padded_box() {
        let live = [
            parcel(0.0, 0.0, 2000.0, 400.0),
            parcel(900.0, 0.0, 2500.0, 400.0),
        ];
        let m = clipmap(&live, 280.0, Vec3::new(-5000.0, 0.0, 100.0));
        assert_eq!(m.levels.len(), 1);
        assert_eq!(m.coarsened, 0);
        let (lo, _) = parcel_box(&live, 280.0);
        let l = m.levels[0];
        assert_eq!(l.min, lo - Vec3::splat(l.voxel_m));
        assert_eq!(l.voxel_m, m.wanted_voxel_m);
    }

    /// Parcels of radius 200 m (45 m voxels) over `side_m` × `side_m`, in a
    /// layer 1.2–2.2 km high.
    fn field(side_m: f32) -> Vec<GpuParcel> {
        let n = 40;
        let mut live = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let x = (i as f32 / n as f32 - 0.5) * side_m;
                let y = (j as f32 / n as f32 - 0.5) * side_m;
                live.push(parcel(x, y, 1500.0 + ((i * j) % 3) as f32 * 200.0, 200.0));
            }
        }
        live
    }

    #[test]
    fn a_100_km_field_keeps_fine_voxels_within_20_km_of_the_camera() {
        let live = field(100_000.0);
        let camera = Vec3::new(-30_000.0, 10_000.0, 300.0);
        let m = clipmap(&live, 150.0, camera);
        assert!(m.levels.len() > 1 && m.levels.len() <= MAX_CLIP_LEVELS);
        assert!(m.voxels() <= MAX_BAKE_VOXELS);
        // Every point of the cloud layer within 20 km (horizontally) of the
        // camera is sampled at ≤ 50 m.
        for i in -20..=20 {
            for j in -20..=20 {
                let d = Vec3::new(i as f32, j as f32, 0.0) * 1000.0;
                if d.length() > 20_000.0 {
                    continue;
                }
                for z in [1400.0, 1800.0, 2300.0] {
                    let p = camera + d + Vec3::new(0.0, 0.0, z - camera.z);
                    if p.x.abs() > 50_000.0 || p.y.abs() > 50_000.0 {
                        continue;
                    }
                    let v = m.voxel_at(p).unwrap_or(f32::INFINITY);
                    assert!(v <= 50.0, "{v} m voxels at {p} ({} levels)", m.levels.len());
                }
            }
        }
        // And the whole field is covered, however far from the camera.
        assert!(m.voxel_at(Vec3::new(49_000.0, -49_000.0, 1500.0)).is_some());
    }

    #[test]
    fn levels_nest_at_twice_the_voxel() {
        let live = field(100_000.0);
        let m = clipmap(&live, 150.0, Vec3::ZERO);
        // Nested within the parcels' box (past it a level may stick out by
        // its rounding to whole cells, but there every level is empty).
        let (lo, hi) = parcel_box(&live, 150.0);
        let inside = |l: &ClipLevel| (l.min.max(lo), l.max().min(hi));
        for w in m.levels.windows(2) {
            assert_eq!(w[1].voxel_m, 2.0 * w[0].voxel_m);
            let ((a0, a1), (b0, b1)) = (inside(&w[0]), inside(&w[1]));
            assert!(a0.cmpge(b0).all() && a1.cmple(b1).all(), "{w:?}");
        }
    }

    #[test]
    fn a_long_thin_region_is_not_refused() {
        // 400 km along x, 1 km across: too long for one texture side at
        // any voxel near the wanted one.
        let live: Vec<_> = (0..=400)
            .map(|i| parcel(i as f32 * 1000.0, 0.0, 2000.0, 300.0))
            .collect();
        let m = clipmap(&live, 280.0, Vec3::new(0.0, 0.0, 500.0));
        assert!(m.stacked_dims().iter().all(|&d| d <= MAX_SIDE));
        assert!(m.voxel_at(Vec3::new(399_000.0, 0.0, 2000.0)).is_some());
        assert!(m.voxel_at(Vec3::new(0.0, 0.0, 2000.0)).unwrap() <= m.levels[0].voxel_m);
    }

    #[test]
    fn a_small_camera_move_keeps_the_levels() {
        let live = field(100_000.0);
        let a = clipmap(&live, 150.0, Vec3::new(1000.0, 0.0, 300.0));
        let b = clipmap(&live, 150.0, Vec3::new(1100.0, 50.0, 300.0));
        assert_eq!(a, b);
    }
}
