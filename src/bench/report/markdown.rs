//! The Markdown of a bench run: performance.md, report.md with every
//! section, and the targets with their verdicts.

use std::fmt::Write as _;

use super::{md, pass_names};
use crate::bench::measure::timing_label;
use crate::bench::pathtraced::PathTracedRow;
use crate::bench::perf::{PerfRow, ScalingRow, on_off};
use crate::bench::{BenchResults, Mode, RunInfo};

/// Header lines shared by the Markdown files.
fn header(info: &RunInfo) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "| | |\n|---|---|");
    let _ = writeln!(s, "| adapter | {} |", info.adapter);
    let _ = writeln!(s, "| driver | {} |", info.driver);
    let _ = writeln!(s, "| backend | {} |", info.backend);
    let _ = writeln!(
        s,
        "| adapter type | {} |",
        if info.cpu_adapter {
            "CPU (software)"
        } else {
            "GPU"
        }
    );
    let _ = writeln!(
        s,
        "| pass timing | {} |",
        if info.gpu_timestamps {
            "GPU timestamps per pass"
        } else {
            "CPU wall clock with a queue sync per pass"
        }
    );
    let _ = writeln!(s, "| resolution | {}×{} |", info.width, info.height);
    let _ = writeln!(s, "| build profile | {} |", info.profile);
    let _ = writeln!(s, "| commit | {} |", info.commit);
    let _ = writeln!(
        s,
        "| mode | {} (per measurement: a pipeline warm-up frame, up to {} warm-up and {} measured frames within {:.1} s; medians) |",
        match info.mode {
            Mode::Full => "full",
            Mode::Quick => "quick",
            Mode::Tiny => "tiny",
        },
        info.reps.warmup,
        info.reps.measured,
        info.reps.budget_ms / 1000.0
    );
    s
}

/// The performance table in Markdown.
pub fn performance_table(rows: &[PerfRow]) -> String {
    let mut s = String::new();
    let passes = pass_names();
    let _ = write!(
        s,
        "| parcels | normals | shadows | physics ms (%) | upload ms (%) |"
    );
    for p in &passes {
        let _ = write!(s, " {p} ms (%) |");
    }
    let _ = writeln!(s, " GPU frame ms | frame ms | fps | frames |");
    let _ = write!(s, "|---:|:---:|:---:|---:|---:|");
    for _ in &passes {
        let _ = write!(s, "---:|");
    }
    let _ = writeln!(s, "---:|---:|---:|---:|");
    for r in rows {
        let m = &r.m;
        let cell = |v: f64| format!("{} ({:.1})", md(v, 2), 100.0 * v / m.parts_ms());
        let _ = write!(
            s,
            "| {} | {} | {} | {} | {} |",
            r.parcels,
            on_off(r.normals),
            on_off(r.shadows),
            cell(m.physics_ms),
            cell(m.upload_ms)
        );
        for p in &passes {
            let _ = write!(
                s,
                " {} |",
                m.pass_ms(p).map_or_else(|| "–".to_string(), cell)
            );
        }
        let _ = writeln!(
            s,
            " {} | {} | {} | {} |",
            md(m.gpu_ms, 2),
            md(m.frame_ms, 2),
            md(m.fps(), 1),
            m.frames
        );
    }
    s
}

/// performance.md.
pub fn performance_md(info: &RunInfo, rows: &[PerfRow]) -> String {
    format!(
        "# cumulus performance\n\n{}\n\
         Scenes hold exactly the listed number of condensed parcels (towers of up to 10 \
         saturated cloudy parcels on a jittered lattice; the count of `cloud_parcels` is \
         checked after every frame). A frame is one physics step of {} s (all terms on), \
         packing + upload, and every render pass, run one after the other; times are medians \
         over the measured frames; a part's share is its median over the sum of the parts' medians. \"–\": the pass does not run in \
         that variant. Pass times: {}. {}\n\n{}",
        header(info),
        crate::bench::measure::PHYSICS_FRAME_DT_S,
        timing_label(info.gpu_timestamps),
        FRAME_COLUMNS,
        performance_table(rows)
    )
}

