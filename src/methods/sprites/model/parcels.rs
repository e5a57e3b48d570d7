//! Physics parcels as sprite clouds, so a physics scene can be drawn as
//! sprites too. Each condensed parcel becomes a cloud of one box sized by
//! its radius (down to its condensation plane: the flat base), filled in
//! proportion to its fill. Parcels that touch form one cloud for the
//! shading (paper §5): its colour levels run from the cloud's base to its
//! top, and the directional term of every one of its sprites looks from
//! the whole cloud's centre, its billow's (the parcels around it) and its
//! parcel's, so a tower has a sunlit side, a shaded side and a dark base,
//! and each billow its own lit side and shaded creases.

use glam::{IVec3, Vec3};
use rayon::prelude::*;

use super::atlas::{FLAT_BOTTOM_TILE, PUFFY_TILES};
use super::cloud::{PRUNE_TYPICAL, ShadeCenters, SpriteBox, SpriteCloud, SpriteCloudSpec};
use super::presets::CloudType;
use super::shading::{ColorLevel, DirectionalMap, LEVELS};
use crate::physics::CloudParcel;

/// Sprites of a parcel at fill 1: a parcel sphere is drawn with up to this
/// many sprites, fewer as its fill drops (never fewer than the paper's 5).
/// 80 of [`PARCEL_ALPHA`] rather than 40 opaque ones: the edge of a sphere
/// builds up over several sprites, softer, as the path-traced parcels'.
/// Chosen against the path tracer (issue 32) with the sunlit shares: 60
/// of alpha 0.42 left the towering cumulus at 0.0701 at 320×240, 80 of
/// 0.35 0.0695 (its sprite pass 1.2× as long), 100 of 0.3 0.0686 (1.4×).
pub const PARCEL_SPRITES: u32 = 80;

/// Alpha of every colour level of a physics cloud (eq. 3's level alpha):
/// about a third, so a sphere's edge builds up over several sprites and
/// its inside over many ([`PARCEL_SPRITES`]).
pub const PARCEL_ALPHA: f32 = 0.35;

/// Side of a parcel's sprites, × its (drawn) radius ([`PARCEL_ALPHA`]).
pub const PARCEL_SPRITE_SIZE: f32 = 0.83;

/// A parcel's billow, for the directional term: the parcels whose centres
/// lie within this × its (drawn) radius ([`billow_centers`]).
pub const BILLOW_REACH: f32 = 3.0;

/// How much more a parcel straight above counts in a billow's centre than
/// one beside it (× the sine of its elevation, none below): the part of
/// a cloud under another part is shaded, as the path tracer shows under a
/// high sun (issue 32: towering cumulus 0.093 → 0.082 FLIP). The sun's own
/// direction in place of straight up did no better (0.0815 against 0.0812
/// on that frame): what lies between a parcel and the sun is
/// [`sunlit_shares`]' part.
pub const BILLOW_ABOVE: f32 = 18.0;

/// The directional mapping (§5.2) of a physics cloud: a side-on sprite
/// gets 0.63 of the sun (the paper's default 0.45 is for authored clouds,
/// whose shading groups are the whole light/dark split), the sunward one
/// a little more than the sun (the sunlit share dims it inside the cloud).
pub const PARCEL_MAP: DirectionalMap = DirectionalMap {
    min: 0.0,
    median: 0.63,
    max: 1.07,
};

/// The sun a sprite keeps behind `d` parcel diameters of cloud
/// ([`sunlit_shares`]): 1 − `SUNLIT_DIM` + `SUNLIT_DIM`·exp(−`SUNLIT_FALLOFF`
/// · max(d − `SUNLIT_FREE`, 0)). What lies behind a few parcels keeps a
/// twelfth of the sun: light scattered through the cloud and round it,
/// which the painter leaves in the shade. Chosen against the path tracer
/// (issue 32, with the other constants of this file: towering cumulus
/// 0.082 → 0.065 at 160×120, 0.084 → 0.0695 at 320×240; fair weather
/// 0.065 → 0.064 and 0.069 → 0.068).
pub const SUNLIT_DIM: f32 = 0.92;
/// Per parcel diameter of cloud toward the sun ([`SUNLIT_DIM`]).
pub const SUNLIT_FALLOFF: f32 = 0.85;
/// Diameters of cloud toward the sun that dim nothing: the fringe of a
/// parcel's own sphere ([`SUNLIT_DIM`]).
pub const SUNLIT_FREE: f32 = 0.18;

