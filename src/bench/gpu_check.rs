//! `cumulus bench --gpu-check`: the headline speed goals measured in one
//! short run that needs only the release binary and `profiles/` (no Rust
//! toolchain, no source tree), and a one-page table of them with the
//! adapter, driver, resolution and commit and a pass or fail against each
//! goal (docs/performance.md, "GPU check").
//!
//! A case's "clouds" time is every GPU pass the clouds cost besides the
//! shared passes (shadow map, sky, terrain, tone map): the bake (re-baked
//! every frame, as in the live window where the parcels move every
//! frame), the march, the temporal resolve, the sprites, the slices and
//! their vertex field, and the composite. Where the tone map blends the
//! cloud image instead of a composite pass (the frames users see), the
//! case is measured again with the scene target kept whole, and the tone
//! map's extra time is counted with the clouds. The goals are for a
//! discrete GPU at 1920×1080: a CPU adapter's figures are written but not
//! judged.

use std::path::Path;

use crate::config::{Camera, MarchPath, RenderConfig, RenderMethod};
use crate::error::Result;
use crate::physics::CloudParcel;
use crate::render::GpuContext;
use crate::render::headless::Headless;
use crate::sky::Sun;

use super::measure::{Measured, Repeats, Source, measure_at};
use super::methods::{Loaded, case_headless, load, load_at};

/// The goals' frame size. units: px
pub const SIZE: (u32, u32) = (1920, 1080);
/// The paper's frame size (Goswami & Neyret 2016, Table 1). units: px
pub const PAPER_SIZE: (u32, u32) = (730, 545);
/// Parcels of the small and the large bench field.
pub const FIELD_COUNTS: [usize; 2] = [85, 10_000];

/// Frames per case: a few warm-up frames, then the median of up to 20
/// within 4 s, so that the whole check stays within a few minutes on a
/// discrete GPU (scene loading and pipeline builds included).
pub const REPEATS: Repeats = Repeats {
    warmup: 5,
    measured: 20,
    budget_ms: 4000.0,
};

/// The passes a frame has whatever its clouds: not counted as clouds.
const SHARED: [&str; 4] = ["shadow", "sky", "terrain", "tonemap"];

/// One measured case.
#[derive(Debug, Clone)]
pub struct CheckRow {
    pub case: String,
    pub width: u32,
    pub height: u32,
    /// Condensed parcels drawn (0 for authored scenes).
    pub parcels: usize,
    /// The clouds' passes (see the module docs). units: ms
    pub clouds_ms: f64,
    /// What `clouds_ms` is made of: (pass, median ms), the tone map's
    /// blend as "blend". units: ms
    pub parts: Vec<(String, f64)>,
    /// The whole GPU frame, first to last timestamp. units: ms
    pub gpu_ms: f64,
    /// The goal on the clouds' time, if this case has one. units: ms
    pub goal_ms: Option<f64>,
}

impl CheckRow {
    /// Met (Some(true)), missed (Some(false)), or no goal / not judged.
    pub fn verdict(&self, judged: bool) -> Option<bool> {
        self.goal_ms.filter(|_| judged).map(|g| self.clouds_ms <= g)
    }
}

/// One case measured as a user's frame draws it, and the time its tone
/// map spends blending the clouds.
struct Case {
    m: Measured,
    /// Where the tone map blends the cloud image (no composite pass), its
    /// time over the plain tone map of the same frame with the scene
    /// target kept whole; 0 elsewhere. units: ms
    blend_ms: f64,
}

/// The clouds' passes of `c` (see the module docs), the tone map's blend
/// of their image as "blend".
fn cloud_parts(c: &Case) -> Vec<(String, f64)> {
    let mut parts: Vec<(String, f64)> =
        c.m.passes
            .iter()
            .filter(|(n, _)| !SHARED.contains(&n.as_str()))
            .cloned()
            .collect();
    if c.blend_ms > 0.0 {
        parts.push(("blend".to_string(), c.blend_ms));
    }
    parts
}

fn row(case: &str, size: (u32, u32), parcels: usize, c: &Case, goal_ms: Option<f64>) -> CheckRow {
    let parts = cloud_parts(c);
    CheckRow {
        case: case.to_string(),
        width: size.0,
        height: size.1,
        parcels,
        clouds_ms: parts.iter().map(|(_, ms)| ms).sum(),
        parts,
        gpu_ms: c.m.gpu_ms,
        goal_ms,
    }
}

/// `parts` as "bake 0.100 · clouds 0.800".
fn parts_text(parts: &[(String, f64)]) -> String {
    let text: Vec<String> = parts.iter().map(|(n, ms)| format!("{n} {ms:.3}")).collect();
    text.join(" · ")
}