/// What the performance table's two frame columns hold.
const FRAME_COLUMNS: &str = "GPU frame ms: the GPU time of the whole frame, from its first to its \
     last timestamp (not a sum of the passes' medians; the scaling targets use it). frame ms: \
     the physics step + packing and upload (CPU) + the GPU frame, the median of their sums; \
     fps = 1000 / frame ms.";

/// One target: what, measured value, limit, verdict.
#[derive(Debug, Clone)]
pub struct Target {
    pub name: String,
    pub measured: String,
    pub goal: String,
    /// None = could not be measured in this run.
    pub pass: Option<bool>,
}

fn perf_row(rows: &[PerfRow], n: usize, normals: bool, shadows: bool) -> Option<&PerfRow> {
    rows.iter()
        .find(|r| r.parcels == n && r.normals == normals && r.shadows == shadows)
}

/// The targets measured within this run (default variant: normals off,
/// shadows on).
pub fn targets(r: &BenchResults) -> Vec<Target> {
    let p = &r.performance;
    let mut out = Vec::new();
    // Both shadow variants: the shadow pass costs the same whatever the
    // parcel count, so with shadows on it hides how the cloud pass grows.
    for shadows in [true, false] {
        let f8 = perf_row(p, 8, false, shadows);
        let f85 = perf_row(p, 85, false, shadows);
        let ratio = f8.zip(f85).map(|(a, b)| b.m.frame_ms / a.m.frame_ms);
        out.push(Target {
            name: format!(
                "frame at 85 parcels / frame at 8 (normals off, shadows {})",
                if shadows { "on" } else { "off" }
            ),
            measured: ratio.map_or("not measured".into(), |x| format!("{x:.2}×")),
            goal: "≤ 2× (paper ≈ 11×)".into(),
            pass: ratio.map(|x| x <= 2.0),
        });
    }
    let f85 = perf_row(p, 85, false, true);
    let on = perf_row(p, 85, true, true);
    let ratio = on.zip(f85).map(|(a, b)| a.m.frame_ms / b.m.frame_ms);
    out.push(Target {
        name: "normals cost: frame with / without normals (85 parcels, shadows on)".into(),
        measured: ratio.map_or("not measured".into(), |x| format!("{x:.2}×")),
        goal: "≤ 1.2× (issue 9; paper 1.8–3×)".into(),
        pass: ratio.map(|x| x <= 1.2),
    });
    let share = f85.map(|b| b.m.physics_ms / b.m.parts_ms());
    out.push(Target {
        name: "physics share of the frame (85 parcels, normals off, shadows on)".into(),
        measured: share.map_or("not measured".into(), |x| format!("{:.1} %", 100.0 * x)),
        goal: "≤ 5 %".into(),
        pass: share.map(|x| x <= 0.05),
    });
    // The default method against the paper's at the same settings
    // (methods.md: same parcels, sun and camera; the worst scene).
    let baked = r
        .methods
        .iter()
        .filter(|m| m.method == crate::config::RenderMethod::Baked)
        .filter_map(|m| m.mean_flip_vs_exact.map(|f| (f, m.scene.as_str())))
        .max_by(|a, b| a.0.total_cmp(&b.0));
    out.push(Target {
        name: "baked against exact at the same settings (methods.md, worst scene)".into(),
        measured: baked.map_or("not measured".into(), |(f, scene)| {
            format!("mean FLIP {f:.4} ({scene})")
        }),
        goal: "mean FLIP ≤ 0.02 (issue 9)".into(),
        pass: baked.map(|(f, _)| f <= 0.02),
    });
    let e = &r.render_error;
    let d = e.default_row();
    let frac = d.time_ms / e.reference_ms;
    out.push(Target {
        name: "default render settings against the reference".into(),
        measured: format!(
            "mean FLIP {:.4} at {:.3} of the reference's run time{}",
            d.mean_flip,
            frac,
            if e.reference.grid_culling {
                " (reference rendered with exact grid culling on this CPU adapter, so cheaper \
                 than brute force)"
            } else {
                ""
            }
        ),
        goal: "mean FLIP ≤ 0.03 at ≤ 1/8 (0.125) of the reference's run time".into(),
        pass: Some(d.mean_flip <= 0.03 && frac <= 0.125),
    });
    out
}