/// The painted colour (sRGB-encoded, shaders/artist.wgsl) of a physics
/// cloud from its base (first) to its top (last), over the cloud's height.
pub const PARCEL_LEVELS: [f32; LEVELS] = [0.87, 0.9, 0.935, 0.965, 1.0];

/// Parcels whose spheres are closer than this × the sum of their radii
/// belong to the same cloud.
pub const TOUCHING: f32 = 1.0;

/// A condensed parcel as a sprite cloud: one box spanning its sphere down to
/// its condensation plane (the flat base), `fill` × [`PARCEL_SPRITES`]
/// sprites of [`PARCEL_SPRITE_SIZE`] × its radius, cumulus tiles, a
/// flat-bottomed tile on the base row. `seed` makes it deterministic (use
/// the parcel's id). Its levels and shading centre are its own;
/// [`parcel_clouds`] gives them the cloud and the billow the parcel
/// belongs to.
pub fn parcel_cloud(p: &CloudParcel, seed: u64) -> SpriteCloud {
    let r = p.radius_m.max(1.0);
    let base = (p.cond_plane_z_m - p.center_m.z).clamp(-r, r);
    let size = [PARCEL_SPRITE_SIZE * r; 2];
    let count = ((p.fill.clamp(0.0, 1.0) * PARCEL_SPRITES as f32).round() as u32).max(5);
    let body = SpriteBox {
        min_m: [-0.7 * r, -0.7 * r, base + 0.2 * r],
        max_m: [0.7 * r, 0.7 * r, 0.7 * r],
        count: Some(count),
        density_per_km3: None,
        width_m: size,
        height_m: size,
        // The puffy tiles are lit from above: turned at most 30° either way.
        rotation_deg: [-30.0, 30.0],
        textures: PUFFY_TILES.to_vec(),
        group: 0,
    };
    // §3.2: flat bottoms with a narrow rotation range (±5°).
    let bottom = SpriteBox {
        min_m: [-0.6 * r, -0.6 * r, base + size[1] * 0.3],
        max_m: [0.6 * r, 0.6 * r, base + size[1] * 0.35],
        // A tenth: a flat row of darker bottoms reads as a seam where a
        // cloud's parcels stand on each other.
        count: Some((count / 10).max(1)),
        rotation_deg: [-5.0, 5.0],
        textures: vec![FLAT_BOTTOM_TILE],
        group: 1,
        ..body.clone()
    };
    let spec = SpriteCloudSpec {
        name: String::new(),
        kind: CloudType::CumulusHumilis,
        center_m: p.center_m.to_array(),
        seed,
        prune_fraction: PRUNE_TYPICAL,
        levels: None,
        boxes: vec![body, bottom],
    };
    let mut cloud = spec.build();
    cloud.levels = levels(p.cond_plane_z_m.min(p.center_m.z), p.center_m.z + r);
    cloud
}

/// The five [`PARCEL_LEVELS`] from `bottom_m` to `top_m` (world heights).
pub fn levels(bottom_m: f32, top_m: f32) -> Vec<ColorLevel> {
    let span = (top_m - bottom_m).max(1.0);
    PARCEL_LEVELS
        .iter()
        .enumerate()
        .map(|(i, &c)| ColorLevel {
            height_m: bottom_m + span * i as f32 / (LEVELS - 1) as f32,
            rgba: [c, c, c, PARCEL_ALPHA],
        })
        .collect()
}

/// The cloud each parcel belongs to: parcels whose spheres touch
/// ([`TOUCHING`]) are joined, through any chain of touching parcels.
/// Returns a cloud index per parcel, numbered in order of first parcel.
pub fn clusters(parcels: &[CloudParcel]) -> Vec<usize> {
    let spheres: Vec<(Vec3, f32)> = parcels.iter().map(|p| (p.center_m, p.radius_m)).collect();
    crate::physics::clusters::touching_groups(&spheres, TOUCHING, &|_, _| true)
}

