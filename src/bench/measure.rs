//! Timing one frame configuration: warm-up frames (pipeline compilation,
//! caches), then the median of several measured frames. A frame is one
//! physics step (optional) + packing/upload + the render passes; pass times
//! come from GPU timestamps when the device has them, else from the CPU
//! clock with a queue sync after each pass (the renderer labels which).

use std::time::Instant;

use crate::config::Camera;
use crate::error::{Error, Result};
use crate::physics::{CloudParcel, ParcelWorld};
use crate::render::headless::Headless;
use crate::render::{FrameInput, GpuContext};
use crate::sky::Sun;

use super::stats::median;

/// Simulated time one physics frame advances in the performance table (the
/// default largest sub-step, so one frame is usually one sub-step). units: s
pub const PHYSICS_FRAME_DT_S: f64 = 1.0;

/// What a measured frame draws.
#[derive(Clone, Copy)]
pub enum Source<'a> {
    /// Step a copy of this world one frame (timed), then draw its condensed
    /// parcels; there must be exactly `expected` of them.
    World {
        world: &'a ParcelWorld,
        expected: usize,
    },
    /// Draw these parcels (no physics).
    Parcels(&'a [CloudParcel]),
}

/// Medians over the measured frames. units: ms
#[derive(Debug, Clone)]
pub struct Measured {
    /// Physics step (0 without physics).
    pub physics_ms: f64,
    /// Packing and buffer writes.
    pub upload_ms: f64,
    /// (pass, median ms) in execution order.
    pub passes: Vec<(String, f64)>,
    /// Median of the per-frame GPU time of the whole frame (first to last
    /// timestamp; with CPU timing, the sum of the passes).
    pub gpu_ms: f64,
    /// Median of the per-frame upload + GPU frame (no physics).
    pub render_ms: f64,
    /// Median of the per-frame physics + upload + GPU frame.
    pub frame_ms: f64,
    /// Frames measured (after warm-up).
    pub frames: usize,
    /// Pass times from GPU timestamps (else CPU clock + queue sync).
    pub gpu_timestamps: bool,
    /// The last frame (RGBA8 sRGB, top row first).
    pub rgba: Vec<u8>,
}

impl Measured {
    /// Median time of one pass, if it ran. units: ms
    pub fn pass_ms(&self, name: &str) -> Option<f64> {
        self.passes.iter().find(|(n, _)| n == name).map(|(_, m)| *m)
    }

    /// Sum of the medians of the parts (physics, upload, each pass): the
    /// denominator of the shares, so that they add up to 100 %. units: ms
    pub fn parts_ms(&self) -> f64 {
        self.physics_ms + self.upload_ms + self.passes.iter().map(|(_, m)| m).sum::<f64>()
    }

    /// Frames per second at the median frame time.
    pub fn fps(&self) -> f64 {
        1000.0 / self.frame_ms
    }
}

/// How the pass times were taken, for tables.
pub fn timing_label(gpu_timestamps: bool) -> &'static str {
    if gpu_timestamps {
        "gpu_timestamps"
    } else {
        "cpu_clock_queue_sync"
    }
}

/// How many frames to render for one measurement.
#[derive(Debug, Clone, Copy)]
pub struct Repeats {
    /// Warm-up frames of the real scene (skipped once one frame alone
    /// would exceed the budget: the pipelines are compiled by then).
    pub warmup: usize,
    /// Most measured frames.
    pub measured: usize,
    /// Wall-clock budget of one measurement: no further frame starts once
    /// it is spent, but at least one frame is always measured. units: ms
    pub budget_ms: f64,
}

/// Renders one cheap frame (the first parcel alone) so that the pipelines
/// are compiled before anything is timed (software adapters compile on the
/// first draw); then warm-up frames of the real scene while they fit the
/// budget, then measured frames while they fit the budget (at least one).
pub fn measure(
    ctx: &GpuContext,
    hl: &mut Headless,
    camera: Camera,
    sun: Sun,
    source: Source<'_>,
    reps: Repeats,
) -> Result<Measured> {
    measure_at(ctx, hl, (camera, sun, 0.0), source, reps)
}