fn verdict(p: Option<bool>) -> &'static str {
    match p {
        Some(true) => "**pass**",
        Some(false) => "**FAIL**",
        None => "not measured",
    }
}

/// report.md: every section.
pub fn report_md(r: &BenchResults) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# cumulus bench report\n\n{}", header(&r.info));

    let _ = writeln!(
        s,
        "## Performance\n\nParcel count × normals × shadows (also in performance.md and \
         performance.csv). A frame = one physics step of {} s + upload + all passes, one after \
         the other; medians; shares in parentheses are % of the sum of the parts' medians. {}\n\n{}",
        crate::bench::measure::PHYSICS_FRAME_DT_S,
        FRAME_COLUMNS,
        performance_table(&r.performance)
    );

    let e = &r.render_error;
    let _ = writeln!(
        s,
        "## Error against run time\n\n### Render settings\n\n\
         One fixed frame ({} condensed parcels, bench camera, terrain and shadows on) at a \
         sweep of settings, each differing from the default in one parameter, against a \
         reference rendered with step {} m (1/16 of the default), {} octaves, {} light samples \
         (the default light march), {} and no early exit, {}×{} rays per pixel; the reference \
         took {} ms. The light-steps rows keep the default light march's length where a first \
         step of at least 1 m allows (see below). Lower resolutions are upscaled \
         (bilinear) to {}×{} before comparing. Error: mean FLIP (nv-flip, default viewing \
         conditions) and RMSE of sRGB values on 0..1. Pareto: no other setting is both \
         faster and more accurate (in mean FLIP). Plot: error_vs_runtime.png (log–log, \
         Pareto points ringed); reference frame: reference.png.\n",
        e.parcels,
        e.reference.step_m,
        e.reference.noise_octaves,
        e.reference.light_steps,
        if e.reference.grid_culling {
            "with grid culling instead of brute force (this is a CPU adapter: Mesa llvmpipe \
             drops whole towers from brute-force marches beyond ~2000 steps, while the grid \
             path takes exactly the brute-force samples; see the exactness line below)"
        } else {
            "every parcel at every sample (no grid culling)"
        },
        crate::bench::accuracy::REFERENCE_SUPERSAMPLE,
        crate::bench::accuracy::REFERENCE_SUPERSAMPLE,
        md(e.reference_ms, 1),
        e.width,
        e.height
    );
    let _ = writeln!(
        s,
        "How the reference differs from each tested setting (besides the swept parameter):\n"
    );
    for d in crate::bench::accuracy::REFERENCE_DIFFERENCES {
        let _ = writeln!(s, "- {d}");
    }
    let _ = writeln!(s);
    if let Some((flip, err)) = e.culling_vs_brute {
        let _ = writeln!(
            s,
            "Exactness of grid culling: at the default settings with the exact method, the \
             grid-culled frame against the brute-force frame has mean FLIP {flip:.5} and RMSE {err:.5} (0 = identical).\n"
        );
    }
    let _ = writeln!(
        s,
        "| parameter | value | size | time ms | time / reference | mean FLIP | RMSE | Pareto |\n\
         |---|---|---|---:|---:|---:|---:|:---:|"
    );
    for row in &e.rows {
        let _ = writeln!(
            s,
            "| {} | {} | {}×{} | {} | {} | {} | {} | {} |",
            row.parameter,
            row.value,
            row.width,
            row.height,
            md(row.time_ms, 2),
            md(row.time_ms / e.reference_ms, 3),
            md(row.mean_flip, 4),
            md(row.rmse, 4),
            if row.pareto { "★" } else { "" }
        );
    }
    s.push_str(&pathtraced_md(r.pathtraced.as_deref()));

    let ph = &r.physics_error;
    let _ = writeln!(
        s,
        "\n### Physics time step\n\n\
         {} parcels released warm and moist at 500–740 m (all terms on, deaths off) simulated \
         for {} s with the frame step = largest sub-step dt (the CFL, sound-speed and \
         acceleration limits may split it: see sub-steps), against a reference at dt = {} s \
         ({} ms; at the end {} of its parcels are condensed, cloud top {}). Error: RMS distance of the parcels from their reference positions; also \
         cloud top and total water. Observed order = log2(error at 2·dt / error at dt). \
         Plot: physics_error_vs_runtime.png.\n\n\
         | dt s | sub-steps | time ms | position RMS m | cloud top err m | water rel. err | observed order | Pareto |\n\
         |---:|---:|---:|---:|---:|---:|---:|:---:|",
        ph.parcels,
        ph.duration_s,
        ph.reference_dt_s,
        md(ph.reference_ms, 1),
        ph.reference_condensed,
        ph.reference_cloud_top_m
            .map_or("none".into(), |z| format!("{z:.0} m"))
    );
    for row in &ph.rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            row.dt_s,
            row.substeps,
            md(row.time_ms, 2),
            md(row.position_rms_m, 3),
            md(row.cloud_top_err_m, 2),
            if row.water_rel_err.is_finite() {
                format!("{:.2e}", row.water_rel_err)
            } else {
                "–".into()
            },
            md(row.order, 2),
            if row.pareto { "★" } else { "" }
        );
    }

    s.push_str(&crate::bench::physics_speed::physics_speed_md(
        &r.physics_speed,
    ));
    let _ = writeln!(
        s,
        "\n## Scaling\n\nGPU time of the whole frame (first to last timestamp, default \
         settings, no physics) against the number of condensed parcels, per method: `baked` \
         (macro field baked into a 3D texture; re-baked in every measured frame, the cost when \
         every parcel moves), `exact` (the paper's path, grid culling) and `brute` (exact, \
         every parcel at every sample). Exact and brute stop at {} parcels (the uniform \
         arrays); brute force at {} in this mode. mean/max list: the exact grid's parcel lists \
         over non-empty cells; coarsened: how often the grid was halved to fit. Plot: \
         scaling.png.\n\n| parcels | method | frame ms | clouds ms | bake ms | mean list | max list | coarsened |\n|---:|---|---:|---:|---:|---:|---:|---:|",
        crate::methods::raymarch::pack::MAX_PARCELS,
        r.scaling
            .iter()
            .filter(|row| row.method == "brute")
            .map(|row| row.parcels)
            .max()
            .unwrap_or(0)
    );
    for row in &r.scaling {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            row.parcels,
            row.method,
            md(row.frame_ms, 2),
            md(row.clouds_ms, 2),
            md(row.bake_ms, 2),
            row.mean_list.map_or("–".into(), |v| md(v, 1)),
            row.max_list.map_or("–".into(), |v| v.to_string()),
            row.coarsened.map_or("–".into(), |v| v.to_string()),
        );
    }
    let _ = writeln!(s, "\n{}", scaling_targets(&r.scaling));
    if let Some(c) = &r.clipmap {
        s.push_str(&crate::bench::clipmap::markdown(c));
    }

    let all = r.pruning.first().map_or(f64::NAN, |p| p.frame_ms);
    let _ = writeln!(
        s,
        "\n## Pruning savings\n\nA scene with terrain, cloud shadows, normals and the aerial \
         perspective against the same scene with each left out (no terrain also means no \
         shadow pass; no aerial perspective removes its code from the terrain and cloud passes). Frame = upload \
         + passes.\n\n| variant | passes | frame ms | / all |\n|---|---|---:|---:|"
    );
    for row in &r.pruning {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            row.variant,
            row.passes,
            md(row.frame_ms, 2),
            md(row.frame_ms / all, 2)
        );
    }

    s.push_str(&crate::bench::landscape::landscape_md(&r.landscape));

    let _ = writeln!(
        s,
        "\n## Targets\n\nRatios measured within this run, so they hold for this adapter \
         and resolution only.\n\n| target | measured | goal | verdict |\n|---|---|---|---|"
    );
    for t in targets(r) {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            t.name,
            t.measured,
            t.goal,
            verdict(t.pass)
        );
    }
    s
}

