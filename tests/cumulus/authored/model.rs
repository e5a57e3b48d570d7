//! The CPU side of the Schpok 2003 authored clouds (src/methods/slices/model): Wyvill
//! blending, ellipsoid fields, keyframes and particle dynamics, media
//! filters, the qualitative controls, noise-octave transforms and the
//! authored scene profile. The slicing geometry is in authored::slicing.

use std::path::Path;

use cumulus::methods::slices::model::animation::{
    ANVIL_SPREAD_PER_S, DECAY_PER_S, GROWTH_PER_S, RISE_M_S,
};
use cumulus::methods::slices::model::octaves::{
    MAX_TIERS, TierUniform, octave_factor, octave_weights,
};
use cumulus::methods::slices::model::*;
use cumulus::scene::SceneProfile;
use glam::{Mat3, Mat4, Vec3};

/// f32 arithmetic on values of order 1: a few ulps of rounding.
const EPS: f32 = 1e-5;

/// The soft-object function of Wyvill, McPheeters & Wyvill 1986 in f64,
/// written from the paper's formula independently of the library.
fn wyvill_formula(s: f64) -> f64 {
    if s >= 1.0 {
        0.0
    } else {
        1.0 - 4.0 / 9.0 * s.powi(6) + 17.0 / 9.0 * s.powi(4) - 22.0 / 9.0 * s.powi(2)
    }
}

#[test]
fn wyvill_blending_matches_the_formula() {
    for i in 0..=120 {
        let s = i as f64 / 100.0;
        let got = wyvill((s * s) as f32) as f64;
        // f32 evaluation of a polynomial with terms ≤ 3: ~1e-7 rounding.
        assert!(
            (got - wyvill_formula(s)).abs() < 1e-6,
            "s = {s}: {got} vs {}",
            wyvill_formula(s)
        );
    }
    // The properties that make it a blending function.
    assert_eq!(wyvill(0.0), 1.0);
    assert!(wyvill(1.0).abs() < EPS);
    assert!((wyvill(0.25) - 0.5).abs() < EPS, "C(1/2) = 1/2");
    assert_eq!(wyvill(1.7), 0.0);
    // Slope in s is zero at both ends: a step of 1e-3 in s changes C by
    // O(1e-6), against 2.4e-3 for a unit slope.
    assert!((1.0 - wyvill(1e-6)).abs() < 1e-5);
    assert!(wyvill(0.999f32 * 0.999).abs() < 1e-5);
}

fn state(centre: [f32; 3], radii: [f32; 3], yaw_deg: f32, strength: f32) -> EllipsoidState {
    EllipsoidState {
        centre_m: centre.into(),
        radii_m: radii.into(),
        rotation: EllipsoidState::rotation_from_deg([0.0, 0.0, yaw_deg]),
        strength,
        base_z_m: f32::NEG_INFINITY,
    }
}

#[test]
fn ellipsoid_field_uses_its_rotated_radii_and_sums_primitives() {
    // Long axis (200 m) turned from x to y by a 90° yaw.
    let e = state([10.0, 20.0, 30.0], [200.0, 100.0, 50.0], 90.0, 2.0);
    let c = Vec3::new(10.0, 20.0, 30.0);
    let along_long = e.field(c + Vec3::new(0.0, 150.0, 0.0));
    assert!(
        (along_long - 2.0 * wyvill_formula(0.75) as f32).abs() < EPS,
        "{along_long}"
    );
    assert_eq!(
        e.field(c + Vec3::new(150.0, 0.0, 0.0)),
        0.0,
        "150 m > the 100 m short axis"
    );
    let up = e.field(c + Vec3::new(0.0, 0.0, 25.0));
    assert!((up - 2.0 * wyvill_formula(0.5) as f32).abs() < EPS);
    // Bounds of the turned ellipsoid: 100 m along x, 200 m along y.
    let h = e.half_extent_m();
    assert!(
        (h - Vec3::new(100.0, 200.0, 50.0)).abs().max_element() < 1e-3,
        "{h}"
    );
    // Two primitives add (no clamp).
    let f = state([10.0, 20.0, 30.0], [100.0; 3], 0.0, 1.0);
    let p = c + Vec3::new(0.0, 0.0, 25.0);
    assert!((field_at(&[e, f], p) - (e.field(p) + f.field(p))).abs() < EPS);
    assert!(field_at(&[e, f], c) > 2.9, "overlapping centres add past 1");
}

