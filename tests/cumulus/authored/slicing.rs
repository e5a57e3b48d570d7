//! The slicing geometry of Schpok 2003 §4.1 on the CPU (src/methods/slices/model/
//! slicing.rs): the orientation rule, back-to-front order, the field at
//! the vertices and the shadow of eq. 2 along the light.

use cumulus::methods::slices::model::{
    EllipsoidState, SliceOrientation, SlicesConfig, build_slices, slice_normal, wyvill,
};
use glam::{Mat3, Vec3};

/// A sphere at the origin. The tests below that count vertices use
/// spheres of 100 m or so: a stack that narrow keeps the configured
/// tessellation (its vertices are closer than MAX_VERTEX_SPACING_M).
fn sphere(radius_m: f32) -> EllipsoidState {
    EllipsoidState {
        centre_m: Vec3::ZERO,
        radii_m: Vec3::splat(radius_m),
        rotation: Mat3::IDENTITY,
        strength: 1.0,
        base_z_m: f32::NEG_INFINITY,
    }
}

fn cfg(quality: u32, tessellation: u32, dirtiness: f32) -> SlicesConfig {
    SlicesConfig {
        quality,
        tessellation,
        dirtiness,
        opacity: 0.8,
        ..SlicesConfig::default()
    }
}

#[test]
fn planes_are_oriented_by_the_rule_for_several_light_view_pairs() {
    let sun = |az: f32, el: f32| {
        let (a, e) = (az.to_radians(), el.to_radians());
        Vec3::new(a.sin() * e.cos(), a.cos() * e.cos(), e.sin())
    };
    use SliceOrientation::*;
    // (to light, view direction, expected orientation, expected normal)
    let cases = [
        // Looking straight down, sun overhead: planes across the light.
        (Vec3::Z, -Vec3::Z, OrthogonalToLight, -Vec3::Z),
        // Sun overhead, looking north: planes contain the light, face north.
        (Vec3::Z, Vec3::Y, ParallelToLight, Vec3::Y),
        // Low sun in the east, looking north: light ⊥ view.
        (sun(90.0, 10.0), Vec3::Y, ParallelToLight, Vec3::Y),
        // Sun behind the viewer, looking north into the lit side.
        (
            sun(180.0, 20.0),
            Vec3::Y,
            OrthogonalToLight,
            -sun(180.0, 20.0),
        ),
        // Looking toward a low sun (backlit cloud).
        (sun(0.0, 30.0), Vec3::Y, OrthogonalToLight, sun(0.0, 30.0)),
        // Sun 60° off the view axis: closer to parallel.
        (
            sun(60.0, 0.0),
            Vec3::Y,
            ParallelToLight,
            Vec3::new(-0.5, 3f32.sqrt() / 2.0, 0.0).normalize(),
        ),
    ];
    for (i, (l, v, orientation, normal)) in cases.into_iter().enumerate() {
        let (o, n) = slice_normal(l, v);
        assert_eq!(o, orientation, "case {i}");
        // Normals are unit vectors from trigonometry: 1e-5 of f32 rounding.
        assert!(
            (n - normal.normalize()).length() < 1e-5,
            "case {i}: {n} vs {normal}"
        );
    }
    // Over a sweep of pairs: the normal is unit, faces along the view, is
    // the light or perpendicular to it, and is at least as close to the
    // view as the best candidate of the other family.
    for i in 0..200 {
        let t = i as f32 * 0.731;
        let l = Vec3::new(t.sin(), (1.7 * t).cos(), 0.3 + (0.4 * t).sin().abs()).normalize();
        let v = Vec3::new((2.3 * t).cos(), (0.9 * t).sin(), (1.3 * t).sin() - 0.2).normalize();
        let (o, n) = slice_normal(l, v);
        assert!((n.length() - 1.0).abs() < 1e-5 && n.dot(v) >= -1e-6);
        let along = l.dot(v).abs();
        let across = (1.0 - l.dot(v).powi(2)).max(0.0).sqrt();
        match o {
            SliceOrientation::OrthogonalToLight => {
                assert!(n.cross(l).length() < 1e-5 && along >= across - 1e-6)
            }
            SliceOrientation::ParallelToLight => {
                assert!(n.dot(l).abs() < 1e-5 && across >= along - 1e-6)
            }
        }
        assert!(
            (n.dot(v) - along.max(across)).abs() < 1e-4,
            "the closest of the candidates"
        );
    }
}

