//! Render methods side by side (`methods.csv`, `methods.md`): each case is
//! a scene, a method and whether the impostor ring is on, timed with
//! [`super::measure`] at the run's frame size; on scenes with physics
//! clouds each method's frame is compared by mean FLIP with the `exact`
//! ray-march of the same parcels, sun and camera (how far Wang's sprites
//! are from Goswami's hypertexture on the same field). Authored scenes
//! (no parcels) have no exact frame and leave the FLIP empty; for them the
//! paper's "cloud block overdraw" (§6.3) of the view is given instead.
//!
//! One line of [`cases`] adds a case.

use std::path::{Path, PathBuf};

use crate::config::{Camera, RenderMethod};
use crate::error::{Error, Result};
use crate::physics::{CloudParcel, ParcelWorld};
use crate::render::GpuContext;
use crate::render::headless::Headless;
use crate::scene::SceneProfile;
use crate::sky::Sun;

use super::measure::{Repeats, Source, measure_at};
use super::stats::{mean_flip, rgb};

/// One measured configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Case {
    /// Profile file in `profiles/`.
    pub scene: &'static str,
    pub method: RenderMethod,
    /// The impostor ring of §6.2 (on: at the scene's
    /// `[render.sprites] impostor_radius_m`; off: every sprite direct).
    pub impostors: bool,
}

/// Every case of the table: every method but the reference on the physics
/// scene, the paper's overcast (Figure 15) as sprites, and Schpok's
/// authored scene by slicing.
pub fn cases() -> Vec<Case> {
    let mut c: Vec<Case> = RenderMethod::ALL
        .into_iter()
        .filter(|m| *m != RenderMethod::Exact)
        .map(|method| Case {
            scene: "fair_weather.toml",
            method,
            impostors: false,
        })
        .collect();
    for impostors in [false, true] {
        c.push(Case {
            scene: "overcast.toml",
            method: RenderMethod::Sprites,
            impostors,
        });
    }
    c.push(Case {
        scene: "authored.toml",
        method: RenderMethod::Slices,
        impostors: false,
    });
    c
}

/// One row of `methods.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodRow {
    pub scene: String,
    pub method: RenderMethod,
    pub impostors: bool,
    /// Median frame (upload + GPU). units: ms
    pub frame_ms: f64,
    /// Mean FLIP against the exact ray-march (None: no parcels to march).
    pub mean_flip_vs_exact: Option<f64>,
    /// Sprites drawn (0 for the ray-marching methods).
    pub sprites: usize,
    /// Mean cloud block overdraw of the scene's own sprite clouds within
    /// 100 km of the camera (§6.3; 4.75 is the paper's overcast).
    pub overdraw: f32,
}

/// A scene loaded and simulated to its start time: its parcels, camera,
/// sun and sprite clouds.
pub(super) struct Loaded {
    pub profile: SceneProfile,
    pub parcels: Vec<CloudParcel>,
    pub camera: Camera,
    pub sun: Sun,
    /// The simulated time it was loaded at (the authored animation's and
    /// the sprite clouds' clock in the measured frames). units: s
    pub time_s: f64,
}