#[test]
fn keyframes_interpolate_linearly_and_hold_past_the_ends() {
    let e = Ellipsoid {
        centre_m: [0.0, 0.0, 1000.0],
        radii_m: [100.0, 100.0, 100.0],
        strength: 1.0,
        keyframes: vec![
            Keyframe {
                time_s: 10.0,
                centre_m: Some([100.0, 0.0, 1000.0]),
                radii_m: None,
                strength: Some(0.0),
            },
            Keyframe {
                time_s: 30.0,
                centre_m: None,
                radii_m: Some([300.0, 100.0, 100.0]),
                strength: None,
            },
        ],
        ..Ellipsoid::default()
    };
    let at = |t| state_at(&e, t, Vec3::ZERO);
    assert_eq!(at(0.0).centre_m, Vec3::new(0.0, 0.0, 1000.0));
    let mid = at(5.0);
    assert!((mid.centre_m - Vec3::new(50.0, 0.0, 1000.0)).length() < 1e-3);
    assert!((mid.strength - 0.5).abs() < EPS);
    // Between keys 1 and 2: the centre and strength are held (missing
    // values carry forward), the radii move.
    let later = at(20.0);
    assert!((later.centre_m - Vec3::new(100.0, 0.0, 1000.0)).length() < 1e-3);
    assert_eq!(later.strength, 0.0);
    assert!((later.radii_m.x - 200.0).abs() < 1e-3, "{}", later.radii_m);
    // Held after the last key.
    assert_eq!(at(1000.0).radii_m, Vec3::new(300.0, 100.0, 100.0));
}

#[test]
fn particle_dynamics_move_grow_and_fade_at_their_rates() {
    let base = Ellipsoid {
        centre_m: [0.0, 0.0, 1000.0],
        radii_m: [100.0, 200.0, 50.0],
        ..Ellipsoid::default()
    };
    let with = |motion| Ellipsoid {
        motion,
        ..base.clone()
    };
    let wind = Vec3::new(3.0, -1.0, 0.0);
    let t = 100.0;
    let still = state_at(&with(Motion::Still), t, wind);
    assert!(
        (still.centre_m - Vec3::new(300.0, -100.0, 1000.0)).length() < 1e-3,
        "drifts with the uniform wind"
    );
    let rising = state_at(&with(Motion::Rising), t, wind);
    assert!((rising.centre_m.z - (1000.0 + RISE_M_S * t)).abs() < 1e-3);
    let grow = (GROWTH_PER_S * t).exp();
    let expanding = state_at(&with(Motion::Expanding), t, Vec3::ZERO);
    assert!((expanding.radii_m - Vec3::new(100.0, 200.0, 50.0) * grow).length() < 1e-2);
    let shrinking = state_at(&with(Motion::Shrinking), t, Vec3::ZERO);
    assert!((shrinking.radii_m.x - 100.0 / grow).abs() < 1e-3);
    assert!((shrinking.strength - (-DECAY_PER_S * t).exp()).abs() < EPS);
    let anvil = state_at(&with(Motion::Anvil), t, Vec3::ZERO);
    let spread = (ANVIL_SPREAD_PER_S * t).exp();
    assert!((anvil.radii_m.x - 100.0 * spread).abs() < 1e-2);
    assert_eq!(
        anvil.radii_m.z, 50.0,
        "the anvil spreads but does not thicken"
    );
}