#[test]
fn planes_come_back_to_front_and_carry_the_field() {
    let states = [
        sphere(100.0),
        EllipsoidState {
            centre_m: Vec3::new(80.0, 30.0, 20.0),
            ..sphere(60.0)
        },
    ];
    for (l, v) in [
        (Vec3::Z, Vec3::new(0.3, 1.0, -0.2)),
        (Vec3::new(1.0, -1.0, 0.5), Vec3::new(-1.0, 0.2, 0.1)),
        (Vec3::Y, Vec3::new(0.1, 0.9, 0.0)),
    ] {
        let c = cfg(16, 8, 0.5);
        let g = build_slices(&states, &c, l, v).unwrap();
        let per_plane = 81;
        assert_eq!(g.vertices.len(), 16 * per_plane);
        assert_eq!(g.indices.len(), 16 * 8 * 8 * 6);
        assert!(
            g.plane_offsets_m.windows(2).all(|w| w[0] > w[1]),
            "offsets decrease"
        );
        // Depth from an eye 20 km back along the view: plane after plane it
        // only decreases (painter's algorithm).
        let eye = -v.normalize() * 2_000.0;
        let depth =
            |k: usize| (Vec3::from(g.vertices[k * per_plane].position_m) - eye).dot(v.normalize());
        assert!(
            (1..16).all(|k| depth(k) < depth(k - 1)),
            "back to front for {l} {v}"
        );
        for (i, vert) in g.vertices.iter().enumerate() {
            let p = Vec3::from(vert.position_m);
            // Positions are 100 m-scale f32: well under millimetre rounding.
            assert!(
                (g.normal.dot(p) - g.plane_offsets_m[i / per_plane]).abs() < 0.01,
                "vertex {i} on its plane"
            );
            let f: f32 = states.iter().map(|e| e.field(p)).sum();
            assert_eq!(vert.density, f);
        }
        // Each plane's triangles use only its own vertices.
        for (t, tri) in g.indices.chunks(3).enumerate() {
            let k = t / (8 * 8 * 2);
            assert!(tri.iter().all(|&i| i as usize / per_plane == k));
        }
        assert!(
            g.vertices.iter().any(|v| v.density > 0.9),
            "the planes cross the cloud's core"
        );
    }
}

/// C(s) of the Wyvill function at the four plane offsets ±12.5, ±37.5,
/// ±62.5, ±87.5 m of 8 planes through a 100 m sphere, worked out by hand from
/// 1 − 4/9·s⁶ + 17/9·s⁴ − 22/9·s².
const C_0125: f32 = 0.962_265;
const C_0375: f32 = 0.692_367_6;
const C_0625: f32 = 0.306_869_5;
const C_0875: f32 = 0.036_239_6;

