//! Clouds as connected groups of spheres (parcels, or the bounding spheres
//! of authored ellipsoids): which primitives make one cloud. The render
//! methods that draw a cloud as a whole read it: the sprites shade
//! touching parcels as one cloud (Wang 2003 §5), the slices give each
//! cloud its own stack of planes (Schpok 2003 slices one cloud). A
//! union-find over a uniform grid of the spheres' centres.

use glam::{IVec3, Vec3};

/// The group each sphere (centre, radius in m) belongs to: spheres whose
/// centres are closer than `reach` × the sum of their radii, and for which
/// `also(i, j)` holds, are joined, through any chain of such pairs.
/// Returns a group index per sphere, numbered in order of first sphere.
pub fn touching_groups(
    spheres: &[(Vec3, f32)],
    reach: f32,
    also: &dyn Fn(usize, usize) -> bool,
) -> Vec<usize> {
    let n = spheres.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let r_max = spheres.iter().map(|s| s.1).fold(1.0f32, f32::max);
    // Two joined spheres are at most reach × 2 r_max apart.
    let centres: Vec<Vec3> = spheres.iter().map(|s| s.0).collect();
    near_pairs(&centres, 2.0 * reach * r_max, |i, j| {
        let ((c, r), (cj, rj)) = (spheres[i], spheres[j]);
        let d = reach * (r + rj);
        if j > i && c.distance_squared(cj) < d * d && also(i, j) {
            let (a, b) = (root(&mut parent, i), root(&mut parent, j));
            parent[a.max(b)] = a.min(b);
        }
    });
    let mut index = vec![usize::MAX; n];
    let mut next = 0;
    (0..n)
        .map(|i| {
            let r = root(&mut parent, i);
            if index[r] == usize::MAX {
                index[r] = next;
                next += 1;
            }
            index[r]
        })
        .collect()
}

/// Points on a uniform grid of side `cell`, to find those near a place.
pub struct PointGrid {
    cell: f32,
    cells: std::collections::HashMap<IVec3, Vec<usize>>,
}

impl PointGrid {
    /// The grid of `points` (indices into it) with cells of side `cell`.
    pub fn new(points: &[Vec3], cell: f32) -> Self {
        let mut grid = PointGrid {
            cell,
            cells: Default::default(),
        };
        for (i, &p) in points.iter().enumerate() {
            grid.cells.entry(grid.cell_of(p)).or_default().push(i);
        }
        grid
    }

    /// The cell holding `p`.
    pub fn cell_of(&self, p: Vec3) -> IVec3 {
        (p / self.cell).floor().as_ivec3()
    }

    /// Calls `near(j)` for every point `j` in the 27 cells around `at`
    /// (every point closer than `cell` among others), in a fixed order.
    pub fn around(&self, at: Vec3, near: impl FnMut(usize)) {
        self.around_cell(self.cell_of(at), near);
    }

    /// [`Self::around`] for every place in the cell `k`.
    pub fn around_cell(&self, k: IVec3, mut near: impl FnMut(usize)) {
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(list) = self.cells.get(&(k + IVec3::new(dx, dy, dz))) {
                        list.iter().for_each(|&j| near(j));
                    }
                }
            }
        }
    }
}

/// Calls `near(i, j)` for every point `i` and every point `j` (itself
/// included) in the 27 grid cells of side `cell` around it: every pair
/// closer than `cell` among others, each ordered pair once.
pub fn near_pairs(centres: &[Vec3], cell: f32, mut near: impl FnMut(usize, usize)) {
    let grid = PointGrid::new(centres, cell);
    for (i, &c) in centres.iter().enumerate() {
        grid.around(c, |j| near(i, j));
    }
}