#[test]
fn cumulonimbus_preset_rises_into_a_flat_spreading_anvil() {
    let cb = cumulonimbus([0.0, 0.0, 1500.0], 9500.0);
    let anvil = cb.last().unwrap();
    assert_eq!(anvil.motion, Motion::Anvil);
    assert!(
        anvil.radii_m[2] * 4.0 < anvil.radii_m[0],
        "flat: {:?}",
        anvil.radii_m
    );
    let tower_top = |t: f32| {
        cb[..cb.len() - 1]
            .iter()
            .map(|e| {
                let s = state_at(e, t, Vec3::ZERO);
                s.centre_m.z + s.radii_m.z
            })
            .fold(f32::MIN, f32::max)
    };
    assert!(tower_top(0.0) < 9500.0, "the tower starts below the anvil");
    let reach = anvil.keyframes[0].time_s;
    assert!(
        tower_top(reach) >= 9500.0 - 1.0,
        "the tower reaches the anvil when it appears"
    );
    assert_eq!(state_at(anvil, 0.0, Vec3::ZERO).strength, 0.0);
    assert_eq!(state_at(anvil, reach, Vec3::ZERO).strength, 1.0);
    assert!(
        state_at(anvil, reach + 300.0, Vec3::ZERO).radii_m.x > anvil.radii_m[0] * 2.0,
        "and spreads"
    );
}

#[test]
fn media_filters_follow_table_2() {
    for i in 0..=100 {
        let n = i as f32 / 100.0;
        assert_eq!(MediaFilter::Cumulus.apply(n), n);
        assert_eq!(MediaFilter::Stratus.apply(n), n);
        assert!((MediaFilter::Wispy.apply(n) - (1.0 - 2.0 * (n - 0.5).abs())).abs() < EPS);
        assert!((MediaFilter::Cirrus.apply(n) - 1.0 / (1.0 + 10.0 * n)).abs() < EPS);
        for m in MediaFilter::ALL {
            let v = m.apply(n);
            assert!((0.0..=1.0).contains(&v), "{} at {n}: {v}", m.name());
        }
    }
    assert_eq!(
        MediaFilter::Wispy.apply(0.5),
        1.0,
        "wisps where the noise crosses its middle"
    );
    assert_eq!(MediaFilter::Wispy.apply(0.0), 0.0);
    assert!((MediaFilter::Cirrus.apply(1.0) - 1.0 / 11.0).abs() < EPS);
    assert_eq!(MediaFilter::ALL.map(MediaFilter::gpu_id), [0, 1, 2, 3]);
}

#[test]
fn qualitative_controls_derive_the_table_2_quantities() {
    let cfg = |opacity, quality, dirtiness, sharpness| SlicesConfig {
        opacity,
        quality,
        dirtiness,
        sharpness,
        ..SlicesConfig::default()
    };
    let c = cfg(0.8, 64, 0.5, 0.25);
    assert!((c.plane_opacity() - 0.8 / 64.0).abs() < 1e-7);
    assert_eq!(c.planes(), 64);
    assert!((c.shadow_magnitude() - 0.5 / (0.8 / 64.0)).abs() < 1e-3);
    assert!((c.alpha_cutoff() - 0.25 * 0.8 / 64.0).abs() < 1e-7);
    assert_eq!(
        SlicesConfig {
            detail: 2.7,
            ..c.clone()
        }
        .lacunarity(),
        2.7
    );
    // The compensations: total opacity across the planes stays Opacity
    // whatever the Quality; a shadow step (magnitude × plane opacity) is
    // Dirtiness whatever Opacity and Quality; the cutoff relative to the
    // plane opacity is Sharpness whatever Opacity.
    for (o, q) in [(0.5, 32), (1.0, 128), (4.0, 1024)] {
        let c = cfg(o, q, 0.7, 0.3);
        assert!((c.plane_opacity() * q as f32 - o).abs() < 1e-5);
        assert!((c.shadow_magnitude() * c.plane_opacity() - 0.7).abs() < 1e-5);
        assert!((c.alpha_cutoff() / c.plane_opacity() - 0.3).abs() < 1e-5);
    }
}