/// Where the shipped scenes are: the first of `$CUMULUS_PROFILES`,
/// `./profiles`, `profiles/` beside the binary or two folders up from it
/// (a cargo build's `target/release/`), and the source tree the binary was
/// built from that holds a `profiles/` folder with `fair_weather.toml`, so
/// the release binary runs the bench from a copy of `profiles/` on a
/// machine without the sources.
pub fn profiles_dir() -> Result<PathBuf> {
    let mut candidates: Vec<PathBuf> = Vec::new();
    if let Some(p) = std::env::var_os("CUMULUS_PROFILES") {
        candidates.push(PathBuf::from(p));
    }
    candidates.push(PathBuf::from("profiles"));
    if let Some(exe_dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    {
        candidates.push(exe_dir.join("profiles"));
        candidates.push(exe_dir.join("../../profiles"));
    }
    candidates.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles"));
    find_profiles(&candidates)
}

/// The first of `candidates` holding the shipped scenes, or an error
/// listing where it looked.
pub fn find_profiles(candidates: &[PathBuf]) -> Result<PathBuf> {
    candidates
        .iter()
        .find(|d| d.join("fair_weather.toml").is_file())
        .cloned()
        .ok_or_else(|| {
            let looked: Vec<String> = candidates.iter().map(|d| d.display().to_string()).collect();
            Error::invalid(
                "profiles folder",
                "none found",
                format!(
                    "a copy of the repository's profiles/ (with fair_weather.toml) in one of: {}; or set CUMULUS_PROFILES",
                    looked.join(", ")
                ),
            )
        })
}

/// The profile `name` of `profiles/` with the bench's `--set` overrides
/// applied and validated as [`crate::scene::load_scene_with`] does; an
/// error also names the scene (an override must suit every bench scene).
pub fn load_profile(name: &str, overrides: &[String]) -> Result<SceneProfile> {
    let path = profiles_dir()?.join(name);
    crate::scene::load_scene_with(Some(&path), overrides)
        .map(|(p, _)| p)
        .map_err(|e| match e {
            Error::InvalidParameter {
                name: key,
                value,
                allowed,
            } if !overrides.is_empty() => Error::InvalidParameter {
                name: key,
                value,
                allowed: format!("{allowed} (in bench scene {name})"),
            },
            other => other,
        })
}

/// Loads every scene of [`cases`] with `overrides`, so a bad one fails
/// before anything is measured.
pub fn check_overrides(overrides: &[String]) -> Result<()> {
    let mut names: Vec<&str> = cases().iter().map(|c| c.scene).collect();
    names.push(super::landscape::SCENE);
    names.dedup();
    for name in names {
        load_profile(name, overrides)?;
    }
    Ok(())
}

impl Loaded {
    /// Frames of this scene's parcels, camera and sun measured on `hl`.
    pub fn measure(
        &self,
        ctx: &GpuContext,
        hl: &mut Headless,
        reps: Repeats,
    ) -> Result<super::measure::Measured> {
        measure_at(
            ctx,
            hl,
            (self.camera, self.sun, self.time_s as f32),
            Source::Parcels(&self.parcels),
            reps,
        )
    }
}

pub(super) fn load(name: &str, overrides: &[String]) -> Result<Loaded> {
    load_at(name, None, overrides)
}

/// `profiles/NAME` with the `--set` `overrides`, simulated (seed 1, 2 s
/// frames) to `time_s`, or to its `[simulation] start_s`.
pub(super) fn load_at(name: &str, time_s: Option<f64>, overrides: &[String]) -> Result<Loaded> {
    let dir = profiles_dir()?;
    let profile = load_profile(name, overrides)?;
    let env = profile.build_atmosphere(&crate::scene::SceneSource::File(dir.join(name)))?;
    let mut world = ParcelWorld::new(env, profile.world_config(&dir)?, 1)?;
    let t = time_s.unwrap_or(profile.simulation.start_s);
    while world.time_s() < t - 1e-9 {
        world.step(2.0f64.min(t - world.time_s()));
    }
    let mut parcels = Vec::new();
    world.cloud_parcels(&mut parcels);
    let clock = profile.clock()?;
    let sun = crate::scene::render_sun(clock.as_ref(), &profile.render, t).0;
    let camera = Camera::from(&profile.camera);
    Ok(Loaded {
        profile,
        parcels,
        camera,
        sun,
        time_s: t,
    })
}

/// Measures every case of [`cases`] at `size`, each scene loaded with the
/// `--set` `overrides`; `tick` after each.
pub fn methods(
    ctx: &GpuContext,
    size: (u32, u32),
    reps: Repeats,
    overrides: &[String],
    mut tick: impl FnMut(&str),
) -> Result<Vec<MethodRow>> {
    let mut rows = Vec::new();
    let mut scenes: Vec<(&str, Loaded, Option<Vec<u8>>)> = Vec::new();
    for case in cases() {
        if !scenes.iter().any(|(n, ..)| *n == case.scene) {
            let l = load(case.scene, overrides)?;
            let reference = if l.parcels.is_empty() {
                None
            } else {
                let m = run_case(ctx, &l, RenderMethod::Exact, false, size, reps)?;
                Some(rgb(&m.0.rgba))
            };
            scenes.push((case.scene, l, reference));
        }
        let (_, l, reference) = scenes
            .iter()
            .find(|(n, ..)| *n == case.scene)
            .expect("loaded above");
        let (m, sprites) = run_case(ctx, l, case.method, case.impostors, size, reps)?;
        let flip = reference
            .as_ref()
            .map(|r| mean_flip(r, &rgb(&m.rgba), size.0, size.1));
        let scene_sprites: Vec<crate::methods::sprites::model::Sprite> = l
            .profile
            .build_sprite_clouds()
            .into_iter()
            .flat_map(|c| c.sprites)
            .collect();
        let overdraw = crate::methods::sprites::model::order::view_overdraw(
            &scene_sprites,
            l.camera.position,
            100_000.0,
        );
        rows.push(MethodRow {
            scene: case.scene.trim_end_matches(".toml").to_string(),
            method: case.method,
            impostors: case.impostors,
            frame_ms: m.render_ms,
            mean_flip_vs_exact: flip,
            sprites,
            overdraw,
        });
        tick(&format!("methods: {} {}", case.scene, case.method));
    }
    Ok(rows)
}

pub(super) fn run_case(
    ctx: &GpuContext,
    l: &Loaded,
    method: RenderMethod,
    impostors: bool,
    size: (u32, u32),
    reps: Repeats,
) -> Result<(super::measure::Measured, usize)> {
    let mut hl = case_headless(ctx, l, method, impostors, size)?;
    let m = l.measure(ctx, &mut hl, reps)?;
    Ok((m, hl.renderer.sprite_stats().sprites))
}

/// The renderer of scene `l` drawn by `method` at `size`, with its sprite
/// clouds and authored ellipsoids, the impostor ring (`impostors`) built.
pub(super) fn case_headless(
    ctx: &GpuContext,
    l: &Loaded,
    method: RenderMethod,
    impostors: bool,
    size: (u32, u32),
) -> Result<Headless> {
    let mut cfg = crate::config::RenderConfig {
        method,
        ..l.profile.render.clone()
    };
    if impostors && cfg.sprites.impostor_radius_m.is_none() {
        return Err(Error::invalid(
            "bench case impostors",
            &l.profile.name,
            "a scene with [render.sprites] impostor_radius_m",
        ));
    }
    if !impostors {
        cfg.sprites.impostor_radius_m = None;
    }
    let mut hl = Headless::new(ctx, &cfg, size.0, size.1)?;
    hl.renderer
        .set_sprite_clouds(ctx, l.profile.build_sprite_clouds())?;
    hl.renderer
        .set_authored(&l.profile.ellipsoids, &l.profile.particles);
    if impostors {
        // The ring completes one face per frame: measure it built, from a
        // camera that has not moved (the paper's steady state; a moving
        // camera re-renders one 256² face per frame on top).
        let input = crate::render::FrameInput {
            camera: l.camera,
            parcels: &l.parcels,
            sun: l.sun,
            time_s: l.time_s as f32,
        };
        for _ in 0..crate::methods::sprites::model::impostor::SECTORS + 1 {
            hl.render(ctx, &input)?;
        }
    }
    Ok(hl)
}

/// `methods.csv`: scene, method, impostors (on/off), frame_ms,
/// mean_flip_vs_exact (empty where there is no exact frame).
pub fn methods_csv(rows: &[MethodRow]) -> Result<Vec<u8>> {
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.scene.clone(),
                r.method.name().to_string(),
                super::perf::on_off(r.impostors).to_string(),
                format!("{:.3}", r.frame_ms),
                r.mean_flip_vs_exact
                    .map_or(String::new(), |f| format!("{f:.4}")),
            ]
        })
        .collect();
    super::report::csv_bytes(
        &[
            "scene",
            "method",
            "impostors",
            "frame_ms",
            "mean_flip_vs_exact",
        ],
        &body,
    )
}