/// The "against the path tracer" section of report.md.
fn pathtraced_md(rows: Option<&[PathTracedRow]>) -> String {
    let mut s = String::from("\n### Against a path tracer\n\n");
    let Some(rows) = rows else {
        s.push_str(
            "Not measured: no error_vs_pathtraced.csv in this folder. Write it first with \
             `python3 benches/pathtraced.py --out DIR` (DIR = this folder; see docs/validation.md).\n",
        );
        return s;
    };
    s.push_str(
        "From error_vs_pathtraced.csv (benches/pathtraced.py): the same frame exported with \
         `cumulus export` and path-traced with Mitsuba 3 `volpath` (multiple scattering, our \
         phase function, sun and sky, terrain and aerial perspective off in both: Mitsuba's \
         scene has no ground and no air), shown through our tone curve; our renders at each \
         setting against it (mean FLIP, RMSE of display sRGB on 0..1). Our picture differs \
         by design where the real-time lighting approximates light transport: the multiply \
         scattered sun as a two-stream diffusion term with a fitted gain and powder, dimmed \
         where the cloud ends behind the sample, instead of all paths, the skylight as the sky's irradiance shaded by one look up through \
         the light volume, a short light march with growing steps; and the baked voxels \
         smooth the finest noise octave. Second panel of error_vs_runtime.png.\n\n\
         | setting | time ms | mean FLIP | RMSE |\n|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            r.setting,
            md(r.time_ms, 1),
            md(r.mean_flip, 4),
            md(r.rmse, 4)
        );
    }
    s
}

