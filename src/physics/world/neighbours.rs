//! Stage 3: the neighbour grid. A counting sort puts the parcels into a
//! uniform grid whose cells are at least the search radius; each parcel then
//! lists its neighbours by scanning the 27 surrounding cells in a fixed
//! order (cells in index order, parcels in creation order within a cell).
//! The list of parcel i depends only on the positions, never on how the
//! work is split between threads, so every later stage that reads it gives
//! bit-identical results at any thread count.
//!
//! Two kinds of pairs are listed: SPH pairs (d < h) and geometric contacts
//! (d < r_i + r_j), whatever their distance relative to h. Spheres grow with
//! height (eq 6) and entrainment, so contacts beyond h are common: the search
//! radius is max(h, 2 r_max) over the living parcels, and no overlap is ever
//! skipped.

use glam::DVec3;
use rayon::prelude::*;

use super::PAR_MIN;

use super::ParcelWorld;

/// Parcels per block of the neighbour lists: each block is filled by one
/// task into its own reused buffer, so building the lists allocates nothing
/// once the buffers have grown.
const BLOCK: usize = 256;

/// One neighbour of a parcel: within the SPH support radius or touching.
/// 16 bytes: the lists are read by five stages, so their size is memory
/// traffic; the few stages that need x_i − x_j take it from the positions
/// of the build (`ParcelWorld::hot_pos`, unchanged until the next drift),
/// the same subtraction as here.
#[derive(Debug, Clone, Copy)]
pub(super) struct Neighbour {
    pub(super) j: usize,
    /// |x_i − x_j|. units: m
    pub(super) dist: f64,
}

/// The uniform grid: cells and the parcels sorted into them.
#[derive(Debug, Clone, Default)]
struct Cells {
    /// Corner of cell (0, 0, 0). units: m
    origin: DVec3,
    /// Cell edge (≥ the search radius). units: m
    cell_m: f64,
    /// Cells along x, y, z.
    dims: [usize; 3],
    /// First index into `sorted` of each cell (and one past the last).
    cell_start: Vec<u32>,
    /// Parcel indices sorted by cell, stable (creation order within a cell).
    sorted: Vec<u32>,
    /// Cell of each parcel.
    cell_of: Vec<u32>,
    /// Placement cursor of each cell (scratch of the sort).
    cursor: Vec<u32>,
}

/// The grid and the neighbour lists built from it.
#[derive(Debug, Clone, Default)]
pub(super) struct NeighbourGrid {
    cells: Cells,
    /// Neighbour lists, one buffer per block of `BLOCK` parcels.
    blocks: Vec<Vec<Neighbour>>,
    /// Range of parcel i's neighbours in its block's buffer.
    range: Vec<(u32, u32)>,
    /// Whether any pair is listed.
    pub(super) any: bool,
}

impl NeighbourGrid {
    /// Parcel i's neighbours.
    pub(super) fn of(&self, i: usize) -> &[Neighbour] {
        let (s, e) = self.range[i];
        &self.blocks[i / BLOCK][s as usize..e as usize]
    }
}

impl Cells {
    /// Cell coordinates of a position (clamped into the grid).
    fn coords(&self, x: DVec3) -> [usize; 3] {
        let c = (x - self.origin) / self.cell_m;
        // `as` saturates: negative (rounding below the origin) becomes 0.
        [
            (c.x as usize).min(self.dims[0] - 1),
            (c.y as usize).min(self.dims[1] - 1),
            (c.z as usize).min(self.dims[2] - 1),
        ]
    }