/// `methods.md`: the same table with sprite counts and the overdraw.
pub fn methods_md(rows: &[MethodRow], width: u32, height: u32) -> String {
    let mut s = format!(
        "# Render methods\n\n{width}×{height}; frame = upload + GPU, median. FLIP: mean against the \
         exact ray-march of the same parcels, sun and camera (authored scenes have none). \
         Overdraw: the paper's cloud block overdraw of the scene's authored sprite clouds \
         ([[sprite_clouds]], [[layers]]; §6.3: Σ sprite area / 16 km² block, mean over the blocks \
         within 100 km; the paper's overcast is 475 %), – where the scene authors none.\n\n\
         | scene | method | impostors | frame (ms) | mean FLIP vs exact | sprites | overdraw |\n\
         |---|---|---|---:|---:|---:|---:|\n"
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {:.1} | {} | {} | {} |\n",
            r.scene,
            r.method,
            super::perf::on_off(r.impostors),
            r.frame_ms,
            r.mean_flip_vs_exact
                .map_or("–".to_string(), |f| format!("{f:.3}")),
            r.sprites,
            if r.overdraw > 0.0 {
                format!("{:.0} %", 100.0 * r.overdraw)
            } else {
                "–".to_string()
            }
        ));
    }
    s.push_str(
        "\nImpostors on: the ring of §6.2 at the scene's `[render.sprites] impostor_radius_m`, \
         measured once built (8 frames) from a still camera; its sprites column counts the \
         sprites still drawn directly.\n",
    );
    for r in rows.iter().filter(|r| r.impostors) {
        if let Some(off) = rows
            .iter()
            .find(|o| !o.impostors && o.scene == r.scene && o.method == r.method)
        {
            s.push_str(&format!(
                "\n{} ({}): impostors on are {:.2}× faster than off (the paper's Figure 15; goal ≥ 2×).\n",
                r.scene,
                r.method,
                off.frame_ms / r.frame_ms.max(1e-9)
            ));
        }
    }
    s
}

/// Writes `methods.csv` and `methods.md` into `dir`.
pub fn write(dir: &Path, rows: &[MethodRow], width: u32, height: u32) -> Result<()> {
    crate::output::write_atomic(&dir.join("methods.csv"), &methods_csv(rows)?)?;
    crate::output::write_atomic(
        &dir.join("methods.md"),
        methods_md(rows, width, height).as_bytes(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_profiles_folder_is_found_or_the_error_says_where_it_looked() {
        let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
        let nowhere = repo.join("no-such-folder");
        let found = find_profiles(&[nowhere.clone(), repo.join("profiles")]).unwrap();
        assert_eq!(found, repo.join("profiles"));
        let e = find_profiles(&[nowhere.clone(), repo.join("src")])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no-such-folder") && e.contains("CUMULUS_PROFILES"),
            "{e}"
        );
    }
}