/// [`measure`] from `camera` under `sun` at the simulated time `time_s`
/// (what an authored scene's animation and its sprite clouds show then;
/// a scene is measured at the time it opens on). units: s
pub fn measure_at(
    ctx: &GpuContext,
    hl: &mut Headless,
    (camera, sun, time_s): (Camera, Sun, f32),
    source: Source<'_>,
    reps: Repeats,
) -> Result<Measured> {
    let mut physics = Vec::new();
    let mut upload = Vec::new();
    let mut gpu = Vec::new();
    let mut render = Vec::new();
    let mut total = Vec::new();
    let mut per_pass: Vec<(String, Vec<f64>)> = Vec::new();

    let first: Vec<CloudParcel> = match source {
        Source::World { world, .. } => super::scenes::cloud_parcels(world),
        Source::Parcels(p) => p.to_vec(),
    };
    let compile = FrameInput {
        camera,
        parcels: &first[..first.len().min(1)],
        sun,
        time_s,
    };
    hl.render(ctx, &compile)?;
    // `march = "auto"` measures both paths in its first frames with clouds:
    // let it decide on the real scene before anything is timed.
    let scene = FrameInput {
        parcels: &first,
        ..compile
    };
    for _ in 0..2 * (crate::methods::raymarch::auto_march::SAMPLES + 2) {
        if hl.renderer.march_path().is_some() || first.is_empty() {
            break;
        }
        hl.render(ctx, &scene)?;
    }

    let start = Instant::now();
    let mut warm_left = reps.warmup;
    // (timestamps?, image) of the last measured frame.
    let last = loop {
        let frame_start = Instant::now();
        let (physics_ms, parcels) = match source {
            Source::World { world, expected } => {
                let mut w = world.clone();
                let t0 = Instant::now();
                w.step(PHYSICS_FRAME_DT_S);
                let ms = t0.elapsed().as_secs_f64() * 1e3;
                let parcels = super::scenes::cloud_parcels(&w);
                if parcels.len() != expected {
                    return Err(Error::invalid(
                        "bench scene condensed parcels after one frame",
                        parcels.len(),
                        format!("exactly {expected}"),
                    ));
                }
                (ms, parcels)
            }
            Source::Parcels(p) => (0.0, p.to_vec()),
        };
        let input = FrameInput {
            camera,
            parcels: &parcels,
            sun,
            time_s,
        };
        let (img, t) = hl.render(ctx, &input)?;
        if t.passes.iter().any(|(_, ms)| !ms.is_finite()) {
            return Err(Error::Gpu(format!(
                "a pass time could not be read: {:?}",
                t.passes
            )));
        }
        let frame_wall_ms = frame_start.elapsed().as_secs_f64() * 1e3;
        if warm_left > 0 && frame_wall_ms * 2.0 <= reps.budget_ms {
            warm_left -= 1;
            continue;
        }
        warm_left = 0;
        let g = t.frame_ms;
        physics.push(physics_ms);
        upload.push(t.upload_ms);
        gpu.push(g);
        render.push(t.upload_ms + g);
        total.push(physics_ms + t.upload_ms + g);
        for (name, ms) in t.passes {
            match per_pass.iter_mut().find(|(n, _)| *n == name) {
                Some((_, v)) => v.push(ms),
                None => per_pass.push((name, vec![ms])),
            }
        }
        let spent = start.elapsed().as_secs_f64() * 1e3;
        if total.len() >= reps.measured.max(1) || spent >= reps.budget_ms {
            break (t.gpu_timestamps, img);
        }
    };
    Ok(Measured {
        physics_ms: median(&physics),
        upload_ms: median(&upload),
        passes: per_pass.into_iter().map(|(n, v)| (n, median(&v))).collect(),
        gpu_ms: median(&gpu),
        render_ms: median(&render),
        frame_ms: median(&total),
        frames: total.len(),
        gpu_timestamps: last.0,
        rgba: last.1,
    })
}