#[test]
fn slices_config_rejects_bad_values_by_key() {
    let bad = |c: SlicesConfig| c.validate().unwrap_err().to_string();
    let d = SlicesConfig::default();
    d.validate().unwrap();
    assert!(
        bad(SlicesConfig {
            quality: 4,
            ..d.clone()
        })
        .contains("render.slices.quality = 4: 8 to 1024")
    );
    assert!(
        bad(SlicesConfig {
            opacity: f32::NAN,
            ..d.clone()
        })
        .contains("render.slices.opacity = NaN")
    );
    assert!(
        bad(SlicesConfig {
            detail: 1.0,
            ..d.clone()
        })
        .contains("render.slices.detail")
    );
    assert!(
        bad(SlicesConfig {
            sharpness: 1.5,
            ..d.clone()
        })
        .contains("render.slices.sharpness")
    );
    assert!(
        bad(SlicesConfig {
            shadow_colour: [0.0, 2.0, 0.0],
            ..d.clone()
        })
        .contains("render.slices.shadow_colour[1]")
    );
    assert!(
        bad(SlicesConfig {
            octaves: 9,
            ..d.clone()
        })
        .contains("render.slices.octaves = 9: 1 to 8")
    );
    assert!(
        bad(SlicesConfig {
            tiers: vec![],
            ..d.clone()
        })
        .contains("render.slices.tiers")
    );
    let two = vec![
        NoiseTier {
            bottom_m: 3000.0,
            ..NoiseTier::default()
        },
        NoiseTier::default(),
    ];
    assert!(
        bad(SlicesConfig {
            tiers: two,
            ..d.clone()
        })
        .contains("render.slices.tiers[1].bottom_m")
    );
}

/// The world point that octave `m` maps to where it mapped `pivot` at t = 0:
/// how far that octave's pattern has moved.
fn pattern_position(m0: Mat4, m: Mat4, pivot: Vec3) -> Vec3 {
    m.inverse().transform_point3(m0.transform_point3(pivot))
}

/// The rotation angle of the linear part of `m` once its scale is removed.
fn rotation_angle_deg(m: Mat4, scale: f32) -> f32 {
    let r = Mat3::from_mat4(m) * (1.0 / scale);
    (((r.x_axis.x + r.y_axis.y + r.z_axis.z - 1.0) / 2.0).clamp(-1.0, 1.0))
        .acos()
        .to_degrees()
}

#[test]
fn octave_translation_follows_the_wind_exponentially_faster_per_octave() {
    let pivot = Vec3::new(500.0, -200.0, 2000.0);
    let base = NoiseMotion {
        wind_m_s: [1.0, 0.0, 0.0],
        torque_deg_s: [0.0; 3],
    };
    let tier = |wind: [f32; 3]| NoiseTier {
        wind_m_s: wind,
        scale_m: 800.0,
        ..NoiseTier::default()
    };
    let lac = 2.0;
    let shift = |t: &NoiseTier, time: f32| {
        let m0 = t.transforms(&base, lac, 4, pivot, 0.0);
        let m = t.transforms(&base, lac, 4, pivot, time);
        (0..4)
            .map(|o| pattern_position(m0[o], m[o], pivot) - pivot)
            .collect::<Vec<_>>()
    };
    let one = shift(&tier([0.0, 2.0, 0.0]), 10.0);
    let two = shift(&tier([0.0, 4.0, 0.0]), 10.0);
    // Octave 0 moves with the Base tier: 1 m/s × 10 s along x.
    assert!(
        (one[0] - Vec3::new(10.0, 0.0, 0.0)).length() < 1e-2,
        "{}",
        one[0]
    );
    for o in 1..4 {
        let f = octave_factor(lac, o);
        // f32 matrices of texel-scale entries: centimetres over kilometres.
        assert!(
            (one[o] - Vec3::new(0.0, 2.0 * 10.0 * f, 0.0)).length() < 0.05,
            "octave {o}: {}",
            one[o]
        );
        assert!(
            (two[o] - one[o] * 2.0).length() < 0.05,
            "translation ∝ wind"
        );
        if o > 1 {
            assert!(
                (one[o].length() / one[o - 1].length() - lac).abs() < 1e-3,
                "×lacunarity per octave"
            );
        }
    }
    // The Base tier moves every tier's first octave together.
    let other = shift(&tier([-7.0, 0.0, 3.0]), 10.0);
    assert!((other[0] - one[0]).length() < 1e-2);
}

