//! Slices per cloud (src/methods/slices/model/clouds.rs, issue 33): a
//! stack of planes per connected group of primitives, sized to it, drawn
//! farthest first, each with the paper's compensation for its own depth.

use cumulus::methods::slices::model::{
    CloudSlices, EllipsoidState, MAX_STACKS, SlicesConfig, cloud_groups, slicing,
};
use glam::{Mat3, Vec3};

fn ellipsoid(centre_m: Vec3, radii_m: Vec3) -> EllipsoidState {
    EllipsoidState {
        centre_m,
        radii_m,
        rotation: Mat3::IDENTITY,
        strength: 1.0,
        base_z_m: f32::NEG_INFINITY,
    }
}

/// Most vertices holding field along one grid line (a row or a column of
/// a plane) of any plane of `g`.
fn most_across(g: &slicing::SliceGeometry) -> (usize, usize) {
    let side = g.side();
    let per_plane = side * side;
    let (mut rows, mut cols) = (0, 0);
    for k in 0..g.plane_offsets_m.len() {
        let v = &g.vertices[k * per_plane..(k + 1) * per_plane];
        for a in 0..side {
            let row = (0..side).filter(|&b| v[a * side + b].density > 0.0).count();
            let col = (0..side).filter(|&b| v[b * side + a].density > 0.0).count();
            rows = rows.max(row);
            cols = cols.max(col);
        }
    }
    (rows, cols)
}

#[test]
fn a_2_km_tower_gets_16_vertices_across_its_planes() {
    // A tower 2 km wide and 5 km tall, alone and among a 15 km field of
    // small cumulus, for the sun high and low and views from the side and
    // from below: any line through its middle crosses ≥ 2 km of it, so a
    // plane through it holds ≥ 16 vertices with field along its rows and
    // along its columns. One stack of 32 × 32 cells over the field (the
    // slicing before issue 33) spaced them ≈ 500 m: 4 across.
    let tower = ellipsoid(
        Vec3::new(0.0, 0.0, 3500.0),
        Vec3::new(1000.0, 1000.0, 2500.0),
    );
    let mut field = vec![tower];
    for i in 0..12 {
        let a = i as f32 * 0.52;
        field.push(ellipsoid(
            Vec3::new(7000.0 * a.cos(), 7000.0 * a.sin(), 1500.0),
            Vec3::new(500.0, 500.0, 300.0),
        ));
    }
    let cfg = SlicesConfig::default();
    let eye = Vec3::new(-2000.0, -20000.0, 1500.0);
    for states in [&field[..1], &field[..]] {
        for to_light in [Vec3::new(0.3, -0.4, 0.9), Vec3::new(-0.9, 0.2, 0.25)] {
            for view in [Vec3::new(0.1, 1.0, 0.15), Vec3::new(0.0, 0.3, 1.0)] {
                let mut s = CloudSlices::grid(states, &cfg, to_light, eye, view).unwrap();
                s.evaluate(&cfg, to_light.normalize(), None).unwrap();
                let stack = s
                    .stacks
                    .iter()
                    .find(|st| s.states[st.primitives.clone()].contains(&tower))
                    .expect("the tower has a stack");
                assert_eq!(stack.primitives.len(), 1, "the tower is a cloud alone");
                let (rows, cols) = most_across(&stack.geometry);
                assert!(
                    rows >= 16 && cols >= 16,
                    "{rows} × {cols} vertices across the tower ({} primitives)",
                    states.len()
                );
            }
        }
    }
}