#[test]
fn shadow_accumulates_along_the_light_as_eq_2() {
    assert!((wyvill(0.375 * 0.375) - C_0375).abs() < 1e-6);
    let d = 0.5;
    // Sun overhead, viewer looking down: 8 planes across the light, the
    // first drawn at z = −87.5 m (farthest), the last at +87.5 m (nearest
    // the sun). The centre vertex of each 3×3 grid is on the z axis.
    let g = build_slices(&[sphere(100.0)], &cfg(8, 2, d), Vec3::Z, -Vec3::Z).unwrap();
    assert_eq!(g.orientation, Some(SliceOrientation::OrthogonalToLight));
    let centre: Vec<_> = (0..8).map(|k| g.vertices[k * 9 + 4]).collect();
    let z: Vec<f32> = centre.iter().map(|v| v.position_m[2]).collect();
    assert_eq!(z, [-87.5, -62.5, -37.5, -12.5, 12.5, 37.5, 62.5, 87.5]);
    // shadow_i = shadow_(i−1) + (Dirtiness ÷ plane opacity) × plane opacity
    // × C_i ÷ 8 (the 8 vertices along each light ray), from the top down.
    let c = [
        C_0875, C_0625, C_0375, C_0125, C_0125, C_0375, C_0625, C_0875,
    ];
    let mut expect = [0.0f32; 8];
    let mut sum = 0.0;
    for k in (0..8).rev() {
        sum += d * c[k] / 8.0;
        expect[k] = sum;
    }
    for k in 0..8 {
        // Sums of eight f32 terms ≤ 0.5: a few ulps.
        assert!(
            (centre[k].shadow - expect[k]).abs() < 1e-5,
            "plane {k}: {} vs {}",
            centre[k].shadow,
            expect[k]
        );
    }
    assert!((centre[0].shadow - d / 4.0 * (C_0125 + C_0375 + C_0625 + C_0875)).abs() < 1e-5);
    // Every other grid vertex is 100 m or more off the axis: outside the
    // sphere, no density and no shadow.
    assert!(
        g.vertices
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 9 != 4)
            .all(|(_, v)| v.shadow == 0.0 && v.density == 0.0)
    );

    // Sun in the east, viewer looking north: planes contain the light; each
    // grid row of 3 vertices runs along x, and the shadow grows westward
    // from x = +100 m.
    let g = build_slices(&[sphere(100.0)], &cfg(8, 2, d), Vec3::X, Vec3::Y).unwrap();
    assert_eq!(g.orientation, Some(SliceOrientation::ParallelToLight));
    // Plane 3 of the draw order is at y = +12.5 m; its middle row is z = 0.
    let row: Vec<_> = (0..3).map(|i| g.vertices[3 * 9 + 3 + i]).collect();
    assert_eq!(
        row.iter().map(|v| v.position_m[0]).collect::<Vec<_>>(),
        [-100.0, 0.0, 100.0]
    );
    assert_eq!(row[1].position_m[1], 12.5);
    assert_eq!(row[2].shadow, 0.0, "nearest the sun, outside the sphere");
    assert!((row[1].shadow - d * C_0125 / 3.0).abs() < 1e-6);
    assert!(
        (row[0].shadow - d * C_0125 / 3.0).abs() < 1e-6,
        "nothing more west of the centre"
    );
}

#[test]
fn quality_does_not_darken_the_shadow() {
    // Behind a 100 m sphere lit from above: the shadow at the bottom of its
    // axis is Dirtiness × the mean of C along a diameter, whatever the
    // number of planes (or, with planes containing the light, of vertices
    // per row).
    let bottom = |quality: u32, tessellation: u32, to_light: Vec3, view: Vec3| {
        let g = build_slices(
            &[sphere(100.0)],
            &cfg(quality, tessellation, 0.5),
            to_light,
            view,
        )
        .unwrap();
        let side = tessellation as usize + 1;
        let centre = (side / 2) * side + side / 2;
        match g.orientation.unwrap() {
            // Draw order starts at the bottom plane (farthest from a viewer above).
            SliceOrientation::OrthogonalToLight => g.vertices[centre].shadow,
            // Planes contain the light (+x): the row's first vertex is its west end.
            SliceOrientation::ParallelToLight => {
                let plane = quality as usize / 2;
                g.vertices[plane * side * side + (side / 2) * side].shadow
            }
        }
    };
    let coarse = bottom(32, 8, Vec3::Z, -Vec3::Z);
    let fine = bottom(128, 8, Vec3::Z, -Vec3::Z);
    // Midpoint sums of a smooth integrand differ by O(1/N²): 1e-3 at N = 32.
    assert!((coarse / fine - 1.0).abs() < 0.01, "{coarse} vs {fine}");
    // The exact mean of C over s in [−1, 1] is 1 − 4/63 + 17/45 − 22/27.
    let mean = 1.0 - 4.0 / 63.0 + 17.0 / 45.0 - 22.0 / 27.0;
    assert!(
        (fine - 0.5 * mean).abs() < 0.005 * mean,
        "{fine} vs {}",
        0.5 * mean
    );
    let rows = [
        bottom(16, 32, Vec3::X, Vec3::Y),
        bottom(16, 128, Vec3::X, Vec3::Y),
    ];
    // A row's grid includes both ends (N + 1 points divided by N + 1): a
    // 1/N bias, 3 % at N = 32.
    assert!((rows[0] / rows[1] - 1.0).abs() < 0.04, "{rows:?}");
}