/// Every condensed parcel (fill > 0) as a sprite cloud laid out full
/// (fill 1: the caller fades it in by its fill, so the layout does not pop
/// as the fill moves), seeded by its stable id ([`CloudParcel::id`]): the
/// same parcel gives the same sprites whichever parcels condense or
/// evaporate around it. Touching parcels are shaded as one cloud: levels
/// from the cloud's lowest condensation plane to its top, one centre for
/// the directional term (the mean of their centres, weighted by volume),
/// a billow centre per parcel ([`billow_centers`]) and the share of the
/// sun (along `sun_dir`) that reaches each sprite ([`sunlit_shares`]).
pub fn parcel_clouds(parcels: &[CloudParcel], sun_dir: Vec3) -> Vec<SpriteCloud> {
    let owned: Vec<CloudParcel> = parcels
        .iter()
        .filter(|p| p.fill > 0.0 && p.radius_m.is_finite() && p.center_m.is_finite())
        .copied()
        .collect();
    let cluster = clusters(&owned);
    let n = cluster.iter().copied().max().map_or(0, |m| m + 1);
    // (bottom, top, Σ r³·centre, Σ r³) per cloud.
    let mut span = vec![(f32::MAX, f32::MIN, Vec3::ZERO, 0.0f32); n];
    for (p, &c) in owned.iter().zip(&cluster) {
        let s = &mut span[c];
        let w = p.radius_m.powi(3).max(1e-6);
        s.0 = s.0.min(p.cond_plane_z_m.min(p.center_m.z));
        s.1 = s.1.max(p.center_m.z + p.radius_m);
        s.2 += p.center_m * w;
        s.3 += w;
    }
    let billows = billow_centers(&owned);
    let mut clouds: Vec<SpriteCloud> = owned
        .iter()
        .zip(&cluster)
        .zip(billows)
        .map(|((p, &c), billow)| {
            let (bottom, top, sum, w) = span[c];
            let mut cloud = parcel_cloud(&CloudParcel { fill: 1.0, ..*p }, p.id);
            cloud.levels = levels(bottom, top);
            cloud.shade_center_m = Some(ShadeCenters {
                cloud_m: sum / w,
                billow_m: billow,
            });
            cloud
        })
        .collect();
    let centres: Vec<Vec3> = clouds.iter().flat_map(|c| c.sprites.iter().map(|s| s.center_m)).collect();
    let mut sunlit = sunlit_shares(&centres, &owned, sun_dir).into_iter();
    for s in clouds.iter_mut().flat_map(|c| c.sprites.iter_mut()) {
        s.sunlit = sunlit.next().unwrap_or(1.0);
    }
    clouds
}