#[test]
fn octave_rotation_follows_the_torque() {
    let pivot = Vec3::ZERO;
    let base = NoiseMotion {
        wind_m_s: [0.0; 3],
        torque_deg_s: [0.0, 0.0, 1.0],
    };
    let t = NoiseTier {
        torque_deg_s: [0.0, 0.0, 3.0],
        scale_m: 1000.0,
        ..NoiseTier::default()
    };
    let lac = 1.5;
    let m = t.transforms(&base, lac, 3, pivot, 4.0);
    // Octave 0: Base torque 1 °/s × 4 s; octave o ≥ 1: 3 °/s × f × 4 s.
    assert!((rotation_angle_deg(m[0], 1.0 / 1000.0) - 4.0).abs() < 0.01);
    for (o, &mo) in m.iter().enumerate().skip(1) {
        let f = octave_factor(lac, o);
        let angle = rotation_angle_deg(mo, f / 1000.0);
        assert!((angle - 12.0 * f).abs() < 0.01, "octave {o}: {angle}");
    }
    // Double the torque, double the angle.
    let t2 = NoiseTier {
        torque_deg_s: [0.0, 0.0, 6.0],
        ..t.clone()
    };
    let m2 = t2.transforms(&base, lac, 3, pivot, 4.0);
    assert!((rotation_angle_deg(m2[1], lac / 1000.0) - 24.0 * lac).abs() < 0.01);
}

#[test]
fn cirrus_tiers_stretch_the_noise_along_the_wind() {
    let base = NoiseMotion::default();
    let t = NoiseTier {
        media: MediaFilter::Cirrus,
        stretch_along_wind: 4.0,
        wind_m_s: [0.0, 5.0, 0.0],
        ..NoiseTier::default()
    };
    let m = t.transforms(&base, 2.0, 2, Vec3::ZERO, 0.0)[1];
    let along = m.transform_vector3(Vec3::Y).length();
    let across = m.transform_vector3(Vec3::X).length();
    assert!(
        (across / along - 4.0).abs() < 1e-4,
        "features 4× longer along the wind: {across} / {along}"
    );
}

#[test]
fn octave_uniform_packs_every_tier_for_the_shaders() {
    assert_eq!(std::mem::size_of::<TierUniform>() % 16, 0);
    let tiers = vec![
        NoiseTier::default(),
        NoiseTier {
            bottom_m: 5000.0,
            media: MediaFilter::Wispy,
            wind_m_s: [3.0, 0.0, 0.0],
            ..NoiseTier::default()
        },
    ];
    let base = NoiseMotion {
        wind_m_s: [1.0, 1.0, 0.0],
        torque_deg_s: [0.0; 3],
    };
    let u = octave_uniform(&tiers, &base, 2.0, 4, Vec3::ZERO, 30.0);
    assert_eq!((u.tier_count, u.octave_count), (2, 4));
    assert_eq!(u.tiers[1].media, MediaFilter::Wispy.gpu_id());
    assert_eq!(u.tiers[1].bottom_m, 5000.0);
    let expect = tiers[1].transforms(&base, 2.0, 4, Vec3::ZERO, 30.0);
    for (o, e) in expect.iter().enumerate() {
        assert_eq!(u.tiers[1].texture_from_world[o], e.to_cols_array_2d());
    }
    assert_eq!(
        u.tiers[1].texture_from_world[4], [[0.0; 4]; 4],
        "unused octaves are zero"
    );
    assert_eq!(
        u.tiers[MAX_TIERS - 1].texture_from_world[0],
        [[0.0; 4]; 4],
        "unused tiers are zero"
    );
    let w = octave_weights(4);
    assert!(
        (w.iter().sum::<f32>() - 1.0).abs() < 1e-6,
        "persistence weights are normalised"
    );
    assert!((w[1] / w[0] - 0.5).abs() < 1e-6 && (w[3] / w[2] - 0.5).abs() < 1e-6);
    assert!((u.tiers[0].first_weight - w[0]).abs() < 1e-7);
}