#[test]
fn nothing_to_slice_and_bad_directions_are_handled() {
    let empty = build_slices(&[], &cfg(8, 4, 0.5), Vec3::Z, Vec3::Y).unwrap();
    assert!(empty.vertices.is_empty() && empty.orientation.is_none());
    let faded = EllipsoidState {
        strength: 0.0,
        ..sphere(100.0)
    };
    assert!(
        build_slices(&[faded], &cfg(8, 4, 0.5), Vec3::Z, Vec3::Y)
            .unwrap()
            .vertices
            .is_empty()
    );
    let e = build_slices(&[sphere(100.0)], &cfg(8, 4, 0.5), Vec3::ZERO, Vec3::Y)
        .unwrap_err()
        .to_string();
    assert!(e.contains("to_light") && e.contains("non-zero"), "{e}");
    let e = build_slices(&[sphere(100.0)], &cfg(8, 4, 0.5), Vec3::Z, Vec3::NAN)
        .unwrap_err()
        .to_string();
    assert!(e.contains("view_dir"), "{e}");
    let e = build_slices(&[sphere(100.0)], &cfg(1024, 512, 0.5), Vec3::Z, Vec3::Y)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("render.slices.tessellation") && e.contains("vertices"),
        "{e}"
    );
}

#[test]
fn the_same_scene_slices_bit_identically() {
    let states = [
        sphere(900.0),
        EllipsoidState {
            centre_m: Vec3::new(500.0, 0.0, 300.0),
            ..sphere(500.0)
        },
    ];
    let a = build_slices(
        &states,
        &cfg(32, 16, 0.4),
        Vec3::new(1.0, 0.5, 1.0),
        Vec3::Y,
    )
    .unwrap();
    let b = build_slices(
        &states,
        &cfg(32, 16, 0.4),
        Vec3::new(1.0, 0.5, 1.0),
        Vec3::Y,
    )
    .unwrap();
    assert_eq!(
        bytemuck::cast_slice::<_, u8>(&a.vertices),
        bytemuck::cast_slice::<_, u8>(&b.vertices)
    );
}

#[test]
fn refreshing_values_on_static_planes_matches_a_rebuild() {
    let a = [
        sphere(900.0),
        EllipsoidState {
            centre_m: Vec3::new(400.0, 0.0, 200.0),
            ..sphere(500.0)
        },
    ];
    // Same bounds, new strengths: the positions stay, the values change.
    let b = [
        EllipsoidState {
            strength: 0.3,
            ..a[0]
        },
        EllipsoidState {
            strength: 2.0,
            ..a[1]
        },
    ];
    let (l, v) = (Vec3::new(0.4, -1.0, 0.8), Vec3::Y);
    let c = cfg(24, 12, 0.6);
    let mut g = build_slices(&a, &c, l, v).unwrap();
    let fresh = build_slices(&b, &c, l, v).unwrap();
    assert_ne!(g.vertices, fresh.vertices);
    g.refresh(&b, &c, l).unwrap();
    assert_eq!(g, fresh);
}