    /// Counting sort of `pos` into a grid of cells no smaller than `search_m`.
    fn sort(&mut self, pos: &[DVec3], search_m: f64) {
        let n = pos.len();
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        for x in pos {
            lo = lo.min(*x);
            hi = hi.max(*x);
        }
        if n == 0 {
            (lo, hi) = (DVec3::ZERO, DVec3::ZERO);
        }
        // Cells ≥ the search radius (so 27 cells cover it), and no more
        // than 4n + 4096 cells (so a few parcels far apart, or a tiny h,
        // cannot ask for a huge grid): coarser cells only cost more tests.
        let extent = hi - lo;
        let max_cells = (4 * n + 4096) as f64;
        let count = |c: f64| {
            ((extent.x / c).floor() + 1.0)
                * ((extent.y / c).floor() + 1.0)
                * ((extent.z / c).floor() + 1.0)
        };
        let mut cell = search_m.max(1e-3);
        if count(cell) > max_cells {
            let vol = extent.x.max(cell) * extent.y.max(cell) * extent.z.max(cell);
            cell = cell.max((vol / max_cells).cbrt());
            while count(cell) > max_cells {
                cell *= 1.25;
            }
        }
        self.origin = lo;
        self.cell_m = cell;
        self.dims = [
            (extent.x / cell).floor() as usize + 1,
            (extent.y / cell).floor() as usize + 1,
            (extent.z / cell).floor() as usize + 1,
        ];
        let cells = self.dims[0] * self.dims[1] * self.dims[2];
        self.cell_start.clear();
        self.cell_start.resize(cells + 1, 0);
        self.cell_of.clear();
        for x in pos {
            let [a, b, c] = self.coords(*x);
            let k = (a * self.dims[1] + b) * self.dims[2] + c;
            self.cell_of.push(k as u32);
            self.cell_start[k + 1] += 1;
        }
        for k in 0..cells {
            self.cell_start[k + 1] += self.cell_start[k];
        }
        // Stable placement: a cursor per cell, parcels in index order.
        self.sorted.clear();
        self.sorted.resize(n, 0);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.cell_start[..cells]);
        for (i, &k) in self.cell_of.iter().enumerate() {
            let slot = &mut self.cursor[k as usize];
            self.sorted[*slot as usize] = i as u32;
            *slot += 1;
        }
    }

    /// Calls `f(j)` for every parcel j in the 27 cells around position `x`,
    /// in the fixed order (columns (dx, dy), then z cells, then index).
    fn scan(&self, x: DVec3, mut f: impl FnMut(usize)) {
        let [a, b, c] = self.coords(x);
        let (z0, z1) = (c.saturating_sub(1), (c + 1).min(self.dims[2] - 1));
        for ia in a.saturating_sub(1)..=(a + 1).min(self.dims[0] - 1) {
            for ib in b.saturating_sub(1)..=(b + 1).min(self.dims[1] - 1) {
                // Cells z0..=z1 of one (x, y) column are contiguous.
                let col = (ia * self.dims[1] + ib) * self.dims[2];
                let (s, e) = (
                    self.cell_start[col + z0] as usize,
                    self.cell_start[col + z1 + 1] as usize,
                );
                for &j in &self.sorted[s..e] {
                    f(j as usize);
                }
            }
        }
    }

    /// Whether some pair lies closer than `d_m`; beyond the cell size the
    /// grid cannot tell, and the answer is "yes" whenever there is a pair.
    fn any_closer(&self, pos: &[DVec3], d_m: f64) -> bool {
        if d_m > self.cell_m {
            return pos.len() > 1;
        }
        let d2 = d_m * d_m;
        (0..pos.len())
            .into_par_iter()
            .with_min_len(PAR_MIN)
            .any(|i| {
                let mut hit = false;
                self.scan(pos[i], |j| {
                    hit |= j != i && (pos[i] - pos[j]).length_squared() < d2;
                });
                hit
            })
    }
}

impl ParcelWorld {
    /// Gathers positions and radii, sorts the grid and lists every parcel's
    /// SPH neighbours and contacts (in parallel, one block per task).
    pub(super) fn build_neighbours(&mut self) {
        let c = &self.cfg.physics;
        let need = c.sph || c.viscosity || c.needs_exposed_area() || c.exchange;
        let h = c.support_radius_m;
        self.parcels
            .par_iter()
            .with_min_len(PAR_MIN)
            .map(|p| (p.position_m, p.radius_m))
            .unzip_into_vecs(&mut self.hot_pos, &mut self.hot_radius);
        let r_max = self.hot_radius.iter().fold(0.0_f64, |a, &b| a.max(b));
        let g = &mut self.grid;
        g.cells.sort(&self.hot_pos, h.max(2.0 * r_max));
        let n = self.parcels.len();
        let blocks = n.div_ceil(BLOCK);
        if g.blocks.len() < blocks {
            g.blocks.resize_with(blocks, Vec::new);
        }
        g.range.clear();
        g.range.resize(n, (0, 0));
        let (pos, rad, cells) = (&self.hot_pos, &self.hot_radius, &g.cells);
        let h2 = h * h;
        g.blocks[..blocks]
            .par_iter_mut()
            .zip(g.range.par_chunks_mut(BLOCK))
            .enumerate()
            .for_each(|(b, (list, ranges))| {
                list.clear();
                if !need {
                    return;
                }
                for (k, out) in ranges.iter_mut().enumerate() {
                    let i = b * BLOCK + k;
                    let start = list.len() as u32;
                    let xi = pos[i];
                    cells.scan(xi, |j| {
                        if j == i {
                            return;
                        }
                        let r = xi - pos[j];
                        let d2 = r.length_squared();
                        let touch = rad[i] + rad[j];
                        if d2 < h2 || d2 < touch * touch {
                            list.push(Neighbour { j, dist: d2.sqrt() });
                        }
                    });
                    *out = (start, list.len() as u32);
                }
            });
        g.any = g.range.iter().any(|(s, e)| e > s);
    }

    /// Whether two parcels can come within the SPH support radius during
    /// the next `frame_dt_s`: a listed pair, or a pair closer than h plus
    /// the most two parcels can close in that time (2 v_max T + a_max T²),
    /// from the positions of the last neighbour build.
    pub(super) fn contact_possible(&self, frame_dt_s: f64, vmax: f64, amax: f64) -> bool {
        let h = self.cfg.physics.support_radius_m;
        let reach = h + 2.0 * vmax * frame_dt_s + amax * frame_dt_s * frame_dt_s;
        self.grid.any || self.grid.cells.any_closer(&self.hot_pos, reach)
    }
}