fn profile_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/authored.toml")
}

#[test]
fn authored_profile_loads_animates_and_round_trips() {
    let p = SceneProfile::load(&profile_path()).unwrap_or_else(|e| panic!("{e}"));
    let e = &p.ellipsoids;
    assert_eq!(e.len(), 18);
    // A cumulonimbus: flat-based at the condensation level, rising cells,
    // and an anvil already spreading at the tropopause; fair-weather
    // cumulus around it, the last one keyframed.
    assert_eq!(e[0].base_m, Some(1500.0));
    let rising: Vec<usize> = (0..e.len())
        .filter(|&i| e[i].motion == Motion::Rising)
        .collect();
    let anvils: Vec<usize> = (0..e.len())
        .filter(|&i| e[i].motion == Motion::Anvil)
        .collect();
    assert!(rising.len() >= 5, "{rising:?}");
    assert_eq!(anvils.len(), 2);
    assert!(
        anvils.iter().all(|&i| e[i].strength > 1.0
            && e[i].keyframes.is_empty()
            && e[i].centre_m[2] > 9000.0)
    );
    let s = &p.render.slices;
    assert_eq!(
        s.tiers.iter().map(|t| t.media).collect::<Vec<_>>(),
        [
            MediaFilter::Cumulus,
            MediaFilter::Wispy,
            MediaFilter::Cirrus
        ]
    );
    let last = e.len() - 1;
    assert!(e[last].keyframes.len() == 2 && p.particles.wind_m_s[0] > 0.0);
    // It animates: the cells rise, the anvil spreads, the keyframed
    // cumulus moves; and the tower stays whole: some cell below 6 km has
    // its full strength at the start, at 600 s and at the end.
    let at = |t| states_at(e, &p.particles, t);
    let (t0, t1) = (at(0.0), at(900.0));
    assert!(
        rising
            .iter()
            .all(|&i| t1[i].centre_m.z > t0[i].centre_m.z + 2000.0)
    );
    assert!(
        anvils
            .iter()
            .all(|&i| t1[i].radii_m.x > 2.0 * t0[i].radii_m.x)
    );
    assert!(t1[last].centre_m.y > t0[last].centre_m.y + 1000.0);
    for t in [0.0, 600.0, 900.0] {
        let now = at(t);
        assert!(
            rising
                .iter()
                .any(|&i| now[i].strength >= 1.0 && now[i].centre_m.z < 6000.0),
            "no full cell low in the tower at {t} s"
        );
    }
    // Saved and reloaded, it is the same scene.
    let text = p.to_toml().unwrap();
    let back = SceneProfile::from_toml(&text, Path::new("saved.toml")).unwrap();
    assert_eq!(back, p);
}