#[test]
fn each_cloud_gets_its_own_stack_farthest_first() {
    // Two overlapping spheres (one cloud) and two lone ones, at different
    // distances from the eye.
    let states = [
        ellipsoid(Vec3::new(0.0, 10000.0, 2000.0), Vec3::splat(800.0)),
        ellipsoid(Vec3::new(3000.0, 4000.0, 2000.0), Vec3::splat(500.0)),
        ellipsoid(Vec3::new(900.0, 10000.0, 2200.0), Vec3::splat(600.0)),
        ellipsoid(Vec3::new(-4000.0, 20000.0, 2000.0), Vec3::splat(700.0)),
    ];
    assert_eq!(cloud_groups(&states), vec![0, 1, 0, 2]);
    let cfg = SlicesConfig {
        quality: 16,
        tessellation: 8,
        ..SlicesConfig::default()
    };
    let eye = Vec3::new(0.0, -2000.0, 1000.0);
    let to_light = Vec3::new(0.4, -0.3, 0.8).normalize();
    let mut s = CloudSlices::grid(&states, &cfg, to_light, eye, Vec3::Y).unwrap();
    s.evaluate(&cfg, to_light, None).unwrap();
    let sizes: Vec<usize> = s.stacks.iter().map(|st| st.primitives.len()).collect();
    // Farthest first: the lone far sphere, the pair, the near sphere.
    assert_eq!(sizes, vec![1, 2, 1]);
    assert!(
        s.stacks
            .windows(2)
            .all(|w| w[0].distance_m > w[1].distance_m)
    );
    for st in &s.stacks {
        let own = &s.states[st.primitives.clone()];
        for v in &st.geometry.vertices {
            let p = Vec3::from(v.position_m);
            // Its own primitives' field alone, summed in the same order
            // (the others add exact zeros): equal to the bit.
            let f: f32 = own.iter().map(|e| e.field(p)).sum();
            assert_eq!(v.density, f);
        }
        // The stack spans its own cloud: every plane within its box.
        let r = own.iter().map(|e| e.radii_m.x).fold(0.0, f32::max);
        let centre = own.iter().map(|e| e.centre_m).sum::<Vec3>() / own.len() as f32;
        assert!(
            st.geometry
                .vertices
                .iter()
                .all(|v| (Vec3::from(v.position_m) - centre).length() < 4.0 * r),
            "a stack sized to its cloud"
        );
    }
    // Drawn in that order: the index buffer runs stack after stack.
    let indices = s.indices(false);
    let (mut at, mut base) = (0, 0u32);
    for st in &s.stacks {
        let (n, v) = (st.geometry.indices.len(), st.geometry.vertices.len() as u32);
        assert!(
            indices[at..at + n]
                .iter()
                .all(|&i| (base..base + v).contains(&i))
        );
        (at, base) = (at + n, base + v);
    }
    assert_eq!(at, indices.len());
}

#[test]
fn empty_triangles_are_left_out_only_when_the_field_is_known() {
    let states = [ellipsoid(
        Vec3::new(0.0, 5000.0, 2000.0),
        Vec3::splat(800.0),
    )];
    let cfg = SlicesConfig {
        quality: 16,
        tessellation: 16,
        ..SlicesConfig::default()
    };
    let l = Vec3::Z;
    let mut s = CloudSlices::grid(&states, &cfg, l, Vec3::ZERO, Vec3::Y).unwrap();
    s.evaluate(&cfg, l, None).unwrap();
    let (all, drawn) = (s.indices(false), s.indices(true));
    let v = s.vertices();
    assert_eq!(all.len(), s.stacks[0].geometry.indices.len());
    // The sphere fills π/6 of its box: many triangles are empty air.
    assert!(
        drawn.len() < all.len() * 3 / 4,
        "{} of {}",
        drawn.len(),
        all.len()
    );
    // Every triangle with field at a corner is kept.
    let with_field = all
        .chunks_exact(3)
        .filter(|t| t.iter().any(|&i| v[i as usize].density > 0.0))
        .count();
    assert_eq!(drawn.len(), 3 * with_field);
}

#[test]
fn many_small_clouds_are_merged_into_at_most_the_cap() {
    // 300 parcel-sized spheres strewn over 30 km × 30 km (a fixed LCG):
    // most apart, merged into at most MAX_STACKS stacks that hold every
    // one of them, neighbours first (so more than one remains).
    let mut seed = 12345u32;
    let mut rnd = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    let states: Vec<EllipsoidState> = (0..300)
        .map(|_| {
            let c = Vec3::new(30000.0 * rnd(), 30000.0 * rnd(), 1500.0 + 500.0 * rnd());
            ellipsoid(c, Vec3::splat(300.0))
        })
        .collect();
    let unmerged = cumulus::physics::clusters::touching_groups(
        &states
            .iter()
            .map(|e| (e.centre_m, 300.0))
            .collect::<Vec<_>>(),
        1.0,
        &|_, _| true,
    );
    assert!(unmerged.iter().max().unwrap() + 1 > MAX_STACKS);
    let groups = cloud_groups(&states);
    let clouds = groups.iter().max().unwrap() + 1;
    assert!(clouds <= MAX_STACKS && clouds > 1, "{clouds} clouds");
    let cfg = SlicesConfig::default();
    let s = CloudSlices::grid(
        &states,
        &cfg,
        Vec3::Z,
        Vec3::new(0.0, -5000.0, 2000.0),
        Vec3::Y,
    )
    .unwrap();
    assert_eq!(s.stacks.len(), clouds);
    assert_eq!(s.states.len(), 300);
}