/// The share of the sun that reaches each of `points` through `parcels`
/// ([`SUNLIT_DIM`]): `d` = Σ over the parcels, of the length of the ray
/// from the point toward the sun (`sun_dir`) inside the parcel's sphere
/// over its diameter (0–1), × its fill (a parcel that has barely
/// condensed hides little). The painter's "what lies behind the cloud
/// from the sun is in its shade", measured on the parcels, so a tower's
/// far side, the parts under its upper billows and each parcel's own far
/// side are shaded whatever the sun's height. A zero or non-finite
/// `sun_dir` is taken as straight up.
pub fn sunlit_shares(points: &[Vec3], parcels: &[CloudParcel], sun_dir: Vec3) -> Vec<f32> {
    let sun = sun_dir.try_normalize().unwrap_or(Vec3::Z);
    // In the plane across the sun (coordinates along two axes in it), a
    // sphere meets the ray from a point when the point lies within its
    // radius of the sphere's centre, so a grid of the centres there
    // (cell = the largest radius) holds every sphere that can.
    let (e1, e2) = sun.any_orthonormal_pair();
    let across = |v: Vec3| Vec3::new(v.dot(e1), v.dot(e2), 0.0);
    let projected: Vec<Vec3> = parcels.iter().map(|p| across(p.center_m)).collect();
    let r_max = parcels.iter().map(|p| p.radius_m).fold(1.0f32, f32::max);
    let grid = crate::physics::clusters::PointGrid::new(&projected, r_max);
    // The points by the cell they fall in: each cell's candidate spheres
    // are gathered once for all its points.
    let mut by_cell: std::collections::BTreeMap<[i32; 3], Vec<usize>> = Default::default();
    for (i, &x) in points.iter().enumerate() {
        by_cell.entry(grid.cell_of(across(x)).to_array()).or_default().push(i);
    }
    let depth = |x: Vec3, candidates: &[usize]| {
        let at = across(x);
        let mut d = 0.0f32;
        for &j in candidates {
            let q = &parcels[j];
            let r = q.radius_m.max(1.0);
            let miss2 = at.distance_squared(projected[j]);
            if miss2 < r * r {
                // The ray x + t·sun, t ≥ 0, inside the sphere.
                let (mid, half) = ((q.center_m - x).dot(sun), (r * r - miss2).sqrt());
                let inside = (mid + half - (mid - half).max(0.0)).max(0.0);
                d += q.fill.clamp(0.0, 1.0) * inside / (2.0 * r);
            }
        }
        d
    };
    // Each point on its own, its spheres in a fixed order: the same shares
    // on any number of threads.
    let cells: Vec<([i32; 3], Vec<usize>)> = by_cell.into_iter().collect();
    let per_cell: Vec<Vec<(usize, f32)>> = cells
        .par_iter()
        .map(|(k, idx)| {
            let mut candidates = Vec::new();
            grid.around_cell(IVec3::from_array(*k), |j| candidates.push(j));
            idx.iter().map(|&i| (i, depth(points[i], &candidates))).collect()
        })
        .collect();
    let mut shares = vec![1.0; points.len()];
    for (i, d) in per_cell.into_iter().flatten() {
        shares[i] = 1.0 - SUNLIT_DIM + SUNLIT_DIM * (-SUNLIT_FALLOFF * (d - SUNLIT_FREE).max(0.0)).exp();
    }
    shares
}