/// The project's scaling targets for `baked`, as ratios within this run.
pub fn scaling_targets(rows: &[ScalingRow]) -> String {
    let frame = |n: usize| {
        rows.iter()
            .find(|r| r.method == "baked" && r.parcels == n)
            .map(|r| r.frame_ms)
    };
    let mut s = format!(
        "Targets (baked, ratios within this run; each frame the median of {} rounds taken \
         in turn over the counts):\n",
        crate::bench::perf::BAKED_ROUNDS
    );
    for (n, goal) in [(1024, 1.5), (4096, 2.0)] {
        let line = match frame(n).zip(frame(85)) {
            Some((a, b)) => {
                let ratio = a / b;
                format!(
                    "- frame({n}) / frame(85) = {} (target ≤ {goal}: {})\n",
                    md(ratio, 2),
                    if ratio <= goal { "met" } else { "NOT met" }
                )
            }
            None => format!("- frame({n}) / frame(85): not measured in this mode\n"),
        };
        s.push_str(&line);
    }
    let bake = |n: usize| {
        rows.iter()
            .find(|r| r.method == "baked" && r.parcels == n)
            .map(|r| r.bake_ms)
    };
    // The bake takes every parcel in one dispatch: its cost is the splat's
    // parcels × box voxels plus the resolve over a region capped at
    // MAX_BAKE_VOXELS, so ten times the parcels must not cost ten times.
    s.push_str(&match bake(10_000).zip(bake(1000)) {
        Some((a, b)) => {
            let ratio = a / b;
            format!(
                "- bake(10000) / bake(1000) = {} (target ≤ 2: {})\n",
                md(ratio, 2),
                if ratio <= 2.0 { "met" } else { "NOT met" }
            )
        }
        None => "- bake(10000) / bake(1000): not measured in this mode\n".into(),
    });
    s
}