#[test]
fn bad_ellipsoids_name_the_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let write = |body: &str| {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, body).unwrap();
        (SceneProfile::load(&path).unwrap_err().to_string(), path)
    };
    let (msg, path) = write(
        "name = \"x\"\n\n[[ellipsoids]]\ncentre_m = [0.0, 0.0, 1000.0]\n\n[[ellipsoids]]\nradii_m = [100.0, 100.0, -5.0]\n",
    );
    assert!(
        msg.starts_with(&format!(
            "{}:7:1: invalid ellipsoids[1].radii_m[2] = -5: 1 to 1e5 m",
            path.display()
        )),
        "{msg}"
    );
    let (msg, _) =
        write("[[ellipsoids]]\nkeyframes = [\n  { time_s = 10.0 },\n  { time_s = 5.0 },\n]\n");
    assert!(
        msg.contains(
            ":2:1: invalid ellipsoids[0].keyframes[1].time_s = 5: later than the previous key"
        ),
        "{msg}"
    );
    let (msg, _) = write("[[ellipsoids]]\nmotion = \"spinning\"\n");
    assert!(msg.contains(":2:") && msg.contains("spinning"), "{msg}");
    let (msg, _) = write("[[ellipsoids]]\nstrength = nan\n");
    assert!(
        msg.contains("invalid ellipsoids[0].strength = NaN: 0 to 4"),
        "{msg}"
    );
    let (msg, _) = write("[render.slices]\nquality = 2\n");
    assert!(
        msg.contains(":2:1: invalid render.slices.quality = 2"),
        "{msg}"
    );
    let (msg, _) =
        write("[render.slices]\n\n[[render.slices.tiers]]\nmedia = \"cirrus\"\nscale_m = 0.0\n");
    assert!(
        msg.contains(":5:1: invalid render.slices.tiers[0].scale_m = 0"),
        "{msg}"
    );
    let (msg, _) = write("[particles]\nwind_m_s = [1.0, 500.0, 0.0]\n");
    assert!(
        msg.contains(":2:1: invalid particles.wind_m_s[1] = 500"),
        "{msg}"
    );
}

#[test]
fn authored_frame_gathers_geometry_and_octaves_for_the_renderer() {
    let p = SceneProfile::load(&profile_path()).unwrap_or_else(|e| panic!("{e}"));
    let eye = Vec3::from(p.camera.position_m);
    let view = Vec3::from(p.camera.target_m) - eye;
    let sun = p.render.sun_direction();
    let s = &p.render.slices;
    let at = |t| authored_frame(&p.ellipsoids, &p.particles, s, t, sun, eye, view).unwrap();
    let f = at(600.0);
    assert_eq!(f.states.len(), 18);
    // A stack per cloud, every primitive with strength in one (two of
    // the storm's cells have faded out by 600 s), each of Quality planes
    // of square grids with vertices no farther apart than the floor,
    // farthest first.
    let stacks = &f.slices.stacks;
    assert!(stacks.len() >= 2, "the storm and the cumulus apart");
    let live = f.states.iter().filter(|e| e.strength > 0.0).count();
    assert!(live < 18);
    assert_eq!(f.slices.states.len(), live);
    for st in stacks {
        let g = &st.geometry;
        assert_eq!(g.plane_offsets_m.len(), 128);
        assert_eq!(g.vertices.len(), 128 * g.side() * g.side());
        let p = |i: usize| Vec3::from(g.vertices[i].position_m);
        // Unless one more cell a side would pass the stack's vertex cap
        // (the storm's spreading anvil, 15 km and more at 128 planes).
        let capped = (128 * (g.side() + 1).pow(2)) as u64 > slicing::MAX_STACK_VERTICES;
        for step in [p(1) - p(0), p(g.side()) - p(0)] {
            // f32 positions of km-scale vertices: 1e-4 relative.
            assert!(capped || step.length() <= slicing::MAX_VERTEX_SPACING_M * 1.0001);
        }
    }
    assert!(
        stacks
            .windows(2)
            .all(|w| w[0].distance_m >= w[1].distance_m)
    );
    let v = f.slices.vertices();
    assert!(
        v.iter().any(|v| v.density > 0.5),
        "the planes cross the clouds"
    );
    assert!(v.iter().any(|v| v.shadow > 0.01), "and shade them");
    assert_eq!((f.octaves.tier_count, f.octaves.octave_count), (3, 4));
    // The noise pivots on the centre of the clouds' bounds at time 0: at
    // t = 0 every tier's first octave maps it to the texture origin.
    let (lo, hi) = ellipsoid::bounds_m(&at(0.0).states).unwrap();
    for tier in &at(0.0).octaves.tiers[..3] {
        let m = Mat4::from_cols_array_2d(&tier.texture_from_world[0]);
        assert!(m.transform_point3((lo + hi) * 0.5).length() < 1e-4);
    }
}
