//! The bench's 100 km clipmap line: the levels the bake would use for
//! `profiles/landscape_100km.toml` and the coarsest voxel within 20 km of
//! its camera (no GPU).

use cumulus::bench::clipmap::{FINE_VOXEL_M, landscape_100km, markdown};

#[test]
fn the_100_km_line_reports_levels_at_twice_the_voxel_and_the_near_voxel() {
    let row = landscape_100km(&[]).unwrap();
    assert!(row.level_voxel_m.len() > 1, "{row:?}");
    for w in row.level_voxel_m.windows(2) {
        assert_eq!(w[1], 2.0 * w[0], "{row:?}");
    }
    // The finest level is what the near field is sampled at.
    assert!(row.near_voxel_m <= FINE_VOXEL_M, "{row:?}");
    assert_eq!(row.near_voxel_m, row.level_voxel_m[0]);
    let line = markdown(&row);
    assert!(line.contains("(target ≤ 50: met)"), "{line}");
}