/// Frames of `hl` from `view` (camera, sun, time) drawing `parcels`; then,
/// if the tone map blended the clouds, the same frames with the scene
/// target kept whole (a composite pass, the plain tone map): the tone
/// map's extra time is the blend's.
fn measure_case(
    ctx: &GpuContext,
    hl: &mut Headless,
    view: (Camera, Sun, f32),
    parcels: &[CloudParcel],
) -> Result<Case> {
    let m = measure_at(ctx, hl, view, Source::Parcels(parcels), REPEATS)?;
    if !hl.renderer.scene_folded() {
        return Ok(Case { m, blend_ms: 0.0 });
    }
    hl.renderer.set_scene_whole(true);
    let whole = measure_at(ctx, hl, view, Source::Parcels(parcels), REPEATS);
    hl.renderer.set_scene_whole(false);
    let tonemap = |m: &Measured| m.pass_ms("tonemap").unwrap_or(0.0);
    let blend_ms = (tonemap(&m) - tonemap(&whole?)).max(0.0);
    Ok(Case { m, blend_ms })
}

/// `size` scaled like `at` is from [`SIZE`] (the paper's frame at a
/// reduced test size keeps its proportion to the others).
fn scaled(size: (u32, u32), at: (u32, u32)) -> (u32, u32) {
    let f = at.0 as f64 / SIZE.0 as f64;
    (
        ((size.0 as f64 * f).round() as u32).max(16),
        ((size.1 as f64 * f).round() as u32).max(16),
    )
}

/// A loaded scene drawn with `cfg` (its sprite clouds and authored
/// ellipsoids too), the bake redone every frame.
fn scene_case(ctx: &GpuContext, l: &Loaded, cfg: &RenderConfig, size: (u32, u32)) -> Result<Case> {
    let mut hl = Headless::new(ctx, cfg, size.0, size.1)?;
    hl.renderer
        .set_sprite_clouds(ctx, l.profile.build_sprite_clouds())?;
    hl.renderer
        .set_authored(&l.profile.ellipsoids, &l.profile.particles);
    hl.renderer.set_always_bake(true);
    measure_case(ctx, &mut hl, view_of(l), &l.parcels)
}

/// A loaded scene's camera, sun and start time.
fn view_of(l: &Loaded) -> (Camera, Sun, f32) {
    (l.camera, l.sun, l.time_s as f32)
}

/// Measures every case at `at` (the goals' [`SIZE`], or smaller for a
/// test), scenes loaded with the `--set` `overrides`; `tick` before each.
pub fn gpu_check(
    ctx: &GpuContext,
    at: (u32, u32),
    overrides: &[String],
    mut tick: impl FnMut(&str),
) -> Result<Vec<CheckRow>> {
    let mut rows = Vec::new();

    tick("the default scene");
    let l = load("fair_weather.toml", overrides)?;
    let m = scene_case(ctx, &l, &l.profile.render, at)?;
    rows.push(row(
        "default scene (fair weather, baked)",
        at,
        l.parcels.len(),
        &m,
        Some(1.0),
    ));

    tick("the landscape");
    let l = load_at("landscape.toml", None, overrides)?;
    for (temporal, case, goal) in [
        (false, "landscape, full-rate march", Some(3.0)),
        (true, "landscape, temporal amortisation", None),
    ] {
        let cfg = RenderConfig {
            temporal: Some(temporal.into()),
            march: MarchPath::Compute,
            ..l.profile.render.clone()
        };
        let m = scene_case(ctx, &l, &cfg, at)?;
        rows.push(row(case, at, l.parcels.len(), &m, goal));
    }

    let paper = scaled(PAPER_SIZE, at);
    for (n, size, goal) in [
        (FIELD_COUNTS[0], at, None),
        (FIELD_COUNTS[1], at, Some(3.0)),
        (FIELD_COUNTS[0], paper, Some(0.5)),
    ] {
        tick(&format!("{n} parcels at {}×{}", size.0, size.1));
        let parcels = super::scenes::cloud_parcels(&super::scenes::cloud_field(n)?);
        let cfg = RenderConfig::default();
        let mut hl = Headless::new(ctx, &cfg, size.0, size.1)?;
        hl.renderer.set_always_bake(true);
        let view = (super::perf::camera(), cfg.sun(), 0.0);
        let m = measure_case(ctx, &mut hl, view, &parcels)?;
        rows.push(row(
            &format!("{n} parcels (bench field, baked)"),
            size,
            n,
            &m,
            goal,
        ));
    }

    tick("the overcast by sprites");
    let l = load("overcast.toml", overrides)?;
    let impostors = l.profile.render.sprites.impostor_radius_m.is_some();
    let mut hl = case_headless(ctx, &l, RenderMethod::Sprites, impostors, at)?;
    let m = measure_case(ctx, &mut hl, view_of(&l), &l.parcels)?;
    rows.push(row("100 km overcast by sprites", at, 0, &m, Some(2.0)));

    tick("the authored scene by slices");
    let mut with_q = overrides.to_vec();
    with_q.push("render.slices.quality=128".into());
    let l = load("authored.toml", &with_q)?;
    let mut hl = case_headless(ctx, &l, RenderMethod::Slices, false, at)?;
    let m = measure_case(ctx, &mut hl, view_of(&l), &l.parcels)?;
    rows.push(row(
        "authored scene by slices, Quality 128",
        at,
        0,
        &m,
        Some(3.0),
    ));
    Ok(rows)
}