#[test]
fn plane_opacity_is_the_paper_s_for_one_ellipsoid_and_grows_with_a_cloud_s_depth() {
    let cfg = SlicesConfig {
        quality: 32,
        opacity: 2.0,
        ..SlicesConfig::default()
    };
    let plane_opacity = |states: &[EllipsoidState], quality: u32| {
        let c = SlicesConfig {
            quality,
            ..cfg.clone()
        };
        let s = CloudSlices::grid(
            states,
            &c,
            Vec3::Z,
            Vec3::new(0.0, -9000.0, 1500.0),
            Vec3::Y,
        )
        .unwrap();
        assert_eq!(s.stacks.len(), 1);
        s.stacks[0].geometry.vertices[0].plane_opacity
    };
    let one = [ellipsoid(
        Vec3::new(0.0, 0.0, 1500.0),
        Vec3::new(500.0, 700.0, 400.0),
    )];
    // One ellipsoid: Opacity ÷ planes exactly (f32 of one division and a
    // product by 1).
    assert!((plane_opacity(&one, 32) - 2.0 / 32.0).abs() < 1e-7);
    // Four spheres in a row along the view (the planes' normal, the light
    // overhead so the planes contain it): the stack is four deep, so each
    // plane is four times as opaque, and Opacity stays the optical depth
    // of one of them whatever the Quality.
    let row: Vec<EllipsoidState> = (0..4)
        .map(|k| ellipsoid(Vec3::new(0.0, 900.0 * k as f32, 1500.0), Vec3::splat(500.0)))
        .collect();
    let depth_ratio = (3.0 * 900.0 + 1000.0) / 1000.0;
    for q in [32u32, 128] {
        let total = plane_opacity(&row, q) * q as f32;
        // f32 products and sums of km-scale depths: 1e-5 relative.
        assert!(
            (total / (2.0 * depth_ratio) - 1.0).abs() < 1e-5,
            "quality {q}: {total}"
        );
    }
}

#[test]
fn many_clouds_share_a_vertex_budget_that_quality_does_not_change() {
    use cumulus::methods::slices::model::clouds::{PLANE_VERTEX_BUDGET, min_spacing_m};
    // 20 parcel-sized clouds 3 km apart: at 33² vertices a plane each they
    // are 2.7× the budget, so their vertices spread out to fit it; a cloud
    // alone keeps the tessellation.
    let states: Vec<EllipsoidState> = (0..20)
        .map(|i| {
            let (x, y) = ((i % 5) as f32, (i / 5) as f32);
            ellipsoid(
                Vec3::new(3000.0 * x, 3000.0 * y, 1500.0),
                Vec3::splat(400.0),
            )
        })
        .collect();
    let eye = Vec3::new(6000.0, -15000.0, 1500.0);
    let l = Vec3::new(0.3, 0.3, 0.9).normalize();
    let sides = |states: &[EllipsoidState], quality: u32| {
        let cfg = SlicesConfig {
            quality,
            ..SlicesConfig::default()
        };
        let s = CloudSlices::grid(states, &cfg, l, eye, Vec3::Y).unwrap();
        s.stacks
            .iter()
            .map(|st| st.geometry.side())
            .collect::<Vec<_>>()
    };
    let (q32, q128) = (sides(&states, 32), sides(&states, 128));
    assert_eq!(q32, q128, "Quality does not change the tessellation");
    assert_eq!(q32.len(), 20);
    let per_plane: usize = q32.iter().map(|s| s * s).sum();
    assert!(
        per_plane <= PLANE_VERTEX_BUDGET,
        "{per_plane} vertices a plane"
    );
    let tessellation = SlicesConfig::default().tessellation as usize;
    assert!(q32.iter().all(|&s| s < tessellation + 1), "{q32:?}");
    assert_eq!(sides(&states[..1], 128), vec![tessellation + 1]);
    let one: Vec<Vec<EllipsoidState>> = vec![states[..1].to_vec()];
    assert_eq!(min_spacing_m(&one, &SlicesConfig::default()), 0.0);
}