/// The centre of each parcel's billow (§5.2's shading group at the scale of
/// the billows): the mean centre of the parcels within [`BILLOW_REACH`] ×
/// its radius, weighted by volume × (1 − distance / reach) × (1 +
/// [`BILLOW_ABOVE`] × the sine of their elevation above it), whichever cloud
/// they belong to (a neighbour that does not touch still hides part of the
/// sky and the sun). On a cloud's surface it lies inward, so the direction
/// from it is about the surface's normal; under a higher part of the cloud
/// it lies above, so the part is shaded.
pub fn billow_centers(parcels: &[CloudParcel]) -> Vec<Vec3> {
    let centres: Vec<Vec3> = parcels.iter().map(|p| p.center_m).collect();
    let r_max = parcels.iter().map(|p| p.radius_m).fold(1.0f32, f32::max);
    let mut sum = vec![(Vec3::ZERO, 0.0f32); parcels.len()];
    crate::physics::clusters::near_pairs(&centres, BILLOW_REACH * r_max, |i, j| {
        let (p, q) = (&parcels[i], &parcels[j]);
        let reach = BILLOW_REACH * p.radius_m.max(1.0);
        let to = q.center_m - p.center_m;
        let above = 1.0 + BILLOW_ABOVE * to.normalize_or_zero().z.max(0.0);
        let k = (1.0 - to.length() / reach).max(0.0) * q.radius_m.powi(3).max(1e-6) * above;
        sum[i].0 += q.center_m * k;
        sum[i].1 += k;
    });
    // Each parcel is within its own reach: the weight is positive.
    sum.into_iter().map(|(s, w)| s / w).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parcel(id: u64, x: f32, z: f32, r: f32) -> CloudParcel {
        CloudParcel {
            id,
            center_m: Vec3::new(x, 0.0, z),
            radius_m: r,
            fill: 1.0,
            cond_plane_z_m: 1000.0,
        }
    }

    /// Touching spheres join, through chains; a sphere apart stays alone.
    #[test]
    fn touching_parcels_form_one_cloud() {
        let ps = [
            parcel(1, 0.0, 1200.0, 100.0),
            parcel(2, 5000.0, 1200.0, 100.0),
            parcel(3, 150.0, 1300.0, 100.0),
            parcel(4, 300.0, 1400.0, 100.0),
        ];
        assert_eq!(clusters(&ps), vec![0, 1, 0, 0]);
    }

    /// A parcel's sprites are shaded with its cloud: levels from the
    /// cloud's base to its top and one centre for the directional term.
    #[test]
    fn a_tower_s_parcels_share_its_levels_and_centre() {
        let ps = [parcel(1, 0.0, 1200.0, 150.0), parcel(2, 0.0, 1450.0, 150.0)];
        let clouds = parcel_clouds(&ps, Vec3::Z);
        assert_eq!(clouds.len(), 2);
        for c in &clouds {
            assert_eq!(c.levels.first().unwrap().height_m, 1000.0);
            assert_eq!(c.levels.last().unwrap().height_m, 1600.0);
            let centre = c.shade_center_m.unwrap().cloud_m;
            assert!((centre.z - 1325.0).abs() < 1e-3, "{centre}");
        }
    }

    /// A billow's centre lies inward from a cloud's side and above a part
    /// under another, more above than beside (BILLOW_ABOVE); a parcel alone
    /// is its own billow; parcels beyond the reach do not count.
    #[test]
    fn billow_centres_lie_inward_and_above() {
        let ps = [
            parcel(1, 0.0, 1200.0, 100.0),
            parcel(2, 200.0, 1200.0, 100.0),
            parcel(3, 0.0, 1400.0, 100.0),
            parcel(4, 5000.0, 1200.0, 100.0),
        ];
        let b = billow_centers(&ps);
        // Parcel 1 sees 2 beside and 3 above at the same distance: the
        // centre moves up more than sideways.
        let d = b[0] - ps[0].center_m;
        assert!(d.x > 0.0 && d.z > d.x, "{d}");
        // Parcel 3, on top, has no parcel above: its centre lies below.
        assert!(b[2].z < ps[2].center_m.z, "{}", b[2]);
        assert_eq!(b[3], ps[3].center_m);
    }

    /// Under a sun straight up, a point keeps less of the sun the more
    /// cloud lies above it, as much less as that cloud's fill; one beside
    /// the column, or above the cloud, keeps it all; a parcel's far side
    /// from the sun is darker than its near side; under a low sun the
    /// parcel on the tower's far side is the shaded one.
    #[test]
    fn sunlit_share_falls_with_the_cloud_toward_the_sun() {
        let share = |d: f32| 1.0 - SUNLIT_DIM + SUNLIT_DIM * (-SUNLIT_FALLOFF * (d - SUNLIT_FREE).max(0.0)).exp();
        let mut ps = vec![
            parcel(1, 0.0, 1200.0, 100.0),
            parcel(2, 0.0, 1400.0, 100.0),
            parcel(3, 0.0, 1600.0, 100.0),
            parcel(4, 250.0, 1200.0, 100.0),
        ];
        let at = |x: f32, z: f32| Vec3::new(x, 0.0, z);
        let points = [at(0.0, 1200.0), at(0.0, 1700.0), at(250.0, 1200.0), at(0.0, 1290.0), at(0.0, 1110.0)];
        let s = sunlit_shares(&points, &ps, Vec3::Z);
        // Half its own sphere and the two above: 2.5 diameters.
        assert!((s[0] - share(2.5)).abs() < 1e-5, "{} vs {}", s[0], share(2.5));
        assert_eq!(s[1], 1.0, "on top of the cloud");
        assert!((s[2] - share(0.5)).abs() < 1e-5, "beside the column: its own half");
        assert!(s[3] > s[0] && s[0] > s[4], "near side, centre, far side: {s:?}");
        // Half-condensed parcels above hide half as much.
        ps[1].fill = 0.5;
        ps[2].fill = 0.5;
        let half = sunlit_shares(&points, &ps, Vec3::Z);
        assert!((half[0] - share(1.5)).abs() < 1e-5, "{} vs {}", half[0], share(1.5));
        // A sun low in the west (−x): parcel 4, east of parcel 1, is behind it.
        let low = sunlit_shares(&points, &ps, Vec3::new(-1.0, 0.0, 0.05));
        assert!(low[2] < low[0] - 0.1, "{low:?}");
        // A zero sun direction is straight up, never NaN.
        assert_eq!(sunlit_shares(&points, &ps, Vec3::ZERO), half);
    }
}