/// The one-page table: where it ran, then a row per case.
pub fn check_md(info: &super::RunInfo, date: &str, rows: &[CheckRow]) -> String {
    let judged = !info.cpu_adapter;
    let mut s = String::from("# GPU check\n\n");
    s += &format!(
        "| | |\n|---|---|\n| adapter | {} |\n| driver | {} |\n| backend | {} |\n| resolution | {}×{} |\n| commit | {} ({} build) |\n| date | {date} |\n| timing | {} |\n\n",
        info.adapter,
        info.driver,
        info.backend,
        info.width,
        info.height,
        info.commit,
        info.profile,
        super::measure::timing_label(info.gpu_timestamps),
    );
    s += "| case | size | parcels | clouds (ms) | of which (ms) | GPU frame (ms) | goal (clouds) | result |\n";
    s += "|---|---|---:|---:|---|---:|---|---|\n";
    for r in rows {
        let goal = r.goal_ms.map_or("–".to_string(), |g| format!("≤ {g} ms"));
        let verdict = match (r.goal_ms, r.verdict(judged)) {
            (None, _) => "",
            (Some(_), None) => "not judged (CPU adapter)",
            (Some(_), Some(true)) => "pass",
            (Some(_), Some(false)) => "**FAIL**",
        };
        s += &format!(
            "| {} | {}×{} | {} | {:.3} | {} | {:.3} | {goal} | {verdict} |\n",
            r.case,
            r.width,
            r.height,
            r.parcels,
            r.clouds_ms,
            parts_text(&r.parts),
            r.gpu_ms
        );
    }
    let goals = rows.iter().filter(|r| r.goal_ms.is_some()).count();
    let met = rows
        .iter()
        .filter(|r| r.verdict(judged) == Some(true))
        .count();
    s += &if judged {
        format!("\n{met} of {goals} goals met.\n")
    } else {
        format!(
            "\nThe goals are for a discrete GPU at {}×{}; this CPU adapter's figures are not judged.\n",
            SIZE.0, SIZE.1
        )
    };
    s += "\n\"clouds\": every GPU pass the clouds cost besides the shadow map, sky, terrain and tone map (bake re-done every frame, march, temporal resolve, sprites, slices and their vertex field, composite), and where the tone map blends the cloud image instead of a composite pass, its time over the plain tone map of the same frame.\n";
    s
}

/// `gpu-check.csv`.
pub fn check_csv(rows: &[CheckRow]) -> Result<Vec<u8>> {
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.case.clone(),
                r.width.to_string(),
                r.height.to_string(),
                r.parcels.to_string(),
                format!("{:.4}", r.clouds_ms),
                format!("{:.4}", r.gpu_ms),
                r.goal_ms.map_or(String::new(), |g| g.to_string()),
                parts_text(&r.parts),
            ]
        })
        .collect();
    super::report::csv_bytes(
        &[
            "case",
            "width",
            "height",
            "parcels",
            "clouds_ms",
            "gpu_ms",
            "goal_ms",
            "clouds_parts",
        ],
        &body,
    )
}

/// Writes `gpu-check.md` and `gpu-check.csv` into `dir`, each whole or
/// not at all.
pub fn write(dir: &Path, md: &str, rows: &[CheckRow]) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| crate::error::Error::io(dir, e))?;
    crate::output::write_atomic(&dir.join("gpu-check.csv"), &check_csv(rows)?)?;
    crate::output::write_atomic(&dir.join("gpu-check.md"), md.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_size_keeps_its_proportion_at_a_test_size() {
        assert_eq!(scaled(PAPER_SIZE, SIZE), PAPER_SIZE);
        assert_eq!(scaled(PAPER_SIZE, (192, 108)), (73, 55));
        assert_eq!(scaled(PAPER_SIZE, (32, 18)), (16, 16));
    }

    #[test]
    fn a_goal_is_judged_only_on_a_gpu() {
        let r = CheckRow {
            case: "x".into(),
            width: 1,
            height: 1,
            parcels: 0,
            clouds_ms: 1.5,
            parts: vec![("clouds".into(), 1.5)],
            gpu_ms: 2.0,
            goal_ms: Some(1.0),
        };
        assert_eq!(r.verdict(true), Some(false));
        assert_eq!(r.verdict(false), None);
        let r = CheckRow {
            clouds_ms: 0.5,
            ..r
        };
        assert_eq!(r.verdict(true), Some(true));
        assert_eq!(CheckRow { goal_ms: None, ..r }.verdict(true), None);
    }
}
